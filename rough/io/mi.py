"""Agilent (Molecular Imaging) PicoView ``.mi`` images, read only.

A text header of lines with a 14-character key field and a value (``xPixels       256``) starts with
``fileType      Image``; lines that start with a space continue the previous one. ``xPixels``,
``yPixels``, ``xLength``, ``yLength`` (metres) and ``dateAcquired`` describe the scan. Each channel
starts with a ``bufferLabel`` line, followed by its ``bufferRange`` and ``bufferUnit`` (``um``, ``V``),
``direction`` and ``filter``. The line ``data          BINARY`` (int16) or ``BINARY_32`` (int32) ends the
header; the channels follow one after another to the end of the file (a file of another length is
refused), little-endian, a raw value over 2^15 (2^31) times
``bufferRange`` giving the height in ``bufferUnit``. Note the mixed units: lateral metres, heights µm.
Channels whose unit is not a length (Deflection, Friction in V) are listed but not read. ASCII data and
spectroscopy files are not read. Facts from Gwyddion's ``mifile.c`` and SurfaceTopography's ``MI.py``.

Orientation: row 0 is the last line stored, as Gwyddion and SurfaceTopography show it (both flip every
file, whatever ``scanUp`` says).
"""

import datetime

import numpy as np

from ..errors import FormatError
from ..surface import Surface, Units, check_size
from .header import check_length, header_count, header_number, metres_or_none
from .registry import Format, channel_list, channel_metadata, choose_channel

FORMAT = Format(
    "mi",
    "Agilent/Molecular Imaging MI",
    (".mi",),
    magic=(b"fileType",),
    carries=("spacing", "units", "metadata", "time", "channels"),
)

KEY_WIDTH = 14
TYPES = {"BINARY": "<i2", "BINARY_32": "<i4"}


def read(data, options):
    data = bytes(data)
    fields, channels, start, encoding = _header(data)
    nx, ny = header_count(fields, "xPixels", "MI"), header_count(fields, "yPixels", "MI")
    check_size((ny, nx), "the MI image")
    dtype = np.dtype(TYPES[encoding])
    block = nx * ny * dtype.itemsize
    check_length(data, start + block * len(channels), "MI", f"header and {len(channels)} channels of {nx}×{ny} points")
    names = [channel["bufferLabel"] for channel in channels]
    units = [metres_or_none(channel.get("bufferUnit", "")) for channel in channels]
    default = next((index for index, metres in enumerate(units) if metres is not None), 0)
    index = choose_channel(names, options.channel, default)
    if units[index] is None:
        raise FormatError(
            f"MI channel {names[index]!r} holds values in {channels[index].get('bufferUnit')!r}, not heights; "
            f"the file holds {channel_list(names)}"
        )
    raw = np.ndarray((ny, nx), dtype, data, start + index * block)
    scale = _number(channels[index], "bufferRange") * units[index] / 2.0 ** (8 * dtype.itemsize - 1)
    heights = raw[::-1].astype(np.float64) * scale
    spacing = (_number(fields, "xLength") / nx, _number(fields, "yLength") / ny)
    units = Units(xy="m", z=channels[index]["bufferUnit"])
    return Surface(heights, spacing, units=units, metadata=_metadata(fields, channels[index], names, index))


def _header(data):
    """``(global fields, [channel fields], data offset, data encoding)``."""
    lines = data[: data.find(b"\ndata ") + 64 if b"\ndata " in data else 0].split(b"\n")
    if not lines or lines[0].rstrip() != b"fileType      Image":
        kind = lines[0][KEY_WIDTH:].strip().decode("latin-1") if lines else ""
        raise FormatError(f"MI fileType {kind!r} is not Image (rough reads MI images)")
    fields, channels, offset = {}, [], 0
    for line in lines:
        offset += len(line) + 1
        text = line.decode("latin-1").rstrip("\r")
        if text.startswith(" "):
            continue
        key, value = text[:KEY_WIDTH].strip(), text[KEY_WIDTH:].strip()
        if key == "data":
            if value not in TYPES:
                raise FormatError(f"MI data encoding {value or 'text'!r} is not read (rough reads BINARY, BINARY_32)")
            if not channels:
                raise FormatError("MI header lists no channel (bufferLabel)")
            return fields, channels, offset, value
        if key == "bufferLabel":
            channels.append({})
        (channels[-1] if channels else fields).setdefault(key, value)
    raise FormatError("MI header has no data line")


def _metadata(fields, channel, names, index):
    metadata = {"vendor": "Agilent", **channel_metadata(names, index)}
    date = _date(fields.get("dateAcquired", ""))
    if date:
        metadata["date"] = date
    for key, name in (("version", "mi_version"), ("mode", "mi_mode")):
        if fields.get(key):
            metadata[name] = fields[key]
    if channel.get("direction"):
        metadata["mi_direction"] = channel["direction"]
    return metadata


def _date(text):
    try:
        return datetime.datetime.strptime(text.strip(), "%a %b %d %H:%M:%S %Y").isoformat()
    except ValueError:
        return None


def _number(fields, key):
    return header_number(fields, key, "MI")
