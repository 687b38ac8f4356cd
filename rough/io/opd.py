"""Wyko OPD (Veeco/Bruker Vision optical profilers, binary ``.opd``), read only.

After two bytes (``01 00``) comes a directory of 24-byte entries: a 16-byte NUL-padded
name, then little-endian uint16 type, uint32 size and uint16 flags. The first entry is
the ``Directory`` itself (type 1, its size the directory's length); the items' data
follow the directory in entry order, each ``size`` bytes long. Types: 3 array, 5 text,
6 int16, 7 float32, 8 float64, 12 int32; type 15 holds one Bruker VCA-typed value
(here only strings, ``12 01 n``, are read). An array starts with uint16 xres, yres and
element size (1 uint8, 2 int16, 4 float32), then the values column by column (x
outer), each column from the bottom of the image up; rough flips them so that row 0 is
the top row, as Vision and Gwyddion show the image. Height arrays (``Raw``, ``OPD``,
``RAW_DATA``, ``RAW DATA``, ``SAMPLE_DATA``) are in waves: heights = value ×
``Wavelength`` (nm) / ``Mult`` (default 1); float values of 1e38 and above and int16
values of 32766 and above are invalid (NaN). ``Pixel_size`` is in mm, dy = dx ×
``Aspect`` (default 1). Intensity arrays (``Image``, ``Intensity``, ``SecArr_0``) are
listed as channels but not read. ``Date`` and ``Time`` are the software's local time,
kept only when day and month cannot be mistaken for each other. Layout as Gwyddion's
``opdfile.c`` and SurfaceTopography's ``OPD.py`` read it.
"""

import datetime
import struct

import numpy as np

from ..errors import FormatError
from ..surface import Surface, Units, check_size
from .registry import Format, channel_metadata, choose_channel

FORMAT = Format(
    "opd",
    "Wyko OPD",
    (".opd",),
    magic=(b"\x01\x00Directory",),
    carries=("spacing", "units", "metadata", "time", "mask", "channels"),
)

ENTRY_SIZE, NAME_SIZE = 24, 16
ARRAY, TEXT, SHORT, FLOAT, DOUBLE, LONG, VARIANT = 3, 5, 6, 7, 8, 12, 15
SCALARS = {SHORT: "<h", FLOAT: "<f", DOUBLE: "<d", LONG: "<i"}
HEIGHT_ARRAYS = ("OPD", "SAMPLE_DATA", "RAW_DATA", "RAW DATA", "Raw")
INTENSITY_ARRAYS = ("Image", "Intensity", "SecArr_0")
ELEMENTS = {1: (np.dtype("u1"), None), 2: (np.dtype("<i2"), 32766), 4: (np.dtype("<f4"), 1e38)}


def read(data, options):
    data = bytes(data)
    items = _directory(data)
    names = [name for name, (kind, _) in items.items() if kind == ARRAY and name in HEIGHT_ARRAYS + INTENSITY_ARRAYS]
    heights_at = [index for index, name in enumerate(names) if name in HEIGHT_ARRAYS]
    if not heights_at:
        raise FormatError("OPD file holds no height array (Raw, OPD or RAW_DATA)")
    index = choose_channel(names, options.channel, heights_at[0])
    if names[index] in INTENSITY_ARRAYS:
        raise FormatError(f"OPD channel {names[index]!r} is an intensity image; rough reads the height channels")
    mult = _scalar(items, "Mult", SHORT, default=1)
    if mult == 0:
        raise FormatError("OPD Mult is 0; the height scale would be infinite")
    wavelength = _scalar(items, "Wavelength", FLOAT) * 1e-9 / mult
    if not (np.isfinite(wavelength) and wavelength != 0):
        raise FormatError(f"OPD height scale {wavelength!r} m per wave is not a finite non-zero number")
    heights = _array(items[names[index]]) * wavelength
    metadata = _metadata(items) | channel_metadata(names, index)
    return Surface(heights, _spacing(items), units=Units(xy="mm", z="nm"), metadata=metadata)


def _directory(data):
    """``{name: (type, bytes)}`` of the non-empty items (the first of each name)."""
    if len(data) < 2 + ENTRY_SIZE:
        raise FormatError("OPD directory is truncated")
    name, kind, size = _entry(data, 2)
    if name != "Directory" or kind != 1 or size < ENTRY_SIZE:
        raise FormatError("not an OPD file (no Directory entry)")
    if 2 + size > len(data):
        raise FormatError(f"OPD directory of {size} bytes runs past the end of the file")
    items, offset, view = {}, 2 + size, memoryview(data)
    for position in range(2 + ENTRY_SIZE, 2 + size - ENTRY_SIZE + 1, ENTRY_SIZE):
        name, kind, size = _entry(data, position)
        if size and offset + size > len(data):
            raise FormatError(f"OPD item {name!r} of {size} bytes runs past the end of the file")
        if size:
            items.setdefault(name, (kind, view[offset : offset + size]))
        offset += size
    return items


def _entry(data, position):
    name = data[position : position + NAME_SIZE].split(b"\0", 1)[0].decode("latin-1").strip()
    kind, size = struct.unpack_from("<HI", data, position + NAME_SIZE)
    return name, kind, size


def _scalar(items, name, kind, default=None):
    if name not in items:
        if default is None:
            raise FormatError(f"OPD file lacks its {name} item")
        return default
    found, raw = items[name]
    if found != kind or len(raw) != struct.calcsize(SCALARS[kind]):
        raise FormatError(f"OPD item {name!r} has type {found} and {len(raw)} bytes, not a {SCALARS[kind][1:]} number")
    return struct.unpack(SCALARS[kind], raw)[0]


def _array(item):
    _, raw = item
    size = len(raw)
    if size < 6:
        raise FormatError(f"OPD array of {size} bytes is too short for its header")
    nx, ny, element = struct.unpack_from("<HHH", raw)
    if element not in ELEMENTS:
        raise FormatError(f"OPD array element size {element} bytes is not 1, 2 or 4")
    if nx == 0 or ny == 0:
        raise FormatError(f"OPD array of {nx}×{ny} points is empty")
    check_size((ny, nx), "the OPD height array")
    if 6 + nx * ny * element > size:
        raise FormatError(f"OPD array of {nx}×{ny} points is longer than its item ({size} bytes)")
    dtype, invalid = ELEMENTS[element]
    values = np.frombuffer(raw, dtype, nx * ny, 6).reshape(nx, ny)[:, ::-1].T.astype(np.float64)
    if invalid is not None:
        values[~(values < invalid)] = np.nan
    return values


def _spacing(items):
    pixel = _scalar(items, "Pixel_size", FLOAT) * 1e-3
    aspect = _scalar(items, "Aspect", FLOAT, default=1.0)
    if not (0 < pixel < np.inf and 0 < aspect < np.inf):
        raise FormatError(f"OPD Pixel_size {pixel * 1e3!r} mm with Aspect {aspect!r} is not a pixel size")
    return (float(pixel), float(pixel * aspect))


def _metadata(items):
    metadata = {}
    title = _text(items, "Title") or _text(items, "DataSetName")
    if title:
        metadata["title"] = title
    date = _date(_text(items, "Date"), _text(items, "Time"))
    if date:
        metadata["date"] = date
    metadata["opd_wavelength"] = f"{_scalar(items, 'Wavelength', FLOAT):.6g} nm"
    if items.get("Magnification", (0,))[0] == FLOAT:
        metadata["opd_magnification"] = f"{_scalar(items, 'Magnification', FLOAT):.6g}"
    mode = _text(items, "MeasMode")
    if mode:
        metadata["opd_mode"] = mode
    return metadata


def _text(items, name):
    """A text item, or a VCA string held in a type-15 item; '' when absent."""
    kind, raw = items.get(name, (None, b""))
    raw = bytes(raw)
    if kind == VARIANT:
        if len(raw) < 3 or raw[:2] != b"\x12\x01" or raw[2] != len(raw) - 3:
            return ""
        return raw[3:].decode("utf-8", "replace").strip()
    if kind == TEXT:
        return raw.split(b"\0", 1)[0].decode("latin-1").strip()
    return ""


def _date(date, time):
    """ISO 8601 from ``M/D/Y`` (or ``D/M/Y``) and ``H:M:S``; '' when ambiguous or unreadable."""
    try:
        first, second, year = (int(part) for part in date.split("/"))
        clock = datetime.time.fromisoformat(time) if time else datetime.time()
    except ValueError:
        return ""
    if first != second and first <= 12 and second <= 12:
        return ""
    month, day = (first, second) if first <= 12 else (second, first)
    try:
        return datetime.datetime.combine(datetime.date(year, month, day), clock).isoformat()
    except ValueError:
        return ""
