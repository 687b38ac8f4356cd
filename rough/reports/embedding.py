"""Figures as ``data:`` URIs, so that a report is one file with nothing to fetch;
the bytes are the same on every run (SVG ids from ``svg.hashsalt``, no dates)."""

import base64
import io

from ..plot.common import pyplot, style

DPI = 110  # PNG maps: sharp on screen, a few hundred kB at most
MEDIA = {"svg": "image/svg+xml", "png": "image/png"}
METADATA = {"svg": {"Date": None}, "png": {"Software": None}}


def data_uri(figure, format="svg"):
    """``figure`` (a matplotlib Figure, closed here) as a ``data:`` URI of ``format``,
    ``"svg"`` (line plots) or ``"png"`` (maps); drawn in rough's style, so that the
    bytes do not depend on the time or the run.

    >>> from rough import plot
    >>> with plot.style():
    ...     import matplotlib.pyplot as plt
    ...     figure, axes = plt.subplots()
    >>> data_uri(figure, "png")[:22]
    'data:image/png;base64,'
    """
    buffer = io.BytesIO()
    try:
        with style():
            figure.savefig(
                buffer, format=format, dpi=DPI, bbox_inches="tight", pad_inches=0.08, metadata=METADATA[format]
            )
    finally:
        pyplot().close(figure)
    return f"data:{MEDIA[format]};base64,{base64.b64encode(buffer.getvalue()).decode('ascii')}"
