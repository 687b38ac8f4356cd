"""Output files that appear only when complete.

Data go to a hidden temporary file in the target's folder (``.rough-*.tmp``), which is
renamed over the target, atomically, once everything is written. A command that
fails or is interrupted removes the temporary file; one killed with SIGKILL can leave
it behind, but never a half-written file under the target's name.
"""

import contextlib
import os
import tempfile

from ..errors import InputError


@contextlib.contextmanager
def atomic_output(path):
    """Yield a binary file object whose contents appear at ``path`` when the block
    ends without an exception. An existing file at ``path`` is replaced atomically."""
    path = os.fspath(path)
    directory = os.path.dirname(os.path.abspath(path))
    if os.path.isdir(path):
        raise InputError(f"{path}: is a folder, not a file to write")
    if not os.path.isdir(directory):
        raise InputError(f"{path}: cannot write, folder {directory} does not exist")
    fd, temporary = tempfile.mkstemp(dir=directory, prefix=".rough-", suffix=".tmp")
    try:
        umask = os.umask(0)
        os.umask(umask)
        os.fchmod(fd, 0o666 & ~umask)
        with os.fdopen(fd, "wb") as stream:
            yield stream
        os.replace(temporary, path)
    except BaseException as error:
        with contextlib.suppress(OSError):
            os.unlink(temporary)
        if isinstance(error, OSError) and not isinstance(error, BrokenPipeError) and error.filename is None:
            raise OSError(error.errno, error.strerror, path) from error  # name the file, not a temporary
        raise
