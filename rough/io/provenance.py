"""rough's own record of a surface's units, metadata and history, as every format
carries it (X3P: a vendor member; EXR: header attributes; GSF: extra keys; text:
``#`` lines). Each format stores the three parts in its own place."""

import json

from ..errors import FormatError
from ..surface import Units

PARTS = ("units", "metadata", "history")


def parts(surface):
    """The three parts as JSON-able objects, keyed by part name."""
    units = {"xy": surface.units.xy, "z": surface.units.z}
    if surface.units.assumed:  # files written before 0.15 had no such key: written only when it says something
        units["assumed"] = list(surface.units.assumed)
    return {"units": units, "metadata": surface.metadata, "history": surface.history}


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
        stated = given["units"]
        assumed = stated.get("assumed", [])
        if not isinstance(assumed, list):
            raise FormatError("rough's units record in the file is damaged")
        units = Units(**{k: str(stated[k]) for k in ("xy", "z") if k in stated}, assumed=tuple(map(str, assumed)))
    history = given.get("history", [])
    for number, entry in enumerate(history, start=1):
        if not isinstance(entry, dict) or not isinstance(entry.get("parameters", {}), dict):
            raise FormatError(f"rough's history record in the file is damaged (entry {number} is malformed)")
    return metadata, units or Units(), history
