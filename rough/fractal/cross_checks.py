"""The cross-checks of a profile's D: the structure function (``variogram``) and the
mean absolute difference (``madogram``) at lags 1 and 2, and a least-squares line
through the log-binned Hann periodogram (``loglog``, docs/math.rst §1.4), with
standard errors from 8 blocks of the profile. :data:`CROSS_CHECKS` maps each name to
its estimator, called as ``estimate(heights, spacing, band, resolution, sampling)``.
"""

import math

import numpy as np

from . import model
from .psd import log_bins, periodogram
from .result import FractalFit
from .scaling import at_bound
from .whittle import BETA_RANGE, band_of, in_band


def _result(beta, prefactor, resolution, band, method, window, sampling, count):
    """A cross-check's result: the exponent clamped to the fractal range (a bound is
    reported as such), the errors filled in by the caller."""
    beta = min(max(beta, BETA_RANGE[0]), BETA_RANGE[1])
    dimension = (5.0 - beta) / 2.0
    amplitude = model.amplitude(prefactor, dimension, resolution)
    bound = at_bound(beta, BETA_RANGE)
    return FractalFit(
        fractal_dimension=dimension,
        fractal_dimension_stderr=math.nan,
        amplitude_coefficient=amplitude,
        amplitude_coefficient_stderr=math.nan,
        resolution=resolution,
        psd_prefactor=prefactor,
        hurst=2.0 - dimension,
        band=band,
        method=method,
        window=window,
        sampling=sampling,
        frequencies_used=count,
        structure_function_coefficient=amplitude / model.structure_factor(dimension),
        verdict="at bound" if bound else "power law",
        at_bound=bound,
        fit_band=band,
    )


def _lag_statistic(heights, lag, statistic):
    steps = heights[lag:] - heights[:-lag]
    return float(np.mean(steps**2)) if statistic == "variogram" else float(np.mean(np.abs(steps)))


def _lag_fit(heights, spacing, resolution, statistic):
    """H from lags 1 and 2 (S ∝ τ^2H, or mean |Δ| ∝ τ^H), and C via the structure
    function at one sample (for the madogram, S = (π/2) mean|Δ|², Gaussian)."""
    ratio = _lag_statistic(heights, 2, statistic) / _lag_statistic(heights, 1, statistic)
    hurst = math.log2(ratio) / (2.0 if statistic == "variogram" else 1.0)
    dimension = min(max(2.0 - hurst, 1.0 + 1e-6), 2.0 - 1e-6)
    first = _lag_statistic(heights, 1, statistic)
    structure = first if statistic == "variogram" else math.pi / 2 * first**2
    structure_coefficient = structure * spacing ** (2 * dimension - 4) * resolution ** (3 - 2 * dimension)
    return dimension, structure_coefficient * model.structure_factor(dimension)


def _blocks(heights, estimate, count=8):
    values = [estimate(part) for part in np.array_split(heights, count) if part.size > 16]
    return float(np.std(values, ddof=1) / math.sqrt(len(values))) if len(values) > 1 else math.nan


def _lag_result(heights, spacing, resolution, statistic, sampling):
    dimension, amplitude = _lag_fit(heights, spacing, resolution, statistic)
    error = _blocks(heights, lambda part: _lag_fit(part, spacing, resolution, statistic)[0])
    fit = _result(
        5.0 - 2.0 * dimension,
        model.prefactor(amplitude, dimension, resolution),
        resolution,
        (1 / (2 * spacing), 1 / spacing),
        statistic,
        "none",
        sampling,
        2,
    )
    fit.fractal_dimension_stderr = None if fit.at_bound else error
    return fit


def variogram(heights, spacing, band, resolution, sampling):
    return _lag_result(heights, spacing, resolution, "variogram", sampling)


def madogram(heights, spacing, band, resolution, sampling):
    return _lag_result(heights, spacing, resolution, "madogram", sampling)


def _loglog_estimate(heights, spacing, band):
    """docs/math.rst §1.4: a least-squares line through the log-binned Hann periodogram over
    the band (default: leaving out k ≤ 2 and the top quarter below Nyquist).
    Returns ``(β, A, band used, frequencies used)``."""
    frequencies, density, _ = periodogram(heights, spacing, "hann")
    low, high = band or (3 / (heights.size * spacing), 0.75 * 0.5 / spacing)
    keep = in_band(frequencies, (low, high)) & (frequencies > 0)
    centres, means, _ = log_bins(frequencies[keep], density[keep])
    slope, intercept = np.polyfit(np.log10(centres), np.log10(means), 1)
    return -slope, 10.0**intercept, band_of(frequencies[keep]), int(keep.sum())


def loglog(heights, spacing, band, resolution, sampling):
    beta, prefactor, used, count = _loglog_estimate(heights, spacing, band)
    fit = _result(
        beta,
        prefactor,
        resolution,
        used,
        "loglog (log-binned, band-limited)",
        "hann",
        sampling,
        count,
    )
    error = _blocks(heights, lambda part: (5.0 - _loglog_estimate(part, spacing, None)[0]) / 2)
    fit.fractal_dimension_stderr = None if fit.at_bound else error
    return fit


#: The cross-check methods of :func:`rough.fractal.fit_fractal`, by name.
CROSS_CHECKS = {"variogram": variogram, "madogram": madogram, "loglog": loglog}
