"""The automatic band chosen by effect size, the χ² test kept as a diagnostic, the
scale-dependent roughness where no band qualifies, and hints that never loop
(issue 32, items 3 and 5)."""

import logging
import math
import re

import numpy as np
import pytest

import rough
from rough import Surface
from rough.fractal.filling import fill_invalid
from rough.fractal.fit import fit_fractal
from rough.fractal.scaling import TOLERANCE, departure, fit_spectrum, profile_bins
from rough.units import parse_frequency

from conftest import shared_data_path
from fbm import fbm

HINTED_BAND = re.compile(r"--band ([^\s:)]+):([^\s:)]+)")  # as --band takes it: 33.47/km:226.5/km


def drifting(n, drift, rng):
    """A band-limited profile whose exponent drifts: β(f) = 2 + drift · log10(f / 0.01)."""
    f = np.fft.rfftfreq(n)
    f[0] = 1.0
    amplitude = f ** (-(2.0 + drift * np.log10(f / 0.01)) / 2)
    amplitude[0] = 0.0
    noise = rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size)
    return Surface(np.fft.irfft(amplitude * noise, n) * 1e-6, (1e-6,))


def bent(n, rng):
    """β = 3 below f = 0.02 (per sample), β = 1.4 above."""
    f = np.fft.rfftfreq(n)
    amplitude = np.where(f < 0.02, f.clip(1e-9) ** -1.5, 0.02**-0.8 * 0.02**-0.7 * f.clip(1e-9) ** -0.7)
    amplitude[0] = 0
    heights = np.fft.irfft(amplitude * (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size)), n)
    return Surface(heights * 1e-6, (1.0,))


def test_a_slightly_curved_spectrum_gets_a_band_the_test_would_reject():
    """β drifts by 0.12 per decade over 4.5 decades (2^15 points): χ² rejects an exact
    power law over the whole band (p < 1e-10), but the local exponent stays within
    0.1 in H over more than 3.5 decades, and D is that of the band's middle."""
    rng = np.random.default_rng(0)
    surface = drifting(2**15, 0.12, rng)
    assert fit_fractal(surface, band=(0, 1e9)).p_value < 1e-10
    fit = fit_fractal(surface)
    assert fit.verdict == "power law" and fit.band_rule != "given"
    assert math.log10(fit.fit_band[1] / fit.fit_band[0]) > 3.5
    middle = math.sqrt(fit.fit_band[0] * fit.fit_band[1]) / 1e6  # per sample
    beta = 2.0 + 0.12 * math.log10(middle / 0.01)
    assert fit.fractal_dimension == pytest.approx((5 - beta) / 2, abs=0.05)
    assert fit.p_value < 0.01  # kept, as a diagnostic


def test_a_strong_drift_is_cut_to_a_shorter_band():
    """β drifts by 0.5 per decade: where the ordinates are many (the high frequencies)
    the local exponents show it, so the band is cut short of the 3.5 decades the
    slight drift keeps; at the lowest decade the few ordinates cannot show it (the
    allowance of three standard errors), so the band reaches down there."""
    rng = np.random.default_rng(1)
    fit = fit_fractal(drifting(2**15, 0.5, rng))
    if fit.verdict == "power law":
        assert math.log10(fit.fit_band[1] / fit.fit_band[0]) < 3.3
        assert fit.fit_band[1] < 0.1e6  # per metre at 1 µm: the top decade and a half is left out


def test_the_departure_of_an_exact_power_law_is_small():
    """Exact fBm over its whole band: the departure stays below 1 in at least 98 of 100
    realisations (the rule's false rejections), for H = 0.2, 0.5 and 0.8."""
    rng = np.random.default_rng(2)
    for hurst in (0.2, 0.5, 0.8):
        values = []
        for _ in range(100):
            heights = fbm(1024, hurst, rng)
            heights = heights - np.polyval(np.polyfit(np.arange(1024), heights, 1), np.arange(1024))
            differences = np.diff(heights)
            m = differences.size
            k = np.arange(1, (m - 1) // 2 + 1)
            ordinates = np.abs(np.fft.rfft(differences)[k]) ** 2 / m
            bins = profile_bins(k / m, 1.0, ordinates, "point").grouped()
            fit = fit_spectrum(bins, (1 + 1e-6, 3 - 1e-6), noise=False)
            values.append(departure(bins, fit, (1 + 1e-6, 3 - 1e-6), TOLERANCE))
        assert np.mean(np.array(values) <= 1) >= 0.98, hurst


def test_the_level_no_longer_chooses_the_band(caplog):
    rng = np.random.default_rng(3)
    surface = drifting(2**13, 0.12, rng)
    strict, lax = fit_fractal(surface, level=0.5), fit_fractal(surface, level=1e-12)
    assert strict.fit_band == lax.fit_band and strict.fractal_dimension == lax.fractal_dimension
    with caplog.at_level(logging.INFO, logger="rough"):
        fit_fractal(surface, level=0.999999)
    assert any("χ² diagnostic" in record.message for record in caplog.records)


def awkward_inputs():
    rng = np.random.default_rng(4)
    yield "white profile", Surface(rng.standard_normal(4096) * 1e-6, (1e-6,))
    yield "white map", Surface(rng.standard_normal((128, 128)) * 1e-6, (1e-6, 1e-6))
    yield "bend", bent(8192, rng)
    yield "steep", Surface(np.cumsum(np.cumsum(rng.standard_normal(2048))) * 1e-9, (1e-6,))
    path = shared_data_path() / "dem" / "faultzone.tif"
    if path.exists():
        yield "faultzone", fill_invalid(rough.read(path))


def test_hints_never_loop():
    """Following a hint's band gives a D (a power law or a bound) whose hint names no
    other band: at most one step, checked up to three."""
    for name, surface in awkward_inputs():
        fit, steps = fit_fractal(surface), 0
        while (match := HINTED_BAND.search(fit.hint or "")) and steps < 3:
            fit = fit_fractal(surface, band=tuple(map(parse_frequency, match.groups())))
            steps += 1
            assert fit.verdict in ("power law", "at bound"), name
            assert fit.band_rule == "given"
        assert steps <= 1, name
        assert not HINTED_BAND.search(fit.hint or "") or steps == 0, name


def test_without_a_band_the_roughness_against_scale_is_given(caplog):
    """White noise over a map: no power-law range; the fit carries the RMS height,
    slope and curvature against scale (finite, from 2 spacings up), and the warning
    says so."""
    rng = np.random.default_rng(5)
    surface = Surface(rng.standard_normal((128, 128)) * 1e-6, (1e-6, 1e-6))
    with caplog.at_level(logging.WARNING, logger="rough"):
        fit = fit_fractal(surface)
    assert fit.verdict == "no power-law range" and math.isnan(fit.fractal_dimension)
    table = fit.scale_dependent
    assert table["direction"] == "x" and table["scale"][0] == pytest.approx(2e-6)
    for key in ("rms_height", "rms_slope", "rms_curvature"):
        assert len(table[key]) == len(table["scale"]) and all(math.isfinite(v) and v > 0 for v in table[key])
    assert table["rms_slope"][0] == pytest.approx(math.sqrt(2) / 2, rel=0.05)  # √2 σ over a step of 2 Δ
    assert any("against scale" in record.message for record in caplog.records)
    assert fit.as_dict()["scale_dependent"]["scale"] == table["scale"]
    assert fit_fractal(Surface(fbm(1024, 0.5, rng, 1e-6, 1e-3), (1e-6,))).scale_dependent is None
