"""Nanosurf NID (and EZD) files, read only.

An INI-style text header (``[Section]`` and ``key=value`` lines, CRLF) starts with ``[DataSet]`` and ends
where a line starts with ``#!``; the binary data follow those two bytes. ``[DataSet]`` lists the groups
(``Gr0-Name=Scan forward``, ``Gr0-Count=8``) and the data sets of each (``Gr0-Ch1=DataSet-0:1``; missing
numbers have no data). The data blocks follow in that order, group by group, and end the file (a file of
another length is refused). Each data set's section gives
``Points`` (x), ``Lines`` (y), ``SaveBits``/``SaveSign``/``SaveOrder`` (``Intel`` is little-endian),
``Dim0Range``/``Dim1Range`` (the scan size in ``Dim0Unit``) and ``Dim2Name``, ``Dim2Unit``, ``Dim2Range``
and ``Dim2Min``: a signed raw value v gives ``Dim2Min + Dim2Range * (v / 2^bits + 1/2)`` (Gwyddion's
``ezdfile.c``; SurfaceTopography's ``EZD.py`` leaves out the offset). Only data sets whose ``Dim2Unit`` is a
length are channels here, named ``Frame (Dim2Name)`` as in SurfaceTopography. The default is the first whose
``Dim2Name`` names a height (``Z-Axis``, ``Z-AxisSensor``, ``Topography``, ``Height``): the channel is chosen
by physical quantity, not by unit, since a deflection calibrated in metres is not a height. A file with no
height channel is refused unless ``--channel`` names one of its length channels.

Orientation: row 0 is the last line stored, as Gwyddion and SurfaceTopography show it.
"""

import datetime

import numpy as np

from ..errors import FormatError
from ..surface import Surface, Units, check_size
from ..units import metres_per
from .header import header_count, header_number, ini_sections, length_unit, metres_or_none
from .registry import Format, channel_list, channel_metadata, choose_channel, names_height

FORMAT = Format(
    "nid",
    "Nanosurf NID",
    (".nid", ".ezd"),
    magic=(b"[DataSet]",),
    carries=("spacing", "units", "metadata", "time", "channels"),
)

DATA_MAGIC = b"\n#!"
MAX_GROUPS = 1000


def read(data, options):
    data = bytes(data)
    marker = data.find(DATA_MAGIC)
    if marker < 0:
        raise FormatError("NID header has no end (no line starting with #!)")
    sections = _sections(data[:marker].decode("latin-1"))
    channels = _channels(sections, marker + len(DATA_MAGIC), len(data))
    if not channels:
        raise FormatError("NID file holds no data set in a length unit (no height channel)")
    names = [channel["name"] for channel in channels]
    index = _default(channels, names) if options.channel is None else choose_channel(names, options.channel)
    channel = channels[index]
    nx, ny, fields = channel["nx"], channel["ny"], channel["fields"]
    raw = np.ndarray((ny, nx), channel["dtype"], data, channel["offset"])[::-1].astype(np.float64)
    fraction = raw / 2.0 ** (8 * channel["dtype"].itemsize) + (0.5 if channel["dtype"].kind == "i" else 0.0)
    z_unit = fields["Dim2Unit"]
    metres = metres_per(z_unit)
    heights = (_number(fields, "Dim2Min", 0.0) + _number(fields, "Dim2Range") * fraction) * metres
    xy_unit = fields.get("Dim0Unit", "m")
    lateral = length_unit(xy_unit, "NID Dim0Unit")
    spacing = (_number(fields, "Dim0Range") * lateral / nx, _number(fields, "Dim1Range") * lateral / ny)
    metadata = {"vendor": "Nanosurf", **_metadata(sections), **channel_metadata(names, index)}
    return Surface(heights, spacing, units=Units(xy=xy_unit, z=z_unit), metadata=metadata)


def _default(channels, names):
    """The first channel whose quantity (``Dim2Name``) is a height; FormatError when there is none."""
    for index, channel in enumerate(channels):
        if names_height(channel["fields"].get("Dim2Name")):
            return index
    raise FormatError(
        f"NID file holds no height channel (Z-Axis, Topography): its length channels {channel_list(names)} "
        "are other quantities; give --channel to read one of them anyway"
    )


def _sections(text):
    sections = ini_sections(text)
    if "DataSet" not in sections:
        raise FormatError("NID header has no [DataSet] section")
    return sections


def _channels(sections, start, file_size):
    """The data sets in a length unit, with their data offsets; every block is checked against the file."""
    listing, channels, offset = sections["DataSet"], [], start
    groups = int(_number(listing, "GroupCount", _group_count(listing)))
    for group in range(min(groups, MAX_GROUPS)):
        for number in range(min(int(_number(listing, f"Gr{group}-Count", 0)), MAX_GROUPS)):
            section = listing.get(f"Gr{group}-Ch{number}")
            if section is None:
                continue
            fields = sections.get(section)
            if fields is None:
                raise FormatError(f"NID data set {section!r} is listed but has no section")
            nx, ny, dtype = _layout(fields, section)
            end = offset + nx * ny * dtype.itemsize
            if end > file_size:
                raise FormatError(f"NID data set {section!r} ends at byte {end} but the file holds {file_size} bytes")
            if metres_or_none(fields.get("Dim2Unit", "")) is not None:
                name = f"{fields.get('Frame', section)} ({fields.get('Dim2Name', '')})"
                channels.append({"name": name, "nx": nx, "ny": ny, "dtype": dtype, "offset": offset, "fields": fields})
            offset = end
    if channels and offset != file_size:
        raise FormatError(f"NID file holds {file_size:,} bytes, its header describes {offset:,} (header and data sets)")
    return channels


def _group_count(listing):
    return sum(1 for key in listing if key.startswith("Gr") and key.endswith("-Count"))


def _layout(fields, section):
    if fields.get("SaveMode", "Binary") != "Binary":
        raise FormatError(f"NID data set {section!r} is saved as {fields['SaveMode']!r}; rough reads Binary")
    nx, ny = (
        header_count(fields, "Points", f"NID data set {section!r}"),
        header_count(fields, "Lines", f"NID data set {section!r}"),
    )
    check_size((ny, nx), f"NID data set {section!r}")
    bits = int(_number(fields, "SaveBits", 32))
    if bits not in (8, 16, 32):
        raise FormatError(f"NID data set {section!r} has {bits} bits per value; rough reads 8, 16 or 32")
    order = "<" if fields.get("SaveOrder", "Intel") == "Intel" else ">"
    kind = "u" if fields.get("SaveSign", "Signed") == "Unsigned" else "i"
    return nx, ny, np.dtype(f"{order}{kind}{bits // 8}")


def _metadata(sections):
    info = sections.get("DataSet-Info", {})
    metadata = {}
    try:
        moment = datetime.datetime.strptime(f"{info.get('Date')} {info.get('Time')}", "%d-%m-%Y %H:%M:%S")
        metadata["date"] = moment.isoformat()
    except ValueError:
        pass
    if info.get("Op. mode"):
        metadata["nid_mode"] = info["Op. mode"]
    return metadata


def _number(fields, key, default=None):
    return header_number(fields, key, "NID", default)
