"""Roughness against scale and the tip's reliability cut-off (issue 32, items 3 and 4):
analytic cases, exact fBm, SurfaceTopography's reference values, a dilated scan."""

import logging
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

import rough
from rough import InputError, Surface
from rough.fractal.fit import fit_fractal
from rough.fractal.scales import reliability_cutoff, scale_dependent, scale_dependent_roughness
from rough.fractal.synth_map import synthesize_map
from rough.metrology.tip import traced

from fbm import fbm


def sine_cutoff(amplitude, wavelength, radius):
    """The cut-off of a sinusoid: the central second difference at step λ has minimum
    -a (2 - 2 cos kλ) / λ², which reaches -1/(2R) where 2(1 - cos u)/u² = 1/(2R a k²)."""
    k = 2 * math.pi / wavelength
    ratio = 0.5 / (radius * amplitude * k**2)
    u = brentq(lambda u: 2 * (1 - math.cos(u)) / u**2 - ratio, 1e-6, 2 * math.pi)
    return 2 * u / k


@pytest.mark.parametrize("radius", [1.5e-3, 2e-3, 5e-3])
def test_the_cutoff_of_a_sinusoid_is_where_its_curvature_meets_the_tip(radius):
    """a = 0.1 µm, λ = 100 µm: the peak curvature a(2π/λ)² = 395 /m beats 1/(2R)
    for R above 1.27 mm."""
    spacing, amplitude, wavelength = 0.1e-6, 0.1e-6, 100e-6
    x = np.arange(20000) * spacing
    cutoff = reliability_cutoff(amplitude * np.sin(2 * math.pi * x / wavelength), spacing, radius)
    assert cutoff == pytest.approx(sine_cutoff(amplitude, wavelength, radius), rel=2e-3)


def test_a_tip_that_follows_every_scale_has_no_cutoff():
    """The peak curvature at 0.8 of 1/(2R): no cut-off; at 1.05 of it, one."""
    spacing, amplitude, wavelength = 0.1e-6, 0.1e-6, 100e-6
    x = np.arange(20000) * spacing
    heights = amplitude * np.sin(2 * math.pi * x / wavelength)
    critical = 0.5 / (amplitude * (2 * math.pi / wavelength) ** 2)
    assert reliability_cutoff(heights, spacing, 0.8 * critical) is None
    assert reliability_cutoff(heights, spacing, 1.05 * critical) is not None


@pytest.mark.parametrize(
    "name, radius, scale, expected, tolerance",
    [
        ("dektak-1.csv", 2.5e-6, 1.0, 1.57e-6, 0.02),  # theirs on the non-uniform scan
        ("di-1.di", 40e-9, 1.0, 90.700854e-9, 0.005),
        ("xy-4.txt", 40e-9, 1e-6, 0.126519e-6, 0.001),  # they read it in µm
    ],
)
def test_the_cutoff_matches_surfacetopography(shared_data, name, radius, scale, expected, tolerance):
    surface = rough.read(shared_data / "SurfaceTopography" / name)
    heights = surface.heights if surface.is_profile else surface.heights
    cutoff = reliability_cutoff(heights * scale, surface.spacing[0] * scale, radius)
    assert cutoff == pytest.approx(expected, rel=tolerance)


def test_the_cutoff_lands_where_the_tip_starts_to_change_the_scan():
    """fBm traced by a round tip: below the cut-off the traced scan's RMS curvature
    falls short of the surface's by more than 20 %, above twice it they agree within
    20 % (the tip shapes the summits only)."""
    rng = np.random.default_rng(3)
    spacing, radius = 0.5e-6, 20e-6
    surface = Surface(fbm(8192, 0.7, rng, spacing, 1e-3), (spacing,))
    scan = traced(surface, radius)
    cutoff = reliability_cutoff(scan.heights, spacing, radius)
    original = scale_dependent(surface.heights, spacing)
    measured = scale_dependent(scan.heights, spacing)
    scale = np.array(original["scale"])
    ratio = np.array(measured["rms_curvature"]) / np.array(original["rms_curvature"])
    assert cutoff is not None and 4 * spacing < cutoff
    assert np.all(ratio[2 * scale < 0.5 * cutoff] < 0.8)
    assert np.all(np.abs(ratio[2 * scale > 2 * cutoff] - 1) < 0.2)


def test_scale_dependent_slope_and_curvature_of_exact_fbm():
    """E[(B(x+λ) - B(x))²] = σ² λ^2H and the second difference's is σ² λ^2H (4 - 2^2H):
    the ensemble RMS slope and curvature are those within 3 %, and the RMS height of
    the detrended windows grows as λ^H (log-log slope within 0.05)."""
    rng = np.random.default_rng(4)
    hurst, spacing, sigma = 0.6, 1e-6, 1e-6
    tables = [scale_dependent([fbm(2048, hurst, rng, spacing, sigma) for _ in range(4)], spacing) for _ in range(20)]
    scale = np.array(tables[0]["scale"])
    slope = np.sqrt(np.mean([np.square(t["rms_slope"]) for t in tables], axis=0))
    curvature = np.sqrt(np.mean([np.square(t["rms_curvature"]) for t in tables], axis=0))
    small = scale < 100 * spacing
    np.testing.assert_allclose(slope[small], sigma * scale[small] ** (hurst - 1), rtol=0.03)
    expected = sigma * scale ** (hurst - 2) * math.sqrt(4 - 2 ** (2 * hurst))
    np.testing.assert_allclose(curvature[small], expected[small], rtol=0.03)
    height = np.mean([t["rms_height"] for t in tables], axis=0)
    assert np.polyfit(np.log(scale[small]), np.log(height[small]), 1)[0] == pytest.approx(hurst, abs=0.05)


def test_scale_dependent_sinusoid_slope_and_curvature():
    """a sin(kx) over whole periods: RMS slope √2 a |sin(kλ/2)| / λ, RMS curvature
    a (2 - 2 cos kλ) / (√2 λ²), to the end effects of n - λ points."""
    spacing, amplitude, wavelength = 1e-6, 2e-6, 64e-6
    x = np.arange(64 * 200) * spacing
    table = scale_dependent(amplitude * np.sin(2 * math.pi * x / wavelength), spacing, (spacing, 16 * spacing))
    k, scale = 2 * math.pi / wavelength, np.array(table["scale"])
    np.testing.assert_allclose(
        table["rms_slope"], math.sqrt(2) * amplitude * np.abs(np.sin(k * scale / 2)) / scale, rtol=0.01
    )
    expected = amplitude * (2 - 2 * np.cos(k * scale)) / (math.sqrt(2) * scale**2)
    np.testing.assert_allclose(table["rms_curvature"], expected, rtol=0.01)


@settings(max_examples=60, deadline=None)
@given(
    values=st.lists(st.integers(-1000, 1000), min_size=8, max_size=300),
    tilt=st.integers(-50, 50),
    power=st.integers(-3, 3),
)
def test_a_line_leaves_height_and_curvature_and_a_factor_scales_everything(values, tilt, power):
    """Quantised heights (ties, repeats): adding a line changes neither the RMS height of
    the detrended windows nor the curvature; a power of two multiplies all three."""
    heights = np.array(values, float)
    line = tilt * np.arange(heights.size)
    base = scale_dependent(heights, 1.0)
    tilted = scale_dependent(heights + line, 1.0)
    scaled = scale_dependent(heights * 2.0**power, 1.0)
    magnitude = 1e-9 * (np.abs(heights).max() + abs(tilt) * heights.size + 1)
    np.testing.assert_allclose(tilted["rms_height"], base["rms_height"], rtol=1e-9, atol=magnitude)
    assert tilted["rms_curvature"] == base["rms_curvature"]
    for key in ("rms_height", "rms_slope", "rms_curvature"):
        assert scaled[key] == [value * 2.0**power for value in base[key]]
        assert all(math.isfinite(value) and value >= 0 for value in base[key])


def test_a_map_gives_its_rows_or_its_columns():
    rng = np.random.default_rng(5)
    rows = np.cumsum(rng.standard_normal((64, 256)), axis=1) * 1e-9
    surface = Surface(rows, (1e-6, 2e-6))
    along_x = scale_dependent_roughness(surface, "x")
    along_y = scale_dependent_roughness(Surface(rows.T.copy(), (2e-6, 1e-6)), "y")
    assert along_x["direction"] == "x" and along_y["direction"] == "y"
    assert along_x["scale"] == along_y["scale"]
    np.testing.assert_allclose(along_x["rms_slope"], along_y["rms_slope"], rtol=1e-12)
    assert scale_dependent_roughness(Surface(rows[0], (1e-6,)))["direction"] == "profile"


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: scale_dependent(np.array([1.0, np.nan, 2, 3, 4, 5]), 1.0), "finite"),
        (lambda: scale_dependent(np.ones(4), 1.0), "at least 5"),
        (lambda: scale_dependent(np.ones(50), 0.0), "positive"),
        (lambda: scale_dependent(np.ones(50), 1.0, (100.0, 200.0)), "no scale"),
        (lambda: reliability_cutoff(np.ones(50), 1.0, -1.0), "positive"),
        (lambda: scale_dependent_roughness(Surface(np.ones((8, 8)), (1.0, 1.0)), "z"), "x or y"),
        (lambda: fit_fractal(Surface(np.arange(64.0) ** 1.5, (1.0,)), method="variogram", tip_radius=1.0), "lags"),
        (lambda: fit_fractal(Surface(np.arange(64.0) ** 1.5, (1.0,)), tip_radius=0.0), "positive"),
    ],
)
def test_bad_input_is_refused_in_one_line(call, message):
    with pytest.raises(InputError, match=message):
        call()


def test_fit_fractal_leaves_out_what_the_tip_cannot_follow(caplog):
    """A profile traced by a tip: with tip_radius the band stops at 1/λc, the fit
    says so in one warning, and D is nearer the surface's than without."""
    rng = np.random.default_rng(6)
    spacing, radius = 0.5e-6, 20e-6
    surface = Surface(fbm(8192, 0.7, rng, spacing, 1e-3), (spacing,))
    scan = traced(surface, radius)
    with caplog.at_level(logging.WARNING, logger="rough"):
        fit = fit_fractal(scan, tip_radius=radius, sampling="point")
    assert fit.reliability_cutoff == pytest.approx(reliability_cutoff(scan.heights, spacing, radius))
    assert fit.fit_band[1] <= 1 / fit.reliability_cutoff * (1 + 1e-9)
    assert sum("cannot follow" in record.message for record in caplog.records) == 1
    blind = fit_fractal(scan, sampling="point", band=(None, 0.5 / spacing))
    assert abs(fit.hurst - 0.7) < abs(blind.hurst - 0.7)
    assert fit_fractal(surface).reliability_cutoff is None


def test_fit_fractal_on_a_map_with_a_tip():
    surface = synthesize_map((512, 512), (1e-6, 1e-6), 2.3, rq=1e-6, seed=7)
    radius = 10e-6
    fit = fit_fractal(traced(surface, radius), tip_radius=radius)
    assert fit.reliability_cutoff is not None and fit.verdict == "power law"
    assert fit.fit_band[1] <= 1 / fit.reliability_cutoff * (1 + 1e-9)


def test_a_tip_that_never_follows_is_refused():
    rng = np.random.default_rng(8)
    with pytest.raises(InputError, match="too few scales"):
        fit_fractal(Surface(rng.standard_normal(512) * 1e-3, (1e-6,)), tip_radius=1e-6)
