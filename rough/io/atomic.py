"""Output files that appear only when complete, and outputs that are not files.

A regular file (or a new name) is written to a hidden temporary file in its folder
(``.rough-*.tmp``), which is renamed over it, atomically, once everything is written.
A command that fails or is interrupted removes the temporary file; one killed with
SIGKILL can leave it behind, but never a half-written file under the target's name.
As with any Unix tool, a symbolic link is followed (its target is replaced, the link
stays), a device, FIFO or other special file is written directly, never replaced,
and ``-`` is standard output.
"""

import contextlib
import io
import os
import stat
import sys
import tempfile

from ..errors import InputError, RoughError


def standard_output():
    """Standard output's binary buffer; a RoughError when standard output is closed."""
    if sys.stdout is None:
        raise RoughError("standard output is closed")
    return sys.stdout.buffer


@contextlib.contextmanager
def atomic_output(path):
    """Yield a binary file object whose contents appear at ``path`` when the block
    ends without an exception. An existing regular file at ``path`` (or at the end of
    the symbolic links it names) is replaced atomically; a device or FIFO is written
    directly; ``-`` is standard output."""
    path = os.fspath(path)
    if path == "-":
        stream = standard_output()
        with _named(path):
            yield stream
            stream.flush()
        return
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        mode = None
    except OSError as error:
        raise OSError(error.errno, error.strerror, path) from None
    if mode is not None and stat.S_ISDIR(mode):
        raise InputError(f"{path}: is a folder, not a file to write", filename=path)
    if mode is not None and not stat.S_ISREG(mode):
        with _named(path), io.BufferedWriter(_Unseekable(os.open(path, os.O_WRONLY | os.O_NOCTTY), "wb")) as stream:
            yield stream
        return
    target = os.path.realpath(path)
    directory = os.path.dirname(target)
    if not os.path.isdir(directory):
        raise InputError(
            f"{path}: cannot write, folder {os.path.dirname(os.path.abspath(path))} does not exist", filename=path
        )
    temporary = None
    try:
        with _named(path):
            fd, temporary = tempfile.mkstemp(dir=directory, prefix=".rough-", suffix=".tmp")
            umask = os.umask(0)
            os.umask(umask)
            os.fchmod(fd, stat.S_IMODE(mode) if mode is not None else 0o666 & ~umask)
            with os.fdopen(fd, "wb") as stream:
                yield stream
            os.replace(temporary, target)
    except BaseException:
        if temporary is not None:
            with contextlib.suppress(OSError):
                os.unlink(temporary)
        raise


class _Unseekable(io.FileIO):
    """A device or FIFO: writers must not seek (``/dev/null`` says it can, and then
    every position is 0)."""

    def seekable(self):
        return False

    def tell(self):
        raise io.UnsupportedOperation("not seekable")

    def seek(self, *args):
        raise io.UnsupportedOperation("not seekable")


@contextlib.contextmanager
def _named(path):
    """OSErrors name ``path`` (or standard output), not a temporary file or none."""
    try:
        yield
    except BrokenPipeError:
        raise
    except OSError as error:
        if error.filename is None or os.path.basename(str(error.filename)).startswith(".rough-"):
            raise OSError(error.errno, error.strerror, "standard output" if path == "-" else path) from error
        raise
