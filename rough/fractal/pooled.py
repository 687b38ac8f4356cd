"""The pooled Whittle fit of profiles: the Whittle likelihood is a sum over
periodogram ordinates, so the profiles' likelihoods add. The periodograms of their
first differences are pooled, ordinate by ordinate (profiles of any length, each at
its own frequencies; ordinates of equal frequency are merged into one bin of their
mean, which leaves the likelihood unchanged), and fitted as one profile is by
:func:`~rough.fractal.fit_fractal` (docs/math.rst §1.9).
"""

import math

import numpy as np

from ..errors import InputError
from .scaling import fit_spectrum, profile_bins
from .whittle import BETA_RANGE, difference_periodogram

MIN_ORDINATES = 8


def periodograms(heights, spacing):
    """Each profile's periodogram of first differences, ``(f, I)``."""
    return [difference_periodogram(profile, spacing) for profile in heights]


def pooled(periodograms, spacing, band, sampling, effect=1.0):
    """:class:`~rough.fractal.scaling.Bins` of the periodograms' ordinates in ``band``
    (``low ≤ f ≤ high``; each periodogram ``(f, I)``, or ``(f, ΣI, n)``: n ordinates at
    f summing to ΣI), one bin per distinct frequency holding the mean of its
    ordinates (the Whittle likelihood of equal-frequency ordinates is that of their
    mean with their count as weight), the weight divided by the design ``effect``;
    None with fewer than MIN_ORDINATES frequencies."""
    low, high = band
    frequencies = np.concatenate([f for f, *_ in periodograms])
    ordinates = np.concatenate([values for _, values, *_ in periodograms])
    keep = (frequencies >= low) & (frequencies <= high)
    distinct, inverse, count = np.unique(frequencies[keep], return_inverse=True, return_counts=True)
    if any(len(periodogram) > 2 for periodogram in periodograms):  # sums of several ordinates, with their counts
        counts = np.concatenate([(*rest, np.ones(f.size, np.int64))[0] for f, _, *rest in periodograms])
        count = np.bincount(inverse, weights=counts[keep]).astype(np.int64)
    if distinct.size < MIN_ORDINATES:
        return None
    bins = profile_bins(distinct, spacing, np.bincount(inverse, weights=ordinates[keep]) / count, sampling)
    bins.count, bins.weight = count, count / effect
    return bins


def whittle_hurst(heights, spacing, scales=None, sampling="point", noise=True):
    """H of the pooled Whittle fit of profiles over a band, without a band search.

    Parameters
    ----------
    heights : list of numpy.ndarray
        The profiles (1-D arrays of finite heights, metres, form removed); a single
        1-D array is one profile.
    spacing : float
        The spacing along the profiles, metres.
    scales : tuple of float, optional
        ``(λmin, λmax)``, the wavelengths fitted, metres; None fits every frequency
        from the lowest to the Nyquist frequency.
    sampling : {"point", "band-limited"}, default "point"
        The spectral model, as for :func:`~rough.fractal.fit_fractal`.
    noise : bool, default True
        Fit a white noise floor too (kept when the likelihood ratio finds it; the
        profiles count as independent here: no design effect).

    Returns
    -------
    float
        The Hurst exponent H = (β - 1)/2 of the fitted exponent β, in (0, 1) (on an
        end of it when the exponent is at a bound).

    Raises
    ------
    rough.InputError
        For NaN heights, a band outside (0, ∞) or reversed, or fewer than 8
        frequencies in the band.

    Examples
    --------
    >>> import numpy as np
    >>> from rough.fractal.pooled import whittle_hurst
    >>> walk = np.cumsum(np.random.default_rng(1).standard_normal((4, 4096)), axis=1)
    >>> round(whittle_hurst(list(walk), 1e-6), 1)  # Brownian motion: H = 1/2
    0.5
    """
    heights = [heights] if isinstance(heights, np.ndarray) and heights.ndim == 1 else heights
    if not all(np.isfinite(profile).all() for profile in heights):
        raise InputError("the profiles hold invalid (NaN) heights; take them through take_profiles first")
    band = _band_of_scales(scales)
    bins = pooled(periodograms(heights, spacing), spacing, band, sampling)
    if bins is None:
        raise InputError("fewer than 8 frequencies in the band; widen it or use longer profiles")
    return (fit_spectrum(bins, BETA_RANGE, noise).exponent - 1.0) / 2.0


def _band_of_scales(scales):
    if scales is None:
        return 0.0, math.inf
    shortest, longest = scales
    if not 0 < shortest < longest:
        raise InputError(f"the wavelengths must be 0 < λmin < λmax, not {shortest:g}, {longest:g}")
    return 1.0 / longest, 1.0 / shortest
