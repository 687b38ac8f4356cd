"""WSxM (Nanotec Electrónica) images: ``.top``, ``.stp``, ``.ch1``…, read only.

The file starts with ``WSxM file copyright …``, ``SxM Image file`` and ``Image header size: N``, then a text
header of ``[Section]`` and ``key: value`` lines that ends with ``[Header end]``; the data follow that line
(``Image header size`` counts up to there, but some programs get it wrong, so the marker decides, as in
Gwyddion). ``[General Info]`` gives ``Number of columns``/``rows`` and ``Image Data Type`` (``short`` or
``integer``: int16, ``float``, ``double``; little-endian), ``[Control]`` the scan size (``X Amplitude: 600
nm``). ``float`` and ``double`` data are heights in the unit of ``[General Info] Z Amplitude`` (``13.7008
nm``) and are taken as stored: rescaling them to that amplitude over the header's ``Maximum`` − ``Minimum``,
printed with six digits, moves every height by up to 1e-5 relative (SurfaceTopography's ``WSXM.py`` 1.27.1
reads the stored values, and its test asserts stp-1.stp Sq 1.6541594 nm). Integer data are counts scaled
so that their range is Z Amplitude: times Z Amplitude / (``[Miscellaneous] Maximum`` − ``Minimum``, whole
counts), or over the data's own range when those are missing, as Gwyddion's ``wsxmfile.c`` does; counts
outside Minimum … Maximum are refused (on top-1.top they are the counts' extremes). The data end the file:
a file of another length is refused.

``Acquisition time`` (``03/11/2011, 20:23:46.484``) does not say whether the day or the month comes first,
so it is kept as written (``wsxm_acquisition_time``), not as ``date``.

The file holds one channel, named by ``[General Info] Acquisition channel``; one that is not a height
(``Topography``, ``Height``, ``Z``), such as ``Phase`` or ``Normal force``, is refused unless ``--channel``
names it.

Orientation: as Gwyddion, which reverses both axes of the stored data (its writer does the same); row 0
is the last line stored, column 0 the last column. SurfaceTopography keeps the stored order.
"""

import numpy as np

from ..errors import FormatError, InputError
from ..surface import Surface, Units, check_size
from ..units import metres_per
from .header import check_length, ini_sections
from .registry import Format, choose_channel, names_height

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
    check_length(data, start + nx * ny * dtype.itemsize, "WSxM", f"header and {nx}×{ny} {kind} values")
    raw = np.ndarray((ny, nx), dtype, data, start)[::-1, ::-1].astype(np.float64)
    amplitude, z_unit = _length(info, "Z Amplitude")
    control = sections.get("Control", {})
    width, xy_unit = _length(control, "X Amplitude")
    height, _ = _length(control, "Y Amplitude") if "Y Amplitude" in control else (width, xy_unit)
    scale = metres_per(z_unit) if dtype.kind == "f" else amplitude / _range(sections.get("Miscellaneous", {}), raw)
    heights = raw * scale
    metadata = _metadata(info)
    _check_height(metadata.get("channel"), options)
    return Surface(heights, (width / nx, height / ny), units=Units(xy=xy_unit, z=z_unit), metadata=metadata)


def _check_height(channel, options):
    """FormatError for a file whose ``Acquisition channel`` is not a height, unless ``--channel`` names it."""
    if channel is None or names_height(channel):
        return
    if options.channel is None:
        raise FormatError(
            f"WSxM file holds the {channel!r} channel, not heights (topography); give --channel to read it anyway"
        )
    choose_channel([channel], options.channel)


def _range(miscellaneous, raw):
    """Maximum − Minimum from the header, or the data's own range; FormatError when a count lies outside
    the header's Minimum … Maximum."""
    try:
        low, high = float(miscellaneous["Minimum"]), float(miscellaneous["Maximum"])
    except (KeyError, ValueError):
        low, high = float(np.nanmin(raw)), float(np.nanmax(raw))
    if raw.min() < low or raw.max() > high:
        raise FormatError(
            f"WSxM counts span {raw.min():g} … {raw.max():g}, outside the header's Minimum … Maximum, "
            f"{low:g} … {high:g}: the data block is not the one the header describes"
        )
    span = high - low
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
    return value * metres, unit.strip().replace("\xb5", "µ")


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
