"""OpenEXR height maps, read and written with the OpenEXR 3 Python API.

Written as Gwyddion writes them, so that Gwyddion builds with OpenEXR open the file
at its true size: one float32 channel ``Y`` (ZIP compression, lossless), the double
attributes ``Gwy::XReal``, ``Gwy::YReal``, ``Gwy::XOffset``, ``Gwy::YOffset`` and the
string attributes ``Gwy::XYUnit``, ``Gwy::ZUnit``, ``Gwy::Title``. rough's units,
metadata and history go in the string attributes ``rough:units``, ``rough:metadata``
and ``rough:history`` (JSON). A one-row image is a profile.

Read: a single height channel, ``Y``, ``Z`` or ``R`` (in that order of preference, or
the only channel there is), in half, float or uint pixels, scaled as Gwyddion does
(``Gwy::ZScale``, or ``Gwy::ZMin``/``Gwy::ZMax`` for integers) and in the units that
``Gwy::XYUnit`` and ``Gwy::ZUnit`` name. Without ``Gwy::XReal`` and ``Gwy::YReal`` the
spacing must come from ``--spacing``. Heights are float32, so a round trip keeps
them to float32 rounding. The chunks must fill the file as the offset table says
(:func:`_check_chunks`), or the file is refused as damaged.
"""

import contextlib
import io
import os
import sys

import numpy as np

from ..errors import FormatError
from ..extras import require
from ..surface import Surface, Units
from ..units import metres_per
from . import limits, provenance
from .registry import Format

FORMAT = Format(
    "exr",
    "OpenEXR",
    (".exr",),
    magic=(b"\x76\x2f\x31\x01",),
    writes=True,
    carries=("spacing", "units", "metadata", "history"),
    height_type="float32",
    read_library="OpenEXR",
    write_library="OpenEXR",
)

HEIGHT_CHANNELS = ("Y", "Z", "R")
MAX_POINTS = 1 << 31
MAX_EXPANSION = 1100  # more than zlib's largest compression ratio (about 1032:1)
# scanlines per chunk of each compression (OpenEXR file layout), by compression number
LINES_PER_CHUNK = (1, 1, 1, 16, 32, 16, 32, 32, 32, 256, 256, 32, 256, 1)
TILED, DEEP, MULTIPART = 0x200, 0x800, 0x1000  # flags of the version field


def read(data, options):
    OpenEXR = require("OpenEXR")

    with _library_quiet():
        parts = _open(OpenEXR, data, header_only=True).parts
    if len(parts) > 1:
        raise FormatError(f"EXR file holds {len(parts)} parts; rough reads single-part files (split it: exrmultipart)")
    header = parts[0].header
    low, high = header["dataWindow"]
    nx, ny = int(high[0] - low[0] + 1), int(high[1] - low[1] + 1)
    if nx < 1 or ny < 1 or nx * ny > MAX_POINTS or nx * ny * 2 > MAX_EXPANSION * len(data):
        raise FormatError(f"EXR data window of {nx}×{ny} pixels is impossible for a file of {len(data)} bytes")
    _check_chunks(bytes(data))
    with _library_quiet():  # the bindings read the pixels on first access
        channels = _open(OpenEXR, data).channels()
        name = _height_channel(channels)
        heights = np.asarray(channels[name].pixels, dtype=np.float64)
    if heights.shape != (ny, nx):
        raise FormatError(f"EXR channel {name} has shape {heights.shape}, expected {(ny, nx)}")
    xy_unit, z_unit, title = (_string(header, key) for key in ("Gwy::XYUnit", "Gwy::ZUnit", "Gwy::Title"))
    xy_factor = metres_per(xy_unit or "m")
    heights = _scale_values(heights, header) * metres_per(z_unit or "m")
    if "Gwy::XReal" in header and "Gwy::YReal" in header:
        spacing = (_double(header, "Gwy::XReal") * xy_factor / nx, _double(header, "Gwy::YReal") * xy_factor / ny)
    elif options.spacing is not None:
        spacing = options.spacing
    else:
        raise FormatError("EXR file has no Gwy::XReal and Gwy::YReal attributes, so no spacing; give it with --spacing")
    origin = (_double(header, "Gwy::XOffset", 0.0) * xy_factor, _double(header, "Gwy::YOffset", 0.0) * xy_factor)
    metadata = {"title": title} if title else {}
    units = Units(xy_unit or "m", z_unit or "m")
    metadata, units, history = provenance.restore(
        {part: header.get(f"rough:{part}") for part in provenance.PARTS}, metadata, units
    )
    if ny == 1:
        return Surface(heights[0], spacing[:1], origin[:1], units, metadata, history)
    return Surface(heights, spacing, origin, units, metadata, history)


def write(surface, stream):
    OpenEXR = require("OpenEXR")

    heights = np.ascontiguousarray(np.atleast_2d(surface.heights), dtype=np.float32)
    ny, nx = heights.shape
    dy = surface.spacing[-1]
    y0 = surface.origin[1] if len(surface.origin) == 2 else 0.0
    header = {
        "compression": OpenEXR.ZIP_COMPRESSION,
        "type": OpenEXR.scanlineimage,
        "Gwy::XReal": np.array([nx * surface.spacing[0]]),
        "Gwy::YReal": np.array([ny * dy]),
        "Gwy::XOffset": np.array([surface.origin[0]]),
        "Gwy::YOffset": np.array([y0]),
        "Gwy::XYUnit": "m",
        "Gwy::ZUnit": "m",
        **{f"rough:{part}": text for part, text in provenance.record(surface).items()},
    }
    if surface.metadata.get("title"):
        header["Gwy::Title"] = str(surface.metadata["title"])
    buffer = io.BytesIO()
    OpenEXR.File(header, {"Y": heights}).write(buffer)
    stream.write(buffer.getbuffer())


def _open(OpenEXR, data, header_only=False):
    try:
        return OpenEXR.File(io.BytesIO(bytes(data)), separate_channels=True, header_only=header_only)
    except Exception as error:  # noqa: BLE001 -- the bindings raise plain RuntimeError/Exception for bad files
        raise FormatError(f"not a readable OpenEXR file ({error})") from None


def _check_chunks(data):
    """Refuse a file whose chunks do not fill it as its header says: every offset in the
    table inside the file, every chunk holding the scanline (or tile) its place in the
    table names, the chunks one after another from the table's end to the file's end.
    The library trusts the packed sizes, so bytes put in before a chunk's data, or taken
    from before it, would otherwise read as other pixels."""
    flags = int.from_bytes(data[4:8], "little")
    attributes, at = _attributes(data, 8)
    if flags & DEEP or attributes.get("type", b"").startswith(b"deep"):
        raise FormatError("EXR file holds deep data (several samples per pixel), not a height map")
    at += bool(flags & MULTIPART)  # the empty header that ends the list of parts
    xmin, ymin, xmax, ymax = np.frombuffer(attributes["dataWindow"], "<i4", count=4).tolist()
    if flags & TILED or attributes.get("type") == b"tiledimage":  # the type names it in a multi-part file
        expected = _tiles(attributes.get("tiles", b""), xmax - xmin + 1, ymax - ymin + 1, (len(data) - at) // 8)
    else:
        compression = attributes["compression"][0]
        if compression >= len(LINES_PER_CHUNK):
            raise FormatError(f"EXR compression {compression} is unknown to rough")
        lines = LINES_PER_CHUNK[compression]
        if at + 8 * -(-(ymax - ymin + 1) // lines) > len(data):
            raise FormatError("EXR offset table does not fit in the file")
        expected = np.arange(ymin, ymax + 1, lines)[:, None]
    width = 4 * (expected.shape[1] + 1 + bool(flags & MULTIPART))  # part, scanline or tile, packed size
    table_end = at + 8 * len(expected)
    offsets = np.frombuffer(data, "<u8", count=len(expected), offset=at)
    outside = np.flatnonzero((offsets < table_end) | (offsets > len(data) - width))
    if outside.size:
        raise FormatError(f"EXR chunk {outside[0]} is at byte {offsets[outside[0]]:,}, outside the file's data")
    starts = offsets.astype(np.int64)
    fields = np.frombuffer(data, np.uint8)[starts[:, None] + np.arange(width)].view("<i4")
    wrong = np.flatnonzero(np.any(fields[:, -1 - expected.shape[1] : -1] != expected, axis=1))
    if wrong.size or (flags & MULTIPART and np.any(fields[:, 0])):
        raise FormatError(f"EXR chunk {(wrong.tolist() or [0])[0]} is not the part of the image its offset names")
    order = np.argsort(starts)
    ends = starts[order] + width + fields[order, -1].astype(np.int64)
    follows = np.concatenate(([table_end], ends[:-1]))
    if np.any(fields[:, -1] < 0) or np.any(starts[order] != follows) or ends[-1] != len(data):
        raise FormatError(f"EXR chunks do not fill the file from its offset table to its end ({len(data):,} bytes)")


def _attributes(data, at):
    """``({name: value bytes}, where the header ends)`` of the header starting at ``at``:
    ``name\\0type\\0`` int32 size, value, …, a NUL byte."""
    attributes = {}
    while at < len(data) and data[at]:
        name_end = data.find(b"\0", at)
        value = data.find(b"\0", name_end + 1) + 5
        size = int.from_bytes(data[value - 4 : value], "little", signed=True)
        if name_end < 0 or value < 5 or size < 0 or value + size > len(data):
            break
        attributes[data[at:name_end].decode("latin-1")] = data[value : value + size]
        at = value + size
    if at >= len(data) or data[at] or len(attributes.get("dataWindow", b"")) != 16 or not attributes.get("compression"):
        raise FormatError("EXR header is damaged")
    return attributes, at + 1


def _tiles(description, width, height, limit):
    """``[[tile x, tile y, level x, level y], …]`` in the order of the offset table (the
    levels of a ripmap by y, then x; the tiles of a level by row); at most ``limit``."""
    if len(description) != 9:
        raise FormatError("EXR tiled file has no tile description")
    tile_x, tile_y = np.frombuffer(description, "<u4", count=2).tolist()
    mode, rounding = description[8] & 15, description[8] >> 4
    if not (tile_x and tile_y) or mode > 2 or rounding > 1:
        raise FormatError("EXR tile description is damaged")

    def count(n):
        """Levels from n pixels down to 1: log2(n), rounded as the file says, plus 1."""
        return ((n - 1).bit_length() if rounding else n.bit_length() - 1) + 1

    def size(n, level):
        return max(1, -(-n >> level) if rounding else n >> level)

    if mode == 0:
        levels = [(0, 0, width, height)]
    elif mode == 1:
        levels = [(lv, lv, size(width, lv), size(height, lv)) for lv in range(count(max(width, height)))]
    else:
        levels = [
            (lx, ly, size(width, lx), size(height, ly)) for ly in range(count(height)) for lx in range(count(width))
        ]
    counts = [(-(-w // tile_x), -(-h // tile_y)) for _, _, w, h in levels]
    if sum(nx * ny for nx, ny in counts) > limit:
        raise FormatError("EXR offset table does not fit in the file")
    return np.concatenate(
        [
            np.stack(np.broadcast_arrays(*np.mgrid[:ny, :nx][::-1], lx, ly), axis=-1).reshape(-1, 4)
            for (lx, ly, _, _), (nx, ny) in zip(levels, counts)
        ]
    )


def _height_channel(channels):
    """Y, Z or R (in that order), or the only channel there is."""
    name = next((c for c in HEIGHT_CHANNELS if c in channels), None)
    if name is None and len(channels) == 1:
        name = next(iter(channels))
    if name is None:
        raise FormatError(f"EXR has channels {', '.join(sorted(channels))}; rough reads one height channel (Y, Z or R)")
    return name


@contextlib.contextmanager
def _library_quiet():
    """Keep the OpenEXR library's own messages about a bad file (the C core writes to
    standard error, the Python bindings to standard output, flushed at once) off both:
    rough reports the failure itself, in one line, and standard output may be a pipe
    that carries data."""
    try:
        saved = [os.dup(1), os.dup(2)]
    except OSError:
        yield
        return
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        sys.stdout.flush()
        sys.stderr.flush()
        os.dup2(devnull, 1)
        os.dup2(devnull, 2)
        yield
    finally:
        for descriptor, copy in enumerate(saved, start=1):
            os.dup2(copy, descriptor)
            os.close(copy)
        os.close(devnull)


def _scale_values(values, header):
    """Gwyddion's value scaling: ``Gwy::ZMin``/``Gwy::ZMax`` map the full uint32 range,
    otherwise ``Gwy::ZScale`` is the value of 1.0 in the file."""
    if "Gwy::ZMax" in header:
        low = _double(header, "Gwy::ZMin", 0.0)
        factor = (_double(header, "Gwy::ZMax") - low) / (2.0**32 - 1 + 0.999)
        return limits.scaled(values, factor, "EXR Gwy::ZMin and Gwy::ZMax", low)
    return limits.scaled(values, _double(header, "Gwy::ZScale", 1.0), "EXR Gwy::ZScale")


def _string(header, key):
    """A text attribute, or None when absent; anything else there is damage."""
    value = header.get(key)
    if value is not None and not isinstance(value, str):
        raise FormatError(f"EXR attribute {key} should be text, not {type(value).__name__}")
    return value


def _double(header, key, default=None):
    value = header.get(key, default)
    if value is None:
        raise FormatError(f"EXR attribute {key} is missing")
    value = float(np.ravel(value)[0])
    if not np.isfinite(value) or (key.endswith("Real") and value <= 0):
        raise FormatError(f"EXR attribute {key} is not a usable length: {value}")
    return value
