"""Igor Pro binary waves (``.ibw``), as Asylum Research AFMs write them; read only, through igor2.

A wave starts with a binary header whose 16-bit words, header and wave header together (64 + 320 bytes in
version 5, 16 or 20 + 110 bytes in versions 2 and 3), add up to zero; that checksum recognises the file.
Asylum stores an image as one wave of shape (x points, y points, channels), column-major, so x runs fastest
in memory; ``sfA`` gives the spacing per dimension in ``dimUnits`` and ``dataUnits`` the heights' unit.
The channel names are the labels of the third dimension (``HeightTrace``, ``AmplitudeTrace``…); channels
without a label are called ``no name (1)``, ``no name (2)``… as in SurfaceTopography's ``IBW.py``. The
wave note (``key:value`` lines) gives ``MicroscopeModel``, ``Date`` and ``Time``. A wave without units is
taken in the ``--unit`` unit (default metres), lateral and vertical alike. Channels whose unit is not a
length are listed but not read. Default channel: the first whose name starts with ``Height``, else the first.

The sections the binary header declares end the file, unless Asylum's thumbnails follow them: 8-bit
previews of ``DataLength`` bytes each, then a ``key:value;`` list (from ``Version:``) that closes the
file and gives each preview's start (``HeightTraceFileStart:2112969`` in spot_1-1000nm.ibw, the byte
where the wave ends). The first preview must start where the wave ends, each where the one before
ends, and the list where the last ends; other bytes after the wave are refused.

Orientation: row 0 is the last line stored, as Gwyddion's ``igorfile.c`` and SurfaceTopography show it.
"""

import datetime
import io
import re
import struct

import numpy as np

from ..errors import FormatError
from ..extras import require
from ..surface import Surface, Units, check_size
from .header import metres_or_none, quiet
from .registry import Format, channel_list, channel_metadata, choose_channel

HEADER_BYTES = {1: 8 + 110, 2: 16 + 110, 3: 20 + 110, 5: 64 + 320}
# The binary header's int32 sizes of the sections that follow it: (offset, count). Version 5 lists the wave
# (wfmSize: wave header and data), formula, note, extended data units, 4 extended dimension units, 4 dimension
# labels and the string indices; versions 1-3 the wave (with 16 bytes of padding), note and formula.
SECTION_SIZES = {1: (2, 1), 2: (2, 2), 3: (2, 3), 5: (4, 13)}
BINARY_HEADER = {1: 8, 2: 16, 3: 20, 5: 64}
THUMBNAIL_START = re.compile(rb"FileStart:(\d+);")
THUMBNAIL_LENGTH = re.compile(rb"DataLength:(\d+);")


def probe(head):
    """A known version number and a header checksum of zero."""
    for order in ("<", ">"):
        version = int(np.frombuffer(head[:2], f"{order}u2")[0]) if len(head) >= 2 else 0
        size = HEADER_BYTES.get(version)
        if size and len(head) >= size:
            return int(np.frombuffer(head[:size], f"{order}u2").sum()) % 65536 == 0
    return False


FORMAT = Format(
    "ibw",
    "Igor binary wave (Asylum Research)",
    (".ibw",),
    probe=probe,
    by_extension=True,
    carries=("spacing", "units", "metadata", "time", "channels"),
    read_library="igor2",
)


def read(data, options):
    binarywave = require("igor2.binarywave")
    data = bytes(data)
    if not probe(data[:512]):
        raise FormatError("Igor wave header checksum does not add up (not an Igor binary wave, or damaged)")
    _check_sizes(data)
    wave = _load(binarywave, data)
    values = np.asarray(wave["wData"])
    if values.ndim == 2:
        values = values[:, :, np.newaxis]
    if values.ndim != 3 or min(values.shape) < 1 or values.dtype.kind not in "iuf":
        raise FormatError(f"Igor wave of shape {values.shape} ({values.dtype}) is not an image of real numbers")
    nx, ny, count = values.shape
    check_size((ny, nx), "the Igor image")
    names = _names(wave, count)
    header = wave["wave_header"]
    z_unit = _text(wave.get("data_units")) or _text(header["dataUnits"]) or options.unit or "m"
    xy_unit = _text(header["dimUnits"][0]) or options.unit or "m"
    default = next((index for index, name in enumerate(names) if name.lower().startswith("height")), 0)
    index = choose_channel(names, options.channel, default)
    metres = metres_or_none(z_unit)
    if metres is None:
        raise FormatError(
            f"Igor channel {names[index]!r} holds values in {z_unit!r}, not heights; "
            f"the file holds {channel_list(names)}"
        )
    lateral = metres_or_none(xy_unit)
    if lateral is None:
        raise FormatError(f"Igor wave's x unit {xy_unit!r} is not a length unit")
    heights = values[:, :, index].T[::-1].astype(np.float64) * metres
    spacing = (float(header["sfA"][0]) * lateral, float(header["sfA"][1]) * lateral)
    metadata = {**_note_metadata(wave.get("note", b"")), **channel_metadata(names, index)}
    return Surface(heights, spacing, units=Units(xy=xy_unit, z=z_unit), metadata=metadata)


def _check_sizes(data):
    """Refuse sections larger than the file before igor2 reads them: it builds a struct format of one item per
    declared byte, so a header claiming a 64 MB note costs gigabytes and seconds."""
    for order in ("<", ">"):
        (version,) = struct.unpack_from(f"{order}H", data)
        if version in SECTION_SIZES:
            break
    offset, count = SECTION_SIZES[version]
    sizes = struct.unpack_from(f"{order}{count}i", data, offset)
    declared = BINARY_HEADER[version] + sum(sizes) - (16 if version < 5 else 0)
    if min(sizes) < 0:
        raise FormatError(f"Igor wave header declares a section of {min(sizes)} bytes (damaged)")
    if declared > len(data):
        raise FormatError(
            f"Igor wave header declares {declared:,} bytes but the file holds {len(data):,} (damaged or truncated)"
        )
    if declared < len(data) and not _thumbnails(data, declared):
        raise FormatError(
            f"Igor wave header declares {declared:,} bytes but the file holds {len(data):,}, and what follows "
            "the wave is not Asylum's thumbnails starting where it ends"
        )


def _thumbnails(data, declared):
    """Whether the bytes after the wave (from ``declared``) are Asylum's thumbnails: blocks of
    ``DataLength`` bytes, the first at ``declared``, each after the other, then their list, which
    starts where the last block ends."""
    data = bytes(data)
    listing = data.rfind(b"Version:", declared)
    length = THUMBNAIL_LENGTH.search(data, listing) if listing >= 0 else None
    if length is None:
        return False
    starts = sorted(int(start) for start in THUMBNAIL_START.findall(data, listing))
    step = int(length.group(1))
    return (
        bool(starts)
        and starts == [declared + step * number for number in range(len(starts))]
        and starts[-1] + step == listing
    )


def _load(binarywave, data):
    try:
        with quiet("igor2"):
            return binarywave.load(io.BytesIO(data))["wave"]
    except Exception as error:  # igor2 raises whatever struct, numpy or its own asserts raise on damaged waves
        raise FormatError(f"Igor wave is damaged or truncated ({type(error).__name__}: {error})") from None


def _names(wave, count):
    labels = wave.get("labels") or []
    layer_labels = labels[2][1:] if len(labels) > 2 else []
    names = [_text(label) for label in layer_labels[:count]]
    names += [f"no name ({number})" for number in range(1, count - len(names) + 1)]
    return [name or f"no name ({number})" for number, name in enumerate(names, 1)]


def _text(value):
    if value is None:
        return ""
    if isinstance(value, np.ndarray):
        value = value.tobytes()
    if isinstance(value, bytes):
        value = value.split(b"\0", 1)[0].decode("latin-1")
    return str(value).strip()


def _note_metadata(note):
    fields = {}
    for line in _text(note if isinstance(note, bytes) else str(note).encode("latin-1")).splitlines():
        key, separator, value = line.partition(":")
        if separator:
            fields.setdefault(key.strip(), value.strip())
    metadata = {}
    if fields.get("MicroscopeModel"):
        metadata.update(instrument=fields["MicroscopeModel"], vendor="Asylum Research")
    moment = f"{fields.get('Date', '')} {fields.get('Time', '')}"
    for pattern in ("%Y-%m-%d %I:%M:%S %p", "%Y-%m-%d %H:%M:%S"):
        try:
            metadata["date"] = datetime.datetime.strptime(moment, pattern).isoformat()
            break
        except ValueError:
            continue
    return metadata
