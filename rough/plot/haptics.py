"""The force figure of render runs (``rough render --plot``)."""

import numpy as np

from ..render import along_and_across
from .common import length_unit, pyplot, runs_of, styled


@styled
def force_figure(runs, title=None):
    """Force profiles of render runs ``[(label, Run), ...]``, one column per run.

    For a profile: the surface height under the stylus and the hand's height (top),
    and F_y and F_x against the position along the profile (bottom), with the ticks
    out of contact shaded; the legends stand right of the last column, clear of the
    traces. For a map: the path of the point over the map's x–y plane, coloured by
    the height under it (top), by the force along the motion (middle) and by the
    force across it (bottom), so that a long dense trace reads as a field rather than
    as overdrawn lines. Lengths are in a unit chosen from their extent; ticks with no
    surface (NaN heights) are left out of the colours. ``title``: e.g. the file name
    (default none).

    Examples
    --------
    >>> from rough.render import Track, simulate
    >>> from rough.plot import force_figure
    >>> import numpy as np
    >>> run = simulate(Track(np.zeros(101), 0.1e-3), speed=0.02)  # 10 mm at 20 mm/s
    >>> figure = force_figure([("20 mm/s", run)])
    >>> [axis.get_xlabel() for axis in figure.axes]
    ['', 'x (mm)']
    """
    plt = pyplot()
    on_map = "y_i" not in runs[0][1].trace.dtype.names
    rows, ratios = (3, [1, 1, 1]) if on_map else (2, [1, 1.4])
    figure, axes = plt.subplots(
        rows,
        len(runs),
        figsize=(5.5 * len(runs) + (0 if on_map else 1.4), 2.6 * rows if on_map else 6),
        sharex="col",
        squeeze=False,
        gridspec_kw={"height_ratios": ratios},
    )
    for column, (label, result) in enumerate(runs):
        heading = label if result.speed is None else f"{result.speed * 1e3:g} mm/s"
        if on_map:
            _map_column(figure, axes[:, column], result.trace, heading)
        else:
            _profile_column(axes[:, column], result.trace, heading)
    if not on_map:
        for axis in axes[:, -1]:
            axis.legend(loc="upper left", bbox_to_anchor=(1.02, 1), borderaxespad=0)
    if title:
        figure.suptitle(title)
    return figure


def _profile_column(axes, trace, heading):
    """Heights (top) and forces (bottom) against x, ticks out of contact shaded."""
    top, bottom = axes
    scale, unit = length_unit(np.nanmax(np.abs(trace["x"]), initial=0))
    height_scale, height_unit = length_unit(_extent(trace["h"], trace["y_i"]))
    x = trace["x"] * scale
    top.plot(x, trace["h"] * height_scale, color="0.3", lw=0.8, label="surface h")
    top.plot(x, trace["y_i"] * height_scale, color="tab:green", lw=0.8, label="hand y_i")
    bottom.plot(x, trace["F_y"], color="tab:blue", lw=0.7, label="F_y")
    bottom.plot(x, trace["F_x"], color="tab:orange", lw=0.7, label="F_x")
    out = 100 * (1 - trace["contact"].mean())
    top.set_title(f"{heading}: F_y std {trace['F_y'].std():.3f} N, out of contact {out:.1f} %", fontsize=9)
    bottom.set_xlabel(f"x ({unit})")
    top.set_ylabel(f"height ({height_unit})")
    bottom.set_ylabel("force on the hand (N)")
    for axis in axes:
        _shade(axis, x, ~trace["contact"])


def _map_column(figure, axes, trace, heading):
    """The path over the map, coloured by the height under it and by the force along
    and across the motion (diverging colours, symmetric about zero)."""
    along, across = along_and_across(trace)
    scale, unit = length_unit(max(_extent(trace["x"]), _extent(trace["y"])))
    height_scale, height_unit = length_unit(_extent(trace["h"]))
    x, y = trace["x"] * scale, trace["y"] * scale
    out = 100 * (1 - trace["contact"].mean())
    layers = (
        (trace["h"] * height_scale, f"height under the point ({height_unit})", "viridis", False),
        (along, "force along the motion (N)", "coolwarm", True),
        (across, "force across the motion (N)", "coolwarm", True),
    )
    for axis, (values, label, colours, signed) in zip(axes, layers):
        shown = np.isfinite(values)
        limit = np.max(np.abs(values[shown]), initial=0) or 1.0
        points = axis.scatter(
            x[shown],
            y[shown],
            c=values[shown],
            s=10,
            cmap=colours,
            vmin=-limit if signed else None,
            vmax=limit if signed else None,
            linewidths=0,
            rasterized=True,
        )
        figure.colorbar(points, ax=axis, label=label, shrink=0.9)
        axis.set_aspect("equal", adjustable="datalim")
        axis.set_ylabel(f"y ({unit})")
    axes[0].set_title(f"{heading}: map, off the map {out:.1f} %", fontsize=9)
    axes[-1].set_xlabel(f"x ({unit})")


def _extent(*values):
    """The largest magnitude among ``values``' finite entries (0 for none)."""
    finite = np.concatenate([np.ravel(v)[np.isfinite(np.ravel(v))] for v in values])
    return float(np.max(np.abs(finite), initial=0))


def _shade(axis, x, mask):
    """Grey spans where ``mask`` holds (ticks out of contact)."""
    for start, stop in runs_of(mask):
        axis.axvspan(x[start], x[min(stop, x.size - 1)], color="0.85", lw=0)
