"""Bruker (Veeco, Digital Instruments) Nanoscope files (``.spm``, ``.001``, ``.di``), read only.

The file starts with a text header of ``\\Key: value`` lines (CRLF), grouped in sections that open with
``\\*Name`` lines: ``\\*File list`` first (its ``Data length`` is the header's size in bytes), then the
equipment, scanner and scan lists, then one ``\\*Ciao image list`` per channel, up to ``\\*File list end``.
Each image list gives ``Data offset`` and ``Data length`` (bytes from the file's start), ``Samps/line``
(x points), ``Number of lines`` (y points), ``Bytes/pixel`` (2 or 4, little-endian signed integers),
``Scan Size`` (``500 500 nm``; ``~m`` is µm) and the channel's name in ``@2:Image Data: S [Height]``.
The file ends where the last of its data blocks does; a file of another length is refused.

Heights follow ``@2:Z scale: V [Sens. Zsens] (0.0050354 V/LSB) 2.910461 V``: a raw value times the hard
value (2.910461 V) over 256^Bytes/pixel gives volts, and the soft scale ``@Sens. Zsens: V 20.82646 nm/V``
(scanner or scan list) turns volts into a length. Channels whose soft scale is not a length (Phase,
Amplitude Error) are listed but not read. Facts from Gwyddion's ``nanoscope.c`` and SurfaceTopography's
``DI.py``.

Channel: by default ``ZSensor`` (the height sensor, closed loop) when the file has one, otherwise the first
``Height`` channel, otherwise the first channel that holds lengths; SurfaceTopography's default, the first
channel, is the same for every example file. Orientation: the file stores the bottom line of the image
first; row 0 here is the last line stored (the top of the image), as Gwyddion and SurfaceTopography show it.
"""

import datetime
import re

import numpy as np

from ..errors import FormatError
from ..surface import Surface, Units, check_size
from .header import length_unit, metres_or_none
from .registry import Format, channel_list, channel_metadata, choose_channel

FORMAT = Format(
    "di",
    "Bruker Nanoscope DI",
    (".spm", ".di", ".001"),
    magic=(b"\\*File list", b"?*File list"),
    carries=("spacing", "units", "metadata", "time", "channels"),
)

END = "\\*file list end"
MAX_HEADER = 1 << 20
SCALE = re.compile(r"^V\s+(?:\[(?P<soft>[^\]]*)\]\s*)?(?:\((?P<lsb>[^)]*)\)\s*)?(?P<value>\S+)\s*(?P<unit>.*)$")


def read(data, options):
    data = bytes(data)
    sections = _sections(_header_text(data))
    scales = _soft_scales(sections)
    images = [_image(fields, scales, len(data), number) for number, fields in _images(sections)]
    if not images:
        raise FormatError("Nanoscope file holds no image (no Ciao image list)")
    _check_length(sections, len(data))
    names = [image["name"] for image in images]
    index = choose_channel(names, options.channel, _default(images))
    image = images[index]
    if image["metres_per_volt"] is None:
        raise FormatError(
            f"Nanoscope channel {image['name']!r} holds values in {image['z_unit'] or 'no unit'}, not heights; "
            f"the file holds {channel_list(names)}"
        )
    raw = np.ndarray((image["ny"], image["nx"]), f"<i{image['bytes']}", data, image["offset"])
    heights = raw[::-1].astype(np.float64) * (image["volts_per_count"] * image["metres_per_volt"])
    spacing = (image["size"][0] / image["nx"], image["size"][1] / image["ny"])
    metadata = {**_file_metadata(sections), **channel_metadata(names, index)}
    if image["direction"]:
        metadata["di_line_direction"] = image["direction"]
    return Surface(heights, spacing, units=Units(xy=image["xy_unit"], z=image["z_unit"]), metadata=metadata)


def _check_length(sections, file_size):
    """FormatError unless the file ends where its last data block (``Data offset`` + ``Data length`` of
    any list after the File list) does."""
    ends = [
        int(fields["Data offset"]) + int(fields["Data length"])
        for _, fields in sections[1:]
        if fields.get("Data offset", "").isdigit() and fields.get("Data length", "").isdigit()
    ]
    if ends and max(ends) != file_size:
        raise FormatError(f"Nanoscope file holds {file_size:,} bytes, its data blocks end at byte {max(ends):,}")


def _header_text(data):
    match = re.match(rb"[\\?]\*File list\r?\n.*?\\Data length:\s*(\d+)", data[:MAX_HEADER], re.DOTALL)
    length = int(match.group(1)) if match else 0
    text = data[: min(length, MAX_HEADER)] if length else data[:MAX_HEADER]
    text = text.decode("latin-1")
    end = text.lower().find(END)
    return text if end < 0 else text[:end]


def _sections(text):
    """``[(name, {key: value})]`` in file order; names lower case, keys as written."""
    sections = []
    for line in text.replace("\r", "\n").split("\n"):
        line = line.strip().lstrip("?")
        if line.startswith("\\*"):
            sections.append((line[2:].strip().lower(), {}))
        elif line.startswith("\\") and sections:
            key, _, value = (line[1:] + " ").partition(": ")
            sections[-1][1].setdefault(key.strip().rstrip(":"), value.strip())
    if not sections or sections[0][0] != "file list":
        raise FormatError("Nanoscope header does not start with its File list section")
    return sections


def _images(sections):
    images = (fields for name, fields in sections if name in ("ciao image list", "image list"))
    return enumerate(images, 1)


def _soft_scales(sections):
    """``{"@Sens. Zsens": "V 20.82646 nm/V", ...}`` from the scanner and scan lists (the scan list wins)."""
    scales = {}
    for name, fields in sections:
        if name in ("scanner list", "ciao scan list"):
            scales.update({key: value for key, value in fields.items() if key.startswith("@")})
    return scales


def _image(fields, scales, file_size, number):
    name = _channel_name(fields, number)
    nx, ny = _count(fields, "Samps/line", name), _count(fields, "Number of lines", name)
    check_size((ny, nx), f"Nanoscope image {number} ({name!r})")
    size_bytes = int(_number(fields, "Bytes/pixel", name, "2"))
    if size_bytes not in (2, 4):
        raise FormatError(f"Nanoscope image {name!r} has {size_bytes} bytes per pixel; rough reads 2 or 4")
    offset, length = _count(fields, "Data offset", name, 0), _count(fields, "Data length", name, 0)
    needed = nx * ny * size_bytes
    if needed > length:
        raise FormatError(f"Nanoscope image {name!r}: {nx}×{ny} points of {size_bytes} bytes exceed its {length} bytes")
    if offset + needed > file_size:
        raise FormatError(
            f"Nanoscope image {number} ({name!r}) ends at byte {offset + needed} but the file holds "
            f"{file_size} bytes (truncated)"
        )
    size, xy_unit = _scan_size(fields, name)
    volts_per_count, metres_per_volt, z_unit = _z_scale(fields, scales, name)
    return {
        "name": name,
        "nx": nx,
        "ny": ny,
        "bytes": size_bytes,
        "offset": offset,
        "size": size,
        "xy_unit": xy_unit,
        "volts_per_count": volts_per_count / 256.0**size_bytes,
        "metres_per_volt": metres_per_volt,
        "z_unit": z_unit,
        "direction": fields.get("Line Direction", ""),
    }


def _channel_name(fields, number):
    value = fields.get("@2:Image Data") or fields.get("Image data") or ""
    match = re.search(r"\[([^\]]+)\]", value) or re.search(r'"([^"]+)"', value)
    return match.group(1).strip() if match else value.strip() or f"image {number}"


def _scan_size(fields, name):
    parts = fields.get("Scan Size", fields.get("Scan size", "")).split()
    numbers = []
    while parts and _is_number(parts[0]):
        numbers.append(abs(float(parts.pop(0))))
    if not numbers or len(parts) != 1 or not all(0 < number < np.inf for number in numbers):
        raise FormatError(f"Nanoscope image {name!r} has no readable Scan Size ({fields.get('Scan Size')!r})")
    unit = _unit(parts[0])
    factor = length_unit(unit, f"Nanoscope Scan Size unit of {name!r}")
    return (numbers[0] * factor, numbers[-1] * factor), unit


def _z_scale(fields, scales, name):
    """(volts per count before dividing by 256^bytes, metres per volt or None, z unit)."""
    match = SCALE.match(fields.get("@2:Z scale", ""))
    if not match or not _is_number(match["value"]):
        raise FormatError(f"Nanoscope image {name!r} has no readable @2:Z scale")
    hard, hard_unit = float(match["value"]), match["unit"].strip()
    if not match["soft"]:
        unit = _unit(hard_unit)
        return hard, metres_or_none(unit), unit
    soft = scales.get("@" + match["soft"], "").split()
    if len(soft) < 2 or soft[0] != "V" or not _is_number(soft[1]):
        raise FormatError(f"Nanoscope soft scale {match['soft']!r} of image {name!r} is missing or unreadable")
    unit, _, per = (soft[2] if len(soft) > 2 else "").partition("/")
    unit = _unit(unit)
    metres = metres_or_none(unit)
    if metres is None:
        return hard, None, unit or hard_unit
    return hard, metres * float(soft[1]) * _volts(hard_unit, name) / _volts(per or "V", name), unit


def _volts(unit, name):
    factors = {"V": 1.0, "mV": 1e-3, "uV": 1e-6, "~V": 1e-6}
    if unit not in factors:
        raise FormatError(f"Nanoscope image {name!r} scales heights through {unit!r}, not volts")
    return factors[unit]


def _file_metadata(sections):
    fields = dict(sections[0][1])
    equipment = next((fields for name, fields in sections if name == "equipment list"), {})
    metadata = {"vendor": "Bruker"}
    instrument = equipment.get("Microscope") or equipment.get("Description")
    if instrument:
        metadata["instrument"] = instrument
    date = _date(fields.get("Date", ""))
    if date:
        metadata["date"] = date
    if fields.get("Version"):
        metadata["di_version"] = fields["Version"]
    return metadata


def _date(text):
    for pattern in ("%I:%M:%S %p %a %b %d %Y", "%H:%M:%S %a %b %d %Y"):
        try:
            return datetime.datetime.strptime(text.strip(), pattern).isoformat()
        except ValueError:
            continue
    return None


def _unit(text):
    return text.strip().replace("~", "µ").replace("\xb5", "µ")


def _is_number(text):
    try:
        return np.isfinite(float(text))
    except ValueError:
        return False


def _number(fields, key, name, default=None):
    text = fields.get(key, default)
    if text is None or not _is_number(text.split()[0] if text.split() else ""):
        raise FormatError(f"Nanoscope image {name!r} has no readable {key} ({text!r})")
    return float(text.split()[0])


def _count(fields, key, name, least=1):
    value = _number(fields, key, name)
    if value != int(value) or not least <= value < 2**40:
        raise FormatError(f"Nanoscope image {name!r}: {key} is {fields[key]!r}, not a count")
    return int(value)


def _default(images):
    lengths = [index for index, image in enumerate(images) if image["metres_per_volt"] is not None]
    for wanted in ("ZSensor", "Height"):
        for index in lengths:
            if images[index]["name"] == wanted:
                return index
    return lengths[0] if lengths else 0
