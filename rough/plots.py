"""Figures that the commands draw with ``--plot FILE`` (matplotlib, no display
needed). Each function returns a matplotlib Figure; :func:`save` writes one
atomically in the format of the file's extension (png, pdf, svg, ...)."""

import math
import os

import numpy as np

MM = 1e3
UM = 1e6


def _pyplot():
    from .extras import require

    matplotlib = require("matplotlib")
    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


def save(figure, path):
    """Write ``figure`` to ``path`` (atomically; ``-`` is standard output, in PNG) and close it."""
    import sys

    from .errors import InputError
    from .io.atomic import atomic_output

    extension = os.path.splitext(os.fspath(path))[1].lstrip(".").lower() or "png"
    try:
        if os.fspath(path) == "-" and sys.stdout is not None and sys.stdout.isatty():
            raise InputError("refusing to write a plot to a terminal: give a file name or a pipe", filename="-")
        with atomic_output(path) as stream:
            figure.savefig(stream, format=extension, dpi=150, bbox_inches="tight")
    finally:
        _pyplot().close(figure)


def features_figure(surface, features=(), density=None):
    """A profile with its detected features shaded, or a map in false colour; and the
    amplitude probability density of the heights with the Gaussian of the same Rq."""
    plt = _pyplot()
    figure, (top, bottom) = plt.subplots(2, 1, figsize=(8, 6.5), gridspec_kw={"height_ratios": [1.3, 1]})
    heights = surface.heights - np.nanmean(surface.heights)
    if surface.is_profile:
        top.plot(surface.positions(0) * MM, heights * UM, lw=0.7, color="0.2")
        for feature in features:
            top.axvspan(
                feature.start * MM,
                feature.end * MM,
                color="tab:red" if feature.kind == "peak" else "tab:blue",
                alpha=0.2,
            )
        top.set_xlabel("x (mm)")
        top.set_ylabel("height (µm)")
        top.set_title(f"{surface.metadata.get('title', 'profile')}: {len(features)} features shaded")
    else:
        x, y = surface.positions(0) * MM, surface.positions(1) * MM
        image = top.imshow(heights * UM, extent=(x[0], x[-1], y[-1], y[0]), cmap="viridis", aspect="equal")
        figure.colorbar(image, ax=top, label="height (µm)")
        top.set_xlabel("x (mm)")
        top.set_ylabel("y (mm)")
    if density is not None:
        centres, values = density
        width = centres[1] - centres[0] if len(centres) > 1 else 1.0
        bottom.bar(centres * UM, values / UM, width=width * UM, color="0.7", label="amplitude density")
        rq = np.sqrt(np.nanmean(heights**2))
        grid = np.linspace(centres[0], centres[-1], 400)
        gaussian = np.exp(-0.5 * (grid / rq) ** 2) / (rq * np.sqrt(2 * np.pi))
        bottom.plot(grid * UM, gaussian / UM, color="tab:orange", label=f"Gaussian, same Rq ({rq * UM:.4g} µm)")
        bottom.set_xlabel("height about the mean (µm)")
        bottom.set_ylabel("probability density (1/µm)")
        bottom.legend(fontsize="small")
    figure.tight_layout()
    return figure


def spectrum_figure(frequencies, density, fit, spacing, title="power spectrum"):
    """The binned spectrum on log-log axes, the fit band shaded and the fitted model
    (power law plus its noise floor) drawn over that band only (profiles: the Hann
    periodogram G in m³, one-sided; maps: the ring-averaged P2 in m⁴). Without a
    power-law range only the data are drawn."""
    plt = _pyplot()
    figure, axes = plt.subplots(figsize=(7, 5))
    axes.loglog(frequencies * 1e-3, density, "o", ms=3.5, color="0.35", label="binned periodogram")
    profile = fit.profile_dimension is None
    if fit.fit_band is not None:
        low, high = fit.fit_band
        grid = np.geomspace(low, high, 200)
        exponent = 5 - 2 * fit.fractal_dimension if profile else 8 - 2 * fit.fractal_dimension
        power = fit.psd_prefactor * grid**-exponent
        if fit.rolloff_wavelength:
            power = power * np.exp(-((grid * fit.rolloff_wavelength) ** 2))
        floor = (fit.noise_rms or 0.0) ** 2 * (2 * spacing[0] if profile else spacing[0] * spacing[1])
        key = "D" if profile else "Ds"
        label = (
            f"{key} = {fit.fractal_dimension:.4f} (bound)"
            if fit.at_bound
            else f"{key} = {fit.fractal_dimension:.4f} ± {fit.fractal_dimension_stderr:.4f}"
        )
        axes.loglog(grid * 1e-3, power + floor, color="tab:red", lw=2, label=f"model: {label}")
        if floor:
            axes.loglog(grid * 1e-3, power, ":", color="tab:red", lw=1, label="power law alone")
            axes.axhline(floor, xmin=0, xmax=1, color="tab:blue", lw=0.8, ls="--", label="noise floor")
        axes.axvspan(low * 1e-3, high * 1e-3, color="tab:red", alpha=0.06, label=f"fit band, p = {fit.p_value:.2g}")
        if fit.band and fit.band[1] < high:
            axes.axvline(fit.band[1] * 1e-3, color="tab:blue", lw=0.8, label="noise crossover")
    else:
        axes.set_title(f"{title}\nno power-law range", fontsize=10)
    axes.set_xlabel("spatial frequency (1/mm)")
    axes.set_ylabel("PSD G(f) (m³)" if profile else "ring-averaged P2 (m⁴)")
    if fit.fit_band is not None:
        axes.set_title(title)
    axes.legend(fontsize="small")
    figure.tight_layout()
    return figure


def _errors(values):
    """Standard errors with None (a sector at a bound) drawn as zero."""
    return np.array([0.0 if value is None else value for value in values])


def rose_figure(rose, title="direction dependence"):
    """Polar roses of C(θ) and D(θ) with their standard errors, mirrored to 360°
    (a spectrum is symmetric, P(-f) = P(f)), the principal direction and the lay
    marked. θ is the wavevector direction, counter-clockwise from +x."""
    plt = _pyplot()
    figure, axes = plt.subplots(1, 2, subplot_kw={"projection": "polar"}, figsize=(10, 5))
    theta = np.radians(np.concatenate([rose.angles, np.add(rose.angles, 180.0), [rose.angles[0] + 360.0]]))
    panels = (
        (
            axes[0],
            np.array(rose.amplitude_coefficient) * 1e9,
            _errors(rose.amplitude_coefficient_stderr) * 1e9,
            f"C(θ) (nm) at η = {rose.resolution * 1e6:.4g} µm",
            "tab:red",
        ),
        (axes[1], np.array(rose.fractal_dimension), _errors(rose.fractal_dimension_stderr), "Ds(θ)", "tab:blue"),
    )
    for axis, values, errors, label, colour in panels:
        closed = np.concatenate([values, values, values[:1]])
        spread = np.concatenate([errors, errors, errors[:1]])
        axis.plot(theta, closed, color=colour, lw=2)
        axis.fill_between(theta, closed - spread, closed + spread, color=colour, alpha=0.2)
        if axis is axes[1] and np.ptp(values) > 0:
            axis.set_ylim(max(2.0, float(np.min(values)) - 0.05), min(3.0, float(np.max(values)) + 0.05))
        inner, outer = axis.get_ylim()
        lays = (rose.lay["long_wavelength"]["direction"], ":"), (rose.lay["resolution"]["direction"], "--")
        for angle, style in ((rose.principal_direction, "-"), *lays):
            for direction in (angle, angle + 180):
                axis.plot(np.radians([direction, direction]), [inner, outer], style, color="0.3", lw=1)
        axis.set_title(label, pad=14)
    figure.suptitle(
        f"{title}\nprincipal wavevector {rose.principal_direction:.1f}° (solid); lay "
        f"{rose.lay['resolution']['direction']:.1f}° at η (dashed), "
        f"{rose.lay['long_wavelength']['direction']:.1f}° at long wavelengths (dotted); "
        f"Str {'undefined' if np.isnan(rose.Str) else format(rose.Str, '.3g')}, Std {rose.Std:.1f}°",
        fontsize=10,
    )
    figure.tight_layout()
    return figure


def force_figure(runs):
    """Force profiles of render runs ``[(label, Run), ...]``: for each, the surface
    height under the stylus and the hand's height (top), and F_y and F_x against the
    position along the profile (bottom), with the ticks out of contact shaded."""
    plt = _pyplot()
    figure, axes = plt.subplots(
        2, len(runs), figsize=(5.5 * len(runs), 6), sharex="col", squeeze=False, gridspec_kw={"height_ratios": [1, 1.4]}
    )
    for column, (label, result) in enumerate(runs):
        trace = result.trace
        x = trace["x"] * MM
        top, bottom = axes[0, column], axes[1, column]
        top.plot(x, trace["h"] * MM, color="0.3", lw=0.8, label="surface h")
        top.plot(x, trace["y_i"] * MM, color="tab:green", lw=0.8, label="hand y_i")
        bottom.plot(x, trace["F_y"], color="tab:blue", lw=0.7, label="F_y")
        bottom.plot(x, trace["F_x"], color="tab:orange", lw=0.7, label="F_x")
        for axis in (top, bottom):
            _shade(axis, x, ~trace["contact"])
        title = label if result.speed is None else f"{result.speed * 1e3:g} mm/s"
        top.set_title(
            f"{title}: F_y std {trace['F_y'].std():.3f} N, out of contact {100 * (1 - trace['contact'].mean()):.1f} %",
            fontsize=9,
        )
        top.set_ylabel("height (mm)")
        bottom.set_ylabel("force on the hand (N)")
        bottom.set_xlabel("x (mm)")
        top.legend(fontsize=7, loc="upper right")
        bottom.legend(fontsize=7, loc="upper right")
    figure.tight_layout()
    return figure


def _shade(axis, x, mask):
    """Grey spans where ``mask`` holds (ticks out of contact)."""
    edges = np.flatnonzero(np.diff(np.concatenate(([0], mask.astype(np.int8), [0]))))
    for start, stop in zip(edges[::2], edges[1::2]):
        axis.axvspan(x[start], x[min(stop, x.size - 1)], color="0.85", lw=0)


def percentage_figure(study, set_ids):
    """For each reference set, the percentage of answers that judged each test surface
    rougher than the reference, grouped by Rq and coloured by D (the paper's Figures
    4 and 5)."""
    from .experiment.analysis import percentages

    plt = _pyplot()
    figure, axes = plt.subplots(1, len(set_ids), figsize=(5.5 * len(set_ids), 4.2), squeeze=False)
    for axis, set_id in zip(axes[0], set_ids):
        cells = percentages(study, set_id)
        entry = next(s for s in study.sets if s["id"] == set_id)
        reference = study.surfaces[entry["reference"]]
        levels_rq = sorted({round(rq, 12) for _, _, rq, _, _ in cells} | {round(reference["rq"], 12)})
        levels_d = sorted({d for _, d, _, _, _ in cells} | {reference["dimension"]})
        width = 0.8 / len(levels_d)
        colours = plt.get_cmap("viridis")(np.linspace(0.15, 0.85, len(levels_d)))
        for k, dimension in enumerate(levels_d):
            label = f"D = {dimension:g}"
            for g, rq in enumerate(levels_rq):
                cell = next(
                    (c for c in cells if math.isclose(c[1], dimension) and math.isclose(c[2], rq, rel_tol=1e-6)), None
                )
                if cell is None:
                    continue
                x = g + (k - (len(levels_d) - 1) / 2) * width
                axis.bar(x, cell[3], width, color=colours[k], label=label)
                axis.text(x, cell[3] + 1, f"{cell[3]:.0f}", ha="center", fontsize=7)
                label = None
        axis.axhline(50, color="0.5", lw=0.8, ls="--")
        axis.set_xticks(range(len(levels_rq)), [f"Rq {rq * 1e3:.4g} mm" for rq in levels_rq])
        axis.set_ylim(0, 110)
        axis.set_ylabel("judged rougher than the reference (%)")
        axis.set_title(
            f"set {set_id}: reference D = {reference['dimension']:g}, Rq = {reference['rq'] * 1e3:.4g} mm", fontsize=9
        )
        handles, labels = axis.get_legend_handles_labels()
        unique = dict(zip(labels, handles))
        axis.legend(unique.values(), unique.keys(), fontsize=7, loc="upper left")
    figure.tight_layout()
    return figure
