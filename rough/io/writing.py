"""Writing a surface: to a path (atomically) or a binary stream, in a format rough
writes (``registry.writable()``), chosen by name or by the path's extension.
"""

import os
import sys

from ..errors import InputError
from . import registry
from .atomic import atomic_output
from .receiving import widen_pipe


def write(surface, target, format=None):
    """Write ``surface`` to a path (atomically) or a binary stream.

    Parameters
    ----------
    surface : Surface
        The surface to write; NaN points are written as each format marks invalid
        points (a mask, or NaN in float data).
    target : str, os.PathLike or binary file object
        A path, ``'-'`` for standard output, or an open binary stream.
    format : str, optional
        A key of :data:`rough.io.WRITABLE` (``rough formats`` lists the formats rough
        writes). Defaults to the format the path's extension names
        (:data:`rough.io.EXTENSIONS`), and to X3P for streams.

    Raises
    ------
    rough.InputError
        When the format cannot be told from the extension, or is unknown.

    Notes
    -----
    A path is written to a hidden temporary file beside it and renamed when
    complete, so a failed or interrupted write never leaves a half-written file.
    What a format keeps is its facts in :mod:`rough.io.registry` (``rough formats``
    shows them): its ``carries`` (spacing, units, metadata, history, ...), and its
    ``height_type``: float64 formats keep the heights exactly, float32 ones to float32
    rounding.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> import numpy as np
    >>> import rough
    >>> scan = rough.read(rough.sample("rock-map.x3p"))
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     rough.write(scan, pathlib.Path(folder) / "scan.x3p")
    ...     again = rough.read(pathlib.Path(folder) / "scan.x3p")
    >>> bool(np.array_equal(again.heights, scan.heights, equal_nan=True))  # NaN points too
    True

    A binary stream gets X3P unless ``format`` says otherwise:

    >>> import io
    >>> buffer = io.BytesIO()
    >>> rough.write(scan, buffer, format="gsf")
    >>> buffer.getvalue()[:21]
    b'Gwyddion Simple Field'
    """
    if isinstance(target, (str, os.PathLike)) and os.fspath(target) != "-":
        chosen = format or format_for_path(target)
        with atomic_output(target) as stream:
            _writer(chosen).write(surface, stream)
    else:
        standard_output = getattr(sys.stdout, "buffer", None)  # absent in some notebook kernels
        stream = standard_output if target == "-" else target
        if stream is None:
            raise InputError("standard output takes no binary data here; write to a file or a binary stream")
        if stream is standard_output:
            widen_pipe(sys.stdout)
        _writer(format or "x3p").write(surface, stream)


def format_for_path(path):
    """The output format implied by a file name's extension."""
    extension = os.path.splitext(os.fspath(path))[1].lower()
    table = registry.extensions()
    if extension not in table:
        known = ", ".join(sorted(table))
        read_only = next((f.title for f in registry.formats().values() if extension in f.extensions), None)
        problem = (
            f"rough reads {read_only} ({extension}) but does not write it"
            if read_only
            else "cannot tell the format from the extension"
        )
        raise InputError(f"{path}: {problem} (use {known}, or -f FORMAT)")
    return table[extension]


def _module(format_name):
    try:
        return registry.module_of(format_name)
    except KeyError:
        raise InputError(f"unknown format {format_name!r} (use one of {', '.join(registry.writable())})") from None


def _writer(format_name):
    format_module = _module(format_name)
    if not hasattr(format_module, "write"):
        title, writable = registry.describe(format_name), ", ".join(registry.writable())
        raise InputError(f"rough reads {title} but does not write it (write one of {writable})")
    return format_module
