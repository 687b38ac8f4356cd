"""BCR-STM and BCRF files (Image Metrology's SPIP exchange format), read only.

A text header of ``key = value`` lines (``%`` and ``#`` start comments) opens the file: ``fileformat =``
``bcrstm`` (int16 data) or ``bcrf`` (float32 data), each also as ``…_unicode`` with a UTF-16LE header.
The header is 2048 characters long unless ``headersize`` says otherwise (characters, so twice as many
bytes in UTF-16). Then ``xpixels`` × ``ypixels`` values follow, row by row, little-endian when
``intelmode = 1``, and end the file (a file of another length is refused). ``xlength``/``ylength`` are
the scan size in ``xunit``/``yunit`` (default nm), ``xoffset``/``yoffset`` its position (the origin
here). Heights are in ``zunit`` (default nm), int16 values times ``bit2nm``; invalid points are int16
32767 or float values above 1.7e38 (``voidpixels``). Rows are kept as stored (Gwyddion and
SurfaceTopography agree). Facts from Gwyddion's ``bcrfile.c`` and SurfaceTopography's ``BCR.py``;
Gwyddion also shifts the heights so that their minimum is ``zmin``, which is not done here.
"""

import numpy as np

from ..errors import FormatError
from ..surface import Surface, Units, check_size
from .header import check_length, header_count, header_number, length_unit
from .registry import Format

FORMAT = Format(
    "bcr",
    "BCR-STM",
    (".bcr", ".bcrf"),
    magic=(b"fileformat = bcr", "fileformat = bcr".encode("utf-16-le")),
    carries=("spacing", "units", "metadata", "mask"),
)

HEADER_CHARACTERS = 2048
FLOAT_VOID = 1.7e38
INT_VOID = 32767


def read(data, options):
    data = bytes(data)
    wide = data[1:2] == b"\0"
    fields, start = _header(data, wide)
    kind = fields.get("fileformat", "")
    if kind not in ("bcrstm", "bcrf", "bcrstm_unicode", "bcrf_unicode"):
        raise FormatError(f"BCR fileformat {kind!r} is not bcrstm or bcrf")
    floats = kind.startswith("bcrf")
    nx, ny = header_count(fields, "xpixels", "BCR"), header_count(fields, "ypixels", "BCR")
    check_size((ny, nx), "the BCR image")
    order = "<" if _number(fields, "intelmode", 1) else ">"
    dtype = np.dtype(f"{order}f4" if floats else f"{order}i2")
    end = start + nx * ny * dtype.itemsize
    check_length(data, end, "BCR", f"header and {nx}×{ny} points")
    raw = np.ndarray((ny, nx), dtype, data, start).astype(np.float64)
    invalid = raw > FLOAT_VOID if floats else raw == INT_VOID
    xy_unit, z_unit = fields.get("xunit", "nm"), fields.get("zunit", "nm")
    lateral, vertical = length_unit(xy_unit, "BCR xunit"), length_unit(z_unit, "BCR zunit")
    if fields.get("yunit", xy_unit) != xy_unit:
        raise FormatError(f"BCR xunit {xy_unit!r} and yunit {fields['yunit']!r} differ")
    scale = vertical if floats else vertical * _number(fields, "bit2nm", 1)
    heights = np.where(invalid, np.nan, raw * scale)
    spacing = (_number(fields, "xlength") * lateral / nx, _number(fields, "ylength") * lateral / ny)
    origin = (_number(fields, "xoffset", 0) * lateral, _number(fields, "yoffset", 0) * lateral)
    metadata = {"bcr_fileformat": kind}
    if fields.get("starttime"):
        metadata["bcr_starttime"] = fields["starttime"]
    return Surface(heights, spacing, origin, Units(xy=xy_unit, z=z_unit), metadata)


def _header(data, wide):
    """``({key: value}, data offset)``."""
    width = 2 if wide else 1
    encoding = "utf-16-le" if wide else "latin-1"
    head = data[: HEADER_CHARACTERS * width].decode(encoding, errors="replace")
    fields = _fields(head)
    characters = int(_number(fields, "headersize", HEADER_CHARACTERS))
    if not 0 < characters * width <= len(data):
        raise FormatError(f"BCR headersize {characters} characters does not fit the file ({len(data)} bytes)")
    if characters != HEADER_CHARACTERS:
        fields = _fields(data[: characters * width].decode(encoding, errors="replace"))
    return fields, characters * width


def _fields(text):
    fields = {}
    for line in text.split("\n"):
        line = line.strip()
        if line and line[0] not in "%#" and "=" in line:
            key, _, value = line.partition("=")
            fields.setdefault(key.strip().lower(), value.strip().strip("\0"))
    return fields


def _number(fields, key, default=None):
    return header_number(fields, key, "BCR", default)
