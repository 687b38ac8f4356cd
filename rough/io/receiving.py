"""Input as it arrives: files, standard input and other streams read whole, within the
caps of :mod:`rough.io.limits`, and zip archives (X3P) hashed on the way in.

Every format reads its bytes through :func:`read_capped`. A stream that starts as a
zip archive goes through :func:`receive`, which fills one buffer with no copy after
the read and takes the MD5 and CRC-32 of each large stored member while the bytes
arrive (the MD5 in a worker thread, as hashlib releases the GIL), so that hashing
overlaps reading; :func:`arrived` gives those digests to the reader.
"""

import contextlib
import fcntl
import hashlib
import mmap
import os
import queue
import stat
import threading
import zipfile
import zlib

import numpy as np

from . import limits
from .registry import HEAD
from .ziparchive import LOCAL_HEADER, ZIP64_MARK

RECEIVE_STEP = 1 << 21  # bytes asked of each read of a stream
HASH_STEP = 1 << 20  # bytes hashed at a time (and the size below which hashing takes no thread)
FIRST_CAPACITY = 1 << 24  # bytes first set aside for a stream of unknown length
HASHED_FROM = 1 << 16  # stored members this large and up are hashed on the way in ...
HASHED_AT_MOST = 4  # ... the first few of them (X3P has one or two large members)


def read_capped(stream, what, is_text=None):
    """All of ``stream``, read in chunks, refused past MAX_INPUT_BYTES, and past
    MAX_TEXT_BYTES once its first bytes show text (``is_text(head)``, asked with up
    to :data:`rough.io.registry.HEAD` bytes): the cap applies while the bytes arrive,
    so a stream is never read further than it. A zip archive comes back as a read-only
    memoryview, hashed as it arrived (:func:`receive`); a terminal is read as typed,
    up to one Ctrl-D (:func:`typed`)."""
    limit = limits.cap("MAX_INPUT_BYTES")
    if is_terminal(stream):
        return typed(stream, what, min(limit, limits.cap("MAX_TEXT_BYTES")))
    received = receive(stream, what, limit)
    if received is not None:
        return received
    size = limits.file_size(stream)
    if size is not None:
        if size > limit:
            raise limits.too_large(what, limit)
        start = stream.tell()
        if is_text is not None and size - start > limits.cap("MAX_TEXT_BYTES") and is_text(stream.read(HEAD)):
            raise limits.too_much_text(size - start)
        stream.seek(start)
        return stream.read()
    parts, total, ceiling, text = [], 0, limit, None if is_text else False
    while part := stream.read(min(HEAD if text is None else limits.CHUNK << 4, ceiling + 1 - total)):
        parts.append(part)
        total += len(part)
        if text is None and total >= HEAD:
            text = is_text(b"".join(parts)[:HEAD])
            ceiling = min(limit, limits.cap("MAX_TEXT_BYTES")) if text else limit
        if total > limit:
            raise limits.too_large(what, limit)
        if total > ceiling:
            raise limits.too_much_text(None)
    data = b"".join(parts)
    if text is None and total > limits.cap("MAX_TEXT_BYTES") and is_text(data):
        raise limits.too_much_text(total)
    return data


def typed(stream, what, limit):
    """What is typed at a terminal, up to the first end of input (Ctrl-D at the start
    of a line, as ``cat`` takes it): each read returns what the terminal has, a line
    at a time, so one Ctrl-D ends it (a read of whole chunks would wait for a second).
    Refused past ``limit`` bytes."""
    parts, total = [], 0
    read = getattr(stream, "read1", stream.read)  # one read of the terminal at a time
    while part := read(limits.CHUNK):
        parts.append(part)
        total += len(part)
        if total > limit:
            raise limits.too_large(what, limit)
    return b"".join(parts)


def is_terminal(stream):
    """Whether ``stream`` (standard input or output, an open file, or None) is a terminal."""
    try:
        return stream.isatty()
    except (AttributeError, OSError, ValueError):  # a closed or unusual stream
        return False


def receive(stream, what, limit):
    """All of a binary stream (standard input, an open file) that starts as a zip
    archive, as a read-only memoryview, or None for any other stream, which the caller
    reads as usual. Refused (InputError) past ``limit`` bytes.

    The bytes go into one buffer as they arrive, with no copy after the read, and the
    data of each stored member whose local header gives its size are hashed on the
    way: the CRC-32 in this thread, the MD5 in a worker thread, so hashing overlaps
    the reading and ends soon after the last byte arrives. :func:`rough.io.x3p.read` takes
    those digests instead of hashing the data again."""
    size = limits.file_size(stream)
    try:  # a look at the first bytes that leaves a file's buffer empty (a later read() would join to it)
        head = os.pread(stream.fileno(), 4, stream.tell()) if size is not None else stream.peek(4)[:4]
        size = None if size is None else size - stream.tell()
    except (AttributeError, OSError, ValueError):
        return None
    if head != b"PK\x03\x04" or not hasattr(stream, "readinto"):
        return None
    if size is not None and size > limit:
        raise limits.too_large(what, limit)
    try:
        buffer = Received(
            -1, min(limit, FIRST_CAPACITY if size is None else size) + 1, flags=mmap.MAP_PRIVATE | mmap.MAP_ANONYMOUS
        )  # private: a shared mapping cannot grow
    except OSError:
        raise MemoryError from None
    with contextlib.suppress(AttributeError, OSError):  # 2 MiB pages: 1/512 of the faults while bytes arrive
        buffer.madvise(mmap.MADV_HUGEPAGE)
    headers, hasher = LocalHeaders(), Hasher()
    view, filled = memoryview(buffer), 0
    try:
        while True:
            if filled == len(buffer):
                if filled > limit:
                    raise limits.too_large(what, limit)
                view = hasher.resize(buffer, view, min(limit + 1, 2 * filled))
            count = stream.readinto(view[filled : filled + RECEIVE_STEP])
            if not count:
                break
            filled += count
            for start, end in headers.walk(view, filled):
                hasher.add(start, end)
            hasher.arrived(view, filled)
            wanted = min(limit + 1, headers.horizon + headers.horizon // 16 + RECEIVE_STEP)
            if size is None and wanted > len(buffer):  # the local headers tell how much more is coming
                view = hasher.resize(buffer, view, wanted)
        digests = hasher.finish()
    finally:
        hasher.stop()
    view.release()
    if filled < len(buffer):
        buffer.resize(max(filled, 1))
    received = memoryview(buffer).toreadonly()[:filled]
    base = address(received)
    buffer.regions = {base + start: found for start, found in digests.items()}
    return received


class Received(mmap.mmap):
    """Anonymous memory (allocated as it is filled) holding a received stream.
    ``regions`` maps the address of each stored member's data hashed on the way in to
    ``(size, (MD5 hex, CRC-32))``."""

    regions = {}


def address(data):
    """Where a buffer's (or an array's) bytes start in memory."""
    array = data if isinstance(data, np.ndarray) else np.frombuffer(data, np.uint8) if len(data) else None
    return 0 if array is None else array.__array_interface__["data"][0]


def arrived(content):
    """``(MD5 hex, CRC-32)`` of ``content`` if :func:`receive` hashed exactly these
    bytes on the way in, else None."""
    regions = getattr(getattr(content, "obj", None), "regions", None)
    if not regions or not isinstance(content, memoryview):
        return None
    size, digests = regions.get(address(content), (None, None))
    return digests if size == len(content) else None


class LocalHeaders:
    """Walks a zip archive's local headers as its bytes arrive. ``walk`` yields the
    data ``(start, end)`` of the first few large stored members whose headers give
    their size (:data:`HASHED_FROM`, :data:`HASHED_AT_MOST`: a hostile archive of a
    million tiny members costs no more than an X3P file); the walk stops at anything
    else (the central directory, a member followed by a data descriptor, ZIP64 sizes).
    ``horizon`` is where the walk has got to."""

    def __init__(self):
        self.position, self.horizon, self.done, self.found = 0, 0, False, 0

    def walk(self, view, filled):
        while not self.done and self.position + LOCAL_HEADER.size <= filled:
            signature, _, flags, method, _, _, _, packed, size, name, extra = LOCAL_HEADER.unpack_from(
                view, self.position
            )
            if signature != b"PK\x03\x04" or flags & 0x8 or ZIP64_MARK in (packed, size):
                self.done = True
                break
            start = self.position + LOCAL_HEADER.size + name + extra
            if method == zipfile.ZIP_STORED and packed == size >= HASHED_FROM and not flags & 0x1:
                if self.found < HASHED_AT_MOST:
                    yield start, start + size
                self.found += 1
            self.position = self.horizon = start + packed


class Hasher:
    """The MD5 and CRC-32 of regions of a buffer being filled, each byte hashed once,
    as it arrives: the CRC-32 in the caller's thread, the MD5 in a worker thread (both
    release the GIL on large buffers, so they run beside the reads)."""

    def __init__(self):
        self.regions = []  # [start, end, hashed up to, md5, crc]
        self.jobs = queue.SimpleQueue()
        self.worker = None
        self.cancelled = self.failed = False

    def add(self, start, end):
        self.regions.append([start, end, start, hashlib.md5(), 0])

    def arrived(self, view, filled):
        for region in self.regions:
            start, end, done, md5, crc = region
            ready = min(end, filled)
            if ready > done and (ready == end or ready - done >= HASH_STEP):
                span = view[done:ready]
                region[4] = zlib.crc32(span, crc)
                region[2] = ready
                if self.worker is None:
                    self.worker = threading.Thread(target=self._work, name="rough-md5", daemon=True)
                    self.worker.start()
                self.jobs.put((md5, span))
                del span

    def _work(self):
        while (job := self.jobs.get()) is not None:
            try:
                if callable(job):
                    job()
                elif not self.cancelled:
                    job[0].update(job[1])
            except Exception:  # noqa: BLE001 -- no digest then (the reader hashes again), and never a hang
                self.cancelled = self.failed = True
            job = None  # drop the view, so that the buffer can be resized

    def resize(self, buffer, view, size):
        """Grow the buffer (the kernel moves its pages, no copy) once the worker holds
        no view of it; returns the new view."""
        if self.worker is not None:
            idle = threading.Event()
            self.jobs.put(idle.set)
            idle.wait()
        view.release()
        buffer.resize(size)
        return memoryview(buffer)

    def finish(self):
        """``{start: (size, (MD5 hex, CRC-32))}`` of the regions that arrived whole."""
        self._join()
        if self.failed:
            return {}
        return {
            start: (end - start, (md5.hexdigest(), crc)) for start, end, done, md5, crc in self.regions if done == end
        }

    def stop(self):
        """Stop the worker without hashing what is still queued (after an error)."""
        self.cancelled = True
        self._join()

    def _join(self):
        if self.worker is not None and self.worker.is_alive():
            self.jobs.put(None)
            self.worker.join()


def hashes(content):
    """``(MD5 hex, CRC-32)`` of ``content`` in one pass: the MD5 in a worker thread
    (hashlib and zlib release the GIL on large buffers) while this one takes the CRC."""
    md5 = hashlib.md5()
    if len(content) < HASH_STEP:
        md5.update(content)
        return md5.hexdigest(), zlib.crc32(content)
    worker = threading.Thread(target=md5.update, args=(content,), daemon=True)
    worker.start()
    try:
        crc = zlib.crc32(content)
    finally:
        worker.join()
    return md5.hexdigest(), crc


def widen_pipe(stream, size=1 << 20):
    """Give a pipe a 1 MiB buffer (Linux), which halves the cost of moving large
    surfaces through shell pipelines. Does nothing for files and terminals."""
    try:
        if stat.S_ISFIFO(os.fstat(stream.fileno()).st_mode):
            fcntl.fcntl(stream.fileno(), getattr(fcntl, "F_SETPIPE_SZ", 1031), size)
    except (OSError, ValueError, AttributeError):
        pass
