"""The force figure of render runs (``rough render --plot``)."""

from ..render import along_and_across
from .common import pyplot, runs_of, styled

MM = 1e3


@styled
def force_figure(runs, title=None):
    """Force profiles of render runs ``[(label, Run), ...]``: for each, the surface
    height under the stylus and the hand's height (top), and F_y and F_x against the
    position along the profile (bottom), with the ticks out of contact shaded. For a
    map, the height under the point and the force along and across the motion
    against time. ``title``: e.g. the file name (default none)."""
    plt = pyplot()
    figure, axes = plt.subplots(
        2, len(runs), figsize=(5.5 * len(runs), 6), sharex="col", squeeze=False, gridspec_kw={"height_ratios": [1, 1.4]}
    )
    for column, (label, result) in enumerate(runs):
        trace = result.trace
        top, bottom = axes[0, column], axes[1, column]
        heading = label if result.speed is None else f"{result.speed * 1e3:g} mm/s"
        out = 100 * (1 - trace["contact"].mean())
        if "y_i" in trace.dtype.names:
            x = trace["x"] * MM
            top.plot(x, trace["h"] * MM, color="0.3", lw=0.8, label="surface h")
            top.plot(x, trace["y_i"] * MM, color="tab:green", lw=0.8, label="hand y_i")
            bottom.plot(x, trace["F_y"], color="tab:blue", lw=0.7, label="F_y")
            bottom.plot(x, trace["F_x"], color="tab:orange", lw=0.7, label="F_x")
            top.set_title(f"{heading}: F_y std {trace['F_y'].std():.3f} N, out of contact {out:.1f} %", fontsize=9)
            bottom.set_xlabel("x (mm)")
        else:
            x = trace["t"]
            along, across = along_and_across(trace)
            top.plot(x, trace["h"] * MM, color="0.3", lw=0.8, label="surface h under the point")
            bottom.plot(x, along, color="tab:orange", lw=0.7, label="F along the motion")
            bottom.plot(x, across, color="tab:blue", lw=0.7, label="F across the motion")
            top.set_title(f"{heading}: map, off the map {out:.1f} %", fontsize=9)
            bottom.set_xlabel("t (s)")
        for axis in (top, bottom):
            _shade(axis, x, ~trace["contact"])
        top.set_ylabel("height (mm)")
        bottom.set_ylabel("force on the hand (N)")
        top.legend(fontsize=7, loc="upper right")
        bottom.legend(fontsize=7, loc="upper right")
    if title:
        figure.suptitle(title)
    return figure


def _shade(axis, x, mask):
    """Grey spans where ``mask`` holds (ticks out of contact)."""
    for start, stop in runs_of(mask):
        axis.axvspan(x[start], x[min(stop, x.size - 1)], color="0.85", lw=0)
