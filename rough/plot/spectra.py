"""Figures of a fractal fit (``rough fit-fractal --plot``): the binned spectrum with
the fitted model over its band, or, without a power-law range, the roughness against
scale.
"""

import numpy as np

from ..units import scale_for
from .common import length_unit, pyplot, styled


@styled
def spectrum_figure(frequencies, density, fit, spacing, title="power spectrum"):
    """The binned spectrum on log-log axes, the fit band shaded and the fitted model
    (power law plus its noise floor) drawn over that band only (profiles: the Hann
    periodogram G in m³, one-sided; maps: the ring-averaged P2 in m⁴). Without a
    power-law range only the data are drawn. ``title``: e.g. the file name."""
    plt = pyplot()
    frequencies, density = np.asarray(frequencies, dtype=float), np.asarray(density, dtype=float)
    figure, axes = plt.subplots(figsize=(7, 5))
    profile = fit.profile_dimension is None
    (per_frequency, frequency_unit), (per_density, density_unit) = _axis_units(frequencies, density, profile)
    axes.loglog(
        frequencies * per_frequency, density * per_density, "o", ms=3.5, color="0.35", label="binned periodogram"
    )
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
        axes.loglog(grid * per_frequency, (power + floor) * per_density, color="tab:red", lw=2, label=f"model: {label}")
        if floor:
            axes.loglog(grid * per_frequency, power * per_density, ":", color="tab:red", lw=1, label="power law alone")
            axes.axhline(floor * per_density, xmin=0, xmax=1, color="tab:blue", lw=0.8, ls="--", label="noise floor")
        axes.axvspan(
            low * per_frequency,
            high * per_frequency,
            color="tab:red",
            alpha=0.06,
            label=f"fit band, p = {fit.p_value:.2g}",
        )
        if fit.band and fit.band[1] < high:
            axes.axvline(fit.band[1] * per_frequency, color="tab:blue", lw=0.8, label="noise crossover")
        axes.set_title("power spectrum", fontsize=9, color="0.25")
    else:
        axes.set_title("power spectrum: no power-law range", fontsize=9, color="0.25")
    axes.set_xlabel(f"spatial frequency ({frequency_unit})")
    axes.set_ylabel(f"PSD G(f) ({density_unit})" if profile else f"ring-averaged P2 ({density_unit})")
    axes.legend()
    figure.suptitle(title)
    return figure


def _axis_units(frequencies, density, profile):
    """``((factor, label), (factor, label))`` for the frequency axis (per the length
    that fits its highest frequency: ``/mm``) and the PSD axis: height² per frequency,
    G in ``µm²·mm`` (P2 in ``µm²·mm²``), the height unit fitting the largest value."""
    finite = np.isfinite(frequencies) & np.isfinite(density) & (frequencies > 0) & (density > 0)
    top = float(frequencies[finite].max()) if finite.any() else 0.0
    per_frequency, frequency_unit = scale_for(top, "1/m")
    length = frequency_unit.lstrip("/") if top else "m"  # the length whose inverse the frequency is in
    per_length = 1.0 / per_frequency if top else 1.0  # lengths in it per metre
    power = 1 if profile else 2
    largest = float(density[finite].max()) * per_length**power if finite.any() else 0.0
    per_height, height_unit = length_unit(np.sqrt(largest))
    superscript = "" if profile else "²"
    return (per_frequency, frequency_unit), (per_height**2 * per_length**power, f"{height_unit}²·{length}{superscript}")


@styled
def scale_dependent_figure(table, title="roughness against scale", cutoff=None):
    """RMS height, slope and curvature against scale on log-log axes, three panels
    side by side (``table`` as :func:`rough.fractal.scales.scale_dependent` gives it;
    scales and heights in the unit that reads naturally, curvature in 1/that unit).
    A reliability cut-off (m) is drawn where the tip stops following the surface.
    ``title``: e.g. the file name.

    Examples
    --------
    >>> import numpy as np
    >>> from rough.fractal.scales import scale_dependent
    >>> from rough.plot import scale_dependent_figure
    >>> heights = np.cumsum(np.random.default_rng(0).standard_normal(1024)) * 1e-8
    >>> figure = scale_dependent_figure(scale_dependent(heights, 1e-6), "random walk")
    >>> [axes.get_ylabel() for axes in figure.axes]
    ['RMS height (nm)', 'RMS slope', 'RMS curvature (1/µm)']
    >>> import matplotlib.pyplot as plt
    >>> plt.close(figure)
    """
    plt = pyplot()
    scale = np.asarray(table["scale"], float)
    per_scale, scale_symbol = length_unit(float(np.max(scale)) if scale.size else 0.0)
    heights = np.asarray(table["rms_height"], float)
    per_height, height_symbol = length_unit(float(np.max(heights)) if heights.size else 0.0)
    figure, axes = plt.subplots(1, 3, figsize=(12, 4.2))
    direction = table.get("direction")
    panels = (
        (heights * per_height, f"RMS height ({height_symbol})", "tab:red"),
        (np.asarray(table["rms_slope"], float), "RMS slope", "tab:green"),
        (np.asarray(table["rms_curvature"], float) / per_scale, f"RMS curvature (1/{scale_symbol})", "tab:blue"),
    )
    for axis, (values, label, colour) in zip(axes, panels):
        shown = values > 0
        axis.loglog(scale[shown] * per_scale, values[shown], "o-", ms=3.5, lw=1.2, color=colour)
        if cutoff:
            axis.axvline(cutoff / 2 * per_scale, color="0.3", lw=0.8, ls="--", label="tip reliability cut-off")
            axis.legend(fontsize=7)
        axis.set_xlabel(f"scale λ ({scale_symbol})")
        axis.set_ylabel(label)
    along = {"x": " (profiles along x)", "y": " (profiles along y)"}.get(direction, "")
    figure.suptitle(f"{title}{along}")
    return figure
