"""Digital Surf SUR (MountainsMap, Digital Surf instruments and exports), read only.

A file holds one or more objects, each a 512-byte little-endian header and its data.
The header starts with ``DIGITAL SURF`` (or ``DSCOMPRESSED`` for the zlib variant) and
gives, at these byte offsets: object count (14, int16), studiable type (18: 1 profile,
2 surface, ...), object and operator names (20, 50; 30 bytes each), non-measured points
flag (86), bits per point (98: 16 or 32), zmin and zmax (100, 104, int32), points per
line and lines (108, 112), spacings dx, dy, dz (120, 124, 128, float32) in the units
named at 180, 196 and 212 (16 bytes each), inversion (290), acquisition time as seconds,
minutes, hours, day, month, year (306-316, int16), compressed data size (324, uint32),
comment and private zone sizes (334, 336), and x, y, z offsets (466, 470, 474, float32).
The comment and private zones follow the header, then the points: int16 or int32 in
rows of ``points per line``, the first stored line first (kept as row 0 here). When the
non-measured flag is set, the value ``zmin - 2`` marks invalid points (NaN here). Heights
are ``value * dz + z offset``. The compressed variant stores a uint32 stream count, then
(uncompressed, compressed) uint32 sizes per stream, then the zlib streams, which
concatenate to the same points; points that would unpack to more than ``MAX_RATIO``
(:mod:`rough.io.limits`) times their compressed size are refused as a bomb.

Facts from Gwyddion's ``surffile.c`` (header layout, compressed streams, unit fix for
the old code-page micro sign) and surfalize's ``sur.py`` (the ``zmin - 2`` marker).
The objects fill the file to its last byte, and their measured counts lie within each
header's zmin … zmax (bytes 100 and 104; on both example files they are the counts'
extremes); a file that breaks either is refused.
Several objects (series, multilayer, RGB-intensity surfaces) are offered as channels
named by their z axis; the first height object is the default. An object is heights when
its studiable type is a profile or surface kind (1, 2, 4, 5, 7, 8, 11, 13, 16) and its
z unit is a length (an empty z unit is ``--unit``, else not a length); images (binary,
intensity, RGB: types 3, 10, 12), force curves and spectra are refused, as is an object
chosen with ``--channel`` that is not heights. An empty lateral unit is ``--unit``, else
metres. The inversion flag is recorded, not applied.

Non-measured points: Gwyddion 2.62 ignores the flag and keeps the marker values as
heights; on ``sur-3.sur`` (flag set, zmin 0) 233,009 of 262,144 points hold ``-2``, two
counts below every measured point, so Gwyddion's Sq (1.920 mm) and the 1.92 mm of
SurfaceTopography's test mostly measure the step between the marker and the measured
points. Gwyddion's heights equal rough's on every measured point; rough's Sq is
1.1132 mm, as SurfaceTopography 1.27.1 reads it.
"""

import datetime
import struct
import zlib

import numpy as np

from ..errors import FormatError
from ..surface import Surface, Units, check_size
from . import limits, registry
from .header import length_unit, metres_or_none
from .registry import Format

FORMAT = Format(
    "sur",
    "Digital Surf SUR",
    (".sur",),
    magic=(b"DIGITAL SURF", b"DSCOMPRESSED"),
    carries=("spacing", "units", "metadata", "time", "channels", "mask"),
)

HEADER_SIZE = 512
MAGIC, MAGIC_COMPRESSED = b"DIGITAL SURF", b"DSCOMPRESSED"
MAX_OBJECTS = 4096
MAX_STREAMS = 1 << 16
TYPES = {1: "profile", 2: "surface", 5: "series of surfaces", 7: "multilayer profile", 8: "multilayer surface"}
TYPES |= {10: "intensity image", 11: "intensity surface", 12: "RGB image", 16: "RGB intensity surface"}
TYPES |= {3: "binary image", 4: "series of profiles", 13: "RGB surface", 14: "force curve", 20: "spectrum"}
HEIGHT_TYPES = {1, 2, 4, 5, 7, 8, 11, 13, 16}
ACQUISITION = {1: "contact stylus", 2: "scanning optical gauge", 5: "contact stylus with skid", 6: "AFM"}
ACQUISITION |= {7: "STM", 8: "video", 9: "interferometer", 10: "structured light projection"}


def read(data, options):
    data = bytes(data)
    objects = _objects(data)
    names = [_channel_name(header, index) for index, (header, _) in enumerate(objects)]
    heights_objects = [index for index, (header, _) in enumerate(objects) if _is_height(header, options)]
    if options.channel is not None:
        index = registry.choose_channel(names, options.channel)
    elif heights_objects:
        index = heights_objects[0]
    else:
        index = 0
    header, offset = objects[index]
    if index not in heights_objects:
        raise FormatError(_not_heights(names[index], header))
    heights = _heights(data, header, offset, options)
    metadata = _metadata(objects[0][0])
    if len(objects) > 1:
        metadata |= registry.channel_metadata(names, index)
    units = Units(xy=header["dx_unit"] or options.unit or "m", z=header["dz_unit"] or options.unit)
    spacing = (_step(header, "dx", options), _step(header, "dy", options))
    origin = tuple(header[f"{axis}_offset"] * _factor(header[f"d{axis}_unit"], options) for axis in "xy")
    if heights.shape[0] == 1:
        return Surface(heights[0], spacing[:1], origin[:1], units, metadata)
    return Surface(heights, spacing, origin, units, metadata)


def _objects(data):
    """``[(header, data offset), ...]`` for every object in the file."""
    objects, position = [], 0
    while len(data) - position >= HEADER_SIZE and data[position : position + 12] in (MAGIC, MAGIC_COMPRESSED):
        if len(objects) >= MAX_OBJECTS:
            raise FormatError(f"SUR file holds more than {MAX_OBJECTS} objects")
        header = _header(data, position)
        start = position + HEADER_SIZE + header["comment_size"] + header["private_size"]
        objects.append((header, start))
        position = start + _data_size(header)
        if position > len(data):
            raise FormatError(
                f"SUR object {len(objects) - 1} needs {position:,} bytes but the file has {len(data):,} bytes"
            )
    if not objects:
        raise FormatError("not a SUR file (no DIGITAL SURF or DSCOMPRESSED header of 512 bytes)")
    if position != len(data):
        raise FormatError(f"SUR file holds {len(data):,} bytes, its {len(objects)} objects {position:,}")
    return objects


def _header(data, position):
    def field(offset, kind):
        return struct.unpack_from("<" + kind, data, position + offset)[0]

    def text(offset, size):
        raw = data[position + offset : position + offset + size].split(b"\0", 1)[0]
        if raw[:1] == b"\xe6":  # micro sign of the old MS-DOS code page
            raw = b"\xb5" + raw[1:]
        return raw.decode("latin-1").strip()

    header = {
        "compressed": data[position : position + 12] == MAGIC_COMPRESSED,
        "type": field(18, "h"),
        "object_name": text(20, 30),
        "operator": text(50, 30),
        "acquisition": field(82, "h"),
        "non_measured": field(86, "h"),
        "bits": field(98, "h"),
        "zmin": field(100, "i"),
        "zmax": field(104, "i"),
        "nx": field(108, "i"),
        "ny": field(112, "i"),
        "dx": field(120, "f"),
        "dy": field(124, "f"),
        "dz": field(128, "f"),
        "z_name": text(164, 16),
        "dx_unit": text(180, 16),
        "dy_unit": text(196, 16),
        "dz_unit": text(212, 16),
        "inversion": field(290, "h"),
        "time": struct.unpack_from("<6h", data, position + 306),
        "compressed_size": field(324, "I"),
        "comment_size": field(334, "H"),
        "private_size": field(336, "H"),
        "x_offset": field(466, "f"),
        "y_offset": field(470, "f"),
        "z_offset": field(474, "f"),
    }
    if header["bits"] not in (16, 32):
        raise FormatError(f"SUR points of {header['bits']} bits are not supported (16 or 32 bits)")
    if header["nx"] < 1 or header["ny"] < 1:
        raise FormatError(f"SUR grid of {header['nx']} × {header['ny']} points is empty or negative")
    check_size((header["ny"], header["nx"]), "the SUR object")
    return header


def _data_size(header):
    return header["compressed_size"] if header["compressed"] else header["nx"] * header["ny"] * header["bits"] // 8


def _not_heights(name, header):
    if header["type"] not in HEIGHT_TYPES:
        kind = TYPES.get(header["type"], f"type {header['type']}")
        return f"SUR object {name!r} is a {kind}, not heights; rough reads height maps and profiles"
    if not header["dz_unit"]:
        return f"SUR object {name!r} names no z unit, so its values are not known to be heights; give --unit"
    return f"SUR object {name!r} holds values in {header['dz_unit']!r}, not a length unit: not heights"


def _is_height(header, options):
    return header["type"] in HEIGHT_TYPES and metres_or_none(header["dz_unit"] or options.unit or "") is not None


def _heights(data, header, offset, options):
    dtype = np.dtype("<i2" if header["bits"] == 16 else "<i4")
    raw = _inflate(data, header, offset) if header["compressed"] else data[offset : offset + _data_size(header)]
    counts = np.frombuffer(raw, dtype, header["nx"] * header["ny"]).reshape(header["ny"], header["nx"])
    _check_range(counts, header)
    z_factor = _factor(header["dz_unit"], options)
    heights = counts * (float(header["dz"]) * z_factor) + header["z_offset"] * z_factor
    if header["non_measured"] == 1:
        heights[counts == header["zmin"] - 2] = np.nan
    return heights


def _check_range(counts, header):
    """FormatError when a measured count lies outside the header's zmin … zmax (when it states a range)."""
    low, high = header["zmin"], header["zmax"]
    measured = counts[counts != low - 2] if header["non_measured"] == 1 else counts
    if high > low and measured.size and (measured.min() < low or measured.max() > high):
        raise FormatError(
            f"SUR points span {measured.min()} … {measured.max()} counts, outside the header's "
            f"zmin … zmax, {low} … {high}: the data block is not the one the header describes"
        )


def _inflate(data, header, offset):
    """The points of a DSCOMPRESSED object: its zlib streams, concatenated."""
    expected = header["nx"] * header["ny"] * header["bits"] // 8
    end = offset + header["compressed_size"]
    count = struct.unpack_from("<I", data, offset)[0]
    if not 0 < count <= MAX_STREAMS or offset + 4 + 8 * count > end:
        raise FormatError(f"SUR compressed data lists {count} streams, which its {end - offset} bytes cannot hold")
    sizes = struct.unpack_from(f"<{2 * count}I", data, offset + 4)
    if sum(sizes[0::2]) != expected:
        raise FormatError(
            f"SUR compressed streams hold {sum(sizes[0::2]):,} bytes, not the {expected:,} bytes of points"
        )
    limits.Budget(end - offset, "SUR compressed data").add(expected)  # a bomb is refused before unpacking
    parts, position = [], offset + 4 + 8 * count
    for size, packed in zip(sizes[0::2], sizes[1::2]):
        if position + packed > end:
            raise FormatError("SUR compressed stream runs past the end of its data")
        inflater = zlib.decompressobj()
        part = inflater.decompress(data[position : position + packed], size)
        if len(part) != size:
            raise FormatError(f"SUR compressed stream gives {len(part):,} bytes, not {size:,} bytes")
        parts.append(part)
        position += packed
    return b"".join(parts)


def _factor(unit, options):
    return length_unit(unit or options.unit or "m", "SUR unit")


def _step(header, key, options):
    step = abs(header[key]) * _factor(header[f"{key}_unit"], options)
    if not 0 < step < np.inf:
        raise FormatError(f"SUR spacing {key} is {header[key]!r} {header[key + '_unit']}, not a positive length")
    return step


def _channel_name(header, index):
    return header["z_name"] or header["object_name"] or f"object {index}"


def _metadata(header):
    metadata = {"vendor": "Digital Surf", "sur_type": TYPES.get(header["type"], str(header["type"]))}
    for key, name in (("title", "object_name"), ("operator", "operator")):
        if header[name]:
            metadata[key] = header[name]
    if header["acquisition"] in ACQUISITION:
        metadata["sur_acquisition"] = ACQUISITION[header["acquisition"]]
    if header["inversion"]:
        metadata["sur_inversion"] = str(header["inversion"])
    second, minute, hour, day, month, year = header["time"]
    try:
        metadata["date"] = datetime.datetime(year, month, day, hour, minute, second).isoformat()
    except ValueError:
        pass
    return metadata
