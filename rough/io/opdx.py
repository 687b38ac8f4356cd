"""Bruker OPDx (Vision64: Dektak stylus profilers and Contour optical profilers), read only.

After the 12-byte magic ``VCA DATA\\x01\\x00\\x00\\x55`` comes a tree of typed items,
each a name (uint32 length, UTF-8), a type byte and a value, all little-endian.
Containers (types 0x7D, 0x46, 0x47) hold a variable length (a byte 1, 2 or 4 giving the
size of the length that follows) and then items up to a terminator item (type 0x7F);
scalars are bool 0x01, int16/uint16 0x04/0x05, int32/uint32 0x06/0x07, int64/uint64
0x0A/0x0B, float32/float64 0x0C/0x0D; 0x12 is a string and 0x13 a quantity (float64,
unit name, unit symbol), both with a variable length; 0x15 a time stamp (a byte, then a
Windows FILETIME: 100 ns since 1601, UTC); 0x18 a unit; 0x40 a double array, 0x42 a
string list, 0x0E a type id and 0x7C positions (a type name, a variable length, the
payload); 0x00 a matrix (type name, uint32, name, variable length, uint32 rows and
columns, float32 values).

``/MetaData/DataKind`` says ``Surface Profile`` (a line scan) or ``Surface Height`` (a
map). A profile's channels are ``/MetaData/1D_Channels/Height``; channel ``C`` has its
heights in ``/1D_Data/C/Array`` (5 bytes, then float64) × ``DataScale`` and its x in
``PositionArray`` (same layout, in ``PositionUnits``). ``Extent`` is last x − first x,
so the spacing is the step between points, Extent / (n − 1). A map
(``/MetaData/PrimaryData2D``) has ``Dimension1Points`` rows and ``Dimension2Points``
columns of float32 in ``/2D_Data/C/Matrix``, row 0 first; its spacing is taken in the
same way from ``Dimension2Extent`` (x) and ``Dimension1Extent`` (y). The date is
``/MetaData/TimeStamp``; the ``Date`` and ``Time`` strings follow the PC's locale and
are not used. Layout as SurfaceTopography's ``OPDx.py`` and Gwyddion's ``dektakvca.c``
read it.
"""

import datetime
import struct

import numpy as np

from ..errors import FormatError
from ..surface import Surface, Units, check_size
from .header import length_unit
from .registry import Format, channel_metadata, choose_channel
from .regrid import profile_from_points

FORMAT = Format(
    "opdx",
    "Bruker OPDx (Dektak)",
    (".opdx",),
    magic=(b"VCA DATA\x01\x00\x00\x55",),
    carries=("spacing", "units", "metadata", "time", "channels"),
)

MAGIC = b"VCA DATA\x01\x00\x00\x55"
CONTAINERS = (0x7D, 0x46, 0x47)
TERMINATOR = 0x7F
SCALARS = {
    0x01: "<?",
    0x04: "<h",
    0x05: "<H",
    0x06: "<i",
    0x07: "<I",
    0x0A: "<q",
    0x0B: "<Q",
    0x0C: "<f",
    0x0D: "<d",
}
TYPED_BLOBS = (0x0E, 0x40, 0x42, 0x7C)
STRING, QUANTITY, TIME_STAMP, UNIT, MATRIX = 0x12, 0x13, 0x15, 0x18, 0x00
ARRAY_PREFIX = 5  # bytes before a double array's values
MAX_DEPTH = 64
FILETIME_EPOCH = datetime.datetime(1601, 1, 1, tzinfo=datetime.timezone.utc)


def read(data, options):
    data = bytes(data)
    if not data.startswith(MAGIC):
        raise FormatError("not an OPDx file (no VCA DATA magic)")
    items = {}
    _container(data, len(MAGIC), len(data), "", items, 0)
    kind = items.get("/MetaData/DataKind")
    if kind == "Surface Profile":
        return _profile(items, options)
    if kind == "Surface Height":
        return _map(items, options)
    raise FormatError(f"OPDx data kind {kind!r} is not a surface profile or height map")


def _container(data, position, end, prefix, items, depth):
    """Read items from ``position`` up to a terminator or ``end``; returns the position after."""
    if depth > MAX_DEPTH:
        raise FormatError(f"OPDx items nested more than {MAX_DEPTH} deep")
    while position < end:
        name, position = _name(data, position, end)
        kind = _take(data, position, 1, end)[0]
        position += 1
        if kind == TERMINATOR:
            return position
        path = f"{prefix}/{name}"
        if kind in CONTAINERS:
            length, position = _length(data, position, end)
            if position + length > min(end, len(data)):
                raise FormatError(f"OPDx container {path!r} of {length} bytes runs past the end of its container")
            _container(data, position, position + length, path, items, depth + 1)
            position += length
        else:
            items[path], position = _value(data, position, kind, end)
    return position


def _value(data, position, kind, end):
    if kind in SCALARS:
        size = struct.calcsize(SCALARS[kind])
        return struct.unpack(SCALARS[kind], _take(data, position, size, end))[0], position + size
    if kind == TIME_STAMP:
        return _take(data, position, 9, end), position + 9
    if kind == MATRIX:
        _, position = _name(data, position, end)
        position += 4
        _, position = _name(data, position, end)
    elif kind in TYPED_BLOBS:
        _, position = _name(data, position, end)
    elif kind not in (STRING, QUANTITY, UNIT):
        raise FormatError(f"OPDx item type 0x{kind:02X} at byte {position - 1} is unknown")
    length, position = _length(data, position, end)
    payload = _take(data, position, length, end)
    if kind == STRING:
        payload = payload.decode("utf-8", "replace")
    elif kind == QUANTITY:
        value = struct.unpack("<d", _take(payload, 0, 8, length))[0]
        _, at = _name(payload, 8, length)
        symbol, _ = _name(payload, at, length)
        payload = (value, symbol)
    elif kind == 0x42:
        payload = _strings(payload)
    return payload, position + length


def _strings(payload):
    names, position = [], 0
    while position < len(payload):
        name, position = _name(payload, position, len(payload))
        names.append(name)
    return names


def _name(data, position, end):
    (size,) = struct.unpack("<I", _take(data, position, 4, end))
    return _take(data, position + 4, size, end).decode("utf-8", "replace"), position + 4 + size


def _length(data, position, end):
    width = _take(data, position, 1, end)[0]
    if width not in (1, 2, 4):
        raise FormatError(f"OPDx length of {width} bytes at byte {position} is not 1, 2 or 4")
    (length,) = struct.unpack({1: "<B", 2: "<H", 4: "<I"}[width], _take(data, position + 1, width, end))
    return length, position + 1 + width


def _take(data, position, size, end):
    if position + size > min(end, len(data)):
        raise FormatError(f"OPDx item at byte {position} runs past the end of its container")
    return data[position : position + size]


def _profile(items, options):
    names = items.get("/MetaData/1D_Channels/Height")
    if not isinstance(names, list) or not names:
        raise FormatError("OPDx profile lists no height channel (/MetaData/1D_Channels/Height)")
    index = choose_channel(names, options.channel)
    prefix = f"/1D_Data/{names[index]}"
    count = _count(items, f"{prefix}/NumPoints")
    heights = _doubles(items, f"{prefix}/Array", count) * _scale(items, f"{prefix}/DataScale")
    x_unit = _symbol(items, f"{prefix}/Extent")
    positions = items.get(f"{prefix}/PositionArray")
    if isinstance(positions, bytes) and isinstance(items.get(f"{prefix}/PositionUnits"), bytes):
        x = _doubles(items, f"{prefix}/PositionArray", count) * _unit_scale(items[f"{prefix}/PositionUnits"])
    else:
        if count < 2:
            raise FormatError(f"OPDx profile of {count} points has no spacing")
        x = np.arange(count) * (_scale(items, f"{prefix}/Extent") / (count - 1))
    metadata = _metadata(items) | channel_metadata(names, index)
    units = Units(xy=_unit_name(x_unit), z=_unit_name(_symbol(items, f"{prefix}/DataScale")))
    return profile_from_points(x, heights, options, units=units, metadata=metadata)


def _map(items, options):
    name = items.get("/MetaData/PrimaryData2D")
    if not isinstance(name, str):
        raise FormatError("OPDx map names no primary data set (/MetaData/PrimaryData2D)")
    index = choose_channel([name], options.channel)
    prefix = f"/2D_Data/{name}"
    rows, columns = _count(items, f"{prefix}/Dimension1Points"), _count(items, f"{prefix}/Dimension2Points")
    if rows < 2 or columns < 2:
        raise FormatError(f"OPDx map of {columns}×{rows} points has no spacing")
    check_size((rows, columns), "the OPDx height map")
    matrix = items.get(f"{prefix}/Matrix")
    if not isinstance(matrix, bytes) or len(matrix) < 8 + 4 * rows * columns:
        raise FormatError(f"OPDx map matrix does not hold {columns}×{rows} float32 values")
    if struct.unpack_from("<2I", matrix) != (rows, columns):
        raise FormatError(
            f"OPDx map matrix is {struct.unpack_from('<2I', matrix)} rows × columns, not {rows} × {columns}"
        )
    heights = np.frombuffer(matrix, "<f4", rows * columns, 8).reshape(rows, columns).astype(np.float64)
    heights *= _scale(items, f"{prefix}/DataScale")
    dx = _scale(items, f"{prefix}/Dimension2Extent") / (columns - 1)
    dy = _scale(items, f"{prefix}/Dimension1Extent") / (rows - 1)
    units = Units(
        xy=_unit_name(_symbol(items, f"{prefix}/Dimension2Extent")),
        z=_unit_name(_symbol(items, f"{prefix}/DataScale")),
    )
    return Surface(heights, (dx, dy), units=units, metadata=_metadata(items) | channel_metadata([name], index))


def _count(items, path):
    value = items.get(path)
    if not isinstance(value, int) or isinstance(value, bool) or value < 1:
        raise FormatError(f"OPDx item {path!r} is {value!r}, not a positive count")
    return value


def _doubles(items, path, count):
    payload = items.get(path)
    if not isinstance(payload, bytes) or len(payload) != ARRAY_PREFIX + 8 * count:
        raise FormatError(f"OPDx array {path!r} does not hold {count} float64 values")
    return np.frombuffer(payload, "<f8", count, ARRAY_PREFIX).astype(np.float64)


def _scale(items, path):
    """A length quantity in metres."""
    value, symbol = _quantity(items, path)
    metres = value * length_unit(symbol, f"OPDx {path!r} unit")
    if not (np.isfinite(metres) and metres > 0):
        raise FormatError(f"OPDx {path!r} is {value!r} {symbol!r}, not a positive length")
    return metres


def _symbol(items, path):
    return _quantity(items, path)[1]


def _quantity(items, path):
    value = items.get(path)
    if not isinstance(value, tuple):
        raise FormatError(f"OPDx file lacks its {path!r} quantity")
    return value


def _unit_scale(payload):
    """Metres per unit of a unit item (name, symbol, float64, 12 bytes)."""
    _, position = _name(payload, 0, len(payload))
    symbol, _ = _name(payload, position, len(payload))
    return length_unit(symbol, "OPDx PositionUnits unit")


def _unit_name(symbol):
    return "um" if symbol in ("µm", "μm") else symbol


def _metadata(items):
    metadata = {"vendor": "Bruker"}
    for path, key in (
        ("/MetaData/MeasurementSettings/InstrumentName", "instrument"),
        ("/MetaData/DataSetName", "title"),
        ("/MetaData/MeasurementSettings/StylusType", "opdx_stylus"),
        ("/MetaData/MeasurementSettings/MeasMode", "opdx_mode"),
    ):
        if isinstance(items.get(path), str) and items[path].strip():
            metadata[key] = items[path].strip()
    stamp = items.get("/MetaData/TimeStamp")
    if isinstance(stamp, bytes) and len(stamp) == 9:
        ticks = int.from_bytes(stamp[1:], "little")
        try:
            when = FILETIME_EPOCH + datetime.timedelta(microseconds=ticks // 10)
        except OverflowError:
            when = None
        if when is not None and ticks:
            metadata["date"] = when.replace(microsecond=0).isoformat()
    return metadata
