"""Sources of :class:`rough.io.tiled.TiledSurface` windows that read a file on disk.

A :class:`FileSource` pickles as its path, the file's size and modification time
when it was opened, and what its format needs to read a window; each process
(a worker, a cluster node) opens the file itself on its first window and keeps the
handle (never pickled). A file changed since it was opened is refused rather than
read: its windows would no longer belong to the map that was described.
"""

import mmap
import os
import threading

import numpy as np

from ..errors import FormatError


def identity(path):
    """``(size, modification time in ns)`` of a file: what must not change while it is read."""
    facts = os.stat(path)
    return facts.st_size, facts.st_mtime_ns


class FileSource:
    """Reads windows of one file; subclasses define ``opened()`` (the handle, made in
    this process) and ``window(rows, cols)``, which calls :meth:`handle` for it."""

    def __init__(self, path):
        self.path = os.fspath(path)
        self.identity = identity(self.path)
        self._local = None

    def __getstate__(self):
        return {key: value for key, value in self.__dict__.items() if key != "_local"}

    def __setstate__(self, state):
        self.__dict__.update(state, _local=None)

    def handle(self):
        """``(handle, lock)`` for this process: the file is opened once per process
        (again after a fork), and a window is read under the lock, as a handle may
        not be used by two threads at once. Each window first checks that the file
        is still the one opened (a file cut short under a memory map would crash)."""
        try:
            now = identity(self.path)
        except OSError as error:
            raise FormatError(f"{self.path} cannot be opened again ({error.strerror})") from None
        if now != self.identity:
            raise FormatError(f"{self.path} has changed since it was opened; read it again")
        local = self._local
        if local is None or local[0] != os.getpid():
            local = self._local = (os.getpid(), self.opened(), threading.Lock())
        return local[1], local[2]

    def opened(self):
        raise NotImplementedError

    def check(self):
        """Check the data as a whole read of the file would (e.g. a checksum over
        them), raising FormatError; a source whose reads check themselves does nothing."""


def mapped(path):
    """A read-only memory map of a whole file (FormatError for an empty one)."""
    with open(path, "rb") as stream:
        try:
            return mmap.mmap(stream.fileno(), 0, access=mmap.ACCESS_READ)
        except ValueError:
            raise FormatError("empty file, no surface to read") from None


def finite(heights):
    """``heights`` (float64, writable) with ±inf made NaN, as :func:`rough.io.read` does."""
    heights[np.isinf(heights)] = np.nan
    return heights
