"""Alicona Imaging AL3D (focus-variation microscopes, MeasureSuite), read only.

The file starts with ``AliconaImaging\\0\\r\\n`` and a header of fixed-size tags (a
20-byte key and a 30-byte value, both NUL-padded, then CRLF): ``Version`` and
``TagCount`` first, then TagCount tags, then a 256-byte comment. The depth image is
little-endian float32 in metres at ``DepthImageOffset``, Rows × Cols, each row padded
to a multiple of 8 bytes; ``InvalidPixelValue`` marks invalid points (NaN here).
``PixelSizeXMeter``/``PixelSizeYMeter`` give the spacing. Layout as Gwyddion's
``alicona.c`` reads it; the texture planes are not read.
"""

import numpy as np

from ..errors import FormatError
from ..surface import Surface
from .registry import Format

FORMAT = Format(
    "al3d", "Alicona AL3D", (".al3d",), magic=(b"AliconaImaging\0",), carries=("spacing", "metadata", "mask")
)

MAGIC = b"AliconaImaging\0\r\n"
TAG_SIZE, KEY_SIZE, VALUE_SIZE = 52, 20, 30
COMMENT_SIZE = 256
MAX_TAGS = 10000


def read(data, options):
    data = bytes(data)
    tags = _header(data)
    cols, rows = _count(tags, "Cols"), _count(tags, "Rows")
    offset = _count(tags, "DepthImageOffset", allow_zero=True)
    if offset == 0:
        raise FormatError("AL3D file holds no depth image (DepthImageOffset 0)")
    stride = (cols * 4 + 7) // 8 * 8
    if offset + (rows - 1) * stride + cols * 4 > len(data):
        raise FormatError(f"AL3D depth image of {cols}×{rows} points runs past the end of the file")
    _check_length(data, tags, offset + rows * stride, rows, cols)
    depth = np.ndarray((rows, cols), "<f4", data, offset, (stride, 4)).astype(np.float64)
    invalid = _number(tags, "InvalidPixelValue", default=np.nan)
    depth[(depth == np.float32(invalid)) | ~np.isfinite(depth)] = np.nan
    spacing = (_length(tags, "PixelSizeXMeter"), _length(tags, "PixelSizeYMeter"))
    metadata = {"instrument": tags["CreatingApplication"]} if tags.get("CreatingApplication") else {}
    return Surface(depth, spacing, metadata=metadata)


def _check_length(data, tags, depth_end, rows, cols):
    """The file ends with the depth image or, when there is one, with the texture
    (NumberOfPlanes byte planes at TextureImageOffset, rows padded to 8 bytes): bytes put
    in before the depth image, or taken from before it, move it off its offset."""
    texture = _count(tags, "TextureImageOffset", allow_zero=True) if "TextureImageOffset" in tags else 0
    planes = _count(tags, "NumberOfPlanes", allow_zero=True) if texture else 0
    if planes:
        ends = (texture + planes * rows * ((cols + 7) // 8 * 8),)
    else:
        ends = (depth_end, depth_end - (-cols * 4) % 8)  # the last row padded, or not
    if len(data) not in ends:
        raise FormatError(f"AL3D header describes a file of {ends[0]:,} bytes; this one has {len(data):,}")


def _header(data):
    if not data.startswith(MAGIC):
        raise FormatError("not an AL3D file (no AliconaImaging magic)")
    position = len(MAGIC)
    version, position = _tag(data, position, "Version")
    count, position = _tag(data, position, "TagCount")
    if not count.isdigit() or int(count) > MAX_TAGS:
        raise FormatError(f"AL3D TagCount {count!r} is not a tag count")
    tags = {"Version": version}
    for _ in range(int(count)):
        key, value, position = _next_tag(data, position)
        tags[key] = value
    if position + COMMENT_SIZE > len(data):
        raise FormatError("AL3D header is truncated")
    return tags


def _tag(data, position, expected):
    key, value, position = _next_tag(data, position)
    if key != expected:
        raise FormatError(f"AL3D header lacks its {expected} tag (found {key!r})")
    return value, position


def _next_tag(data, position):
    record = data[position : position + TAG_SIZE]
    if len(record) < TAG_SIZE:
        raise FormatError("AL3D header is truncated")
    if record[-2:] != b"\r\n":
        raise FormatError(f"AL3D header tag at byte {position} lacks its CRLF terminator")
    key = record[:KEY_SIZE].split(b"\0", 1)[0].decode("latin-1")
    value = record[KEY_SIZE : KEY_SIZE + VALUE_SIZE].split(b"\0", 1)[0].decode("latin-1").strip()
    return key, value, position + TAG_SIZE


def _count(tags, key, allow_zero=False):
    value = tags.get(key)
    if value is None or not value.isdigit() or (int(value) == 0 and not allow_zero):
        raise FormatError(f"AL3D tag {key} is {value!r}, not a positive integer")
    return int(value)


def _number(tags, key, default=None):
    try:
        return float(tags[key])
    except KeyError:
        if default is None:
            raise FormatError(f"AL3D header lacks its {key} tag") from None
        return default
    except ValueError:
        raise FormatError(f"AL3D tag {key} is {tags[key]!r}, not a number") from None


def _length(tags, key):
    value = _number(tags, key)
    if not (0 < value < np.inf):
        raise FormatError(f"AL3D tag {key} is {tags[key]!r}, not a pixel size")
    return value
