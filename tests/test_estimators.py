"""The raw H estimators of rough.fractal.estimators: their statistics against brute-force
loops and analytic results, their refusals, and invariances (hypothesis)."""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rough.errors import InputError
from rough.fractal import estimators as est
from rough.fractal.pooled import whittle_hurst

from conftest import shared_data_path
from fbm import fbm

LOG_LOG = ["variogram", "dfa", "wavelet", "higuchi"]


def unequal_profiles(seed=4, lengths=(97, 150, 64, 150, 211)):
    rng = np.random.default_rng(seed)
    return [fbm(n, 0.6, rng) for n in lengths]


def brute_variogram(profile, lag):
    return np.sum((profile[lag:] - profile[:-lag]) ** 2), profile.size - lag


def brute_dfa(profile, window):
    total, count = 0.0, 0
    n = profile.size
    starts = [k * window for k in range(n // window)] + [n - (k + 1) * window for k in range(n // window)]
    for start in starts:
        piece = profile[start : start + window]
        x = np.arange(window)
        total += np.mean((piece - np.polyval(np.polyfit(x, piece, 1), x)) ** 2)
        count += 1
    return total, count


def brute_wavelet(profile, level):
    approximation = profile
    for _ in range(level):
        # valid correlation with the filters, every second position
        detail = np.correlate(approximation, est.WAVELET, "valid")[::2]
        approximation = np.correlate(approximation, est.DAUBECHIES4, "valid")[::2]
    return np.sum(np.abs(detail)), detail.size


def brute_higuchi(profile, step):
    n = profile.size
    total, count = 0.0, 0
    for offset in range(step):
        terms = (n - 1 - offset) // step
        if terms < 1:
            continue
        points = profile[offset : offset + terms * step + 1 : step]
        total += np.sum(np.abs(np.diff(points))) / (terms * step**2)
        count += 1
    return total, count


BRUTE = {
    "variogram": (est.structure_function, brute_variogram, [1, 3, 17, 60]),
    "dfa": (est.fluctuation, brute_dfa, [4, 7, 16, 50]),
    "wavelet": (est.wavelet_coefficients, brute_wavelet, [1, 2, 3, 4]),
    "higuchi": (est.curve_length, brute_higuchi, [1, 2, 9, 40]),
}


@pytest.mark.parametrize("name", LOG_LOG)
def test_pooled_statistic_of_unequal_profiles_matches_a_loop(name):
    """NaN padding of unequal profiles (and DFA's windows from both ends) gives, per
    profile, the sums and counts of a direct loop over that profile alone."""
    statistic, brute, scales = BRUTE[name]
    profiles = unequal_profiles()
    sums, counts = statistic(est.Padded.of(profiles), np.array(scales))
    for row, profile in enumerate(profiles):
        for column, scale in enumerate(scales):
            total, count = brute(profile, scale)
            assert counts[row, column] == count
            assert sums[row, column] == pytest.approx(total, rel=1e-9, abs=1e-12 * max(total, 1))


@pytest.mark.parametrize("slope", [0.3, -2.5])
def test_a_line_gives_exact_power_laws(slope):
    """z = b x: S(τ) = b² τ² and Higuchi's L(k)/(n − 1) = |b|/k exactly, so the log-log
    fits give H = 1 (the public estimators refuse a line: see below)."""
    profiles = [slope * np.arange(n, dtype=float) for n in (300, 257)]
    padded = est.Padded.of(profiles)
    lags = np.array([1, 2, 5, 30])
    sums, counts = est.structure_function(padded, lags)
    np.testing.assert_allclose(sums / counts, np.tile(slope**2 * lags**2.0, (2, 1)), rtol=1e-12)
    sums, counts = est.curve_length(padded, lags)
    np.testing.assert_allclose(sums / counts, np.tile(abs(slope) / lags, (2, 1)), rtol=1e-12)
    for name in ("variogram", "higuchi"):
        chosen = est.sample_scales(name, padded.lengths, 1.0)
        assert est.pooled_hurst(name, padded, chosen)[0] == pytest.approx(1.0, abs=1e-10)


def test_the_wavelet_is_orthonormal_and_blind_to_lines():
    """Daubechies-4: unit-norm filters, orthogonal to each other and to their shifts by
    two, and two vanishing moments (a constant and a line give zero details)."""
    low, high = est.DAUBECHIES4, est.WAVELET
    assert low @ low == pytest.approx(1.0) and high @ high == pytest.approx(1.0)
    assert low @ high == pytest.approx(0.0, abs=1e-15)
    assert low[2:] @ low[:2] == pytest.approx(0.0, abs=1e-15)
    assert low.sum() == pytest.approx(math.sqrt(2.0))
    assert high @ np.ones(4) == pytest.approx(0.0, abs=1e-15)
    assert high @ np.arange(4.0) == pytest.approx(0.0, abs=1e-15)
    sums, _ = est.wavelet_coefficients(est.Padded.of([3.0 + 0.7 * np.arange(200.0)]), [1, 2, 3])
    assert np.all(sums < 1e-12)


def test_a_power_law_statistic_gives_its_exponent():
    """The line in log-log through an exact power law recovers its exponent: the
    variogram's S(τ) = τ^(2H) recovers H (checked through the slope conversion)."""
    scaling = est.SCALINGS["variogram"]
    lags = est.log_scales(1, 100)
    x = np.log(lags) - np.log(lags).mean()
    slope = np.log(lags**1.4) @ x / (x @ x)
    assert (slope - scaling.b) / scaling.a == pytest.approx(0.7)


@pytest.mark.parametrize("name", LOG_LOG)
def test_raw_values_on_brownian_profiles(name):
    """Brownian motion (H = 1/2), 64 profiles of 1024: the raw values lie near 1/2 (the
    wavelet's finest levels read low; the bound allows that)."""
    rng = np.random.default_rng(11)
    profiles = [fbm(1024, 0.5, rng) for _ in range(64)]
    estimate = est.ESTIMATORS[name](profiles, 1e-3)
    assert estimate.estimator == name
    assert abs(estimate.hurst - 0.5) < 0.06
    assert estimate.points >= 3
    assert 0 < estimate.scales[0] < estimate.scales[1] <= 1.024


@pytest.mark.parametrize("name", LOG_LOG)
def test_refusals(name):
    estimate = est.ESTIMATORS[name]
    line = [np.linspace(0, 1, 200), 5 + np.linspace(0, 2, 300)]
    with pytest.raises(InputError, match="straight lines"):
        estimate(line, 1.0)
    with pytest.raises(InputError, match="finite"):
        estimate([np.array([1.0, np.nan] * 50)], 1.0)
    with pytest.raises(InputError, match="spacing"):
        estimate([np.random.default_rng(0).standard_normal(100)], 0.0)
    with pytest.raises(InputError, match="fewer than three scales"):
        estimate([np.random.default_rng(0).standard_normal(500)], 1.0, scales=(10.0, 11.0))
    with pytest.raises(InputError, match="smallest first"):
        estimate([np.random.default_rng(0).standard_normal(500)], 1.0, scales=(10.0, 5.0))
    with pytest.raises(InputError, match="no profiles"):
        estimate([], 1.0)


@pytest.mark.parametrize("name", LOG_LOG)
def test_scales_in_metres_are_the_range_used(name):
    rng = np.random.default_rng(2)
    profiles = [fbm(2048, 0.7, rng) for _ in range(4)]
    estimate = est.ESTIMATORS[name](profiles, 0.5, scales=(4.0, 100.0))
    assert 4.0 <= estimate.scales[0] < estimate.scales[1] <= 100.0


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**32 - 1),
    hurst=st.floats(0.05, 0.95),
    factor=st.floats(1e-6, 1e6) | st.floats(-1e6, -1e-6),
    quantum=st.sampled_from([0.0, 0.5, 3.0]),
    name=st.sampled_from(LOG_LOG),
)
def test_scaling_the_heights_leaves_h_unchanged(seed, hurst, factor, quantum, name):
    """H of k z is H of z for any k ≠ 0, also for quantised heights (ties, constant
    stretches): the same value within rounding, or the same refusal."""
    rng = np.random.default_rng(seed)
    profiles = [fbm(n, hurst, rng, scale=4.0) for n in (300, 256)]
    if quantum:
        profiles = [np.round(profile / quantum) for profile in profiles]
    try:
        expected = est.ESTIMATORS[name](profiles, 1.0).hurst
    except InputError as error:
        with pytest.raises(InputError, match=str(error)[:20]):
            est.ESTIMATORS[name]([factor * profile for profile in profiles], 1.0)
        return
    assert est.ESTIMATORS[name]([factor * profile for profile in profiles], 1.0).hurst == pytest.approx(
        expected, abs=1e-9
    )


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), name=st.sampled_from(LOG_LOG))
def test_the_order_of_the_profiles_does_not_matter(seed, name):
    rng = np.random.default_rng(seed)
    profiles = [fbm(n, 0.5, rng) for n in rng.integers(64, 400, size=6)]
    order = rng.permutation(len(profiles))
    first = est.ESTIMATORS[name](profiles, 1.0).hurst
    assert est.ESTIMATORS[name]([profiles[i] for i in order], 1.0).hurst == pytest.approx(first, abs=1e-12)


def test_whittle_entry_calls_the_pooled_whittle_fit():
    rng = np.random.default_rng(3)
    profiles = [fbm(1024, 0.5, rng) for _ in range(4)]
    estimate = est.ESTIMATORS["whittle"](profiles, 1e-3)
    assert estimate.hurst == whittle_hurst(profiles, 1e-3)
    assert estimate.points == 4 * 512
    assert estimate.scales == (2e-3, 1.024)
    assert est.whittle(profiles, 1e-3, scales=(0.01, 0.1)).points == 4 * sum(
        1 for k in range(1, 513) if 10 <= 1024 / k <= 100
    )


CORONA = shared_data_path() / "dem" / "coronaA_grids.npz"


def _longest_run(row):
    finite = np.concatenate([[False], np.isfinite(row), [False]])
    edges = np.flatnonzero(np.diff(finite.astype(int)))
    best = np.argmax(edges[1::2] - edges[::2])
    run = row[edges[2 * best] : edges[2 * best + 1]]
    x = np.linspace(-1.0, 1.0, run.size)
    return run - np.polyval(np.polyfit(x, run, 1), x)


@pytest.mark.skipif(not CORONA.is_file(), reason="../shared/data/dem/coronaA_grids.npz is not there")
@pytest.mark.parametrize("name", LOG_LOG)
def test_corona_heights_is_smoother_across_slip(name):
    """Corona Heights (slip along x): H along the rows < H along the columns, as the
    fault literature finds (Candela et al. 2012: 0.58 ± 0.07 along, 0.81 ± 0.04 across)."""
    grid = np.load(CORONA)["Z_grid"]
    spacing = 0.005685771715431078
    along = [_longest_run(row) for row in grid if np.isfinite(row).sum() >= 64]
    across = [_longest_run(column) for column in grid.T if np.isfinite(column).sum() >= 64]
    h_along = est.ESTIMATORS[name](along, spacing).hurst
    h_across = est.ESTIMATORS[name](across, spacing).hurst
    assert h_along + 0.1 < h_across
