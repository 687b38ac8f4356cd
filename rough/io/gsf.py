"""GSF: Gwyddion Simple Field, read and written.

The line ``Gwyddion Simple Field 1.0``, then ``Key = Value`` lines (XRes and YRes
required; XReal, YReal, XOffset, YOffset, XYUnits, ZUnits, Title optional), then 1–4
NUL bytes so that the data start at a multiple of 4, then XRes·YRes little-endian
float32 values, row-major. A field one row high (YRes = 1) is a profile.

Values are float32, so a round trip keeps heights to float32 rounding. rough writes
metres and keeps its units, metadata and history in the extra keys ``rough.units``,
``rough.metadata`` and ``rough.history`` (JSON on one line), which Gwyddion shows as
metadata.
"""

import numpy as np

from ..errors import FormatError
from ..surface import Surface, Units
from ..units import metres_per
from . import provenance
from .registry import Format

FORMAT = Format(
    "gsf",
    "Gwyddion Simple Field",
    (".gsf",),
    magic=(b"Gwyddion Simple Field",),
    writes=True,
    carries=("spacing", "units", "metadata", "mask", "history"),
    height_type="float32",
)

MAGIC = b"Gwyddion Simple Field 1.0"
MAX_HEADER_BYTES = 1 << 20


def read(data, options):
    end = bytes(data[:MAX_HEADER_BYTES]).find(b"\0")
    if end < 0:
        raise FormatError("GSF header is not terminated by a NUL byte")
    lines = bytes(data[:end]).decode("utf-8", "replace").splitlines()
    if lines[0].strip() != MAGIC.decode():
        raise FormatError(f"not a GSF 1.0 file (first line {lines[0][:40]!r})")
    header = {}
    for line in lines[1:]:
        key, equals, value = line.partition("=")
        if equals:
            header[key.strip()] = value.strip()
    nx, ny = _count(header, "XRes"), _count(header, "YRes")
    start = end + (4 - end % 4)
    needed = nx * ny * 4
    if len(data) - start != needed:
        raise FormatError(f"GSF declares {nx}×{ny} points ({needed} bytes) but holds {len(data) - start} bytes of data")
    heights = np.frombuffer(data, "<f4", count=nx * ny, offset=start).astype(np.float64)
    z_factor = metres_per(header.get("ZUnits") or "m")
    xy_factor = metres_per(header.get("XYUnits") or "m")
    if z_factor != 1.0:
        heights *= z_factor
    real = [_real(header, "XReal", nx) * xy_factor, _real(header, "YReal", ny) * xy_factor]
    offsets = [_float(header, "XOffset", 0.0) * xy_factor, _float(header, "YOffset", 0.0) * xy_factor]
    spacing = (real[0] / nx, real[1] / ny)
    metadata, units, history = _extras(header)
    if ny == 1:
        return Surface(heights, spacing[:1], offsets[:1], units, metadata, history)
    return Surface(heights.reshape(ny, nx), spacing, tuple(offsets), units, metadata, history)


def write(surface, stream):
    nx, ny = (*surface.points, 1)[:2]
    dy = surface.spacing[1] if len(surface.spacing) == 2 else surface.spacing[0]
    y0 = surface.origin[1] if len(surface.origin) == 2 else 0.0
    lines = [
        MAGIC.decode(),
        f"XRes = {nx}",
        f"YRes = {ny}",
        f"XReal = {nx * surface.spacing[0]!r}",
        f"YReal = {ny * dy!r}",
        f"XOffset = {surface.origin[0]!r}",
        f"YOffset = {y0!r}",
        "XYUnits = m",
        "ZUnits = m",
    ]
    if surface.metadata.get("title"):
        lines.append(f"Title = {_one_line(surface.metadata['title'])}")
    lines += [f"rough.{part} = {text}" for part, text in provenance.record(surface).items()]
    header = ("\n".join(lines) + "\n").encode("utf-8")
    stream.write(header + bytes(4 - len(header) % 4))
    stream.write(memoryview(np.ascontiguousarray(surface.heights, dtype="<f4")).cast("B"))


def _count(header, key):
    value = header.get(key, "")
    if not value.isdigit() or int(value) < 1:
        raise FormatError(f"GSF {key} must be a positive whole number, not {value!r}")
    return int(value)


def _float(header, key, default):
    try:
        value = float(header.get(key, default))
    except ValueError:
        raise FormatError(f"GSF {key} is not a number: {header[key]!r}") from None
    if not np.isfinite(value):
        raise FormatError(f"GSF {key} is not finite")
    return value


def _real(header, key, n):
    value = _float(header, key, float(n))
    if value <= 0:
        raise FormatError(f"GSF {key} must be a positive length, not {value}")
    return value


def _extras(header):
    metadata = {"title": header["Title"]} if header.get("Title") else {}
    units = Units(header.get("XYUnits") or "m", header.get("ZUnits") or "m")
    return provenance.restore({part: header.get(f"rough.{part}") for part in provenance.PARTS}, metadata, units)


def _one_line(text):
    """Header-safe text: no line breaks, NULs or other control characters (the exact
    title travels in rough.metadata)."""
    return " ".join("".join(c if c.isprintable() else " " for c in str(text)).split())
