"""TrueMap TMD (TrueMap, GelSight exports), read only.

Layout (little-endian), as SurfaceTopography's and surfalize's readers read it: a
32-byte magic ``Binary TrueMap Data File v2.0\\r\\n\\0``, a 24-byte comment (v2 only),
then uint32 width and height (points), float32 x and y lengths and x and y offsets,
then width × height float32 heights, row by row, x fastest (the first stored row is
row 0 here), which end the file (a file of another length is refused). The format
names no unit: lengths and heights are taken as micrometres, as both readers do.
Spacing is length / points; NaN heights stay invalid. Version 1 files (no comment
field) are read by the same rule.
"""

import struct

import numpy as np

from ..errors import FormatError
from ..surface import Surface, Units, check_size
from .header import check_length
from .registry import Format

FORMAT = Format(
    "tmd", "TrueMap TMD", (".tmd",), magic=(b"Binary TrueMap Data File",), carries=("spacing", "units", "mask")
)

MAGIC_SIZE, COMMENT_SIZE = 32, 24
MICROMETRE = 1e-6


def read(data, options):
    data = bytes(data)
    version_two = data[:MAGIC_SIZE].startswith(b"Binary TrueMap Data File v2")
    position = MAGIC_SIZE + (COMMENT_SIZE if version_two else 0)
    if len(data) < position + 24:
        raise FormatError("TMD header is truncated")
    nx, ny, length_x, length_y, offset_x, offset_y = struct.unpack_from("<2I4f", data, position)
    if nx < 1 or ny < 1:
        raise FormatError(f"TMD grid of {nx} × {ny} points is empty")
    check_size((ny, nx), "the TMD map")
    start = position + 24
    check_length(data, start + nx * ny * 4, "TMD", f"header and {nx} × {ny} float32 heights")
    for name, length in (("x", length_x), ("y", length_y)):
        if not 0 < length < np.inf:
            raise FormatError(f"TMD {name} length is {length!r} µm, not a positive length")
    heights = np.frombuffer(data, "<f4", nx * ny, start).reshape(ny, nx) * MICROMETRE
    metadata = {"vendor": "TrueMap"}
    comment = data[MAGIC_SIZE:position].split(b"\0", 1)[0].decode("latin-1").strip()
    if comment:
        metadata["comment"] = comment
    spacing = (length_x / nx * MICROMETRE, length_y / ny * MICROMETRE)
    origin = (offset_x * MICROMETRE, offset_y * MICROMETRE)
    return Surface(heights, spacing, origin, Units(xy="um", z="um"), metadata)
