"""Gwyddion native ``.gwy`` files, read and written.

A ``.gwy`` file is ``GWYP`` and one serialised object (Gwyddion user guide, "Native file format"): a type name
(NUL-terminated), a little-endian uint32 byte count, then components, each a NUL-terminated name, a type byte
(``b c i q d s o`` for boolean, char, int32, int64, double, string, object; upper case ``C I Q D S O`` for arrays,
with a uint32 count first) and the value. The top object is a ``GwyContainer`` whose key ``/N/data`` holds channel
N as a ``GwyDataField`` (``xres``, ``yres``, ``xreal``, ``yreal``, ``xoff``, ``yoff``, ``si_unit_xy``, ``si_unit_z``,
``data``: xres·yres doubles, row-major), ``/N/data/title`` its title, ``/N/mask`` a mask field (non-zero = masked)
and ``/N/meta`` a container of strings. Graphs are ``/N/graph/graph/M`` (``GwyGraphModel`` with ``x_unit``,
``y_unit`` and ``curves``, each a ``GwyGraphCurveModel`` with ``xdata`` and ``ydata``).

Reading: the data fields are the channels, by title (default: the first whose title names a height, such
as ``Height``, ``Topography``, ``Z-Axis`` or ``ZSensor``, else the first in a length unit whose title does
not name another quantity such as deflection, amplitude, phase or friction; a file with none of these is
refused unless ``--channel`` names a channel: a deflection in metres is not a height); masked points are NaN
(Gwyddion marks the invalid points of the files it imports with a mask; a user's own grain mask is read the
same way). Row 0 is Gwyddion's top row, the first stored (smallest y). A field one row high is a profile. A
file with no data field but a graph gives the first curve of the chosen graph as a profile (through
:func:`rough.io.regrid.profile_from_points`). Units: the ``unitstr`` of ``si_unit_xy`` and ``si_unit_z``
(``m``, or prefixed such as ``µm``); an empty unit is ``--unit`` (Gwyddion writes fields that were never
given a unit so), else metres for the lateral unit, and a z without unit and without ``--unit`` is refused;
a channel whose values are not lengths is refused. The reader is rough's own, bounded by the file's size
(gwyfile's reader trusts lengths and can loop forever on a damaged file).

Writing (with gwyfile): channel 0 in metres, titled by the metadata's ``title`` less any NUL characters (GWY
strings end at NUL; the full title travels in ``rough.metadata``), else "Height"; NaN points are
filled with the mean of the valid ones (a data field cannot hold NaN) and marked in ``/0/mask``, as Gwyddion's own
importers do. A profile is written as a field one row high, so NaN points keep their place. rough's units, metadata
and history are the strings ``rough.units``, ``rough.metadata`` and ``rough.history`` (JSON) in ``/0/meta``, which
Gwyddion shows as metadata.
"""

import re
import struct

import numpy as np

from ..errors import FormatError, InputError
from ..extras import require
from ..surface import Surface, Units, check_size
from ..units import metres_per
from . import provenance, regrid
from .registry import Format, channel_list, channel_metadata, choose_channel, names_height

FORMAT = Format(
    "gwy",
    "Gwyddion GWY",
    (".gwy",),
    magic=(b"GWYP",),
    writes=True,
    carries=("spacing", "units", "metadata", "channels", "mask", "history"),
    write_library="gwyfile",
)

MAGIC = b"GWYP"
MAX_DEPTH = 32
SCALARS = {"b": "<B", "c": "<c", "i": "<i", "q": "<q", "d": "<d"}
ARRAYS = {"C": "<u1", "I": "<i4", "Q": "<i8", "D": "<f8"}
OTHER = re.compile(r"deflection|amplitude|phase|friction|force|current|error|intensity|frequency", re.IGNORECASE)


class _Object(dict):
    """A deserialised Gwyddion object: its components, and its type name in ``kind``."""

    def __init__(self, kind, components):
        super().__init__(components)
        self.kind = kind


def read(data, options):
    data = bytes(data)
    if not data.startswith(MAGIC):
        raise FormatError("not a Gwyddion GWY file (no GWYP magic)")
    container, end = _object(data, len(MAGIC), len(data), 0)
    if container.kind != "GwyContainer":
        raise FormatError(f"GWY file holds a {container.kind}, not a GwyContainer")
    fields = _numbered(container, r"/(\d+)/data", "GwyDataField")
    if fields:
        return _field_surface(container, fields, options)
    graphs = _numbered(container, r"/(\d+)/graph/graph/(\d+)", "GwyGraphModel")
    if graphs:
        return _graph_surface(graphs, options)
    raise FormatError("GWY file holds no data field or graph")


def _numbered(container, pattern, kind):
    """``{key: object}`` for the container keys matching ``pattern`` that hold a ``kind`` object, by number."""
    found = []
    for key, value in container.items():
        match = re.fullmatch(pattern, key)
        if match and isinstance(value, _Object) and value.kind == kind:
            found.append((tuple(map(int, match.groups())), key))
    return {key: container[key] for _, key in sorted(found)}


def _field_surface(container, fields, options):
    keys = list(fields)
    titles = [_string(container.get(f"{key}/title")) or f"channel {key.split('/')[1]}" for key in keys]
    index = choose_channel(titles, options.channel) if options.channel is not None else _default(titles, fields)
    key = keys[index]
    field = fields[key]
    xres, yres = _int(field, "xres"), _int(field, "yres")
    check_size((yres, xres), "the GWY data field")
    values = _array(field, "data", xres * yres).reshape(yres, xres).astype(np.float64)
    mask = container.get(key.replace("/data", "/mask"))
    if isinstance(mask, _Object) and mask.kind == "GwyDataField":
        if (_int(mask, "xres"), _int(mask, "yres")) != (xres, yres):
            raise FormatError("GWY mask is not the size of its data field")
        values[_array(mask, "data", xres * yres).reshape(yres, xres) > 0] = np.nan
    xy_unit, xy = _unit(field.get("si_unit_xy"), "lateral", default=options.unit or "m")
    z_unit, z = _unit(field.get("si_unit_z"), f"channel {titles[index]!r}", default=options.unit)
    values *= z
    spacing = (_real(field, "xreal") * xy / xres, _real(field, "yreal") * xy / yres)
    origin = (_number(field, "xoff") * xy, _number(field, "yoff") * xy)
    metadata, units, history = _provenance(container.get(key.replace("/data", "/meta")), titles[index], xy_unit, z_unit)
    metadata.update(channel_metadata(titles, index) if len(titles) > 1 else {})
    if yres == 1:
        return Surface(values[0], spacing[:1], origin[:1], units, metadata, history)
    return Surface(values, spacing, origin, units, metadata, history)


def _graph_surface(graphs, options):
    keys = list(graphs)
    titles = [_string(graphs[key].get("title")) or key for key in keys]
    index = choose_channel(titles, options.channel)
    graph = graphs[keys[index]]
    curves = graph.get("curves")
    if not isinstance(curves, list) or not curves or not isinstance(curves[0], _Object):
        raise FormatError(f"GWY graph {titles[index]!r} holds no curve")
    x, z = (np.asarray(curves[0].get(name), dtype=np.float64) for name in ("xdata", "ydata"))
    if x.shape != z.shape or x.ndim != 1:
        raise FormatError("GWY graph curve has x and y data of different lengths")
    xy_unit, xy = _unit(graph.get("x_unit"), "graph x", default=options.unit or "m")
    z_unit, factor = _unit(graph.get("y_unit"), f"graph {titles[index]!r}", default=options.unit)
    metadata = {"title": titles[index], **channel_metadata(titles, index)}
    return regrid.profile_from_points(x * xy, z * factor, options, units=Units(xy_unit, z_unit), metadata=metadata)


def _default(titles, fields):
    """The first channel titled as a height, else the first in a length unit (or none) not titled as another
    quantity; FormatError listing the channels when there is none."""
    for index, title in enumerate(titles):
        if names_height(title):
            return index
    for index, (title, field) in enumerate(zip(titles, fields.values())):
        if not OTHER.search(title) and _is_length(field.get("si_unit_z")):
            return index
    raise FormatError(f"GWY file holds no height channel: {channel_list(titles)}; give --channel to read one anyway")


def _is_length(unit):
    text = (_string(unit.get("unitstr")) if isinstance(unit, _Object) else None) or ""
    try:
        return not text.strip() or metres_per(text.strip()) > 0
    except InputError:
        return False


def _provenance(meta, title, xy_unit, z_unit):
    """rough's own record when the file has one (the channel title rough wrote is then
    not metadata), else the channel title."""
    stored = {}
    if isinstance(meta, _Object):
        stored = {part: _string(meta.get(f"rough.{part}")) for part in provenance.PARTS}
    metadata = {} if stored.get("metadata") else {"title": title}
    return provenance.restore(stored, metadata, Units(xy_unit, z_unit))


def _unit(unit, what, default=None):
    text = _string(unit.get("unitstr")) if isinstance(unit, _Object) else None
    text = (text or "").strip() or default
    if text is None:
        raise FormatError(f"GWY {what} values have no unit; give --unit (e.g. --unit nm) if they are lengths")
    try:
        return text, metres_per(text)
    except InputError:
        raise FormatError(f"GWY {what} values are in {text!r}, not a length; rough reads height channels") from None


def _string(value):
    return value if isinstance(value, str) else None


def _int(field, key):
    value = field.get(key)
    if not isinstance(value, int) or value < 1:
        raise FormatError(f"GWY data field {key} is {value!r}, not a positive count")
    return value


def _number(field, key, default=0.0):
    value = field.get(key, default)
    if not isinstance(value, float) or not np.isfinite(value):
        raise FormatError(f"GWY data field {key} is {value!r}, not a finite number")
    return value


def _real(field, key):
    value = _number(field, key, 1.0)
    if value <= 0:
        raise FormatError(f"GWY data field {key} is {value!r}, not a positive size")
    return value


def _array(field, key, count):
    values = field.get(key)
    if not isinstance(values, np.ndarray) or values.size != count:
        raise FormatError(f"GWY data field holds {getattr(values, 'size', 0)} values, not the {count} it declares")
    return values


def _object(data, position, end, depth):
    """The object serialised at ``position`` (not past ``end``) and the position after it."""
    if depth > MAX_DEPTH:
        raise FormatError(f"GWY objects nested more than {MAX_DEPTH} deep")
    kind, position = _name(data, position, end)
    if position + 4 > end:
        raise FormatError("GWY file is truncated (object size)")
    (size,) = struct.unpack_from("<I", data, position)
    position += 4
    stop = position + size
    if stop > end:
        raise FormatError(f"GWY {kind} object declares {size} bytes, past the end of its container")
    components = {}
    while position < stop:
        name, position = _name(data, position, stop)
        if position >= stop:
            raise FormatError(f"GWY component {name!r} has no type")
        code = chr(data[position])
        components[name], position = _value(data, code, position + 1, stop, depth)
    return _Object(kind, components), stop


def _name(data, position, end):
    stop = data.find(b"\0", position, end)
    if stop < 0:
        raise FormatError("GWY file is truncated (unterminated name)")
    try:
        return data[position:stop].decode("utf-8"), stop + 1
    except UnicodeDecodeError:
        raise FormatError("GWY name is not UTF-8") from None


def _value(data, code, position, end, depth):
    if code in SCALARS:
        size = struct.calcsize(SCALARS[code])
        if position + size > end:
            raise FormatError("GWY file is truncated (a number)")
        (value,) = struct.unpack_from(SCALARS[code], data, position)
        return (bool(value) if code == "b" else value), position + size
    if code == "s":
        return _name(data, position, end)
    if code == "o":
        return _object(data, position, end, depth + 1)
    if code not in "CIQDSO" or position + 4 > end:
        raise FormatError(f"GWY component of unknown type {code!r}" if code not in "CIQDSO" else "GWY file truncated")
    (count,) = struct.unpack_from("<I", data, position)
    position += 4
    if code in ARRAYS:
        size = count * np.dtype(ARRAYS[code]).itemsize
        if position + size > end:
            raise FormatError(f"GWY array of {count} items runs past the end of its object")
        return np.frombuffer(data, ARRAYS[code], count, position), position + size
    if count > end - position:
        raise FormatError(f"GWY list of {count} items is longer than its object")
    items = []
    for _ in range(count):
        item, position = _name(data, position, end) if code == "S" else _object(data, position, end, depth + 1)
        items.append(item)
    return items, position


def write(surface, stream):
    objects = require("gwyfile").objects
    heights = np.atleast_2d(surface.heights)
    valid = ~np.isnan(heights)
    filled = np.where(valid, heights, np.mean(heights[valid]) if valid.any() else 0.0)
    dx = surface.spacing[0]
    dy = surface.spacing[1] if len(surface.spacing) == 2 else dx
    x0, y0 = (*surface.origin, 0.0)[:2]
    shape = {"xreal": heights.shape[1] * dx, "yreal": heights.shape[0] * dy, "xoff": x0, "yoff": y0}
    container = objects.GwyContainer()
    container["/0/data"] = objects.GwyDataField(filled, **shape, si_unit_xy="m", si_unit_z="m")
    container["/0/data/title"] = str(surface.metadata.get("title") or "").replace("\0", "") or "Height"
    if not valid.all():
        container["/0/mask"] = objects.GwyDataField((~valid).astype(np.float64), **shape, si_unit_xy="m")
    record = {f"rough.{part}": text for part, text in provenance.record(surface).items()}
    container["/0/meta"] = objects.GwyContainer(record, typecodes=dict.fromkeys(record, "s"))
    container.typecodes["/0/data/title"] = "s"
    container.tofile(stream)
