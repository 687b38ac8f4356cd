"""The rose figure (``rough rose --plot``): C(θ) and D(θ) on polar axes."""

import numpy as np

from ..units import format_length
from .common import length_unit, pyplot, styled


def _errors(values):
    """Standard errors with None (a sector at a bound) drawn as zero."""
    return np.array([0.0 if value is None else value for value in values])


def _outer(values):
    """The radial axis' end: a little past the largest finite value (1 when there is none)."""
    finite = values[np.isfinite(values)]
    return float(finite.max()) * 1.05 if finite.size and finite.max() > 0 else 1.0


@styled
def rose_figure(rose, title="direction dependence"):
    """Polar roses of C(θ) and D(θ) with their standard errors, mirrored to 360°
    (a spectrum is symmetric, P(-f) = P(f)), the principal direction and the lay
    marked. θ is the wavevector direction, counter-clockwise from +x. ``title``:
    e.g. the file name."""
    plt = pyplot()
    figure, axes = plt.subplots(1, 2, subplot_kw={"projection": "polar"}, figsize=(10, 5.6))
    figure.get_layout_engine().set(h_pad=0.12)  # room between the title and the panels' titles
    theta = np.radians(np.concatenate([rose.angles, np.add(rose.angles, 180.0), [rose.angles[0] + 360.0]]))
    amplitude = np.array(rose.amplitude_coefficient, dtype=float)
    per_metre, unit = length_unit(np.nanmax(np.abs(amplitude)) if np.isfinite(amplitude).any() else 0.0)
    panels = (
        (
            axes[0],
            amplitude * per_metre,
            _errors(rose.amplitude_coefficient_stderr) * per_metre,
            f"C(θ) ({unit}) at η = {format_length(rose.resolution, 4)}",
            "tab:red",
        ),
        (axes[1], np.array(rose.fractal_dimension), _errors(rose.fractal_dimension_stderr), "Ds(θ)", "tab:blue"),
    )
    for axis, values, errors, label, colour in panels:
        closed = np.concatenate([values, values, values[:1]])
        spread = np.concatenate([errors, errors, errors[:1]])
        axis.plot(theta, closed, color=colour, lw=2)
        if axis is axes[0]:  # C is positive: its radius starts at 0, the error band clipped there
            axis.fill_between(theta, np.maximum(closed - spread, 0.0), closed + spread, color=colour, alpha=0.2)
            axis.set_ylim(0.0, _outer(closed + spread))
        else:
            axis.fill_between(theta, closed - spread, closed + spread, color=colour, alpha=0.2)
        if axis is axes[1] and np.ptp(values) > 0:
            axis.set_ylim(max(2.0, float(np.min(values)) - 0.05), min(3.0, float(np.max(values)) + 0.05))
        inner, outer = axis.get_ylim()
        lays = (rose.lay["long_wavelength"]["direction"], ":"), (rose.lay["resolution"]["direction"], "--")
        for angle, style_ in ((rose.principal_direction, "-"), *lays):
            for direction in (angle, angle + 180):
                axis.plot(np.radians([direction, direction]), [inner, outer], style_, color="0.3", lw=1)
        axis.set_title(label, pad=14)
    figure.suptitle(title)
    figure.supxlabel(
        f"principal wavevector {rose.principal_direction:.1f}° (solid); lay "
        f"{rose.lay['resolution']['direction']:.1f}° at η (dashed), "
        f"{rose.lay['long_wavelength']['direction']:.1f}° at long wavelengths (dotted); "
        f"Str {'undefined' if np.isnan(rose.Str) else format(rose.Str, '.3g')}, Std {rose.Std:.1f}° "
        "(plane removed)",
        fontsize=9,
        color="0.25",
    )
    return figure
