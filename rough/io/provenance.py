"""rough's own record of a surface's units, metadata and history, as every format
carries it (X3P: a vendor member; EXR: header attributes; GSF: extra keys; text:
``#`` lines). Each format stores the three parts in its own place."""

import json

from ..errors import FormatError
from ..surface import Units

PARTS = ("units", "metadata", "history")


def parts(surface):
    """The three parts as JSON-able objects, keyed by part name."""
    return {"units": vars(surface.units), "metadata": surface.metadata, "history": surface.history}


def record(surface):
    """The JSON text of each part, keyed by part name."""
    return {key: json.dumps(value) for key, value in parts(surface).items()}


def restore(stored, metadata=None, units=None):
    """``(metadata, units, history)`` from the parts a file carries (JSON text or
    parsed objects; any part may be missing), on top of what the file's own header
    said."""
    given = {part: json.loads(value) if isinstance(value, str) else value for part, value in stored.items() if value}
    for part, kind in (("units", dict), ("metadata", dict), ("history", list)):
        if part in given and not isinstance(given[part], kind):
            raise FormatError(f"rough's {part} record in the file is damaged")
    metadata = {**(metadata or {}), **{str(k): str(v) for k, v in given.get("metadata", {}).items()}}
    if "units" in given:
        units = Units(**{k: str(v) for k, v in given["units"].items() if k in ("xy", "z")})
    history = given.get("history", [])
    for number, entry in enumerate(history, start=1):
        if not isinstance(entry, dict) or not isinstance(entry.get("parameters", {}), dict):
            raise FormatError(f"rough's history record in the file is damaged (entry {number} is malformed)")
    return metadata, units or Units(), history
