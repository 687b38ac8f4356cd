"""Where a command's results go, checked before any work: a name that cannot be
written (a folder, a folder that does not exist or is not writable) or whose extension
names no format of its kind is refused when the options are parsed, in one usage line
(exit status 2), so that a long computation never ends in "cannot write"."""

import errno
import functools
import os
import sys

import click

from .. import extras, io


def figure_formats():
    """The file name extensions matplotlib writes figures as (``png``, ``svg``, ``pdf``, …)."""
    extras.require("matplotlib")
    from matplotlib.backend_bases import FigureCanvasBase  # optional: plot

    return tuple(FigureCanvasBase.get_supported_filetypes())


def surface_formats():
    """The file name extensions rough writes surfaces as (``x3p``, ``tif``, ``npy``, …)."""
    return tuple(extension.lstrip(".") for extension in io.registry.extensions())


#: The kinds of side file: (what they are, the extensions that name them or a function
#: giving those, the names to suggest).
FIGURE = ("a figure", figure_formats, ".png, .svg or .pdf")
TABLE = ("a TSV table", ("tsv", "txt"), ".tsv")
TRACE = ("a trace", ("tsv", "txt", "npy"), ".tsv or .npy")
SURFACE = ("a surface", surface_formats, ".x3p, .tif or .npy")
#: The placeholders of side files' names: filled in per input or per run.
PLACEHOLDERS = ("{stem}", "{name}", "{speed}")


def check_target(path, param, kind=None):
    """Refuse, before any reading or computing, an output name that cannot be
    written, in one usage line (exit status 2): a folder, a name in a folder that does
    not exist or cannot be written, or (for a ``kind`` of side file, :data:`FIGURE`,
    :data:`TABLE`, :data:`TRACE`) an extension that names no format of that kind.
    Standard output (``-``), devices and FIFOs (written directly, as
    :func:`rough.io.atomic_output` does) pass; placeholders ``{stem}`` … in the name
    are checked as if filled in; a figure on standard output is refused when that is a
    terminal."""
    flag = param.opts[-1] if isinstance(param, click.Parameter) else param

    def refuse(problem):
        raise click.BadParameter(f"{path}: {problem}", param_hint=f"'{flag}'")

    if path == "-":
        if kind is FIGURE and io.is_terminal(sys.stdout):
            refuse("refusing to draw a figure on a terminal: give a file name or a pipe")
        return path
    named = functools.reduce(lambda name, mark: name.replace(mark, "x"), PLACEHOLDERS, os.fspath(path))
    if named.endswith(os.sep) or os.path.isdir(named):
        refuse("is a folder, not a file to write (give a file name in it)")
    if os.path.exists(named) and not os.path.isfile(named):
        return path  # a device or FIFO: written directly
    folder = os.path.dirname(os.path.realpath(named))
    if os.path.exists(folder) and not os.path.isdir(folder):
        refuse(os.strerror(errno.ENOTDIR))
    if not os.path.isdir(folder):
        refuse(f"cannot write, folder {os.path.dirname(os.path.abspath(named))} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        refuse(f"cannot write in folder {folder} (permission denied)")
    extension = os.path.splitext(named)[1].lstrip(".").lower()
    if kind is not None and extension:
        what, known, suggested = kind
        if extension not in (known() if callable(known) else known):
            refuse(f"cannot write {what} as .{extension} (name a {suggested} file)")
    return path


def side_file(kind=None):
    """A click callback that checks a side file's name (``--trace``, ``--psd``,
    ``--list``…) with :func:`check_target` when the options are parsed."""

    def check(ctx, param, value):
        return value if value is None else check_target(value, param, kind)

    return check
