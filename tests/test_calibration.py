"""Calibration of the H estimators (rough.fractal.calibrate) against generators written
independently of it: tests/fbm.py (Davies-Harte) and an exact Cholesky factorisation of
the fractional Gaussian noise covariance written here.

The statistical checks use fixed seeds, so they are deterministic; the counts are chosen
so that a correct calibration passes by a wide margin (each docstring gives the spread).
Run time: about 30 s for the four log-log estimators (their calibration curves are built
once per design and cached: two lengths, one noise level) and about as much again for
the Whittle entry (one numerical optimisation per replicate).
"""

import math

import numpy as np
import pytest
import scipy.linalg

from rough.errors import InputError
from rough.fractal import calibrate as cal

from fbm import fbm

LOG_LOG = ["variogram", "dfa", "wavelet", "higuchi"]
HURSTS = (0.3, 0.5, 0.8)
SPACING = 1e-6


def without_line(profile):
    x = np.linspace(-1.0, 1.0, profile.size)
    return profile - np.polyval(np.polyfit(x, profile, 1), x)


def cholesky_fbm(n, hurst, count, rng):
    """``count`` exact fBm profiles of n points: the Cholesky factor of the fGn
    covariance times white noise, then a cumulative sum."""
    lags = np.arange(n - 1.0)
    gamma = 0.5 * ((lags + 1) ** (2 * hurst) - 2 * lags ** (2 * hurst) + np.abs(lags - 1) ** (2 * hurst))
    factor = scipy.linalg.cholesky(scipy.linalg.toeplitz(gamma), lower=True)
    increments = factor @ rng.standard_normal((n - 1, count))
    return np.vstack([np.zeros((1, count)), np.cumsum(increments, axis=0)]).T


def davies_harte(n, hurst, count, rng):
    return [fbm(n, hurst, rng, SPACING, 3e-9) for _ in range(count)]


def outcomes(generator, n, count, names, seed):
    """{name: [(true H, corrected H, interval), ...]} over ``count`` profiles at each H."""
    found = {name: [] for name in names}
    for index, hurst in enumerate(HURSTS):
        rng = np.random.default_rng([seed, n, index])
        for profile in generator(n, hurst, count, rng):
            for result in cal.compare([without_line(profile)], SPACING, estimators=names):
                found[result.estimator].append((hurst, result.hurst, result.interval))
    return found


@pytest.fixture(scope="module")
def log_log_runs():
    return {
        ("davies-harte", 1024): outcomes(davies_harte, 1024, 200, LOG_LOG, 1),
        ("davies-harte", 4096): outcomes(davies_harte, 4096, 200, LOG_LOG, 2),
        ("cholesky", 1024): outcomes(cholesky_fbm, 1024, 200, LOG_LOG, 3),
    }


def check_unbiased_and_covered(rows):
    """Per H, the mean corrected H within 0.02 of the truth; pooled over the H, the 95 %
    interval's coverage in [0.90, 0.98]."""
    rows = np.array([(true, corrected, low, high) for true, corrected, (low, high) in rows])
    for hurst in HURSTS:
        chosen = rows[rows[:, 0] == hurst]
        assert abs(chosen[:, 1].mean() - hurst) < 0.02, f"H = {hurst}: mean {chosen[:, 1].mean():.4f}"
    coverage = np.mean((rows[:, 2] <= rows[:, 0]) & (rows[:, 0] <= rows[:, 3]))
    assert 0.90 <= coverage <= 0.98, f"coverage {coverage:.3f}"


@pytest.mark.parametrize("name", LOG_LOG)
@pytest.mark.parametrize("source", [("davies-harte", 1024), ("davies-harte", 4096), ("cholesky", 1024)])
def test_calibrated_log_log_estimators(log_log_runs, source, name):
    """200 profiles at each of H = 0.3, 0.5, 0.8 (a line removed, default calibration).

    Bias: the SD of one corrected H is at most about 0.07 (n = 1024), so the mean of 200
    has a standard error ≤ 0.005: 0.02 is four standard errors plus the calibration
    curve's own error (≈ 0.003 with 400 replicates per grid H).
    Coverage: 600 intervals; at a true 95 % the binomial SD is 0.9 %, so 90 % and 98 %
    are 5.6 and 3.4 SD away."""
    check_unbiased_and_covered(log_log_runs[source][name])


def test_calibrated_whittle():
    """The Whittle entry, 80 profiles at each H (n = 1024) and Davies-Harte: the mean of
    80 corrected values has a standard error ≈ 0.003 (SD ≈ 0.025); 240 intervals give a
    binomial SD of 1.4 % at 95 % (90 % and 98 %: 3.6 and 2.1 SD)."""
    check_unbiased_and_covered(outcomes(davies_harte, 1024, 80, ["whittle"], 4)["whittle"])


def test_the_generator_is_exact_fbm():
    """Var z(t) = t^(2H) and the lag-1 increment correlation 2^(2H-1) - 1, from 8000
    profiles (relative SE of a variance: 1.6 %; tolerance 8 %)."""
    rng = np.random.default_rng(9)
    for hurst in (0.2, 0.7, 0.95):
        rows = cal.fbm_rows(8000, 100, hurst, rng)
        assert np.all(rows[:, 0] == 0)
        for t in (1, 7, 99):
            assert rows[:, t].var() == pytest.approx(t ** (2 * hurst), rel=0.08)
        steps = np.diff(rows, axis=1)
        correlation = np.mean(steps[:, 10] * steps[:, 11])
        assert correlation == pytest.approx(2 ** (2 * hurst - 1) - 1, abs=0.05)


def test_inversion_of_a_known_curve():
    curve = cal.Curve(cal.GRID * 0.8 + 0.05, np.full(cal.GRID.size, 0.02), 100)
    hurst, (low, high), at_bound = cal.invert(curve, 0.45)
    assert hurst == pytest.approx(0.5, abs=1e-3) and at_bound is None
    assert low == pytest.approx(0.5 - 1.96 * 0.02 / 0.8, abs=1e-3)
    assert high == pytest.approx(0.5 + 1.96 * 0.02 / 0.8, abs=1e-3)
    assert cal.invert(curve, 0.45, floor=0.04)[1][1] == pytest.approx(0.5 + 1.96 * 0.04 / 0.8, abs=1e-3)
    assert cal.invert(curve, 0.45, floor=0.01) == cal.invert(curve, 0.45)
    hurst, (low, high), at_bound = cal.invert(curve, 0.85)  # above the curve (0.834 at most)
    assert (hurst, at_bound, high) == (cal.GRID[-1], "high", cal.GRID[-1])
    assert low == pytest.approx((0.85 - 1.96 * 0.02 - 0.05) / 0.8, abs=1e-3)
    assert cal.invert(curve, 0.9) == (cal.GRID[-1], (cal.GRID[-1], cal.GRID[-1]), "high")
    assert cal.invert(curve, -0.5) == (cal.GRID[0], (cal.GRID[0], cal.GRID[0]), "low")


def test_the_result_is_deterministic_and_cached():
    profile = without_line(fbm(512, 0.6, np.random.default_rng(5)))
    cal.clear_cache()
    first = cal.calibrated("dfa", [profile], 1.0, replicates=30, seed=3)
    assert len(cal._CURVES) == 1
    cal.clear_cache()
    assert cal.calibrated("dfa", [profile], 1.0, replicates=30, seed=3) == first
    assert cal.calibrated("dfa", [profile], 1.0, replicates=30, seed=4) != first
    assert len(cal._CURVES) == 2
    assert first.replicates == 30 and first.estimator == "dfa"
    assert first.bias == pytest.approx(first.raw - first.hurst)
    assert first.interval[0] < first.hurst < first.interval[1]
    assert "30 replicates" in first.method


def test_relative_noise():
    """±1 steps: S(Δ) = 1 exactly; noise σ leaves 1 - 2σ² to the fBm."""
    walk = np.cumsum(np.where(np.random.default_rng(0).random(1000) < 0.5, -1.0, 1.0))
    assert cal.relative_noise([walk], 0.5) == pytest.approx(0.5 / math.sqrt(0.5))
    assert cal.relative_noise([walk], None) == 0.0
    with pytest.raises(InputError, match="more than"):
        cal.relative_noise([walk], 0.8)


def test_noise_is_calibrated_away():
    """fBm (H = 0.5) plus white noise of 0.8 × its step RMS, 100 profiles of 1024: with the
    noise given, the corrected variogram H is unbiased within 0.03 (SE ≈ 0.006); without
    it the correction is short by more than 0.05."""
    rng = np.random.default_rng(21)
    given, ignored = [], []
    for _ in range(100):
        profile = without_line(fbm(1024, 0.5, rng) + 0.8 * rng.standard_normal(1024))
        given.append(cal.calibrated("variogram", [profile], 1.0, noise_rms=0.8, replicates=100).hurst)
        ignored.append(cal.calibrated("variogram", [profile], 1.0, replicates=100).hurst)
    assert abs(np.mean(given) - 0.5) < 0.03
    assert np.mean(ignored) < 0.45


def test_block_jackknife_widens_the_interval_of_correlated_profiles():
    """64 profiles that are 16 independent ones, each 4 times (neighbours), with a little
    noise: the synthetic (independent) profiles understate the spread by a factor 2; the
    jackknife over 16 blocks of four finds it (its SD has 15 degrees of freedom, a
    relative SD of about 18 %, so the bound 1.3 is 2.5 of them away)."""
    rng = np.random.default_rng(8)
    originals = [fbm(512, 0.6, rng) for _ in range(16)]
    profiles = [without_line(originals[i // 4] + 1e-3 * rng.standard_normal(512)) for i in range(64)]
    positions = np.arange(64.0)
    plain = cal.calibrated("higuchi", profiles, 1.0, replicates=50)
    blocked = cal.calibrated("higuchi", profiles, 1.0, replicates=50, positions=positions)
    assert blocked.hurst == plain.hurst
    assert blocked.interval[1] - blocked.interval[0] > 1.3 * (plain.interval[1] - plain.interval[0])
    assert "jackknife" in blocked.method and "jackknife" not in plain.method
    few = cal.calibrated("higuchi", profiles[:7], 1.0, replicates=50, positions=positions[:7])
    assert "jackknife" not in few.method
    with pytest.raises(InputError, match="positions"):
        cal.calibrated("higuchi", profiles, 1.0, replicates=50, positions=positions[:5])


def test_refusals():
    profile = without_line(fbm(256, 0.5, np.random.default_rng(1)))
    with pytest.raises(InputError, match="unknown estimator"):
        cal.compare([profile], 1.0, estimators=["box-counting"])
    with pytest.raises(InputError, match="replicates"):
        cal.calibrated("dfa", [profile], 1.0, replicates=1)
    with pytest.raises(InputError, match="form order"):
        cal.calibrated("dfa", [profile], 1.0, order=7)
    with pytest.raises(InputError, match="finite"):
        cal.calibrated("dfa", [np.full(100, np.nan)], 1.0)


def test_unequal_lengths_keep_their_lengths():
    """Synthetic replicates cut each profile to the input's length and remove its form."""
    design = cal.Design((100, 150, 150), 1.0, None, 1, 0.0, 3, 0)
    padded = design.synthetic(0.5, np.random.default_rng(0), 2)
    assert list(padded.lengths) == [100, 150, 150] * 2
    assert np.isnan(padded.heights[0, 100:]).all() and np.isfinite(padded.heights[1]).all()
    for row, length in zip(padded.heights, padded.lengths):
        part = row[:length]
        assert abs(np.polyfit(np.arange(length), part, 1)).max() < 1e-9 * max(1.0, np.abs(part).max())


def test_band_limited_data_are_calibrated_on_band_limited_profiles():
    """rough's own synthesis is band-limited: the Whittle fit under that model, calibrated
    on band-limited profiles, gives back the H it was made with (D = 1.3, H = 0.7), where
    the point-sample model reads about 0.77."""
    from rough.fractal.synth import synthesize_profile

    estimates = []
    for seed in range(4):
        profile = synthesize_profile(2048, 1e-5, 1.3, rq=1e-6, seed=seed).heights
        profile = profile - np.polyval(np.polyfit(np.arange(profile.size), profile, 1), np.arange(profile.size))
        estimates.append(cal.calibrated("whittle", [profile], 1e-5, replicates=8, sampling="band-limited").hurst)
    assert np.mean(estimates) == pytest.approx(0.7, abs=0.02)
