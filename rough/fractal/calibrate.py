"""Calibration of the H estimators by parametric bootstrap (docs/math.rst §1.10).

Exact fBm (circulant embedding of fractional Gaussian noise, Davies & Harte 1987) of the
input's own profile count and lengths, with its form removed as the input's was and
white noise of the input's relative level, is run through the same estimator over a
grid of H in (0, 1). The mean and standard deviation of the raw Ĥ at each grid H are the
calibration curve; the bias-corrected H inverts the mean curve at the raw value, and the
95 % interval is the Neyman inversion: every H whose central 95 % of Ĥ (mean ± 1.96 SD)
holds the raw value.

The curve depends only on the design (estimator, profile lengths, spacing, scales, form
order, relative noise, replicates, seed), so it is cached per design for the session;
:func:`clear_cache` empties the cache. Everything is deterministic from ``seed``.

>>> import numpy as np
>>> walk = np.cumsum(np.random.default_rng(5).standard_normal(1024))  # H = 1/2
>>> result = calibrated("variogram", [walk - walk.mean()], 1e-3, order=0, replicates=100)
>>> f"raw {result.raw:.2f}, H = {result.hurst:.2f} ({result.interval[0]:.2f}-{result.interval[1]:.2f})"
'raw 0.52, H = 0.53 (0.45-0.62)'
"""

import dataclasses
import functools
import math

import numpy as np
import scipy.fft

from ..compiled import one_blas_thread
from ..errors import InputError
from . import estimators as est
from .jackknife import jackknife_variance, neighbour_blocks

GRID = np.linspace(0.02, 0.98, 17)  # the H of the calibration curve
QUANTILE = 1.959963984540054  # the central 95 % of a normal distribution: mean ± this many SD
POINT_BUDGET = 2_000_000  # synthetic heights per grid H for the default number of replicates
REPLICATES = (10, 400)  # the default number of replicates lies in this range
WHITTLE_BUDGET = 1_000_000  # the same for the Whittle fit, which costs far more per replicate
WHITTLE_REPLICATES = (4, 16)
CHUNK = 2**20  # synthetic heights made at once
_CURVES = {}


@dataclasses.dataclass(frozen=True)
class Curve:
    """Mean and standard deviation of the raw Ĥ at each H of :data:`GRID`, each averaged
    with the two neighbouring grid H (beyond the ends: the mean extrapolated linearly, the
    variance repeated)."""

    mean: np.ndarray
    sd: np.ndarray
    replicates: int


@dataclasses.dataclass(frozen=True)
class Calibrated:
    """A calibrated estimate of H.

    Attributes
    ----------
    estimator : str
        The name in :data:`rough.fractal.ESTIMATORS`.
    raw : float
        The estimator's raw H.
    hurst : float
        The bias-corrected H (a bound of the calibration grid when ``at_bound`` is set).
    interval : tuple of float
        (low, high), the 95 % confidence interval of H; an end at 0.02 or 0.98 (the grid's
        ends) means "at or beyond".
    bias : float
        raw − hurst: the estimator's mean bias at the corrected H.
    replicates : int
        Synthetic replicates per grid H.
    method : str
        How the value was obtained, in words.
    scales : tuple of float
        (smallest, largest) scale the estimator used, m.
    at_bound : str or None
        "low" or "high" when the raw value lies outside the calibration curve's range, so
        ``hurst`` is the grid's bound; None otherwise.
    """

    estimator: str
    raw: float
    hurst: float
    interval: tuple
    bias: float
    replicates: int
    method: str
    scales: tuple
    at_bound: str = None


def clear_cache():
    """Forget every cached calibration curve."""
    _CURVES.clear()


def fbm_rows(count, length, hurst, rng):
    """``count`` independent exact fBm profiles of ``length`` points, unit variance of the
    one-sample increment: ``(count, length)``, each starting at 0.

    Circulant embedding of the fractional Gaussian noise autocovariance
    γ(k) = (|k + 1|^2H − 2|k|^2H + |k − 1|^2H) / 2 in a circulant of size 2m (m ≥ n − 1, a
    fast FFT length; its eigenvalues are checked to be non-negative); the real and
    imaginary parts of one complex transform are two independent paths (Davies & Harte
    1987; Wood & Chan 1994). Written independently of tests/fbm.py.
    """
    amplitudes = _embedding(length, hurst)
    half = amplitudes.size // 2
    pairs = -(-count // 2)
    white = rng.standard_normal((pairs, 2 * half)) + 1j * rng.standard_normal((pairs, 2 * half))
    noise = scipy.fft.fft(amplitudes * white, axis=1, overwrite_x=True)[:, : length - 1]
    increments = np.concatenate([noise.real, noise.imag])[:count]
    return np.concatenate([np.zeros((count, 1)), np.cumsum(increments, axis=1)], axis=1)


def band_limited_rows(count, length, hurst, rng):
    """``count`` band-limited fractal profiles of ``length`` points: white noise shaped
    to the power law |f|^-(1+2H) up to the Nyquist frequency and no further (nothing
    folds back: what rough's synthesis and resampling make), over twice the length
    and cut, so that the profiles are not periodic; unit scale."""
    size = scipy.fft.next_fast_len(2 * length)
    frequencies = np.arange(size // 2 + 1) / size
    gain = np.zeros_like(frequencies)
    gain[1:] = frequencies[1:] ** -(0.5 + hurst)
    white = rng.standard_normal((count, gain.size)) + 1j * rng.standard_normal((count, gain.size))
    rows = scipy.fft.irfft(white * gain, size, axis=1, overwrite_x=True)[:, :length]
    return rows / np.sqrt(np.mean(np.diff(rows, axis=1) ** 2))


@functools.lru_cache(maxsize=64)
def _embedding(length, hurst):
    """sqrt(eigenvalues / 2m) of the smallest fast circulant embedding (m ≥ n − 1) that is
    non-negative definite (rounding aside): it is for fGn, but it is checked."""
    half = scipy.fft.next_fast_len(max(length - 1, 2))
    exponent = 2.0 * hurst
    while True:
        lags = np.arange(half + 1.0)
        autocovariance = 0.5 * ((lags + 1) ** exponent - 2 * lags**exponent + np.abs(lags - 1) ** exponent)
        eigenvalues = scipy.fft.fft(np.concatenate([autocovariance, autocovariance[-2:0:-1]])).real
        if eigenvalues.min() >= -1e-10 * eigenvalues.max():
            return np.sqrt(np.clip(eigenvalues, 0.0, None) / (2 * half))
        half *= 2


def relative_noise(profiles, noise_rms):
    """The white noise's RMS relative to the fBm part's RMS one-sample increment:
    σn / sqrt(S(Δ) − 2σn²), with S(Δ) the data's pooled mean squared one-sample increment
    (white noise of RMS σn adds 2σn² to it). 0 when ``noise_rms`` is None or 0.

    Raises :class:`rough.errors.InputError` when the noise would account for all of S(Δ).
    """
    if not noise_rms:
        return 0.0
    if not (math.isfinite(noise_rms) and noise_rms > 0):
        raise InputError(f"the noise RMS must be a positive length, not {noise_rms}")
    largest = largest_noise(profiles)
    if not noise_rms < largest:
        raise InputError(
            f"noise RMS {noise_rms:.3g} m is more than the heights' one-sample increments allow "
            f"(less than {largest:.3g} m)"
        )
    return noise_rms / math.sqrt(2 * (largest**2 - noise_rms**2))


def largest_noise(profiles):
    """The RMS of white noise that would account for all of the profiles' one-sample
    increments, sqrt(S(Δ) / 2), m: any noise floor must be below it."""
    sums, counts = est.structure_function(est.Padded.of(est.checked(profiles, 1.0)), [1])
    return math.sqrt(sums.sum() / counts.sum() / 2)


@dataclasses.dataclass(frozen=True)
class Design:
    """Everything the calibration curve depends on."""

    lengths: tuple  # profile lengths, points
    spacing: float
    scales: tuple
    order: int
    noise: float  # relative, see relative_noise (3 significant digits)
    replicates: int
    seed: int
    sampling: str = "point"

    def synthetic(self, hurst, rng, count):
        """``count`` replicates of the input's profiles: exact fBm cut to each length, white
        noise added, form of ``order`` removed per profile; one :class:`Padded`."""
        lengths = np.array(self.lengths)
        generate = band_limited_rows if self.sampling == "band-limited" else fbm_rows
        rows = generate(count * lengths.size, lengths.max(), hurst, rng)
        if self.noise:
            rows += self.noise * rng.standard_normal(rows.shape)
        all_lengths = np.tile(lengths, count)
        for length in np.unique(lengths):
            basis = np.linalg.qr(np.vander(np.linspace(-1.0, 1.0, length), self.order + 1))[0]
            chosen = slice(None) if length == lengths.min() == lengths.max() else all_lengths == length
            part = rows[chosen, :length]
            rows[chosen, :length] = part - (part @ basis) @ basis.T
            rows[chosen, length:] = np.nan
        return est.Padded(rows, all_lengths)


@one_blas_thread
def _estimate(name, profiles, spacing, scales, noisy, sampling="point"):
    """The raw estimate of ``name``; the Whittle fit gets a noise floor only for ``noisy``
    data, and the sampling model given."""
    if name == "whittle":
        return est.whittle(profiles, spacing, scales, noise=noisy, sampling=sampling)
    return est.ESTIMATORS[name](profiles, spacing, scales)


@one_blas_thread
def _raw_values(name, padded, groups, design):
    """Raw Ĥ of each group of rows (a replicate) of the synthetic ``padded``."""
    if name == "whittle":
        starts = list(groups) + [padded.heights.shape[0]]
        return np.array(
            [
                est.whittle(
                    [row[:length] for row, length in zip(padded.heights[a:b], padded.lengths[a:b])],
                    design.spacing,
                    design.scales,
                    noise=bool(design.noise),
                    sampling=design.sampling,
                ).hurst
                for a, b in zip(starts[:-1], starts[1:])
            ]
        )
    chosen = est.sample_scales(name, np.array(design.lengths), design.spacing, design.scales)
    return est.pooled_hurst(name, padded, chosen, groups)


def curves(names, design):
    """The calibration :class:`Curve` of each estimator in ``names`` for ``design`` (from the
    cache, or made sharing one set of synthetic data among the estimators not cached)."""
    missing = [name for name in names if (name, design) not in _CURVES]
    if missing:
        profiles = len(design.lengths)
        per_chunk = max(1, CHUNK // (profiles * max(design.lengths)))
        values = {name: np.empty((GRID.size, design.replicates)) for name in missing}
        for index, hurst in enumerate(GRID):
            rng = np.random.default_rng([design.seed, index])
            for start in range(0, design.replicates, per_chunk):
                count = min(per_chunk, design.replicates - start)
                padded = design.synthetic(hurst, rng, count)
                groups = np.arange(count) * profiles
                for name in missing:
                    values[name][index, start : start + count] = _raw_values(name, padded, groups, design)
        for name in missing:
            mean = _smoothed(np.pad(values[name].mean(axis=1), 1, mode="reflect", reflect_type="odd"))
            variance = _smoothed(np.pad(values[name].var(axis=1, ddof=1), 1, mode="edge"))
            _CURVES[name, design] = Curve(mean, np.sqrt(variance), design.replicates)
    return {name: _CURVES[name, design] for name in names}


def _smoothed(padded):
    return np.convolve(padded, np.ones(3) / 3, "valid")


def default_replicates(profiles, name):
    """Replicates per grid H when none are given: :data:`POINT_BUDGET` heights per grid H
    within :data:`REPLICATES`; for ``whittle`` (one numerical optimisation per replicate)
    :data:`WHITTLE_BUDGET` heights within :data:`WHITTLE_REPLICATES`."""
    total = sum(profile.size for profile in profiles)
    budget, limits = (WHITTLE_BUDGET, WHITTLE_REPLICATES) if name == "whittle" else (POINT_BUDGET, REPLICATES)
    return int(np.clip(budget // total, *limits))


def invert(curve, raw, floor=0.0):
    """``(hurst, (low, high), at_bound)`` from a raw value: the inverse of the mean curve
    (made non-decreasing by a running maximum) and the H whose mean ± 1.96 SD holds the
    raw value, on a fine linear interpolation of the curve; the SD is the curve's or
    ``floor``, whichever is larger at each H."""
    fine = np.linspace(GRID[0], GRID[-1], 2001)
    mean = np.interp(fine, GRID, np.maximum.accumulate(curve.mean))
    spread = QUANTILE * np.maximum(np.interp(fine, GRID, curve.sd), floor)
    at_bound = "low" if raw < mean[0] else "high" if raw > mean[-1] else None
    hurst = float(np.interp(raw, mean, fine))
    inside = np.abs(raw - mean) <= spread
    interval = (float(fine[inside].min()), float(fine[inside].max())) if inside.any() else (hurst, hurst)
    return hurst, interval, at_bound


def block_spread(name, profiles, spacing, scales, positions, noisy=True):
    """The delete-one-block jackknife SD of the raw Ĥ (the Whittle fit with a noise
    floor only for ``noisy`` data), or None with too few profiles for the blocks of
    :func:`rough.fractal.jackknife.neighbour_blocks` (the blocks of neighbours whose
    jackknife gives the pooled fit's standard errors)."""
    positions = np.asarray(positions, dtype=float)
    if positions.shape != (len(profiles),) or not np.isfinite(positions).all():
        raise InputError("positions must give one finite offset per profile")
    blocks = neighbour_blocks(positions)
    if blocks is None:
        return None
    leave_out = []
    for block in blocks:
        kept = np.setdiff1d(np.arange(len(profiles)), block)
        leave_out.append(_estimate(name, [profiles[i] for i in kept], spacing, scales, noisy).hurst)
    return float(math.sqrt(jackknife_variance(leave_out)))


def calibrated(
    name,
    heights,
    spacing,
    scales=None,
    noise_rms=None,
    replicates=None,
    seed=0,
    order=1,
    positions=None,
    sampling="point",
):
    """H from estimator ``name``, corrected for its bias, with a 95 % confidence interval.

    Parameters
    ----------
    name : str
        An estimator of :data:`rough.fractal.ESTIMATORS`.
    heights : list of 1-D arrays
        Finite heights (m) with their form removed; NaN is refused (give finite runs).
    spacing : float
        Sampling step, m.
    scales : (float, float), optional
        The estimator's scale range, m (None: its default).
    noise_rms : float, optional
        RMS of white measurement noise in the heights, m; the synthetic fBm is scaled so that
        its one-sample increments plus the noise's match the data's (:func:`relative_noise`).
    replicates : int, optional
        Synthetic replicates per grid H (each one the input's whole set of profiles); None
        gives :func:`default_replicates`.
    seed : int
        Seed of the synthetic data; the result is deterministic from it.
    order : int
        The polynomial order of the form removed from each profile (1: a line), removed
        from the synthetic profiles the same way.
    positions : 1-D array, optional
        Each profile's offset across the direction (m). With at least 8 profiles, the SD
        in the Neyman inversion is, at each H, the larger of the synthetic (independent)
        profiles' and the delete-one-block jackknife SD of the data (16 blocks of
        neighbours, fewer with fewer profiles; :func:`block_spread`).
    sampling : {"point", "band-limited"}, default "point"
        How the data were sampled: point samples of a fractal surface (instruments; the
        synthetic profiles are exact fBm) or band-limited (rough's synthesis and
        resampling; the synthetic profiles are :func:`band_limited_rows`). The Whittle
        fit uses the same model.

    Returns
    -------
    Calibrated
    """
    return compare(heights, spacing, scales, noise_rms, [name], replicates, seed, order, positions, sampling)[0]


def compare(
    heights,
    spacing,
    scales=None,
    noise_rms=None,
    estimators=None,
    replicates=None,
    seed=0,
    order=1,
    positions=None,
    sampling="point",
):
    """:func:`calibrated` for several estimators (None: all of them, in registry order),
    sharing one set of synthetic data among those whose curves are not cached.

    Returns
    -------
    list of Calibrated
        One per estimator, in the order asked. NaN in ``heights`` is refused.
    """
    names = list(est.ESTIMATORS) if estimators is None else list(estimators)
    if sampling not in ("point", "band-limited"):
        raise InputError(f"sampling must be point or band-limited, not {sampling!r}")
    unknown = [name for name in names if name not in est.ESTIMATORS]
    if unknown:
        raise InputError(f"unknown estimator {unknown[0]!r}; the estimators are {', '.join(est.ESTIMATORS)}")
    if not (isinstance(order, (int, np.integer)) and 0 <= order <= 3):
        raise InputError(f"the form order must be 0, 1, 2 or 3, not {order}")
    profiles = est.checked(heights, spacing)
    if replicates is not None and not (isinstance(replicates, (int, np.integer)) and replicates >= 2):
        raise InputError(f"replicates must be an integer of at least 2, not {replicates}")
    raws = {name: _estimate(name, profiles, spacing, scales, noise_rms is not None, sampling) for name in names}
    noise = float(f"{relative_noise(profiles, noise_rms):.3g}")
    designs = {}
    for name in names:
        count = default_replicates(profiles, name) if replicates is None else replicates
        designs.setdefault(count, []).append(name)
    found = {}
    for count, members in designs.items():
        design = Design(
            tuple(sorted(profile.size for profile in profiles)),
            float(spacing),
            None if scales is None else tuple(map(float, scales)),
            int(order),
            noise,
            int(count),
            int(seed),
            sampling,
        )
        found.update({name: (curve, design) for name, curve in curves(members, design).items()})
    results = []
    for name in names:
        raw = raws[name]
        curve, design = found[name]
        jackknife = (
            None
            if positions is None
            else block_spread(name, profiles, spacing, scales, positions, noise_rms is not None)
        )
        hurst, interval, at_bound = invert(curve, raw.hurst, jackknife or 0.0)
        results.append(
            Calibrated(
                name,
                raw.hurst,
                hurst,
                interval,
                raw.hurst - hurst,
                design.replicates,
                _method(raw, design, jackknife, float(np.interp(hurst, GRID, curve.sd))),
                raw.scales,
                at_bound,
            )
        )
    return results


def _method(raw, design, jackknife, bootstrap):
    text = (
        f"{raw.estimator} over {raw.scales[0]:.3g}-{raw.scales[1]:.3g} m ({raw.points} points), "
        f"calibrated on {design.replicates} replicates of exact fBm (circulant embedding) at each of "
        f"{GRID.size} H from {GRID[0]:g} to {GRID[-1]:g}, form order {design.order}, relative noise "
        f"{design.noise:g}; 95 % Neyman interval"
    )
    if jackknife is not None:
        text += f", with the block jackknife SD {jackknife:.3g} where it exceeds the bootstrap's ({bootstrap:.3g} here)"
    return text
