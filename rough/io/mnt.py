"""Digital Surf MountainsMap MNT documents, read only: the height map of the first
studiable.

An MNT file is an OLE2 compound file (read with olefile). Its ``ScopedContents``
stream is a uint64 size and a tree of little-endian entries: a uint16 tag, a uint64
size and the payload, which is either a value or a sequence of entries (some lists put
a uint64 entry size before each entry). Strings are a byte 0x04 and UTF-16LE text.
The layout was worked out here on two files (MountainsMap 9.2 and 10.3) and checked
against a BCR export of the same measurement (``bcrf-1.bcrf``: equal to 1e-7 µm); no
vendor documentation exists. The facts used:

* the studiables are the entries of tag 0x02bd in the root entry (tag 0x0001); the
  first is the one read;
* an axis is an entry holding a name entry (an id and ``X``, ``Y`` or ``Z``), the step
  (tag 1, float64) in the unit of tag 2, a display unit (tag 3) and an offset in that
  display unit (tag 5); the entry around an x or y axis gives its point count (tag 1);
* objects are an entry whose tag 1 holds a class number: class 9049 is an array
  (uint32 count, then the data), class 9056 a validity image (columns, rows, bytes, 1,
  then a class 9048 array);
* array data are a uint64 byte count, then blocks in any order, each a uint64 element
  offset, a uint32 element count, a uint32 compressed size and a zlib stream (an array
  larger than ``MAX_RATIO`` times the stream, :mod:`rough.io.limits`, is refused as a bomb);
* heights are int32 counts, rows of x, the first stored row first (row 0 here):
  ``count * z step + z offset``;
* the validity image is one byte per point on a grid with a one-point border; codes
  with bit 0 clear (22 in the example, against 9 for measured points) mark points not
  measured (NaN here).

SurfaceTopography 1.27.1 reads the same heights; its later reader applies a different
height scale and takes every zero count as invalid, which drops 126 measured points of
``mnt-2.mnt``. MountainsMap's extent along an axis is (n - 1) steps, and its export of
the same measurement (``bcrf-1.bcrf``) and SurfaceTopography give that extent as the
size; in rough's convention (size = n · spacing) the spacing is therefore
step · (n - 1) / n, and the size equals MountainsMap's extent (mnt-1: 1777.404 µm,
not 960 steps = 1779.257 µm).
"""

import io
import re
import struct
import zlib

import numpy as np

from ..errors import FormatError
from ..extras import require
from ..surface import Surface, Units, check_size
from . import limits
from .header import length_unit
from .registry import Format

FORMAT = Format(
    "mnt",
    "Digital Surf MountainsMap MNT",
    (".mnt",),
    magic=(b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1",),
    carries=("spacing", "units", "metadata", "mask"),
    read_library="olefile",
)

ENTRY = struct.Struct("<HQ")
ROOT, STUDIABLES, NAME = 0x0001, 0x02BD, 0xFFFF
ARRAY, VALIDITY = 9049, 9056
MAX_ENTRIES = 1 << 20
MAX_DEPTH = 64


def read(data, options):
    olefile = require("olefile")
    try:
        # a stream, not bytes: olefile takes bytes shorter than 1536 for a file name
        with olefile.OleFileIO(io.BytesIO(bytes(data))) as document:
            if not document.exists("ScopedContents"):
                raise FormatError("OLE2 file is not a MountainsMap document (no ScopedContents stream)")
            contents = document.openstream("ScopedContents").read()
            header = document.openstream("XmlHeader").read() if document.exists("XmlHeader") else b""
    except OSError as error:
        raise FormatError(f"not a readable OLE2 compound file ({error})") from None
    studiable = _first_studiable(contents)
    axes, arrays = _scan(contents, studiable)
    x, y, z = (_axis(contents, axes, name) for name in "XYZ")
    nx, ny = x["count"], y["count"]
    if ARRAY not in arrays:
        raise FormatError("MNT studiable holds no height array")
    counts = _array(contents, arrays[ARRAY], nx * ny, 4).view("<i4").reshape(ny, nx)
    heights = counts * (z["step"] * z["factor"]) + z["offset"] * z["display_factor"]
    if VALIDITY in arrays:
        heights[_not_measured(contents, arrays[VALIDITY], nx, ny)] = np.nan
    spacing = tuple(axis["step"] * axis["factor"] * max(axis["count"] - 1, 1) / axis["count"] for axis in (x, y))
    origin = (x["offset"] * x["display_factor"], y["offset"] * y["display_factor"])
    units = Units(xy=x["unit"], z=z["display_unit"])
    return Surface(heights, spacing, origin, units, _metadata(header))


def _entries(data, start, end):
    """``[(tag, payload start, payload end), ...]`` when ``data[start:end]`` is exactly
    a sequence of entries (plain, or each after its uint64 size), else None."""
    for prefixed in (False, True):
        found, position = [], start
        while position < end:
            if prefixed:
                if position + 8 > end:
                    break
                size_before = struct.unpack_from("<Q", data, position)[0]
                position += 8
            if position + ENTRY.size > end:
                break
            tag, size = ENTRY.unpack_from(data, position)
            if size > end - position - ENTRY.size or (prefixed and size_before != size + ENTRY.size):
                break
            found.append((tag, position + ENTRY.size, position + ENTRY.size + size))
            position += ENTRY.size + size
        else:
            return found
    return None


def _children(data, entry):
    return _entries(data, entry[1], entry[2]) or []


def _child(data, entry, tag):
    return next((child for child in _children(data, entry) if child[0] == tag), None)


def _first_studiable(data):
    if len(data) < 8:
        raise FormatError("MNT ScopedContents stream is truncated")
    root = next((entry for entry in _entries(data, 8, len(data)) or [] if entry[0] == ROOT), None)
    block = root and _child(data, root, STUDIABLES)
    holder = block and _child(data, block, 0x0002)
    listing = holder and _child(data, holder, 0x0001)
    studiables = listing and _children(data, listing)
    if not studiables:
        raise FormatError("MNT ScopedContents holds no studiable (tag 0x02bd)")
    return studiables[0]


def _scan(data, studiable):
    """The axes ``{name: (axis entry, count or None)}`` and the first object of each
    class ``{class: payload entry}`` inside ``studiable``."""
    axes, arrays, visited = {}, {}, 0
    pending = [(studiable, None, 0)]
    while pending:
        entry, parent, depth = pending.pop()
        visited += 1
        if visited > MAX_ENTRIES or depth > MAX_DEPTH:
            raise FormatError("MNT ScopedContents tree is too large or too deep to read")
        children = _children(data, entry)
        tags = {child[0]: child for child in children}
        name = _axis_name(data, tags)
        if name and name not in axes:
            count = _uint(data, parent.get(0x0001)) if parent else None
            axes[name] = (tags, count)
        kind = _uint(data, _child(data, tags[0x0001], 0x0001)) if {0x0001, 0x0002} <= tags.keys() else None
        if kind in (ARRAY, VALIDITY) and kind not in arrays:
            arrays[kind] = tags[0x0002]
        pending.extend((child, tags, depth + 1) for child in reversed(children))
    return axes, arrays


def _axis_name(data, tags):
    if not {NAME, 0x0001, 0x0002, 0x0003, 0x0005} <= tags.keys() or tags[0x0001][2] - tags[0x0001][1] != 8:
        return None
    label = _child(data, tags[NAME], 0x0002)
    return _text(data, label) if label else None


def _axis(data, axes, name):
    if name not in axes:
        raise FormatError(f"MNT studiable has no {name} axis")
    tags, count = axes[name]
    step = struct.unpack_from("<d", data, tags[0x0001][1])[0]
    offset = _double(data, tags[0x0005])
    unit, display_unit = _text(data, tags[0x0002]), _text(data, tags[0x0003])
    if not unit or not display_unit:
        raise FormatError(f"MNT {name} axis names no unit")
    if not 0 < step < np.inf:
        raise FormatError(f"MNT {name} step is {step!r} {unit}, not a positive length")
    if name != "Z" and not count:
        raise FormatError(f"MNT {name} axis gives no point count")
    facts = {"step": step, "offset": offset, "count": count, "unit": unit, "display_unit": display_unit}
    return facts | {
        "factor": length_unit(unit, f"MNT {name} unit"),
        "display_factor": length_unit(display_unit, f"MNT {name} unit"),
    }


def _double(data, entry):
    if entry[2] - entry[1] != 8:
        raise FormatError("MNT axis offset is not a float64")
    return struct.unpack_from("<d", data, entry[1])[0]


def _uint(data, entry):
    if entry is None or entry[2] - entry[1] != 4:
        return None
    return struct.unpack_from("<I", data, entry[1])[0]


def _text(data, entry):
    raw = data[entry[1] : entry[2]]
    if raw[:1] != b"\x04" or len(raw) % 2 != 1:
        return None
    return raw[1:].decode("utf-16-le", "replace")


def _array(data, payload, count, size):
    """The bytes of a class 9049 or 9048 array of ``count`` elements of ``size`` bytes."""
    entries = _entries(data, payload[1], payload[2]) or []
    tags = {entry[0]: entry for entry in entries}
    declared = _uint(data, tags.get(0x0001))
    if declared != count or 0x0002 not in tags:
        raise FormatError(f"MNT array holds {declared} points, not the {count:,} points of its grid")
    start, end = tags[0x0002][1], tags[0x0002][2]
    if end - start < 8 or struct.unpack_from("<Q", data, start)[0] != count * size:
        raise FormatError(f"MNT array is not {count * size:,} bytes long")
    check_size((count,), "the MNT array")
    limits.Budget(len(data), "MNT array data").add(count * size)  # a bomb is refused before unpacking
    out = bytearray(count * size)
    filled, position = 0, start + 8
    while position < end:
        if position + 16 > end:
            raise FormatError("MNT array block header runs past the end of its data")
        offset, elements, packed = struct.unpack_from("<QII", data, position)
        position += 16
        if position + packed > end or offset + elements > count:
            raise FormatError("MNT array block runs past the end of its data")
        block = zlib.decompressobj().decompress(data[position : position + packed], elements * size)
        if len(block) != elements * size:
            raise FormatError(f"MNT array block gives {len(block):,} bytes, not {elements * size:,} bytes")
        out[offset * size : (offset + elements) * size] = block
        filled += elements
        position += packed
    if filled != count:
        raise FormatError(f"MNT array blocks hold {filled:,} of its {count:,} points")
    return np.frombuffer(bytes(out), np.uint8)


def _not_measured(data, payload, nx, ny):
    tags = {entry[0]: entry for entry in _entries(data, payload[1], payload[2]) or []}
    width, height = _uint(data, tags.get(0x0001)), _uint(data, tags.get(0x0002))
    image = tags.get(0x0005)
    inner = image and _child(data, image, 0x0002)
    if (width, height) != (nx, ny) or inner is None:
        raise FormatError(f"MNT validity image is {width} × {height} points, not {nx} × {ny}")
    codes = _array(data, inner, (nx + 2) * (ny + 2), 1).reshape(ny + 2, nx + 2)[1:-1, 1:-1]
    return (codes & 1) == 0


def _metadata(header):
    text = header.decode("utf-16-le", "replace")
    metadata = {"vendor": "Digital Surf"}
    product, version = re.search(r"<ProductName>([^<]*)<", text), re.search(r"<Version>([^<]*)<", text)
    if product:
        metadata["mnt_software"] = " ".join(part.group(1) for part in (product, version) if part)
    return metadata
