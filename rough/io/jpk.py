"""JPK Instruments (Bruker) AFM image scans (``.jpk``, ``.jpk-qi-image``), read only, through tifffile.

A JPK image scan is a TIFF (big-endian as JPK writes it) whose first IFD is a thumbnail carrying the scan's
private tags: ``GridULength`` (0x8042) and ``GridVLength`` (0x8043), the scan size in metres (float64),
and ``StartDate`` (0x8003). Every further IFD holding 16- or 32-bit grey values is one channel:
``Channel`` (0x8050, e.g. ``height``, ``vDeflection``), ``ChannelRetrace`` (0x8051), ``GridReflect`` (0x8045),
``ChannelFancyName`` (0x8052, e.g. ``Height (measured)``), ``NrOfSlots`` (0x8080) and ``DefaultSlot``
(0x8081, a slot's name). Slot i's tags start at 0x8090 + 0x30·i: ``SlotName`` (+0x00), ``EncoderUnit``
(+0x12), ``ScalingType`` (+0x13, ``LinearScaling``), ``ScalingMultiply`` (+0x14) and ``ScalingOffset``
(+0x15). A raw value v of the default slot is ``v * multiply + offset`` in ``EncoderUnit``. Facts from
Gwyddion's ``jpkscan.c`` and SurfaceTopography's ``JPK.py``; no JPK file was at hand, so rough's tests
read TIFFs written with these tags, not an instrument's file.

Channels are those whose default slot's unit is a length, named by ``ChannelFancyName`` (``Channel`` when
there is none) with `` (retrace)`` for retrace scans. The default is the first whose ``Channel`` or fancy
name says height: a vertical deflection calibrated in metres is not a height, and a file with no height
channel is refused unless ``--channel`` names one.

Orientation: the first scan line is stored first and is the bottom of the image unless the channel's
``GridReflect`` is set; row 0 here is the top row, as Gwyddion shows it (the stored lines reversed, or as
stored when reflected; checked with Gwyddion 2 on TIFFs written both ways).
"""

import io

import numpy as np

from ..errors import FormatError
from ..extras import require
from ..surface import Surface, Units, check_size
from .header import first_tiff_tags, metres_or_none, quiet
from .registry import Format, channel_list, channel_metadata, choose_channel, names_height

START_DATE, GRID_U, GRID_V, GRID_REFLECT = 0x8003, 0x8042, 0x8043, 0x8045
CHANNEL, RETRACE, FANCY_NAME, SLOT_COUNT, DEFAULT_SLOT = 0x8050, 0x8051, 0x8052, 0x8080, 0x8081
SLOTS, SLOT_STRIDE = 0x8090, 0x30
SLOT_NAME, ENCODER_UNIT, SCALING_TYPE, MULTIPLY, OFFSET = 0x00, 0x12, 0x13, 0x14, 0x15
MAX_SLOTS = 64


def probe(head):
    """``GridULength`` (0x8042) among the first IFD's entries of a classic TIFF."""
    return any(tag == GRID_U for tag, *_ in first_tiff_tags(head))


FORMAT = Format(
    "jpk",
    "JPK Instruments image scan",
    (".jpk", ".jpk-qi-image"),
    magic=(b"MM\0*", b"II*\0"),
    probe=probe,
    carries=("spacing", "units", "metadata", "time", "channels"),
    read_library="tifffile",
)


def read(data, options):
    tifffile = require("tifffile")
    data = bytes(data)
    try:
        with quiet("tifffile"), tifffile.TiffFile(io.BytesIO(data)) as tiff:
            scan = {tag.code: tag.value for tag in tiff.pages[0].tags.values()}
            channels = [_channel(page, len(data)) for page in tiff.pages]
            channels = [channel for channel in channels if channel is not None]
            names = [channel["name"] for channel in channels]
            index = _default(channels, names) if options.channel is None else choose_channel(names, options.channel)
            channel = channels[index]
            raw = channel["page"].asarray()
    except FormatError:
        raise
    except Exception as error:  # tifffile raises its own, struct and numpy errors on damaged files
        raise FormatError(f"JPK TIFF is damaged or truncated ({type(error).__name__}: {error})") from None
    ny, nx = raw.shape
    check_size((ny, nx), "the JPK image")
    reflected = bool(channel["tags"].get(GRID_REFLECT, 0))
    counts = (raw if reflected else raw[::-1]).astype(np.float64)
    heights = (counts * channel["multiply"] + channel["offset"]) * metres_or_none(channel["unit"])
    spacing = (_length(scan, GRID_U) / nx, _length(scan, GRID_V) / ny)
    metadata = {"vendor": "JPK Instruments", **channel_metadata(names, index)}
    if isinstance(scan.get(START_DATE), str) and scan[START_DATE].strip():
        metadata["jpk_start_date"] = scan[START_DATE].strip()
    return Surface(heights, spacing, units=Units(xy="m", z=channel["unit"]), metadata=metadata)


def _channel(page, size):
    """The facts of an IFD that is a channel in a length unit, or None (thumbnail, other quantities)."""
    tags = {tag.code: tag.value for tag in page.tags.values()}
    name = _text(tags.get(FANCY_NAME)) or _text(tags.get(CHANNEL))
    if not name or page.photometric not in (0, 1) or page.bitspersample not in (16, 32):
        return None
    slot = _default_slot(tags, name)
    if metres_or_none(slot["unit"]) is None:
        return None
    for offset, count in zip(page.dataoffsets, page.databytecounts):
        if offset + count > size:
            raise FormatError(f"JPK channel {name!r} ends at byte {offset + count} but the file holds {size} bytes")
    retrace = " (retrace)" if tags.get(RETRACE) else ""
    return {"name": name + retrace, "page": page, "tags": tags, **slot}


def _default_slot(tags, name):
    """Unit, multiplier and offset of the channel's default slot."""
    wanted = _text(tags.get(DEFAULT_SLOT))
    count = tags.get(SLOT_COUNT, 0)
    for slot in range(min(int(count) if isinstance(count, int) else 0, MAX_SLOTS)):
        base = SLOTS + SLOT_STRIDE * slot
        if _text(tags.get(base + SLOT_NAME)) != wanted:
            continue
        if _text(tags.get(base + SCALING_TYPE)) != "LinearScaling":
            raise FormatError(f"JPK channel {name!r} has scaling {tags.get(base + SCALING_TYPE)!r}; rough reads linear")
        multiply, offset = tags.get(base + MULTIPLY), tags.get(base + OFFSET, 0.0)
        if not all(isinstance(value, float) and np.isfinite(value) for value in (multiply, offset)):
            raise FormatError(f"JPK channel {name!r} has scaling {multiply!r} × raw + {offset!r}, not two numbers")
        return {"unit": _text(tags.get(base + ENCODER_UNIT)), "multiply": multiply, "offset": offset}
    raise FormatError(f"JPK channel {name!r} has no slot named {wanted!r} (its default slot)")


def _default(channels, names):
    for index, channel in enumerate(channels):
        if names_height(_text(channel["tags"].get(CHANNEL))) or names_height(channel["name"]):
            return index
    if not channels:
        raise FormatError("JPK file holds no channel in a length unit (no height channel)")
    raise FormatError(
        f"JPK file holds no height channel: its length channels {channel_list(names)} are other quantities; "
        "give --channel to read one of them anyway"
    )


def _length(tags, code):
    value = tags.get(code)
    if not isinstance(value, float) or not 0 < abs(value) < np.inf:
        raise FormatError(f"JPK scan size tag 0x{code:x} is {value!r}, not a positive length in metres")
    return abs(value)


def _text(value):
    return value.strip() if isinstance(value, str) else ""
