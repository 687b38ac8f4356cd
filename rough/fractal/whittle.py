"""The Whittle fits of a spectrum: a profile's first differences under the exact
spectrum of sampled fractal data (point or band-limited, the likelier kept), and a
map's ring-averaged 2-D periodogram (for the whole map, or a sector of it for the
rose); the default limits of the band, and the sampling read from a surface's history.
"""

import dataclasses
import math

import numpy as np

from ..compiled import one_blas_thread
from ..errors import InputError
from .choices import SAMPLINGS
from .psd import ring_spectrum, windowed_map
from .result import Settings, dimension_and_amplitude, from_outcome
from .scaling import (
    at_bound,
    conclude,
    decades,
    fit_band,
    fit_spectrum,
    profile_bins,
    ring_bins,
    scaling_range,
    scaling_ranges,
)

BETA_RANGE = (1.0 + 1e-6, 3.0 - 1e-6)
MAP_RANGE = (BETA_RANGE[0] + 1.0, BETA_RANGE[1] + 1.0)
LOWEST_RING = 4
RESAMPLED_TOP = 0.8
EVIDENCE = 1.5  # log-likelihood units in favour of band-limited data before point samples are given up
FLAT = 1e-9  # RMS residual below this fraction of the largest height is rounding, not roughness


def sampling_of(surface):
    """``"band-limited"`` when rough made the surface's spectrum (synth, resample),
    ``"point"`` otherwise."""
    return history_sampling(surface) or "point"


def default_top(surface, nyquist, sampling):
    """The default top of the fit band: 80 % of the Nyquist frequency after rough's
    resample (its anti-aliasing filter rolls off above that), the Nyquist frequency
    for other band-limited data, and half of it for point-sampled maps."""
    if any(entry.get("command") == "resample" for entry in surface.history):
        return RESAMPLED_TOP * nyquist
    return nyquist if sampling == "band-limited" or surface.is_profile else nyquist / 2


@dataclasses.dataclass
class Options:
    """The spectral model's options: a white noise floor (kept when the likelihood
    ratio finds it), a Gaussian roll-off, and the goodness-of-fit test's level."""

    noise: bool = True
    rolloff: bool = False
    level: float = 0.01


def history_sampling(surface):
    """``"band-limited"`` when the surface's history says rough made its spectrum
    (synth, resample), None when it does not say."""
    made = {entry.get("command") for entry in surface.history}
    return "band-limited" if made & {"synth", "resample"} else None


@one_blas_thread
def band_outcome(bins, exponent_range, band, options):
    """The fit over ``band`` when both its ends are given, else over the scaling range
    found inside ``bins`` (see :mod:`rough.fractal.scaling`)."""
    if band is not None and None not in band:
        return fit_band(bins, exponent_range, options.noise, options.rolloff)
    return scaling_range(bins, exponent_range, noise=options.noise, rolloff=options.rolloff)


# -- profiles: Whittle on the differences ------------------------------------------------


def difference_periodogram(heights, spacing):
    """``(f, I)``: the two-sided periodogram Δ/m |DFT|² of the first differences at
    0 < f < the Nyquist frequency (1/m, m²·m)."""
    differences = np.diff(heights)
    m = differences.size
    transform = np.fft.rfft(differences)
    k = np.arange(1, (m - 1) // 2 + 1)
    return k / (m * spacing), spacing / m * np.abs(transform[k]) ** 2


@one_blas_thread
def whittle_profile(heights, surface, band, resolution, sampling, options):
    """The Whittle fit of a levelled profile's ``heights`` over ``band`` (its scaling
    range when an end is open), ``sampling`` a pair (model, where it came from; None:
    both models fitted, the likelier kept): a :class:`~rough.fractal.result.FractalFit`."""
    spacing = surface.spacing[0]
    frequencies, ordinates = difference_periodogram(heights, spacing)
    top = default_top(surface, 0.5 / spacing, sampling[0])
    keep = in_band(frequencies, ((band or (None, None))[0], top if band is None or band[1] is None else band[1]))
    if keep.sum() < 8:
        raise InputError(f"only {keep.sum()} frequencies in the fit band; widen --band or use more points")
    frequencies, ordinates = frequencies[keep], ordinates[keep]
    sampling, source = sampling
    samplings = SAMPLINGS if source is None else (sampling,)
    models = {name: profile_bins(frequencies, spacing, ordinates, name) for name in samplings}
    if band is not None and None not in band:
        outcomes = {name: band_outcome(bins, BETA_RANGE, band, options) for name, bins in models.items()}
    else:
        outcomes = scaling_ranges(models, BETA_RANGE, noise=options.noise, rolloff=options.rolloff)
    sampling, outcome, spread = _likelier(outcomes, spacing, options)
    return from_outcome(
        outcome,
        "profile",
        resolution,
        Settings(
            "whittle",
            "none (first differences)",
            sampling,
            source or "likelihood",
            spread,
            len(outcome.fit.bins) if outcome.fit else int(keep.sum()),
        ),
    )


@one_blas_thread
def _likelier(outcomes, spacing, options):
    """``(sampling, outcome, spread)``: of the samplings' outcomes, the one with the
    better verdict and the wider band; over its band both sampling models are then
    fitted without a noise floor (two parameters each, so their likelihoods compare
    directly: a floor could stand in for the folded power). Instruments take point
    samples, so band-limited is chosen only when its log-likelihood is larger by
    EVIDENCE and its exponent is not on a bound; the model chosen then gets its floor
    if the likelihood ratio finds one. When the log-likelihoods
    differ by less than 1, half the difference of their exponents is ``spread``
    (added to the standard error)."""
    rank = {"power law": 2, "at bound": 1, "no power-law range": 0}

    def quality(item):
        outcome = item[1]
        return rank[outcome.verdict], decades(*outcome.band) if outcome.band else 0.0

    sampling, outcome = max(outcomes.items(), key=quality)
    if len(outcomes) == 1 or outcome.fit is None:
        return sampling, outcome, 0.0
    frequencies, density = outcome.fit.bins.frequency, outcome.fit.bins.density
    plain = {
        name: fit_spectrum(profile_bins(frequencies, spacing, density, name), BETA_RANGE, False, options.rolloff)
        for name in SAMPLINGS
    }
    likelier = "band-limited" if plain["point"].nll - plain["band-limited"].nll > EVIDENCE else "point"
    if at_bound(plain[likelier].exponent, BETA_RANGE):
        likelier = sampling
    close = abs(plain["point"].nll - plain["band-limited"].nll) < 1
    spread = abs(plain["point"].exponent - plain["band-limited"].exponent) / 2 if close else 0.0
    if likelier == sampling:
        return sampling, outcome, spread
    fit = fit_spectrum(
        profile_bins(frequencies, spacing, density, likelier), BETA_RANGE, options.noise, options.rolloff
    )
    grid = fit.bins.grouped() if outcome.automatic else None
    return likelier, conclude(fit, BETA_RANGE, outcome.best_p, grid), spread


def refuse_flat(residual, heights):
    """Refuse a surface with no roughness left once its form is removed (a constant or
    a plane): its spectrum is rounding noise, and any D fitted to it is meaningless."""
    if not np.linalg.norm(residual) / math.sqrt(residual.size) > FLAT * np.max(np.abs(heights)):
        raise InputError("the surface is flat once its form is removed: there is no roughness to fit")


def in_band(frequencies, band):
    low, high = band or (None, None)
    keep = np.ones(frequencies.shape, bool)
    if low is not None:
        keep &= frequencies >= low
    if high is not None:
        keep &= frequencies <= high
    return keep


def band_of(frequencies):
    return (float(frequencies.min()), float(frequencies.max()))


def map_band(surface, band, sampling):
    """``(step, low, high)`` of a map's ring fit (1/m): the ring spacing (the coarser of
    the two axes' frequency steps) and ``band`` with its open ends set to the defaults,
    from the LOWEST_RING-th ring up to :func:`default_top` of the smaller Nyquist frequency."""
    ny, nx = surface.heights.shape
    dx, dy = surface.spacing
    step = max(1 / (nx * dx), 1 / (ny * dy))
    low, high = band or (None, None)
    low = LOWEST_RING * step if low is None else low
    high = default_top(surface, min(0.5 / dx, 0.5 / dy), sampling) if high is None else high
    return step, low, high


@one_blas_thread
def whittle_map(surface, order, band, resolution, sampling, sector, options):
    """The ring-binned Whittle fit of a map's windowed 2-D periodogram (only the
    wavevectors of ``sector``, if given): a :class:`~rough.fractal.result.FractalFit`."""
    step, low, high = map_band(surface, band, sampling[0])
    field, power = windowed_map(surface, order)
    refuse_flat(field, surface.heights)
    rings = ring_spectrum(field, power, surface.spacing, low, high, step, sector)
    del field
    method = "whittle (ring-binned 2-D periodogram)" + ("" if sector is None else ", sector")
    return fit_rings(rings, surface.spacing, band, resolution, sampling, options, method)


def fit_rings(rings, spacing, band, resolution, sampling, options, method):
    """The Whittle fit of a prepared ring spectrum (see
    :func:`~rough.fractal.psd.ring_spectrum`; a tiled map's Welch average, for one) over
    ``band`` (its scaling range when an end is open): a :class:`~rough.fractal.result.FractalFit`."""
    if rings["count"].size < 4:
        raise InputError(f"only {rings['count'].size} frequency rings in the fit band; widen --band")
    outcome = band_outcome(ring_bins(rings, spacing), MAP_RANGE, band, options)
    count = int(outcome.fit.bins.count.sum()) if outcome.fit else int(rings["count"].sum())
    settings = Settings(method, "hann (periodic)", sampling[0], sampling[1], 0.0, count)
    return from_outcome(outcome, "map", resolution, settings)


@one_blas_thread
def ring_fit(bins, resolution, options):
    """A sector's fit (rose): Ds and C (at η = ``resolution``) with standard errors
    (None at a bound), the noise RMS (m, None without a floor) and whether the
    exponent sits at the edge of the fractal range."""
    fit = fit_spectrum(bins, MAP_RANGE, options.noise, options.rolloff)
    values = dimension_and_amplitude(fit, resolution, profile=False)
    bound = at_bound(fit.exponent, MAP_RANGE)
    return {
        "dimension": values["dimension"],
        "dimension_error": None if bound else values["dimension_error"],
        "amplitude": values["amplitude"],
        "amplitude_error": None if bound else values["amplitude_error"],
        "prefactor": float(fit.prefactor),
        "frequencies_used": int(bins.count.sum()),
        "at_bound": bound,
        "noise_rms": math.sqrt(fit.noise_variance) if fit.noise_variance else None,
        "fit": fit,
    }
