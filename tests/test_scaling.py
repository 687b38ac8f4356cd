"""Fits you can trust on real scans: the noise floor, the automatic scaling range,
the sampling model chosen by likelihood, bounds reported as bounds (issue 16)."""

import json
import math

import numpy as np
import pytest
from fourier import fourier_map, fourier_profile

from rough import Surface
from rough.fractal.fit import fit_fractal
from rough.fractal.scaling import gof_p_value, profile_bins
from rough.fractal.sectors import rose
from rough.fractal.whittle import difference_periodogram

from conftest import rough
from fbm import fbm


def fbm_with_noise(n, hurst, rng, spacing, crossover):
    """Exact fBm plus white noise whose density equals the fBm's spectrum at
    ``crossover`` (1/m); returns the heights and the noise RMS."""
    heights = fbm(n, hurst, rng, spacing, 3e-6)
    prefactor = 2 * 9e-12 * math.gamma(2 * hurst + 1) * math.sin(math.pi * hurst) / (2 * math.pi) ** (2 * hurst + 1)
    sigma = math.sqrt(prefactor * crossover ** -(2 * hurst + 1) / (2 * spacing))
    return heights + sigma * rng.standard_normal(n), sigma


@pytest.mark.parametrize("hurst", [0.5, 0.8])
@pytest.mark.parametrize("fraction", [1 / 8, 1 / 4, 1 / 2])
def test_a_noise_floor_costs_no_bias_and_the_band_ends_at_the_crossover(hurst, fraction):
    n, spacing = 4096, 1e-6
    crossover = fraction * 0.5 / spacing
    rng = np.random.default_rng(int(1000 * hurst + 8 / fraction))
    fits, sigmas = [], []
    for _ in range(30):
        heights, sigma = fbm_with_noise(n, hurst, rng, spacing, crossover)
        fits.append(fit_fractal(Surface(heights, (spacing,))))
        sigmas.append(sigma)
    assert all(fit.verdict == "power law" for fit in fits)
    assert abs(np.mean([fit.hurst for fit in fits]) - hurst) <= 0.03
    assert 0.75 <= np.median([fit.band[1] / crossover for fit in fits]) <= 1.35
    found = [fit.noise_rms / sigma for fit, sigma in zip(fits, sigmas) if fit.noise_rms]
    assert len(found) >= 27 and abs(np.median(found) - 1) < 0.1


def test_without_the_floor_the_same_data_are_biased():
    """The control: the whole-band power law alone is far off on the half-Nyquist case."""
    rng = np.random.default_rng(3)
    spacing = 1e-6
    estimates = []
    for _ in range(10):
        heights, _ = fbm_with_noise(4096, 0.5, rng, spacing, 0.25 / spacing)
        estimates.append(fit_fractal(Surface(heights, (spacing,)), noise=False, band=(None, 0.5 / spacing)).hurst)
    assert np.mean(estimates) < 0.5 - 0.05


@pytest.mark.parametrize("dimension", [1.2, 1.5, 1.8])
def test_band_limited_profiles_from_another_synthesis_are_unbiased(dimension):
    rng = np.random.default_rng(int(dimension * 100))
    fits = [fit_fractal(Surface(fourier_profile(1024, 2 - dimension, rng, 1e-6) * 1e-3, (1e-6,))) for _ in range(60)]
    assert abs(np.mean([fit.fractal_dimension for fit in fits]) - dimension) <= 0.02
    assert sum(fit.sampling == "band-limited" for fit in fits) >= 45
    assert all(fit.sampling_source == "likelihood" for fit in fits)


@pytest.mark.parametrize("dimension", [2.2, 2.5, 2.8])
def test_band_limited_maps_from_another_synthesis_are_unbiased(dimension):
    rng = np.random.default_rng(int(dimension * 100))
    fits = [fit_fractal(Surface(fourier_map(256, 3 - dimension, rng, 1e-6) * 1e-3, (1e-6, 1e-6))) for _ in range(12)]
    assert abs(np.mean([fit.fractal_dimension for fit in fits]) - dimension) <= 0.02


def test_the_test_is_calibrated_on_an_exact_power_law():
    """p-values of the goodness-of-fit test over the whole band of exact fBm are close
    to uniform: about 10 % fall below 0.1."""
    rng = np.random.default_rng(4)
    values = []
    for _ in range(200):
        heights = fbm(1024, 0.5, rng)
        heights = heights - np.polyval(np.polyfit(np.arange(1024), heights, 1), np.arange(1024))
        fit = fit_fractal(Surface(heights, (1.0,)), band=(0, 0.5), noise=False)
        values.append(fit.p_value)
    assert 0.04 <= np.mean(np.array(values) < 0.1) <= 0.18


def test_a_bend_fails_the_test():
    """A spectrum that bends (β = 3 below the middle, β = 1.4 above) cannot pass as
    one power law over both halves, so the band found stays on one side."""
    rng = np.random.default_rng(5)
    n = 8192
    f = np.fft.rfftfreq(n)
    amplitude = np.where(f < 0.02, f.clip(1e-9) ** -1.5, 0.02**-0.8 * 0.02**-0.7 * f.clip(1e-9) ** -0.7)
    amplitude[0] = 0
    heights = np.fft.irfft(amplitude * (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size)), n)
    surface = Surface(heights * 1e-6, (1.0,))
    whole = fit_fractal(surface, band=(0, 0.5))
    assert whole.p_value < 1e-6
    found = fit_fractal(surface)
    assert found.band[1] < 0.02 * 1.3 or found.band[0] > 0.02 / 1.3


def test_a_bound_is_a_result_on_the_command_line(tmp_path):
    """A spectrum steeper than any fractal's (a random walk integrated once more):
    JSON says at_bound with a null error, the text has no "±" and gives a hint (which,
    the local exponent lying outside the range at every scale, names no band)."""
    rng = np.random.default_rng(7)
    heights = np.cumsum(np.cumsum(rng.standard_normal(4096))) * 1e-9
    path = tmp_path / "steep.tsv"
    np.savetxt(path, np.column_stack([np.arange(4096) * 1e-6, heights]), delimiter="\t")
    values = json.loads(rough("fit-fractal", "--json", "--unit", "m", path, check=True).stdout)
    assert values["at_bound"] is True and values["fractal_dimension_stderr"] is None
    assert values["fractal_dimension"] == pytest.approx(1.0, abs=1e-3) and values["verdict"] == "at bound"
    text = rough("fit-fractal", "--unit", "m", path, check=True).stdout.decode()
    first = next(line for line in text.splitlines() if line.startswith("fractal_dimension "))
    assert "±" not in first and "bound" in first and "outside a fractal's range" in first  # no band to try


def test_the_sampling_model_is_chosen_and_reported():
    rng = np.random.default_rng(8)
    exact = fit_fractal(Surface(fbm(4096, 0.5, rng), (1.0,)))
    limited = fit_fractal(Surface(fourier_profile(4096, 0.5, rng), (1.0,)))
    assert (exact.sampling, exact.sampling_source) == ("point", "likelihood")
    assert (limited.sampling, limited.sampling_source) == ("band-limited", "likelihood")
    assert fit_fractal(Surface(fbm(4096, 0.5, rng), (1.0,)), sampling="point").sampling_source == "option"


def test_the_rolloff_is_fitted_when_asked():
    """fBm smoothed by a Gaussian filter (a tip's transfer exp(-(f/fc)²) on the power):
    with --rolloff the fit recovers H and a roll-off wavelength near 1/fc."""
    rng = np.random.default_rng(9)
    n, cutoff = 8192, 0.05
    estimates = []
    for _ in range(8):
        heights = fbm(n, 0.6, rng)
        f = np.fft.rfftfreq(n)
        heights = np.fft.irfft(np.fft.rfft(heights) * np.exp(-0.5 * (f / cutoff) ** 2), n)
        fit = fit_fractal(Surface(heights, (1.0,)), rolloff=True, sampling="band-limited", band=(None, 0.2))
        estimates.append((fit.hurst, fit.rolloff_wavelength))
    hurst, wavelength = np.mean(estimates, axis=0)
    assert abs(hurst - 0.6) <= 0.05
    assert wavelength == pytest.approx(1 / cutoff, rel=0.25)


def test_gof_p_value_of_the_true_spectrum_is_uniform_ish():
    rng = np.random.default_rng(10)
    values = []
    for _ in range(200):
        heights = fourier_profile(2048, 0.5, rng)
        frequencies, ordinates = difference_periodogram(heights, 1.0)
        bins = profile_bins(frequencies, 1.0, ordinates, "band-limited")
        expected = 2 * np.sin(np.pi * frequencies) ** 2 * frequencies**-2.0 * 2 * 2048 / 2048
        values.append(gof_p_value(bins, expected * np.mean(ordinates / expected), 1))
    assert 0.05 <= np.mean(np.array(values) < 0.1) <= 0.16


def test_rose_leaves_bound_sectors_out_of_the_tests():
    """A map of grooves along x plus white noise: sectors across the grooves see a
    steep spectrum, the others only noise. Bound sectors have null errors and the
    isotropy tests use only the others (or say they cannot test)."""
    rng = np.random.default_rng(11)
    n = 256
    grooves = np.cumsum(np.cumsum(rng.standard_normal(n)))[:, None] * np.ones((1, n)) * 1e-9
    surface = Surface(grooves + 1e-9 * rng.standard_normal((n, n)), (1e-6, 1e-6))
    result = rose(surface, step=30)
    for bound, error in zip(result.at_bound, result.fractal_dimension_stderr):
        assert (error is None) == bound
    assert any(result.at_bound)
    inside = len(result.at_bound) - sum(result.at_bound)
    if inside < 2:
        assert result.isotropy_p_value["fractal_dimension"] is None


def test_rose_names_the_lay_per_scale():
    rng = np.random.default_rng(12)
    surface = Surface(fourier_map(256, 0.5, rng, 1e-6) * 1e-3, (1e-6, 1e-6))
    result = rose(surface, step=15).as_dict()
    assert set(result["lay"]) == {"long_wavelength", "resolution"}
    assert result["lay"]["resolution"]["wavelength"] == pytest.approx(1e-6)
    assert result["lay"]["long_wavelength"]["wavelength"] == pytest.approx(1 / result["band"][0])
