"""ISO 25178-71 SDF (Surface Data File), read only: the ASCII (``aISO-1.0``,
``aISO-2.0``) and binary (``bISO-1.0``, ``bISO-2.0``) variants, uncompressed.

The header gives NumPoints (x) × NumProfiles (y), Xscale and Yscale (metres per
point) and Zscale (metres per data unit). ASCII data are whitespace-separated
numbers in which ``BAD`` marks an invalid point (NaN), closed by a ``*`` line (a file
without it is cut short and refused, since its last number may be cut); binary data use DataType
0–7 (uint8, uint16, uint32, float32, int8, int16, int32, float64), little-endian.
The 2.0 revision keeps the ASCII layout and widens the binary NumPoints and
NumProfiles from uint16 to uint32 (as surfalize's ``sdf.py`` reads it).
One profile (NumProfiles = 1) reads as a profile.

Binary data end the file, or are followed by a text trailer closed by a ``*`` line (as the
ASCII variant's trailer is); other bytes after them are refused, since nothing else tells a
trailer from data moved by damage.
"""

import re
import struct

import numpy as np

from ..errors import FormatError
from ..surface import Surface
from . import limits
from .registry import Format

FORMAT = Format(
    "sdf",
    "ISO 25178-71 SDF",
    (".sdf",),
    magic=(b"aISO-1.0", b"bISO-1.0", b"aISO-2.0", b"bISO-2.0"),
    carries=("spacing", "metadata", "time", "mask"),
)

BINARY_HEADERS = {
    b"bISO-1.0": struct.Struct("<8s10s12s12sHHddddBBB"),
    b"bISO-2.0": struct.Struct("<8s10s12s12sIIddddBBB"),
}
ASCII_MAGIC = ("aISO-1.0", "aISO-2.0")
DATA_TYPES = ("<u1", "<u2", "<u4", "<f4", "<i1", "<i2", "<i4", "<f8")
MAX_POINTS = 1 << 31
TRAILER = re.compile(rb"[\t\n\r\x20-\x7e]*\*\s*")


def read(data, options):
    if bytes(data[:8]) in BINARY_HEADERS:
        header, values = _binary(data, BINARY_HEADERS[bytes(data[:8])])
    else:
        header, values = _ascii(bytes(data).decode("latin-1"))
    nx, ny = header["NumPoints"], header["NumProfiles"]
    heights = limits.scaled(values.astype(np.float64), header["Zscale"], f"SDF Zscale {header['Zscale']!r}")
    spacing = (header["Xscale"], header["Yscale"])
    metadata = {"instrument": header.get("ManufacID", "")} if header.get("ManufacID") else {}
    if _date(header.get("CreateDate")):
        metadata["date"] = _date(header["CreateDate"])
    if ny == 1:
        return Surface(heights, spacing[:1], metadata=metadata)
    return Surface(heights.reshape(ny, nx), spacing, metadata=metadata)


def _ascii(text):
    lines = text.splitlines()
    if not lines or lines[0].strip() not in ASCII_MAGIC:
        raise FormatError("not an SDF file (no aISO-1.0 or aISO-2.0 line)")
    header, position = {}, 1
    while position < len(lines) and lines[position].strip() != "*":
        key, equals, value = lines[position].partition("=")
        if equals:
            header[key.strip()] = value.strip()
        position += 1
    if position == len(lines):
        raise FormatError("SDF header is not closed by a '*' line")
    header = _checked(header)
    body = []
    for line in lines[position + 1 :]:
        if line.strip() == "*":
            break
        body.extend(line.split())
    else:
        raise FormatError("SDF data are not closed by a '*' line (the file is cut short)")
    count = header["NumPoints"] * header["NumProfiles"]
    if len(body) != count:
        raise FormatError(
            f"SDF declares {header['NumPoints']}×{header['NumProfiles']} points but holds {len(body)} values"
        )
    values = np.array([np.nan if item.upper() == "BAD" else float(item) for item in body])
    if np.isinf(values).any():
        bad = body[int(np.argmax(np.isinf(values)))]
        raise FormatError(f"SDF value {bad[:40]!r} is beyond the float64 range")
    return header, values


def _binary(data, layout):
    if len(data) < layout.size:
        raise FormatError(f"binary SDF file shorter than its {layout.size}-byte header")
    fields = layout.unpack_from(bytes(data[: layout.size]))
    names = (
        "version",
        "ManufacID",
        "CreateDate",
        "ModDate",
        "NumPoints",
        "NumProfiles",
        "Xscale",
        "Yscale",
        "Zscale",
        "Zresolution",
        "Compression",
        "DataType",
        "CheckType",
    )
    header = {
        name: (value.decode("latin-1").strip("\0 ") if isinstance(value, bytes) else value)
        for name, value in zip(names, fields)
    }
    header = _checked(header)
    dtype = np.dtype(DATA_TYPES[header["DataType"]])
    count = header["NumPoints"] * header["NumProfiles"]
    if layout.size + count * dtype.itemsize > len(data):
        raise FormatError(f"binary SDF declares {count} points but is too short to hold them")
    end = layout.size + count * dtype.itemsize
    if end < len(data) and not TRAILER.fullmatch(bytes(data[end:])):
        raise FormatError(
            f"binary SDF file holds {len(data):,} bytes, its header describes {end:,} ({count} points of "
            f"{dtype.itemsize} bytes), and the rest is not a text trailer closed by '*'"
        )
    return header, np.frombuffer(data, dtype, count=count, offset=layout.size)


def _checked(header):
    """Header values converted and validated."""
    checked = dict(header)
    for key in ("NumPoints", "NumProfiles", "Compression", "DataType"):
        try:
            checked[key] = int(header.get(key, 0 if key in ("Compression", "DataType") else -1))
        except ValueError:
            raise FormatError(f"SDF {key} is not a whole number: {header[key]!r}") from None
    for key in ("Xscale", "Yscale", "Zscale"):
        try:
            checked[key] = float(header[key])
        except (KeyError, ValueError):
            raise FormatError(f"SDF header lacks a numeric {key}") from None
    if checked["NumPoints"] < 1 or checked["NumProfiles"] < 1:
        raise FormatError("SDF NumPoints and NumProfiles must be positive")
    if checked["NumPoints"] * checked["NumProfiles"] > MAX_POINTS:
        raise FormatError("SDF declares more points than rough handles")
    if not (checked["Xscale"] > 0 and checked["Yscale"] > 0 and np.isfinite(checked["Zscale"])):
        raise FormatError("SDF Xscale and Yscale must be positive lengths and Zscale finite")
    if checked["Compression"] != 0:
        raise FormatError("compressed SDF data are not supported")
    if not 0 <= checked["DataType"] < len(DATA_TYPES):
        raise FormatError(f"SDF DataType {checked['DataType']} is not one of 0–7")
    return checked


def _date(text):
    """ISO 25178-71 dates are DDMMYYYYHHMM."""
    match = re.fullmatch(r"(\d\d)(\d\d)(\d{4})(\d\d)(\d\d)", (text or "").strip())
    if not match:
        return None
    day, month, year, hour, minute = match.groups()
    return f"{year}-{month}-{day}T{hour}:{minute}:00"
