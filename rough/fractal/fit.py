"""Fractal dimension D and amplitude coefficient C from the power spectrum.

Profiles, ``method="whittle"`` (the default): the profile's form is removed (order 1
by default), its first differences are taken (they are stationary for a fractal
profile, and their spectrum is flat enough that no window is needed against
leakage), and the Whittle likelihood of their periodogram is maximised over the
band. The model is the exact spectrum of the differences:
``S(f) = 2A sin²(πfΔ) Σ_m |f + m/Δ|^-β`` for point samples of a fractal surface
(power above the Nyquist frequency folds back), or the m = 0 term alone for
band-limited data (what rough's ``synth`` and ``resample`` make: by default the
sampling is read from the surface's history). Unlike a log-log line through the
periodogram, this is unbiased over the whole band, and close to efficient: on
exact fBm of n = 1024 points its scatter in D is the Cramér-Rao bound (0.021 at
D = 1.2, 0.020 at 1.5, 0.015 at 1.8). The standard errors come from the Fisher
information.

Maps: the periodic-Hann-windowed 2-D periodogram, averaged over rings of one
frequency step (leaving out the axis lines, where edges leak, and the lowest eight
rings), is fitted by the gamma (binned Whittle) likelihood of ``P2 = C2 |f|^-(8-2Ds)``,
with the window's known smoothing of a power law in the model. By default the band
stops at the Nyquist frequency for band-limited data and for profiles, at half of it
for point-sampled maps (aliasing is not modelled for maps), and at 80 % of it after
rough's resample (below the roll-off of its anti-aliasing filter).
``sector=(angle, width)`` (radians) restricts the fit to wavevectors within
``width/2`` of ``angle`` (mod 180°), for direction-dependent fits.

Cross-checks for profiles: ``variogram`` (structure function at lags 1 and 2),
``madogram`` (mean absolute difference at lags 1 and 2), and ``loglog`` (the
band-limited, log-binned least-squares line through the Hann periodogram of
docs/math.rst §1.4), with standard errors from 8 blocks.

This module chooses and runs them; the Whittle fits live in
:mod:`rough.fractal.whittle`, the cross-checks in :mod:`rough.fractal.cross_checks` and
the result in :mod:`rough.fractal.result`.
"""

import logging

import numpy as np

from .. import units
from ..errors import InputError
from ..metrology import detrend
from .cross_checks import CROSS_CHECKS
from .filling import fill_invalid
from .result import announce
from .scales import reliability_cutoff, scale_dependent
from .whittle import (
    SAMPLINGS,
    Options,
    default_top,
    history_sampling,
    map_band,
    refuse_flat,
    sampling_of,
    whittle_map,
    whittle_profile,
)

log = logging.getLogger("rough")
METHODS = ("whittle", *CROSS_CHECKS)
#: Why a spectrum refuses a surface with invalid points, naming the keyword and the option that fill them.
GAPS_REFUSED = "the spectrum needs gap-free data: this surface has invalid points (fill them: fill=True, or --fill)"
TIP_SPAN = 8  # a tip's cut-off must leave this many wavelengths of the scan length to fit


def fit_fractal(
    surface,
    band=None,
    resolution=None,
    method="whittle",
    order=1,
    sampling=None,
    sector=None,
    noise=True,
    rolloff=False,
    level=0.01,
    tip_radius=None,
    fill=False,
):
    """The fractal dimension D (Ds for maps) and amplitude coefficient C of a surface.

    Parameters
    ----------
    surface : Surface
        A profile or map; a spectrum needs gap-free data, so invalid (NaN) points
        are refused unless ``fill`` fills them.
    band : tuple of (float or None), optional
        ``(fmin, fmax)`` in 1/m. With both ends given, exactly that band is fitted.
        Otherwise (the default) the band is the scaling range: the widest band of at
        least a decade inside the limits (the given end, else from the lowest
        frequency, for maps the fourth ring, up to the Nyquist frequency for profiles
        and band-limited maps, half of it for point-sampled maps, 80 % of it after
        rough's resample) over which the local exponent stays within 0.1 in H (plus
        three of its standard errors) of the band's (docs/math.rst §1.8).
    resolution : float, optional
        The η in metres at which C is stated; default the (smaller) spacing.
    method : {"whittle", "variogram", "madogram", "loglog"}, default "whittle"
        The Whittle likelihood of the spectrum, or (profiles only) one of the
        cross-checks: the structure function or the mean absolute difference at lags
        1 and 2, or a least-squares line through the log-binned Hann periodogram.
    order : int, default 1
        The degree of the polynomial form removed first.
    sampling : {"point", "band-limited"}, optional
        Whether power above the Nyquist frequency folded back when the data were
        sampled (``point``) or not (``band-limited``: what rough's synthesis and
        resampling make). Default: band-limited when the surface's history says rough
        made its spectrum; otherwise, for profiles, chosen by likelihood (point
        samples unless band-limited is likelier by 1.5 in log-likelihood) and, for
        maps, point samples with the band stopping at half the Nyquist frequency.
    sector : tuple of float, optional
        Maps only: ``(angle, width)`` in radians, to fit only the wavevectors within
        ``width/2`` of ``angle`` (mod 180°).
    noise : bool, default True
        Fit a white noise floor along with the power law (kept when the likelihood
        ratio against no floor passes its 0.1 % test and the floor rises above the
        power law inside the band); its RMS is reported in metres.
    rolloff : bool, default False
        Also fit a Gaussian short-wavelength roll-off ``exp(-(f/fc)²)`` of the power
        law (a tip's or the optics' transfer); 1/fc is reported.
    level : float, default 0.01
        The level of the goodness-of-fit diagnostic: a fit band whose p-value falls
        below it is logged (at info level) as departing from the model by more than
        chance. It does not choose the band.
    tip_radius : float, optional
        The radius of the stylus tip, metres: the frequencies above 1/λc, where the
        tip cannot follow the surface (:func:`rough.fractal.scales.reliability_cutoff`,
        along x for a map), are left out of the fit, and λc is reported.
    fill : bool, default False
        Fill invalid points first (:func:`rough.fractal.fill_invalid`: linear along
        a profile, biharmonic in a map), as ``rough fit-fractal --fill`` does; the
        fill is recorded in the surface's history.

    Returns
    -------
    FractalFit
        D (or Ds), C, their standard errors, and what the fit used; without a
        power-law range, the roughness against scale instead.

    Raises
    ------
    rough.InputError
        For invalid points without ``fill``, an unknown method or sampling, a sector
        for a profile, a method other than Whittle for a map, a surface that is flat once its form is
        removed, too few frequencies (8) or rings (4) in the band, a tip radius that
        is not positive or given with the variogram or madogram, or a tip whose
        reliability cut-off exceeds an eighth of the scan's length.

    Notes
    -----
    Profiles: the Whittle likelihood of the periodogram of the first differences
    under their exact spectrum, ``2A sin²(πfΔ) Σ_m |f + m/Δ|^-β`` for point samples
    (the m = 0 term alone for band-limited data); standard errors from the Fisher
    information. Maps: the gamma (binned Whittle) likelihood of the ring-averaged,
    Hann-windowed periodogram, the axis lines and the lowest eight rings left out.
    A fitted exponent at the edge of the fractal range is warned about: the data do
    not follow a power law in the band.

    Examples
    --------
    The sample profile was synthesised with D = 1.3; its history says it is
    band-limited:

    >>> import rough
    >>> from rough.fractal.fit import fit_fractal
    >>> scan = rough.read(rough.sample("rock-profile.tsv"))
    >>> fit = fit_fractal(scan)
    >>> fit.sampling, round(fit.fractal_dimension, 2), fit.frequencies_used
    ('band-limited', 1.31, 1023)
    >>> [f"{f * 1e-3:.3f}/mm" for f in fit.band]  # 1/L to the Nyquist frequency
    ['0.016/mm', '16.173/mm']

    A map (Ds = 2.3 by design) needs its invalid points filled first:

    >>> scan = rough.read(rough.sample("rock-map.x3p"))
    >>> try:
    ...     fit_fractal(scan)
    ... except rough.InputError as error:
    ...     print(error)
    the spectrum needs gap-free data: this surface has invalid points (fill them: fill=True, or --fill)
    >>> fit = fit_fractal(scan, fill=True)
    >>> print(f"Ds = {fit.fractal_dimension:.2f} ± {fit.fractal_dimension_stderr:.2f}, D = {fit.profile_dimension:.2f}")
    Ds = 2.34 ± 0.03, D = 1.34
    """
    if method not in METHODS:
        raise InputError(f"method must be one of {', '.join(METHODS)}, not {method!r}")
    surface = fill_invalid(surface) if fill else surface
    if np.isnan(surface.heights).any():
        raise InputError(GAPS_REFUSED)
    if sampling is not None and sampling not in SAMPLINGS:
        raise InputError(f"sampling must be one of {', '.join(SAMPLINGS)}, not {sampling!r}")
    if not 0 < level < 1:
        raise InputError(f"the test's level must lie between 0 and 1, not {level}")
    if tip_radius is not None and not tip_radius > 0:
        raise InputError(f"the tip radius must be positive, not {tip_radius} m")
    if tip_radius is not None and method in ("variogram", "madogram"):
        raise InputError(f"the {method} uses lags of 1 and 2 samples only: with a tip radius use whittle or loglog")
    options = Options(noise, rolloff, level)
    source = "option" if sampling else "history" if history_sampling(surface) else None
    sampling = sampling or sampling_of(surface)
    resolution = resolution or min(surface.spacing)
    if surface.is_profile and sector is not None:
        raise InputError("a direction (sector) needs a map")
    if not surface.is_profile and method != "whittle":
        raise InputError(f"maps are fitted by the Whittle method only, not {method}")
    levelled = detrend(surface, order=order).heights if surface.is_profile or tip_radius is not None else None
    if surface.is_profile:
        refuse_flat(levelled, surface.heights)
    cutoff = None if tip_radius is None else tip_cutoff(levelled, surface, tip_radius)
    if cutoff is not None:
        band = below_cutoff(surface, band, sampling, cutoff)
    if surface.is_profile and method != "whittle":
        fit = CROSS_CHECKS[method](levelled, surface.spacing[0], band, resolution, sampling)
    elif surface.is_profile:
        fit = whittle_profile(levelled, surface, band, resolution, (sampling, source), options)
    else:
        del levelled
        fit = whittle_map(surface, order, band, resolution, (sampling, source or "maps: band"), sector, options)
    fit.reliability_cutoff = cutoff
    if sector is not None:
        return fit
    if fit.verdict == "no power-law range":
        fit.scale_dependent = _roughness_by_scale(surface, order, cutoff)
    return announce(fit, level)


def tip_cutoff(levelled, surface, tip_radius):
    """The reliability cut-off of a tip over the levelled heights (a map's rows), m, or
    None; refused when the tip follows the surface at no scale."""
    heights = levelled if surface.is_profile else np.atleast_2d(levelled)
    cutoff = reliability_cutoff(heights, surface.spacing[0], tip_radius)
    length = heights.shape[-1] * surface.spacing[0]
    if cutoff is not None and cutoff > length / TIP_SPAN:
        raise InputError(
            f"a tip of radius {units.format_length(tip_radius, 4)} cannot follow this surface below "
            f"{units.format_length(cutoff, 4)}, more than 1/{TIP_SPAN} of the scan's length along x "
            f"({units.format_length(length, 4)}): too few scales are left to fit"
        )
    if cutoff is not None:
        log.warning(
            f"a tip of radius {units.format_length(tip_radius, 4)} cannot follow the surface below "
            f"{units.format_length(cutoff, 4)} (the curvature criterion): frequencies above "
            f"{units.format_quantity(1 / cutoff, '1/m', 4)} are left out of the fit"
        )
    return cutoff


def below_cutoff(surface, band, sampling, cutoff):
    """``band`` with its top at most 1/``cutoff`` (an open top set to the default's)."""
    low, high = band or (None, None)
    if high is None:
        nyquist = 0.5 / surface.spacing[0]
        high = default_top(surface, nyquist, sampling) if surface.is_profile else map_band(surface, None, sampling)[2]
    return (low, min(high, 1.0 / cutoff))


def _roughness_by_scale(surface, order, cutoff):
    """The scale-dependent roughness of the levelled surface (a map's rows), from the
    reliability cut-off up."""
    table = scale_dependent(detrend(surface, order=order).heights, surface.spacing[0], cutoff=cutoff)
    return {**table, "direction": "profile" if surface.is_profile else "x"}
