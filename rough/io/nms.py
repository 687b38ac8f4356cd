"""Nanofocus µsurf NMS (confocal microscopes), read only.

A fixed 3468-byte little-endian header, then nx × ny uint16 heights, row by row (row 0
first, as stored), then nx × ny uint8 intensities (not read), and nothing after them: a file of
another length is refused. Header fields used: the
z range zmin, zmax (float64, µm) at byte 16, the format name (``OM_MS_2.0``) at byte
32, the image kind (``Confocal Height Image``) at byte 52, the date (``YYYY-MM-DDTHH:MM``)
at byte 1076, nx, ny (uint32) at byte 1368 and dx, dy (float64, **nm**) at byte 1376.
Heights are zmin + raw × (zmax − zmin) / 65535: the raw values span 0 … 65535 and the
uint32 at byte 12 is 65535. No invalid-point marker is known. Offsets as
SurfaceTopography's ``NMS.py`` and surfalize's ``nms.py`` read them; the units are ours:

* dx is in nanometres. nms-1.nms says 312.5 for 512 points: 312.5 nm gives a 160 µm
  field, the field of a µsurf 100× objective, with a 3.3 µm height range. Read as µm
  the field would be 160 mm, and as mm (SurfaceTopography) 160 m, neither possible
  for a confocal microscope; surfalize also reads nm.
* The height scale: SurfaceTopography divides by 65534 and surfalize adds zmax instead
  of zmin; with 65534 the largest raw value would lie above zmax.
"""

import datetime
import struct

import numpy as np

from ..errors import FormatError
from ..surface import Surface, Units, check_size
from .header import check_length
from .registry import Format

FORMAT = Format(
    "nms",
    "Nanofocus NMS",
    (".nms",),
    magic=((32, b"OM_MS_"),),
    by_extension=True,
    carries=("spacing", "units", "metadata", "time"),
)

HEADER_SIZE = 3468
FULL_SCALE = 65535


def read(data, options):
    data = bytes(data)
    if len(data) < HEADER_SIZE:
        raise FormatError(f"NMS header is truncated ({len(data)} bytes of {HEADER_SIZE})")
    zmin, zmax = struct.unpack_from("<2d", data, 16)
    nx, ny = struct.unpack_from("<2I", data, 1368)
    dx, dy = struct.unpack_from("<2d", data, 1376)
    if nx == 0 or ny == 0:
        raise FormatError(f"NMS image of {nx}×{ny} points is empty")
    check_size((ny, nx), "the NMS height image")
    check_length(data, HEADER_SIZE + 3 * nx * ny, "NMS", f"header, {nx}×{ny} uint16 heights and uint8 intensities")
    if not (np.isfinite(zmin) and np.isfinite(zmax) and zmax >= zmin):
        raise FormatError(f"NMS z range {zmin!r} … {zmax!r} µm is not a range")
    for name, step in (("dx", dx), ("dy", dy)):
        if not (0 < step < np.inf):
            raise FormatError(f"NMS {name} {step!r} nm is not a pixel size")
    raw = np.frombuffer(data, "<u2", nx * ny, HEADER_SIZE).reshape(ny, nx)
    heights = (zmin + raw * ((zmax - zmin) / FULL_SCALE)) * 1e-6
    return Surface(heights, (dx * 1e-9, dy * 1e-9), units=Units(xy="nm", z="um"), metadata=_metadata(data))


def _metadata(data):
    metadata = {"vendor": "Nanofocus"}
    title = _text(data, 52, 64)
    if title:
        metadata["title"] = title
    version = _text(data, 32, 20)
    if version:
        metadata["nms_format"] = version
    try:
        metadata["date"] = datetime.datetime.fromisoformat(_text(data, 1076, 20)).isoformat()
    except ValueError:
        pass
    return metadata


def _text(data, offset, size):
    return data[offset : offset + size].split(b"\0", 1)[0].decode("latin-1").strip()
