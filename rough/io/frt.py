"""FRT MicroProf (FRT / FormFactor optical profilers, Mark III software), read only.

Layout (little-endian), as Gwyddion's ``microprof.c`` and SurfaceTopography's ``FRT.py``
read it: ``FRTM_GLIDERV`` and a 4-character version (``1.00``: block headers are a
uint16 id and a uint32 size; ``1.01``: a uint16 id and a uint64 size), a uint16 block
count, then the blocks. Block 0x0066 gives columns, rows and bits per point (16:
uint16, 32: int32); 0x0067 the x and y ranges and centre offsets in metres; 0x006c the
height factor (metres per count, after a uint32 range code); 0x0072 the measurement
start as Unix time; 0x000b the single image; 0x007d, when present, several images,
each with a uint32 data type (bit 0x4 topography, 0x2 intensity, ...), columns, rows
and bits. Points run row by row, x fastest; the first stored row is the bottom line
of the image, so rows are read in reverse (the last stored row is row 0), as
Gwyddion's ``microprof.c`` and SurfaceTopography do. A count of 1 marks an invalid
point (NaN here).
Images are offered as channels; the topography is the default. Spacing is range /
points. The header's block count walks the file to its last byte, and each image block
holds exactly its images (as in frt-1.frt and frt-2.frt); a file that does not is refused.
"""

import datetime
import struct

import numpy as np

from ..errors import FormatError
from ..surface import Surface, Units, check_size
from . import registry
from .registry import Format

FORMAT = Format(
    "frt",
    "FRT MicroProf",
    (".frt",),
    magic=(b"FRTM_",),
    carries=("spacing", "units", "metadata", "time", "channels", "mask"),
)

MAGIC = b"FRTM_GLIDERV"
INVALID = 1
KINDS = ((0x4, "Topography"), (0x2, "Intensity"), (0x1, "Piezo"), (0x80, "Thickness"), (0x1000, "AFM"))
KINDS += ((0x400, "Phase"), (0x2000, "Quality"), (0x40, "Camera"))
HEIGHT_KINDS = 0x4 | 0x80 | 0x800 | 0x1000


def read(data, options):
    data = bytes(data)
    blocks = _blocks(data)
    images = _images(data, blocks)
    names = _names(images)
    default = next((i for i, image in enumerate(images) if image[0] & 0x4), 0)
    index = registry.choose_channel(names, options.channel, default)
    kind, nx, ny, bits, offset = images[index]
    counts = np.frombuffer(data, "<u2" if bits == 16 else "<i4", nx * ny, offset).reshape(ny, nx)[::-1]
    is_height = bool(kind & HEIGHT_KINDS)
    heights = counts * (_double(data, blocks, 0x6C, 4) if is_height else 1.0)
    heights[counts == INVALID] = np.nan
    range_x, range_y = _double(data, blocks, 0x67, 0), _double(data, blocks, 0x67, 8)
    for name, length in (("x", range_x), ("y", range_y)):
        if not 0 < length < np.inf:
            raise FormatError(f"FRT {name} range is {length!r} m, not a positive length")
    metadata = {"vendor": "FRT", **registry.channel_metadata(names, index), **_texts(data, blocks)}
    if 0x72 in blocks:
        started = struct.unpack_from("<I", data, blocks[0x72][0])[0]
        metadata["date"] = datetime.datetime.fromtimestamp(started, datetime.timezone.utc).isoformat()
    units = Units(xy="m", z="m" if is_height else "1")
    return Surface(heights, (range_x / nx, range_y / ny), units=units, metadata=metadata)


def _blocks(data):
    """``{block id: (offset, size)}``."""
    if not data.startswith(MAGIC) or len(data) < 18:
        raise FormatError("not an FRT file (no FRTM_GLIDERV magic)")
    version = data[12:16]
    if version not in (b"1.00", b"1.01"):
        raise FormatError(f"FRT version {version.decode('latin-1')!r} is not supported (1.00 or 1.01)")
    layout = "<HI" if version == b"1.00" else "<HQ"
    header = struct.calcsize(layout)
    count = struct.unpack_from("<H", data, 16)[0]
    blocks, position = {}, 18
    for _ in range(count):
        if position + header > len(data):
            raise FormatError(f"FRT file of {len(data):,} bytes ends before its {count} blocks do")
        block, size = struct.unpack_from(layout, data, position)
        position += header
        if position + size > len(data):
            raise FormatError(f"FRT block 0x{block:04x} of {size:,} bytes runs past the end of the file")
        blocks.setdefault(block, (position, size))
        position += size
    if position != len(data):
        raise FormatError(f"FRT file holds {len(data):,} bytes, its {count} blocks {position:,}")
    return blocks


def _images(data, blocks):
    """``[(data type, columns, rows, bits, offset), ...]``: the images of block 0x007d,
    or the single image of block 0x000b."""
    images = []
    if 0x7D in blocks:
        offset, size = blocks[0x7D]
        position, end = offset + 8, offset + size
        while end - position > 16:
            kind, nx, ny, bits = struct.unpack_from("<4I", data, position)
            position = _checked_image(nx, ny, bits, position + 16, end)
            images.append((kind, nx, ny, bits, position - nx * ny * bits // 8))
        if images and position != end:
            raise FormatError(f"FRT block 0x007d holds {size:,} bytes, its images {position - offset:,}")
    if not images:
        if 0x66 not in blocks or 0x0B not in blocks:
            raise FormatError("FRT file holds no image (no block 0x000b or 0x007d)")
        nx, ny, bits = struct.unpack_from("<3I", data, _need(blocks, 0x66, 12))
        offset, size = blocks[0x0B]
        if _checked_image(nx, ny, bits, offset, offset + size) != offset + size:
            raise FormatError(
                f"FRT block 0x000b holds {size:,} bytes, its {nx} × {ny} points of {bits} bits {nx * ny * bits // 8:,}"
            )
        images.append((0x4, nx, ny, bits, offset))
    return images


def _checked_image(nx, ny, bits, offset, end):
    if bits not in (16, 32):
        raise FormatError(f"FRT points of {bits} bits are not supported (16 or 32 bits)")
    if nx < 1 or ny < 1:
        raise FormatError(f"FRT image of {nx} × {ny} points is empty")
    check_size((ny, nx), "the FRT image")
    if offset + nx * ny * bits // 8 > end:
        raise FormatError(f"FRT image of {nx} × {ny} points runs past the end of its block")
    return offset + nx * ny * bits // 8


def _names(images):
    names = []
    for kind, *_ in images:
        name = next((label for bit, label in KINDS if kind & bit), f"type 0x{kind:x}")
        if kind & 0x10000000:
            name += " (bottom sensor)"
        names.append(name if name not in names else f"{name} {len(names)}")
    return names


def _need(blocks, block, size):
    if block not in blocks or blocks[block][1] < size:
        raise FormatError(f"FRT file lacks its block 0x{block:04x}")
    return blocks[block][0]


def _double(data, blocks, block, at):
    return struct.unpack_from("<d", data, _need(blocks, block, at + 8) + at)[0]


def _texts(data, blocks):
    texts = {}
    for block, key in ((0x65, "comment"), (0x77, "frt_parameter_set")):
        if block in blocks:
            offset, size = blocks[block]
            text = data[offset : offset + size].split(b"\0", 1)[0].decode("latin-1").strip()
            if text:
                texts[key] = text
    return texts
