"""WSxM (Nanotec Electrónica) images: ``.top``, ``.stp``, ``.ch1``…, read only.

The file starts with ``WSxM file copyright …``, ``SxM Image file`` and ``Image header size: N``, then a text
header of ``[Section]`` and ``key: value`` lines that ends with ``[Header end]``; the data follow that line
(``Image header size`` counts up to there, but some programs get it wrong, so the marker decides, as in
Gwyddion). ``[General Info]`` gives ``Number of columns``/``rows`` and ``Image Data Type`` (``short`` or
``integer``: int16, ``float``, ``double``; little-endian), ``[Control]`` the scan size (``X Amplitude: 600
nm``). Heights are scaled so that their range is ``[General Info] Z Amplitude`` (``13.7008 nm``): times
Z Amplitude / (``[Miscellaneous] Maximum`` − ``Minimum``), as SurfaceTopography's ``WSXM.py`` does, or over
the data's own range when those are missing (Gwyddion's ``wsxmfile.c`` always uses the data's range; the
two differ by about 1e-6 relative, from the rounding of the header values).

``Acquisition time`` (``03/11/2011, 20:23:46.484``) does not say whether the day or the month comes first,
so it is kept as written (``wsxm_acquisition_time``), not as ``date``.

Orientation: as Gwyddion, which reverses both axes of the stored data (its writer does the same); row 0
is the last line stored, column 0 the last column. SurfaceTopography keeps the stored order.
"""

import numpy as np

from ..errors import FormatError, InputError
from ..surface import Surface, Units, check_size
from ..units import metres_per
from .header import ini_sections
from .registry import Format

FORMAT = Format(
    "wsxm",
    "WSxM (Nanotec)",
    (".top", ".stp", ".ch1", ".f.top"),
    magic=(b"WSxM file copyright",),
    carries=("spacing", "units", "metadata"),
)

END = b"[Header end]"
TYPES = {"short": "<i2", "integer": "<i2", "float": "<f4", "double": "<f8"}


def read(data, options):
    data = bytes(data)
    lines = data.split(b"\n", 3)
    if len(lines) < 4 or lines[1].strip() != b"SxM Image file":
        raise FormatError("WSxM file is not an image (no 'SxM Image file' line)")
    end = data.find(END)
    if end < 0:
        raise FormatError("WSxM header has no [Header end] line")
    start = data.find(b"\n", end) + 1 or len(data)
    sections = ini_sections(data[:end].decode("latin-1"), ":")
    info = sections.get("General Info", {})
    nx, ny = _count(info, "Number of columns"), _count(info, "Number of rows")
    check_size((ny, nx), "the WSxM image")
    kind = info.get("Image Data Type", "short")
    if kind not in TYPES:
        raise FormatError(f"WSxM Image Data Type {kind!r} is not short, integer, float or double")
    dtype = np.dtype(TYPES[kind])
    if start + nx * ny * dtype.itemsize > len(data):
        raise FormatError(f"WSxM image of {nx}×{ny} {kind} values runs past the end of the file ({len(data)} bytes)")
    raw = np.ndarray((ny, nx), dtype, data, start)[::-1, ::-1].astype(np.float64)
    amplitude, z_unit = _length(info, "Z Amplitude")
    control = sections.get("Control", {})
    width, xy_unit = _length(control, "X Amplitude")
    height, _ = _length(control, "Y Amplitude") if "Y Amplitude" in control else (width, xy_unit)
    heights = raw * (amplitude / _range(sections.get("Miscellaneous", {}), raw))
    metadata = _metadata(info)
    return Surface(heights, (width / nx, height / ny), units=Units(xy=xy_unit, z=z_unit), metadata=metadata)


def _range(miscellaneous, raw):
    """Maximum − Minimum from the header, or the data's own range."""
    try:
        span = float(miscellaneous["Maximum"]) - float(miscellaneous["Minimum"])
    except (KeyError, ValueError):
        span = float(np.nanmax(raw) - np.nanmin(raw))
    if not 0 < span < np.inf:
        raise FormatError(f"WSxM data range {span:g} (raw values) cannot scale the heights to their Z Amplitude")
    return span


def _length(fields, key):
    """``(metres, unit)`` of a ``600 nm`` value."""
    text = fields.get(key, "")
    number, _, unit = text.partition(" ")
    try:
        value, metres = float(number), metres_per(unit.strip().replace("\xb5", "µ"))
    except (ValueError, InputError):
        raise FormatError(f"WSxM {key} is {text!r}, not a length") from None
    if not 0 < value < np.inf:
        raise FormatError(f"WSxM {key} is {text!r}, not a positive length")
    return value * metres, unit.strip()


def _count(fields, key):
    text = fields.get(key, "")
    if not text.isdigit() or int(text) < 1:
        raise FormatError(f"WSxM {key} is {text!r}, not a positive count")
    return int(text)


def _metadata(info):
    metadata = {"vendor": "Nanotec"}
    if info.get("Acquisition time"):
        metadata["wsxm_acquisition_time"] = info["Acquisition time"]
    if info.get("Acquisition channel"):
        metadata["channel"] = info["Acquisition channel"]
    if info.get("Head type"):
        metadata["wsxm_head"] = info["Head type"]
    return metadata
