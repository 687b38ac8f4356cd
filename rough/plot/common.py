"""What every figure shares: matplotlib loaded on demand (an optional dependency,
through :func:`rough.extras.require`) on the Agg backend, one style (:data:`STYLE`,
applied by :func:`style` and :func:`styled`), lengths in the unit that reads
naturally, and :func:`save`, which writes a figure atomically as PNG, SVG or PDF.
"""

import functools
import math
import os
import sys

import numpy as np

from ..errors import InputError
from ..extras import require
from ..io.atomic import atomic_output
from ..units import scale_for

#: The rcParams of every rough figure: font sizes, a light grid, constrained layout
#: (the successor of tight layout: it makes room for colour bars, legends and titles),
#: reproducible SVG ids and PDF text that stays text.
STYLE = {
    "font.size": 10,
    "axes.titlesize": 10,
    "axes.labelsize": 10,
    "xtick.labelsize": 9,
    "ytick.labelsize": 9,
    "legend.fontsize": 8,
    "legend.framealpha": 0.9,
    "figure.titlesize": 12,
    "figure.titleweight": "bold",
    "axes.grid": True,
    "grid.color": "0.88",
    "grid.linewidth": 0.6,
    "axes.axisbelow": True,
    "lines.linewidth": 1.0,
    "image.cmap": "viridis",
    "figure.constrained_layout.use": True,
    "figure.facecolor": "white",
    "savefig.facecolor": "white",
    "savefig.dpi": 150,
    "svg.hashsalt": "rough",
    "pdf.fonttype": 42,
}
#: Formats :func:`save` writes (``--format`` of ``rough show``).
FORMATS = ("png", "svg", "pdf")


def pyplot():
    """matplotlib's pyplot on the Agg backend (no display needed), or
    :class:`~rough.extras.MissingExtra` naming the extra to install."""
    require("matplotlib").use("Agg", force=True)
    return require("matplotlib.pyplot")


def style():
    """A context in which matplotlib draws in rough's style (:data:`STYLE`).

    Every figure function of this module builds its figure inside it, and
    :func:`save` writes inside it, so all of rough's figures share font sizes, grid
    and layout. Use it to draw your own figures to match.

    Returns
    -------
    contextlib.AbstractContextManager
        :func:`matplotlib.pyplot.rc_context` with :data:`STYLE`.

    Examples
    --------
    >>> from rough import plot
    >>> with plot.style():
    ...     import matplotlib.pyplot as plt
    ...     figure, axes = plt.subplots()
    >>> axes.xaxis.get_gridlines()[0].get_visible()
    True
    >>> plt.close(figure)
    """
    return pyplot().rc_context(STYLE)


def styled(function):
    """Build the figure of ``function`` inside :func:`style`."""

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with style():
            return function(*args, **kwargs)

    return wrapper


def save(figure, path, format=None, dpi=150):
    """Write ``figure`` to ``path`` atomically and close it.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        The figure, e.g. from :func:`~rough.plot.surface_figure`.
    path : str or os.PathLike
        The file; ``-`` is standard output (refused when it is a terminal).
    format : str, optional
        ``png``, ``svg``, ``pdf`` (or another that matplotlib writes: ``eps``,
        ``jpg``, ...). Default: from the file's extension; PNG for ``-`` and for a
        name without one.
    dpi : float, default 150
        Resolution of PNG output (and of the images inside SVG and PDF).

    Raises
    ------
    rough.InputError
        For a format matplotlib does not write, standard output on a terminal, or a
        folder that does not exist.
    """
    path = os.fspath(path)
    try:
        if format is None:
            format = os.path.splitext(path)[1].lstrip(".").lower() or "png"
        if format not in figure.canvas.get_supported_filetypes():
            raise InputError(f"{path}: cannot write a figure as {format!r} (use .png, .svg or .pdf)", filename=path)
        if path == "-" and sys.stdout is not None and sys.stdout.isatty():
            raise InputError("refusing to write a plot to a terminal: give a file name or a pipe", filename="-")
        with style(), atomic_output(path) as stream:
            figure.savefig(stream, format=format, dpi=dpi, bbox_inches="tight", pad_inches=0.08)
    finally:
        pyplot().close(figure)


def length_unit(metres):
    """The unit (factor, symbol) in which a length of ``metres`` reads naturally, as
    :func:`rough.units.scale_for` chooses it for every printed length:
    ``length_unit(6.4e-3)`` → ``(1000.0, 'mm')``; 0 and NaN give metres.

    Examples
    --------
    >>> from rough.plot import length_unit
    >>> length_unit(6.4e-3), length_unit(5e-4), length_unit(7.7e-8)
    ((1000.0, 'mm'), (1000000.0, 'µm'), (1000000000.0, 'nm'))
    """
    return scale_for(abs(float(metres)), "m")


def nice_length(longest):
    """The largest 1, 2 or 5 × 10^k not above ``longest``."""
    if longest <= 0 or not math.isfinite(longest):
        return 0.0
    power = 10.0 ** math.floor(math.log10(longest))
    return max(step * power for step in (1, 2, 5) if step * power <= longest * (1 + 1e-9))


def runs_of(mask):
    """(start, stop) index pairs of the runs where ``mask`` holds."""
    edges = np.flatnonzero(np.diff(np.concatenate(([0], mask.astype(np.int8), [0]))))
    return list(zip(edges[::2], edges[1::2]))
