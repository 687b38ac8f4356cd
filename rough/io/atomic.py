"""Output files that appear only when complete, and outputs that are not files.

A regular file (or a new name) is written to a hidden temporary file in its folder
(``.rough-*.tmp``), flushed to the disk, and renamed over it, atomically, once
everything is written (the folder is flushed too, so that a crash after the rename
keeps the new file). A command that fails, is interrupted or gets a terminating
signal it can catch removes the temporary file; one killed with SIGKILL can leave it
behind, but never a half-written file under the target's name. As with any Unix
tool, a symbolic link is followed (its target is replaced, the link stays), a device,
FIFO or other special file is written directly, never replaced, and ``-`` is
standard output. A name for one of the process's open descriptors (``/dev/stdout``,
``/dev/stderr``, ``/dev/fd/N``, ``/proc/self/fd/N``, or a link to one) is written
through that descriptor, whatever it is open on: ``-o /dev/stdout >> log`` appends
to ``log``, as ``-o -`` does, and never replaces it.
"""

import contextlib
import io
import os
import re
import signal
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
    descriptor = _descriptor(path)
    if descriptor is not None:
        with _named(path), _through(descriptor, path) as stream:
            yield stream
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
    with _SignalsEndHere() as ended:
        try:
            with _named(path):
                fd, temporary = tempfile.mkstemp(dir=directory, prefix=".rough-", suffix=".tmp")
                umask = os.umask(0)
                os.umask(umask)
                os.fchmod(fd, stat.S_IMODE(mode) if mode is not None else 0o666 & ~umask)
                with os.fdopen(fd, "wb") as stream:
                    yield stream
                    stream.flush()
                    os.fsync(stream.fileno())  # the data on the disk before the name
                os.replace(temporary, target)
                _sync_folder(directory)
        except BaseException:
            if temporary is not None:
                with contextlib.suppress(OSError):
                    os.unlink(temporary)
            ended.die()
            raise


# /dev/fd/N, /proc/self/fd/N, /proc/PID/fd/N (also of a thread, /proc/PID/task/TID/fd/N)
_FD_NAME = re.compile(r"/(?:dev|proc/(?P<process>self|thread-self|\d+)(?:/task/\d+)?)/fd/(?P<fd>\d+)")
_STANDARD_NAMES = {"/dev/stdin": 0, "/dev/stdout": 1, "/dev/stderr": 2}


def names_a_terminal(path):
    """Whether ``path`` names one of this process's descriptors (``/dev/stdout``, ...)
    that is open on a terminal."""
    descriptor = _descriptor(os.fspath(path))
    return descriptor is not None and os.isatty(descriptor)


def _descriptor(path):
    """The number of this process's descriptor that ``path`` names, directly or
    through symbolic links, or None."""
    name = os.path.abspath(path)
    for _ in range(40):  # the kernel's limit on links followed
        name = os.path.join(os.path.realpath(os.path.dirname(name)), os.path.basename(name))
        if name in _STANDARD_NAMES:
            return _STANDARD_NAMES[name]
        match = _FD_NAME.fullmatch(name)
        if match:
            own = match["process"] in (None, "self", "thread-self", str(os.getpid()))
            return int(match["fd"]) if own else None
        if not os.path.islink(name):
            return None
        name = os.path.join(os.path.dirname(name), os.readlink(name))
    return None


@contextlib.contextmanager
def _through(descriptor, path):
    """A binary stream writing through a duplicate of ``descriptor`` (named ``path``):
    its file position and append mode are the descriptor's. Python's own buffered
    standard streams are flushed first, so that what they hold comes out before."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(AttributeError, OSError, ValueError):
            stream.flush()
    try:
        duplicate = os.dup(descriptor)
    except OSError:
        raise InputError(f"{path}: descriptor {descriptor} is not open", filename=path) from None
    with io.BufferedWriter(_Unseekable(duplicate, "wb")) as stream:
        yield stream


def _sync_folder(directory):
    """Flush the folder's entries (the rename) to the disk, where the system can."""
    with contextlib.suppress(OSError):
        fd = os.open(directory, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


# The signals whose default action ends the process and that a program can catch and
# return from (SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGSYS and SIGTRAP are faults of
# the process itself: Python cannot go on after them). SIGINT is Python's KeyboardInterrupt.
_TERMINATING = tuple(
    getattr(signal, name)
    for name in (
        "SIGHUP",
        "SIGQUIT",
        "SIGTERM",
        "SIGUSR1",
        "SIGUSR2",
        "SIGPIPE",
        "SIGALRM",
        "SIGVTALRM",
        "SIGPROF",
        "SIGXCPU",
        "SIGXFSZ",
        "SIGIO",
        "SIGPWR",
        "SIGSTKFLT",
    )
    if hasattr(signal, name)
)


class _Signalled(BaseException):
    """A terminating signal arrived while a temporary file existed."""

    def __init__(self, signum):
        super().__init__(signum)
        self.signum = signum


def _signalled(signum, frame):
    raise _Signalled(signum)


class _SignalsEndHere:
    """While the block runs (in the main thread), the terminating signals still at their
    default action raise :class:`_Signalled` instead, so that the block can remove its
    temporary file; its ``die()`` then ends the process by that signal's default action,
    so that the exit status says which (``kill -USR1`` gives 138, as it would without
    rough). Handlers set by others (the command line's SIGTERM and SIGHUP, nohup's
    ignored SIGHUP, an outer block's) are left alone."""

    def __enter__(self):
        self.installed = {}
        with contextlib.suppress(ValueError):  # not the main thread: signals are not ours to catch
            for signum in _TERMINATING:
                if signal.getsignal(signum) == signal.SIG_DFL:
                    self.installed[signum] = signal.signal(signum, _signalled)
        return self

    def __exit__(self, *exception):
        for signum, handler in self.installed.items():
            signal.signal(signum, handler)

    def die(self):
        """In an ``except`` block: if a signal this block caught is the exception,
        end the process by it."""
        error = sys.exc_info()[1]
        if isinstance(error, _Signalled) and error.signum in self.installed:
            signal.signal(error.signum, signal.SIG_DFL)
            os.kill(os.getpid(), error.signum)


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
