"""Zip archives read and written without copying their members.

Reading: :func:`member` and :func:`located` give a stored member as a view of the
archive's bytes (found through the central directory that :class:`ViewFile` lets
zipfile read without a copy), and unpack a compressed one in chunks within the caps
of :mod:`rough.io.limits`. Writing: :class:`ZipWriter` writes stored members front to
back to any binary stream, a pipe included, with ZIP64 fields where a size or offset
needs them. X3P and NPZ are read this way; X3P is written this way.
"""

import bz2
import io
import lzma
import struct
import zipfile
import zlib

from ..errors import FormatError
from ..surface import timestamp
from . import limits

# What zipfile raises for damaged or unusual archives (bz2 raises OSError, lzma LZMAError)
ZIP_ERRORS = (
    zipfile.BadZipFile,
    zipfile.LargeZipFile,
    NotImplementedError,
    RuntimeError,
    OSError,
    EOFError,
    zlib.error,
    lzma.LZMAError,
)


class ViewFile(io.RawIOBase):
    """A read-only, seekable file over a buffer, for zipfile to find the central
    directory in; io.BytesIO would copy anything but bytes."""

    def __init__(self, data):
        self.view, self.position = memoryview(data), 0

    def readable(self):
        return True

    def seekable(self):
        return True

    def readinto(self, target):
        part = self.view[self.position : self.position + len(target)]
        target[: len(part)] = part
        self.position += len(part)
        return len(part)

    def seek(self, offset, whence=io.SEEK_SET):
        self.position = max(0, (0, self.position, len(self.view))[whence] + offset)
        return self.position

    def tell(self):
        return self.position


def member(archive, name, data, limit=None, expected=None, check_crc=True):
    """A member's bytes; stored members are returned as a zero-copy view of ``data``
    after their CRC is checked (unless the caller checks an MD5 of them instead).
    Sizes are checked before anything is read."""
    info, content = located(archive, name, data, limit, expected)
    if check_crc and zlib.crc32(content) != info.CRC:
        raise FormatError(f"{name} fails its zip CRC check: the archive is damaged")
    return content


def located(archive, name, data, limit=None, expected=None):
    """``(zip entry, bytes)`` of a member, its CRC unchecked: a view of ``data`` for a
    stored member, else the member unpacked."""
    try:
        info = archive.getinfo(name)
    except KeyError:
        raise FormatError(f"the archive has no member {name!r}") from None
    if expected is not None and info.file_size != expected:
        raise FormatError(f"{name} holds {info.file_size} bytes, but the header implies {expected}")
    if limit is not None and info.file_size > limit:
        raise FormatError(f"{name} is {info.file_size} bytes, more than rough reads ({limit})")
    if info.flag_bits & 0x1:
        raise FormatError(f"{name} is encrypted; X3P members are plain")
    view = memoryview(data)
    header = bytes(view[info.header_offset : info.header_offset + 30])
    if len(header) < 30 or header[:4] != b"PK\x03\x04":
        raise FormatError(f"damaged zip: no local header for {name}")
    start = info.header_offset + 30 + sum(struct.unpack("<HH", header[26:30]))
    if info.compress_type == zipfile.ZIP_STORED:
        content = view[start : start + info.file_size]
        if len(content) != info.file_size:
            raise FormatError(f"truncated archive: {name} is cut short")
    else:
        content = _unpacked(info, view[start : start + info.compress_size], name)
    return info, content


def _unpacked(info, packed, name):
    """A compressed member unpacked in chunks, never past the size its entry declares,
    which must itself be within the caps of rough.io.limits."""
    limits.Budget(len(packed), name).add(info.file_size)
    content, filled = bytearray(info.file_size), 0
    try:
        unpacker, packed = _unpacker(info, bytes(packed), name)
        while not unpacker.eof:
            part = unpacker.decompress(packed, min(limits.CHUNK << 4, info.file_size - filled + 1))
            packed = getattr(unpacker, "unconsumed_tail", b"")
            if (not part and getattr(unpacker, "needs_input", not packed)) or filled + len(part) > info.file_size:
                break
            content[filled : filled + len(part)] = part
            filled += len(part)
    except ZIP_ERRORS as error:
        raise FormatError(f"{name} cannot be unpacked ({type(error).__name__}: {error})") from None
    if not unpacker.eof or filled != info.file_size:
        raise FormatError(f"{name} does not hold the {info.file_size} bytes its zip entry declares")
    return content


def _unpacker(info, packed, name):
    """The decompressor of a zip member and the bytes to feed it."""
    if info.compress_type == zipfile.ZIP_DEFLATED:
        return zlib.decompressobj(-15), packed
    if info.compress_type == zipfile.ZIP_BZIP2:
        return bz2.BZ2Decompressor(), packed
    if info.compress_type == zipfile.ZIP_LZMA and len(packed) > 4:  # zip's LZMA: version, size, properties
        size = struct.unpack("<H", packed[2:4])[0]
        properties = lzma._decode_filter_properties(lzma.FILTER_LZMA1, packed[4 : 4 + size])
        return lzma.LZMADecompressor(lzma.FORMAT_RAW, filters=[properties]), packed[4 + size :]
    raise FormatError(f"{name} cannot be unpacked (zip compression method {info.compress_type})")


LOCAL_HEADER = struct.Struct("<4s5H3L2H")  # signature, version, flags, method, time, date, CRC, sizes, name, extra
CENTRAL_HEADER = struct.Struct("<4s4B4H3L5H2L")
END_RECORD = struct.Struct("<4s4H2LH")
ZIP64_END_RECORD = struct.Struct("<4sQ2H2L4Q")
ZIP64_LOCATOR = struct.Struct("<4sLQL")
ZIP64_LIMIT = 0xFFFFFFFF  # sizes and offsets from here on go in ZIP64 fields
ZIP64_MARK = 0xFFFFFFFF  # what a header's field holds when a ZIP64 field holds the value
UNIX = 3  # the "made by" system, for the Unix permissions in the external attributes


class ZipWriter:
    """A zip archive of stored members written front to back to any binary stream
    (pipes included: nothing is sought back). Each local header holds its member's
    CRC-32 and sizes, so no data descriptor follows the data, and member data are
    written as given, without a copy."""

    def __init__(self, stream):
        self.stream, self.offset, self.entries = stream, 0, []
        year, month, day, hour, minute, second = _zip_time()
        self.time = hour << 11 | minute << 5 | second // 2
        self.date = (year - 1980) << 9 | month << 5 | day

    def add(self, name, content, crc=None, align=None):
        """One member; ``crc`` is the CRC-32 of ``content`` if known; ``align`` pads the
        local header's extra field so that the data start at a multiple of it."""
        name = name.encode("ascii")
        size = len(content)
        crc = zlib.crc32(content) if crc is None else crc
        large = size >= ZIP64_LIMIT
        extra = struct.pack("<2H2Q", 1, 16, size, size) if large else b""
        padding = b""
        if align:
            gap = -(self.offset + LOCAL_HEADER.size + len(name) + len(extra) + 6) % align
            padding = struct.pack("<3H", 0xD935, 2 + gap, align) + bytes(gap)
        extra += padding
        fields = self._fields(name, extra, crc, size)
        header = LOCAL_HEADER.pack(b"PK\x03\x04", 45 if large else 20, 0, *fields)
        self.entries.append((name, crc, size, self.offset, padding))  # the central directory repeats the padding
        self._put(header + name + extra)
        self._put(content)

    def close(self):
        """The central directory and its end records."""
        start, records = self.offset, []
        for name, crc, size, offset, padding in self.entries:
            wide = [size, size] if size >= ZIP64_LIMIT else []
            wide += [offset] if offset >= ZIP64_LIMIT else []
            extra = (struct.pack(f"<2H{len(wide)}Q", 1, 8 * len(wide), *wide) if wide else b"") + padding
            version = 45 if wide else 20
            fields = self._fields(name, extra, crc, size)
            place = ZIP64_MARK if offset >= ZIP64_LIMIT else offset
            attributes = (0, 0, 0, 0o644 << 16, place)  # comment length, disk, internal and external attributes, offset
            records.append(CENTRAL_HEADER.pack(b"PK\x01\x02", version, UNIX, version, 0, 0, *fields, *attributes))
            records.append(name + extra)
        directory = b"".join(records)
        count, end = len(self.entries), start + len(directory)
        tail = b""
        if count >= 0xFFFF or len(directory) >= ZIP64_LIMIT or start >= ZIP64_LIMIT:
            tail = ZIP64_END_RECORD.pack(
                b"PK\x06\x06", ZIP64_END_RECORD.size - 12, 45, 45, 0, 0, count, count, len(directory), start
            ) + ZIP64_LOCATOR.pack(b"PK\x06\x07", 0, end, 1)
        if tail:
            count, size, start = 0xFFFF, ZIP64_MARK, ZIP64_MARK
        else:
            size = len(directory)
        tail += END_RECORD.pack(b"PK\x05\x06", 0, 0, count, count, size, start, 0)
        self._put(directory + tail)

    def _fields(self, name, extra, crc, size):
        """Method, time, date, CRC-32, sizes and name and extra lengths, as both headers hold them."""
        stated = ZIP64_MARK if size >= ZIP64_LIMIT else size
        return zipfile.ZIP_STORED, self.time, self.date, crc, stated, stated, len(name), len(extra)

    def _put(self, content):
        view = memoryview(content)
        while len(view):
            written = self.stream.write(view)
            if written is None or written >= len(view):
                break
            view = view[written:]  # a raw stream may take part of it
        self.offset += len(content)


def _zip_time():
    """The ZIP entries' time: ZIP cannot hold one before 1980, so earlier ones (as
    SOURCE_DATE_EPOCH=0 asks for) are stored as 1980-01-01 00:00:00, and none after
    2107."""
    stamp = timestamp()
    moment = tuple(
        int(part) for part in (stamp[0:4], stamp[5:7], stamp[8:10], stamp[11:13], stamp[14:16], stamp[17:19])
    )
    return min(max(moment, (1980, 1, 1, 0, 0, 0)), (2107, 12, 31, 23, 59, 59))
