"""The uncertainty of the pooled fit of a map's profiles: neighbouring profiles are
correlated, so the Fisher information overstates what they know. The likelihood's
weights are divided by the design effect (how many profiles count as one independent
profile), and the standard errors of H, D and C come from a delete-one-block jackknife
over blocks of neighbouring profiles; the per-profile spread is the standard
deviation of the profiles' own H over the same band (docs/math.rst §1.9).
"""

import math

import numpy as np

from . import model
from .pooled import pooled
from .scaling import at_bound, fit_spectrum
from .whittle import BETA_RANGE

JACKKNIFE_BLOCKS = 16  # at most; at least MIN_BLOCKS
MIN_BLOCKS = 8


def neighbour_blocks(positions):
    """The profiles' indices in blocks of neighbours (sorted by position, ties in the
    given order): JACKKNIFE_BLOCKS of them, one profile each between MIN_BLOCKS and
    JACKKNIFE_BLOCKS profiles; None with fewer than MIN_BLOCKS profiles."""
    order = np.argsort(positions, kind="stable")
    count = min(JACKKNIFE_BLOCKS, order.size)
    return np.array_split(order, count) if count >= MIN_BLOCKS else None


def _replicates(periodograms, blocks, spacing, band, sampling, noise, rolloff):
    """The fit over ``band`` without each block of profiles in turn (a block without
    which fewer than 8 frequencies remain gives none); None when fewer than
    MIN_BLOCKS fits result."""
    fits = []
    for block in blocks:
        left = np.ones(len(periodograms), bool)
        left[block] = False
        bins = pooled([periodograms[i] for i in np.flatnonzero(left)], spacing, band, sampling)
        if bins is not None:
            fits.append(fit_spectrum(bins, BETA_RANGE, noise, rolloff))
    return fits if len(fits) >= MIN_BLOCKS else None


def jackknife_variance(values):
    """The delete-one jackknife variance of the estimates ``values`` (one per left-out
    block; along the first axis)."""
    values = np.asarray(values, dtype=np.float64)
    count = values.shape[0]
    return (count - 1) / count * np.sum((values - values.mean(axis=0)) ** 2, axis=0)


def design_effect(periodograms, blocks, spacing, band, sampling):
    """How many profiles count as one independent profile: the jackknife's variance of
    the exponent over the Fisher information's, in the power law's fit (no floor) over
    every frequency of ``band``; between 1 and the number of profiles (1 without
    blocks)."""
    if blocks is None:
        return 1.0
    whole = fit_spectrum(pooled(periodograms, spacing, band, sampling), BETA_RANGE, False)
    if at_bound(whole.exponent, BETA_RANGE):
        return 1.0
    replicates = _replicates(periodograms, blocks, spacing, band, sampling, False, False)
    if replicates is None:
        return 1.0
    ratio = jackknife_variance([fit.exponent for fit in replicates]) / whole.covariance[1, 1]
    return float(min(max(ratio, 1.0), len(periodograms)))


def uncertainty(profiles, periodograms, blocks, outcome, fit, sampling, options, spread=True):
    """The standard errors of H (= those of D) and C, how they were found, and the
    per-profile spread of H over the band fitted."""
    nan = {"hurst": math.nan, "amplitude": math.nan, "spread": math.nan, "method": "none (no fit)"}
    if outcome.fit is None:
        return nan
    band = outcome.band
    spread = _spread(periodograms, profiles.spacing, band, sampling) if spread else math.nan
    if outcome.verdict == "at bound":
        return {**nan, "hurst": None, "amplitude": None, "spread": spread, "method": "none (at a bound)"}
    floor = options.noise and bool(outcome.fit.noise_variance)
    replicates = blocks and _replicates(periodograms, blocks, profiles.spacing, band, sampling, floor, options.rolloff)
    if not replicates:
        method = f"Fisher information (too few profiles for a jackknife of {MIN_BLOCKS} blocks over the band)"
        errors = (fit.fractal_dimension_stderr, fit.amplitude_coefficient_stderr)
        return {"hurst": errors[0], "amplitude": errors[1], "spread": spread, "method": method}
    estimates = []
    for replicate in replicates:
        dimension = (5.0 - replicate.exponent) / 2.0
        estimates.append((dimension, math.log(model.amplitude(replicate.prefactor, dimension, fit.resolution))))
    variance = jackknife_variance(estimates)
    return {
        "hurst": float(math.sqrt(variance[0])),
        "amplitude": float(fit.amplitude_coefficient * math.sqrt(variance[1])),
        "spread": spread,
        "method": f"delete-one-block jackknife ({len(replicates)} blocks of neighbouring profiles)",
    }


def _spread(periodograms, spacing, band, sampling):
    """The standard deviation of the profiles' own H over ``band`` (no noise floor);
    NaN with fewer than two profiles of 8 frequencies there. A profile flat over the
    band (no power at all: a constant run) has no H and is left out."""
    values = []
    for periodogram in periodograms:
        bins = pooled([periodogram], spacing, band, sampling)
        if bins is not None and np.any(bins.density > 0):
            values.append((fit_spectrum(bins, BETA_RANGE, False).exponent - 1.0) / 2.0)
    return float(np.std(values, ddof=1)) if len(values) > 1 else math.nan
