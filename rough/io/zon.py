"""Keyence ZON (VR-series 3D profilers), read only.

The file starts with ``KPK0`` or ``KPK1`` and a uint32 (little-endian) BMP size, then
a BMP preview, then a ZIP archive whose members are named by UUIDs; in ``KPK1`` files
each member is itself zstd-compressed (members starting with the zstd frame magic are
unpacked here whatever the header says). XML members give the calibration
(``686613b8-…``: ``XYCalibration/MeterPerPixel``, ``ZCalibration/MeterPerUnit``), the
scan time (``1d35862b-…``: ``ScanDateTime``, ``MM/DD/YYYY hh:mm:ss ±hh:mm``) and the
device (``cbc1d39b-…``: ``DeviceModelName``, ``DeviceSerialId``). A binary member starts
with four uint32: xres, yres, bytes per point and bytes per row, then yres rows (row 0
first, as stored). The heights are member ``4cdb0c75-…`` (int32 × MeterPerUnit); a
member of one byte per point on the same grid is the mask, whose non-zero points are
invalid (NaN here); three-byte members are colour images (not read). Layout as
SurfaceTopography's ``ZON.py`` and surfalize's ``zon.py`` read it (the mask as surfalize
applies it; SurfaceTopography ignores it).
"""

import datetime
import io
import lzma
import struct
import xml.etree.ElementTree
import zipfile
import zlib

import numpy as np

from ..errors import FormatError
from ..extras import require
from ..surface import Surface, Units, check_size
from . import limits
from .registry import Format

FORMAT = Format(
    "zon",
    "Keyence ZON",
    (".zon",),
    magic=(b"KPK0", b"KPK1"),
    probe=lambda head: head[8:10] == b"BM",
    carries=("spacing", "units", "metadata", "time", "mask"),
    read_library="zstandard",
)

HEIGHTS = "4cdb0c75-5706-48cc-a9a1-adf395d609ae"
CALIBRATION = "686613b8-27b5-4a29-8ffc-438c2780873e"
SCAN = "1d35862b-3b48-4df2-9235-833ef590b043"
DEVICE = "cbc1d39b-215f-4d56-a20e-cf8e5f570755"
ZSTD_MAGIC = b"\x28\xb5\x2f\xfd"
GRID_HEADER = 16
MAX_XML_BYTES = 1 << 20
# What zipfile and its codecs raise for a damaged, encrypted or exotic member.
UNPACK_ERRORS = (
    zipfile.BadZipFile,
    NotImplementedError,
    RuntimeError,
    EOFError,
    OSError,
    ValueError,
    struct.error,
    zlib.error,
    lzma.LZMAError,
)


def read(data, options):
    data = bytes(data)
    zstandard = require("zstandard")
    if len(data) < 10 or data[8:10] != b"BM":
        raise FormatError("not a ZON file (no BMP preview after the KPK header)")
    (preview,) = struct.unpack_from("<I", data, 4)
    if 8 + preview >= len(data):
        raise FormatError(f"ZON preview of {preview} bytes leaves no archive in the file")
    archive = _Archive(data, zstandard)
    names = archive.names()
    if HEIGHTS not in names:
        raise FormatError("ZON archive holds no height member")
    meter_per_pixel = _length(archive.xml(CALIBRATION), "XYCalibration/MeterPerPixel")
    meter_per_unit = _length(archive.xml(CALIBRATION), "ZCalibration/MeterPerUnit")
    raw = archive.grid(HEIGHTS, 4, "<i4")
    heights = limits.scaled(raw.astype(np.float64), meter_per_unit, "ZON MeterPerUnit")
    mask = archive.mask(raw.shape)
    if mask is not None:
        heights[mask != 0] = np.nan
    metadata = _metadata(archive)
    return Surface(heights, (meter_per_pixel, meter_per_pixel), units=Units(xy="m", z="m"), metadata=metadata)


class _Archive:
    """The ZIP archive's members, unpacked (zstd too) within rough's input budget."""

    def __init__(self, data, zstandard):
        try:
            self.zip = zipfile.ZipFile(io.BytesIO(data))
        except UNPACK_ERRORS as error:
            raise FormatError(f"ZON archive is not a readable ZIP ({str(error)!r})") from None
        self.zstandard = zstandard
        self.budget = limits.Budget(len(data), "ZON archive")

    def names(self):
        return set(self.zip.namelist())

    def member(self, name, size=None):
        """Up to ``size`` bytes (all when None) of member ``name``, zstd-unpacked."""
        try:
            with self.zip.open(name) as stream:
                packed = stream.read(len(ZSTD_MAGIC)) == ZSTD_MAGIC
            with self.zip.open(name) as stream:
                return self._read(self.zstandard.ZstdDecompressor().stream_reader(stream) if packed else stream, size)
        except UNPACK_ERRORS + (self.zstandard.ZstdError,) as error:
            raise FormatError(f"ZON member {name!r} cannot be unpacked ({str(error)!r})") from None

    def _read(self, stream, size):
        parts, total = [], 0
        while size is None or total < size:
            want = self.budget.room() if size is None else min(size - total, self.budget.room())
            part = stream.read(min(want, limits.CHUNK << 4))
            if not part:
                break
            self.budget.add(len(part))
            parts.append(part)
            total += len(part)
        return b"".join(parts)

    def xml(self, name):
        if name not in self.names():
            return None
        text = self.member(name, MAX_XML_BYTES + 1)
        if len(text) > MAX_XML_BYTES:
            raise FormatError(f"ZON member {name!r} is more than {MAX_XML_BYTES} bytes of XML")
        try:
            return xml.etree.ElementTree.fromstring(text)
        except xml.etree.ElementTree.ParseError as error:
            raise FormatError(f"ZON member {name!r} is not readable XML ({str(error)!r})") from None

    def header(self, name):
        head = self.member(name, GRID_HEADER)
        if len(head) < GRID_HEADER or head[:1] == b"<" or head[:3] == b"\xef\xbb\xbf":
            return None
        return struct.unpack("<4I", head)

    def grid(self, name, item, dtype):
        header = self.header(name)
        if header is None:
            raise FormatError(f"ZON member {name!r} is not a data grid")
        xres, yres, size, stride = header
        if size != item or xres == 0 or yres == 0 or stride < xres * item or stride % item:
            raise FormatError(f"ZON grid {name!r} of {xres}×{yres} points, {size} and {stride} bytes, is malformed")
        check_size((yres, xres), "the ZON grid")
        body = self.member(name, GRID_HEADER + yres * stride)
        if len(body) < GRID_HEADER + yres * stride:
            raise FormatError(f"ZON grid {name!r} of {xres}×{yres} points is truncated")
        values = np.frombuffer(body, dtype, yres * stride // item, GRID_HEADER)
        return values.reshape(yres, stride // item)[:, :xres]

    def mask(self, shape):
        """The first one-byte grid of ``shape`` (rows, columns), or None."""
        for name in sorted(self.names() - {HEIGHTS}):
            header = self.header(name)
            if header is not None and header[2] == 1 and (header[1], header[0]) == shape:
                return self.grid(name, 1, "u1")
        return None


def _length(root, path):
    node = None if root is None else root.find(path)
    try:
        value = float(node.text)
    except (AttributeError, TypeError, ValueError):
        raise FormatError(f"ZON calibration lacks a number for {path}") from None
    if not (0 < value < np.inf):
        raise FormatError(f"ZON calibration {path} is {value!r} m, not a positive length")
    return value


def _metadata(archive):
    metadata = {"vendor": "Keyence"}
    device = archive.xml(DEVICE)
    for path, key in (("DeviceModelName", "instrument"), ("DeviceSerialId", "zon_serial")):
        text = None if device is None else device.findtext(path)
        if text and text.strip():
            metadata[key] = text.strip()
    scan = archive.xml(SCAN)
    when = None if scan is None else scan.findtext("ScanDateTime")
    try:
        metadata["date"] = datetime.datetime.strptime(when.strip(), "%m/%d/%Y %H:%M:%S %z").isoformat()
    except (AttributeError, ValueError):
        pass
    return metadata
