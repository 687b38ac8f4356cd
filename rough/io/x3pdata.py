"""The binary data of an X3P file: checked against its MD5 (or zip CRC-32), scaled to
metres, and read a window at a time from disk for :func:`rough.io.x3p.open_tiles`.

Checks: :func:`checked_member` hashes a member once, MD5 and CRC-32 together, and
holds it to main.xml's MD5 (a mismatch refuses the file unless ``verify`` is False,
when it warns) and to its zip CRC-32 only where no MD5 is checked. A map read in
windows is described from its header (:func:`open_data`), then checked the same way
before its first window (:meth:`DataSource.check`, which :func:`rough.io.open_tiles`
calls): a stored member in one pass over its bytes on disk, a deflated one in one
streaming pass of its decompressed bytes, so that no window is ever read from data
that fail, and a map that turns out to fit in memory is checked once, by its read.

Windows (:class:`DataSource`): a stored member is a memory map of the file at the
member's data; a deflated one is decompressed front to back as far as the rows asked
for (restarted when a window lies before the last one read; the last window's bytes
are kept, so strips with a halo do not restart it). The valid-point mask, if any, is
read once per process (it holds a bit per point).
"""

import collections
import concurrent.futures
import hashlib
import logging
import struct
import zipfile
import zlib

import numpy as np

from ..errors import FormatError
from . import limits, receiving, ziparchive
from .windowed import FileSource, finite, mapped

log = logging.getLogger("rough")

STEP = 1 << 20  # bytes decompressed at a time (and handed to the MD5 thread)
PACKED_STEP = 1 << 18  # compressed bytes fed to zlib at a time
HASHED_STEP = 1 << 24  # bytes of a stored member hashed at a time when a map is opened in windows


def check(verify, problem):
    """Refuse a file for a checksum ``problem`` (a warning with ``verify`` False)."""
    if problem is None:
        return
    if verify:
        raise FormatError(f"{problem}; the file may be damaged (--ignore-checksums reads it anyway)")
    log.warning("%s; reading anyway", problem)


def md5_problem(actual, stated, name):
    if stated is None:
        return f"main.xml gives no MD5 checksum for {name}"
    if stated.lower() != actual:
        return f"{name} checksum mismatch (main.xml says {stated}, the data are {actual})"
    return None


def scaled(raw, axis, offset=True):
    """Raw values of an axis as float64 lengths: integer data times ``Increment``, plus
    ``Offset`` (with ``offset``)."""
    values = raw.astype(np.float64) if raw.dtype != np.float64 else raw
    factor = axis["increment"] if axis["code"] in ("I", "L") else 1.0
    shift = axis["offset"] if offset else 0.0
    if factor == 1.0 and not shift:
        return values
    return limits.scaled(values, factor, f"the Increment {factor!r} and Offset {shift!r}", shift)


def checked_member(archive, prefix, link, data, stated, verify, **sizes):
    """``(bytes, MD5 hex, CRC-32)`` of a binary member, hashed once: on the way in (a
    stored member of a stream, by :func:`rough.io.receiving.receive`), while it is
    unpacked (a deflated one, :func:`inflated`), or in one pass (MD5 and CRC-32 side by
    side); its MD5 checked against ``stated``, its zip CRC-32 only when there is no MD5
    to check."""
    info = archive.NameToInfo.get(f"{prefix}{link}")
    if info is not None and info.compress_type == zipfile.ZIP_DEFLATED:
        _sized(info, **sizes)
        start = data_start(info, data)
        content, digests = inflated(info, memoryview(data)[start : start + info.compress_size])
    else:
        info, content = ziparchive.located(archive, f"{prefix}{link}", data, **sizes)
        digests = receiving.arrived(content) or receiving.hashes(content)
    _judge(info, link, digests, stated, verify)
    return content, *digests


def _sized(info, expected=None, limit=None):
    if expected is not None and info.file_size != expected:
        raise FormatError(f"{info.filename} holds {info.file_size} bytes, but the header implies {expected}")
    if limit is not None and info.file_size > limit:
        raise FormatError(f"{info.filename} is {info.file_size} bytes, more than rough reads ({limit})")


def inflated(info, packed):
    """``(bytes, (MD5 hex, CRC-32))`` of a deflated member, hashed as it is unpacked:
    each step's bytes go to a worker thread for the MD5 and CRC-32 while this one
    unpacks the next (zlib and hashlib release the GIL), so the digests cost little
    beyond the decompression. Within the caps of :mod:`rough.io.limits`."""
    limits.Budget(len(packed), info.filename).add(info.file_size)
    content = bytearray(info.file_size)
    view, filled, stream, hasher = memoryview(content), 0, _Inflater(packed, info), receiving.Hasher()
    hasher.add(0, info.file_size)
    try:
        while filled < info.file_size:
            part = stream.next(min(STEP, info.file_size - filled))
            view[filled : filled + len(part)] = part
            filled += len(part)
            hasher.arrived(view, filled)
        stream.finish()
        digests = hasher.finish()
    finally:
        hasher.stop()
    view.release()
    found = digests.get(0)
    return content, found[1] if found else receiving.hashes(content)


def _judge(info, link, digests, stated, verify):
    actual, crc = digests
    if not (verify and stated) and crc != info.CRC:
        raise FormatError(f"{info.filename} fails its zip CRC check: the archive is damaged")
    check(verify, md5_problem(actual, stated, link))


def data_start(info, data):
    """Where a member's data start in the archive's bytes ``data`` (after its local header)."""
    if info.flag_bits & 0x1:
        raise FormatError(f"{info.filename} is encrypted; X3P members are plain")
    try:
        signature, name, extra = struct.unpack_from("<4s22xHH", data, info.header_offset)
    except struct.error:
        signature = None
    if signature != b"PK\x03\x04":
        raise FormatError(f"damaged zip: no local header for {info.filename}")
    start = info.header_offset + 30 + name + extra
    packed = info.compress_size if info.compress_type != zipfile.ZIP_STORED else info.file_size
    if start + packed > len(data):
        raise FormatError(f"truncated archive: {info.filename} is cut short")
    return start


def open_data(archive, prefix, link, data, size):
    """The zip entry of a data member that :class:`DataSource` can read in windows
    (stored or deflated, of the size the header implies; its checksum is
    :meth:`DataSource.check`'s); None for another compression (the caller reads the
    file whole)."""
    try:
        info = archive.getinfo(f"{prefix}{link}")
    except KeyError:
        raise FormatError(f"the archive has no member {prefix}{link!r}") from None
    if info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
        return None
    _sized(info, expected=size)
    data_start(info, data)
    return info


def _member_digests(info, data):
    """``(MD5 hex, CRC-32)`` of a stored or deflated member, in one pass, none kept."""
    start = data_start(info, data)
    packed = memoryview(data)[start : start + info.compress_size]
    if info.compress_type == zipfile.ZIP_STORED:
        return _digests(packed[at : at + HASHED_STEP] for at in range(0, info.file_size, HASHED_STEP))
    return _digests(_inflated_parts(info, packed))


def _inflated_parts(info, packed):
    """A deflated member's bytes, a step at a time (none kept); FormatError unless it
    holds exactly the bytes its entry declares, or past :data:`rough.io.limits.MAX_RATIO`."""
    if info.file_size > limits.RATIO_FLOOR and info.file_size > limits.cap("MAX_RATIO") * max(len(packed), 1):
        raise FormatError(
            f"{info.filename} unpacks to more than {limits.cap('MAX_RATIO')}× its {limits.human(len(packed))} "
            "(a compression bomb?); refusing (set ROUGH_MAX_RATIO to raise the cap)"
        )
    stream = _Inflater(packed, info)
    while stream.position < info.file_size:
        yield stream.next(min(STEP, info.file_size - stream.position))
    stream.finish()


def _digests(parts):
    """``(MD5 hex, CRC-32)`` of consecutive byte chunks, in one pass: the MD5 in a
    worker thread beside the CRC-32 and whatever makes the chunks (hashlib and zlib
    release the GIL), at most two chunks behind, so that Ctrl-C stops it soon."""
    md5, crc, queued = hashlib.md5(), 0, collections.deque()
    with concurrent.futures.ThreadPoolExecutor(1, thread_name_prefix="rough-md5") as worker:
        try:
            for part in parts:
                queued.append(worker.submit(md5.update, part))
                crc = zlib.crc32(part, crc)
                if len(queued) > 2:
                    queued.popleft().result()
        except BaseException:
            worker.shutdown(cancel_futures=True)
            raise
    return md5.hexdigest(), crc


class _Inflater:
    """A deflated member's bytes, front to back, a given count at a time."""

    def __init__(self, packed, info):
        self.packed, self.info = packed, info
        self.unpacker, self.read, self.pending, self.position = zlib.decompressobj(-15), 0, b"", 0

    def next(self, count):
        """The next ``count`` bytes (FormatError if the member ends or fails first)."""
        parts, got = [], 0
        try:
            while got < count:
                if not self.pending:
                    self.pending = self.packed[self.read : self.read + PACKED_STEP]
                    self.read += len(self.pending)
                part = self.unpacker.decompress(self.pending, count - got)
                self.pending = self.unpacker.unconsumed_tail
                if not part and (self.unpacker.eof or self.read >= len(self.packed)) and not self.pending:
                    break
                parts.append(part)
                got += len(part)
        except zlib.error as error:
            raise FormatError(f"{self.info.filename} cannot be unpacked (zlib: {error})") from None
        if got < count:
            raise self.short()
        self.position += got
        return parts[0] if len(parts) == 1 else b"".join(parts)

    def finish(self):
        """Refuse a stream that does not end where its entry says (data past the end, or no end)."""
        if self.unpacker.eof:
            return
        try:
            extra = self.unpacker.decompress(self.pending or self.packed[self.read :], 1)
        except zlib.error:
            extra = b""
        if extra or not self.unpacker.eof:
            raise self.short()

    def short(self):
        return FormatError(f"{self.info.filename} does not hold the {self.info.file_size} bytes its zip entry declares")


class DataSource(FileSource):
    """Windows of one layer of an X3P map's data member (stored or deflated), scaled
    as :func:`scaled` does, invalid points (the mask, ±inf) NaN.

    ``data`` and ``mask`` are zip entry names; ``layout`` is ``(dtype, nx, first
    row of the layer in the member)``; ``axis`` is the CZ axis's description;
    ``stated`` the data's MD5 as the header gives it (or None) and ``verify``
    whether a wrong one is an error (:func:`check`)."""

    def __init__(self, path, data, mask, layout, axis, stated=None, verify=True):
        super().__init__(path)
        self.data, self.mask, self.layout, self.axis = data, mask, layout, axis
        self.stated, self.verify = stated, verify

    def check(self):
        """The data member's MD5 (its zip CRC-32 when the header states none) over one
        pass, as a whole read checks it: FormatError when it fails."""
        file = mapped(self.path)
        with zipfile.ZipFile(ziparchive.ViewFile(file)) as archive:
            info = archive.getinfo(self.data)
            _judge(info, info.filename, _member_digests(info, file), self.stated, self.verify)

    def opened(self):
        return _Opened(self.path, self.data, self.mask, self.layout)

    def window(self, rows, cols):
        """Rows and columns (slices of the layer, bounded, step 1) as float64 metres, NaN invalid."""
        opened, lock = self.handle()
        try:
            with lock:
                raw, valid = opened.rows(rows.start, rows.stop - rows.start)
            heights = scaled(np.array(raw[:, cols], dtype=np.float64), self.axis)
        except FormatError as error:
            raise FormatError(f"{self.path}: {error}") from None
        if valid is not None:
            heights[~valid[:, cols]] = np.nan
        return finite(heights)


class _Opened:
    """A data member opened in one process: its memory map, the deflate stream's state,
    the packed mask."""

    def __init__(self, path, data, mask, layout):
        self.file = mapped(path)
        archive = zipfile.ZipFile(ziparchive.ViewFile(self.file))
        self.info = archive.getinfo(data)
        self.start = data_start(self.info, self.file)
        self.dtype, self.nx, self.first = np.dtype(layout[0]), layout[1], layout[2]
        self.valid = None if mask is None else np.frombuffer(ziparchive.located(archive, mask, self.file)[1], np.uint8)
        self.stream, self.last = None, (0, b"")
        archive.close()

    def rows(self, first, count):
        """``(raw values of ``count`` rows of the layer from ``first``, valid points or None)``."""
        row_bytes = self.nx * self.dtype.itemsize
        begin, end = (self.first + first) * row_bytes, (self.first + first + count) * row_bytes
        if self.info.compress_type == zipfile.ZIP_STORED:
            raw = np.frombuffer(self.file, self.dtype, count=count * self.nx, offset=self.start + begin)
        else:
            raw = np.frombuffer(self._inflated(begin, end), self.dtype)
        return raw.reshape(count, self.nx), self._valid(first, count)

    def _inflated(self, begin, end):
        """Bytes ``begin:end`` of a deflated member: from the bytes kept of the last
        window (they end where the stream is) and onward in the stream, which restarts
        when they lie before it."""
        kept_at, kept = self.last
        if not kept_at <= begin <= kept_at + len(kept) or self.stream is None:
            if self.stream is None or begin < self.stream.position:
                packed = memoryview(self.file)[self.start : self.start + self.info.compress_size]
                self.stream = _Inflater(packed, self.info)
            while self.stream.position < begin:
                self.stream.next(min(STEP, begin - self.stream.position))
            kept_at, kept = begin, b""
        kept = kept[begin - kept_at :]  # up to where the stream is
        if end - begin > len(kept):
            kept = kept + self.stream.next(end - begin - len(kept)) if kept else self.stream.next(end - begin)
        self.last = (begin, kept)
        return kept[: end - begin]

    def _valid(self, first, count):
        if self.valid is None:
            return None
        start = (self.first + first) * self.nx
        bits = np.unpackbits(self.valid[start // 8 : -(-(start + count * self.nx) // 8)], bitorder="little")
        return bits[start % 8 : start % 8 + count * self.nx].astype(bool).reshape(count, self.nx)
