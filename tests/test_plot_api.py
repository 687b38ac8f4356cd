"""rough.plot's one-call figures (surface, spectrum, rose, abbott) against what they
draw, and the amplitude density's robust range when outlier pits would squash it."""

import numpy as np
import pytest

import rough
from rough import metrology

pytest.importorskip("matplotlib")

from rough import plot  # noqa: E402 -- after the skip: plot needs matplotlib
from rough.plot.features import features_figure  # noqa: E402

PROFILE = rough.sample("rock-profile.tsv")
MAP = rough.sample("rock-map.x3p")


def texts(figure):
    """Every text in the figure: titles, labels, legends, annotations."""
    return [t.get_text() for t in figure.findobj(lambda artist: hasattr(artist, "get_text"))]


def close(figure):
    import matplotlib.pyplot as plt  # optional: plot

    plt.close(figure)


def test_the_one_call_figures_are_public_names():
    assert {"surface", "spectrum", "rose", "abbott"} <= set(dir(plot))


def test_surface_removes_the_form_it_is_asked_to_and_says_so():
    y, x = np.mgrid[0:64, 0:80] * 1e-6
    bump = 1e-7 * np.exp(-((x - 40e-6) ** 2 + (y - 30e-6) ** 2) / (10e-6) ** 2)
    tilted = rough.Surface(0.5 * x + 0.2 * y + bump, 1e-6)
    figure = plot.surface(tilted, title="tilted plane", order=1)
    levelled = plot.surface_figure(metrology.detrend(tilted, order=1), title="tilted plane")
    assert np.array_equal(figure.axes[0].images[0].get_array(), levelled.axes[0].images[0].get_array())
    assert "least-squares plane removed" in " ".join(texts(figure))
    as_given = plot.surface(tilted)
    assert "removed" not in " ".join(texts(as_given))
    for each in (figure, levelled, as_given):
        close(each)


def test_spectrum_draws_the_fitted_power_law_over_the_fit_band():
    profile = rough.read(PROFILE)
    fit = rough.fit_fractal(profile)
    figure = plot.spectrum(fit, profile)
    axes = figure.axes[0]
    lines = {line.get_label(): line for line in axes.get_lines()}
    model = next(line for label, line in lines.items() if label.startswith("model"))
    law = lines.get("power law alone", model)  # without a noise floor, the model is the power law
    frequencies, power = (np.asarray(a) for a in law.get_data())
    # whatever the axes' units: the band's ends, and the slope -(5 - 2D) on log-log axes
    assert frequencies[-1] / frequencies[0] == pytest.approx(fit.fit_band[1] / fit.fit_band[0], rel=1e-12)
    slope = np.polyfit(np.log(frequencies), np.log(power), 1)[0]
    assert slope == pytest.approx(-(5 - 2 * fit.fractal_dimension), rel=1e-9)
    assert np.asarray(model.get_xdata())[0] == frequencies[0]
    assert (axes.get_xscale(), axes.get_yscale()) == ("log", "log")
    close(figure)


def test_spectrum_without_a_power_law_range_draws_roughness_against_scale():
    fit = rough.fit_fractal(rough.read(PROFILE))
    fit.scale_dependent = {
        "scale": [1e-4, 1e-3],
        "rms_height": [1e-6, 1e-5],
        "rms_slope": [0.1, 0.05],
        "rms_curvature": [1e3, 1e2],
        "direction": "profile",
    }
    figure = plot.spectrum(fit, rough.read(PROFILE), title="made up")
    assert [axes.get_ylabel() for axes in figure.axes] == ["RMS height (µm)", "RMS slope", "RMS curvature (1/mm)"]
    assert "made up: no power-law band" in texts(figure)
    close(figure)


def test_rose_draws_both_roses_on_polar_axes():
    scan = rough.fractal.fill_invalid(rough.read(MAP))
    result = rough.rose(scan, step=30)
    figure = plot.rose(result, title="rock-map")
    assert [axes.name for axes in figure.axes] == ["polar", "polar"]
    drawn = figure.axes[1].get_lines()[0].get_ydata()
    assert drawn[: len(result.angles)] == pytest.approx(result.fractal_dimension)
    assert "rock-map" in texts(figure)
    close(figure)


def test_abbott_of_a_ramp_is_all_core():
    # heights evenly from -1 to +1 µm: Rk = 2 µm, Rpk = Rvk = 0 (ISO 13565-2)
    ramp = rough.Surface(np.linspace(-1e-6, 1e-6, 1001), 1e-6)
    figure = plot.abbott(ramp)
    axes = figure.axes[0]
    assert "Rk = 2 µm" in texts(figure)
    straight = next(line for line in axes.get_lines() if line.get_label() == "equivalent straight line")
    assert np.asarray(straight.get_ydata()) == pytest.approx([1.0, -1.0])
    assert axes.get_xlabel() == "material ratio (%)"
    close(figure)


def test_abbott_leaves_out_invalid_points_and_counts_them():
    scan = rough.read(MAP)
    figure = plot.abbott(scan)
    invalid = int(np.count_nonzero(~scan.valid))
    assert f"{scan.heights.size - invalid} of {scan.heights.size} points valid" in texts(figure)
    core = metrology.MaterialRatioCurve(scan).core()
    scale, unit = plot.length_unit(float(np.nanmax(scan.heights) - np.nanmin(scan.heights)))
    assert f"Sk = {core.height * scale:.4g} {unit}" in texts(figure)
    close(figure)


# -- the amplitude density's range --------------------------------------------------------------


def gaussian_profile(points=20000, seed=3):
    return np.random.default_rng(seed).standard_normal(points) * 1e-6


def density_axes(figure):
    return next(axes for axes in figure.axes if axes.get_xlabel().startswith("height about the mean ("))


def test_outlier_pits_do_not_squash_the_density():
    heights = gaussian_profile()
    heights[[100, 5000, 9000]] = -200e-6  # three pits 200 σ deep
    surface = rough.Surface(heights, 1e-6)
    figure = features_figure(surface, density=metrology.amplitude_density(surface))
    axes = density_axes(figure)
    low, high = axes.get_xlim()
    assert -12 < low < -3 and 3 < high < 12  # µm: the Gaussian fills the panel, the pits are off it
    assert axes.get_xlabel() == "height about the mean (µm)"
    labels = {text for text in texts(figure) if text.startswith("amplitude density")}
    assert labels == {"amplitude density (3 points below the range shown)"}
    bars = axes.patches
    widths = bars[0].get_width()
    shown = sum(bar.get_height() for bar in bars) * widths  # the fraction of the points drawn
    assert shown == pytest.approx(1 - 3 / heights.size, rel=1e-9)
    close(figure)


def test_a_gaussian_is_drawn_whole():
    surface = rough.Surface(gaussian_profile(), 1e-6)
    centres, values = metrology.amplitude_density(surface)
    figure = features_figure(surface, density=(centres, values))
    axes = density_axes(figure)
    assert [bar.get_height() for bar in axes.patches] == pytest.approx(values * 1e-6)
    assert "amplitude density" in texts(figure)
    close(figure)


def test_the_density_range_of_nan_and_tails():
    heights = np.concatenate([gaussian_profile(5000), [np.nan] * 10, [50e-6, 60e-6], [-70e-6]])
    centres, values, outside = plot.shown_density(heights, (np.linspace(-1, 1, 40), np.ones(40)))
    assert outside == (1, 2)
    assert centres.size == 40 and np.all(np.isfinite(values))
