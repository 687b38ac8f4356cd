"""Park Systems TIFF (XEI, SmartScan), read only, through tifffile.

The TIFF's image is an 8-bit colour-mapped preview; the measurement is in private tags of the first IFD:
50432 holds the magic 0x0E031301, 50433 the version (0x1000001 or 0x1000002), 50434 the data and 50435 a
binary header (at least 356 bytes in version 1, 580 in version 2, little-endian, text fields UTF-16).
The header gives the image type (0: a 2-D map), the channel's name (``Z Height``), x and y points, the
scan size in µm, ``swap_xy``, and the height scaling: a raw value v gives
``(v * z_scale + z_offset) * data_gain`` in the header's z unit. Version 2 adds the data type (int16,
int32 or float32; version 1 is always int16); the data tag holds exactly the points, no more, no fewer.
Header layout as Gwyddion's ``psia.c`` and SurfaceTopography's ``PS.py`` read it (the latter leaves out
``z_offset``). Line profiles, spectroscopy and images with swapped axes are not read.

Orientation: row 0 is the last line stored, as Gwyddion shows it (SurfaceTopography keeps the stored order).
"""

import datetime
import io
import struct

import numpy as np

from ..errors import FormatError
from ..extras import require
from ..surface import Surface, Units, check_size
from .header import first_tiff_tags, length_unit, quiet
from .registry import Format, channel_metadata

MAGIC = 0x0E031301
VERSIONS = {0x1000001: 356, 0x1000002: 580}
TAG_MAGIC, TAG_VERSION, TAG_DATA, TAG_HEADER = 50432, 50433, 50434, 50435
DATA_TYPES = {0: "<i2", 1: "<i4", 2: "<f4"}


def probe(head):
    """Tag 50432 with Park's magic number among the first IFD's entries."""
    for tag, kind, number, value in first_tiff_tags(head):
        if tag == TAG_MAGIC:
            return kind == 4 and number == 1 and value == MAGIC
    return False


FORMAT = Format(
    "ps",
    "Park Systems TIFF",
    (".tiff", ".tif"),
    magic=(b"II*\0", b"MM\0*"),
    probe=probe,
    carries=("spacing", "units", "metadata", "time"),
    read_library="tifffile",
)


def read(data, options):
    tifffile = require("tifffile")
    tags = _tags(tifffile, bytes(data))
    if tags.get(TAG_MAGIC) != MAGIC:
        raise FormatError("TIFF lacks Park Systems' magic tag 50432")
    version = tags.get(TAG_VERSION)
    if version not in VERSIONS:
        raise FormatError(f"Park Systems TIFF version {version!r} is not 0x1000001 or 0x1000002")
    header = _header(_bytes(tags, TAG_HEADER), VERSIONS[version])
    nx, ny = header["nx"], header["ny"]
    check_size((ny, nx), "the Park Systems image")
    dtype = np.dtype(DATA_TYPES[header["data_type"]])
    payload = _bytes(tags, TAG_DATA)
    if len(payload) < nx * ny * dtype.itemsize:
        raise FormatError(f"Park Systems data tag holds {len(payload)} bytes, fewer than {nx}×{ny} points need")
    if len(payload) > nx * ny * dtype.itemsize:
        raise FormatError(
            f"Park Systems data tag holds {len(payload):,} bytes, more than its {nx}×{ny} points "
            f"({nx * ny * dtype.itemsize:,} bytes)"
        )
    raw = np.frombuffer(payload, dtype, nx * ny).reshape(ny, nx)[::-1].astype(np.float64)
    z_unit = header["z_unit"] or "um"
    metres = length_unit(z_unit, "Park Systems z unit")
    heights = (raw * header["z_scale"] + header["z_offset"]) * header["data_gain"] * metres
    spacing = (header["width"] * 1e-6 / nx, header["height"] * 1e-6 / ny)
    name = header["source_name"] or "Z Height"
    metadata = {"vendor": "Park Systems", **channel_metadata([name], 0), **_tiff_metadata(tags)}
    return Surface(heights, spacing, units=Units(xy="um", z=z_unit), metadata=metadata)


def _tags(tifffile, data):
    try:
        with quiet("tifffile"), tifffile.TiffFile(io.BytesIO(data)) as tiff:
            return {tag.code: tag.value for tag in tiff.pages[0].tags.values()}
    except Exception as error:  # tifffile raises its own, struct and numpy errors on damaged files
        raise FormatError(f"Park Systems TIFF is damaged or truncated ({type(error).__name__}: {error})") from None


def _bytes(tags, code):
    value = tags.get(code)
    if not isinstance(value, bytes):
        raise FormatError(f"Park Systems TIFF lacks its tag {code} (truncated or damaged)")
    return value


def _header(raw, least):
    if len(raw) < least:
        raise FormatError(f"Park Systems header holds {len(raw)} bytes, fewer than its version's {least}")
    image_type, nx, ny = struct.unpack_from("<I", raw, 0)[0], *struct.unpack_from("<II", raw, 100)
    if image_type != 0:
        raise FormatError(f"Park Systems image type {image_type} is not a 2-D map (line profiles are not read)")
    if struct.unpack_from("<I", raw, 136)[0]:
        raise FormatError("Park Systems image with swapped x and y axes is not read")
    width, height = (abs(value) for value in struct.unpack_from("<dd", raw, 140))
    data_gain, z_scale, z_offset = struct.unpack_from("<ddd", raw, 220)
    data_type = struct.unpack_from("<I", raw, 348)[0] if least == VERSIONS[0x1000002] else 0
    if data_type not in DATA_TYPES:
        raise FormatError(f"Park Systems data type {data_type} is not int16, int32 or float32")
    numbers = (width, height, data_gain, z_scale or 1.0, z_offset)
    if not all(np.isfinite(numbers)) or not width > 0 or not height > 0 or nx < 1 or ny < 1:
        raise FormatError(f"Park Systems header has an unusable size or scale ({nx}×{ny} points, {numbers})")
    return {
        "nx": nx,
        "ny": ny,
        "width": width,
        "height": height,
        "data_gain": data_gain,
        "z_scale": z_scale or 1.0,
        "z_offset": z_offset,
        "data_type": data_type,
        "source_name": _utf16(raw, 4, 32),
        "z_unit": _utf16(raw, 244, 8),
    }


def _utf16(raw, offset, characters):
    return raw[offset : offset + 2 * characters].decode("utf-16-le", errors="replace").split("\0", 1)[0].strip()


def _tiff_metadata(tags):
    metadata = {}
    if isinstance(tags.get(305), str) and tags[305].strip():
        metadata["ps_software"] = tags[305].strip()
    try:
        metadata["date"] = datetime.datetime.strptime(str(tags.get(306)), "%Y:%m:%d %H:%M:%S").isoformat()
    except ValueError:
        pass
    return metadata
