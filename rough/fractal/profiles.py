"""Profiles by direction: H, D and C of a map from its 1-D profiles along a direction
(docs/math.rst §1.9), as the fault-roughness literature measures them (Candela et al.
2009, 2012; Renard et al. 2006).

The profiles: ``"x"`` takes the rows, ``"y"`` the columns, an angle θ (radians,
counter-clockwise from +x) parallel sampling lines rotated exactly by θ, spaced by the
smaller grid spacing along and across and covering the map, their heights
interpolated bilinearly (a point whose interpolation stencil touches an invalid point
is invalid). Gaps: each profile's longest run of valid points (``"longest"``), or its
interior gaps filled linearly (``"fill"``, the invalid ends trimmed); profiles shorter
than ``min_points`` are dropped, and each keeps its polynomial form of ``order`` removed.

The fit: the Whittle likelihood is a sum over periodogram ordinates, so the profiles'
likelihoods add. The periodograms of their first differences are pooled, ordinate by
ordinate (profiles of any length, each at its own frequencies; ordinates of equal
frequency are merged into one bin of their mean, which leaves the likelihood
unchanged), and fitted as one profile is by :func:`~rough.fractal.fit.fit_fractal`,
band and all. Neighbouring profiles of a map are correlated, so the Fisher
information overstates what they know: the likelihood's weights are divided by the
design effect (how many profiles count as one independent profile), and the standard
errors of H, D and C come from a delete-one-block jackknife over blocks of
neighbouring profiles. The per-profile spread is the standard deviation of the
profiles' own H over the same band.
"""

import dataclasses
import math

import numpy as np

from ..errors import InputError
from . import model
from .fit import (
    BETA_RANGE,
    RESAMPLED_TOP,
    Options,
    Settings,
    announce,
    band_outcome,
    difference_periodogram,
    from_outcome,
    history_sampling,
    refuse_flat,
)
from .scaling import at_bound, fit_spectrum, profile_bins

GAPS = ("longest", "fill")
JACKKNIFE_BLOCKS = 16  # at most; at least MIN_BLOCKS
MIN_BLOCKS = 8
INTERPOLATED_TOP = 0.25  # of the Nyquist frequency: bilinear interpolation damps the spectrum above it
SNAP = 1e-9  # grid indices this close to an integer are taken as that integer
LINES_PER_BLOCK = 256  # sampling lines interpolated at a time
MIN_ORDINATES = 8


@dataclasses.dataclass
class ProfileSet:
    """Profiles taken from a surface along one direction (see :func:`take_profiles`).

    Attributes
    ----------
    heights : list of numpy.ndarray
        One 1-D float64 array per profile, every value finite, metres, its polynomial
        form of the given order removed.
    spacing : float
        The spacing along the profiles, metres.
    label : str
        ``"x"``, ``"y"``, the angle (``"30°"``) or ``"profile"`` for a profile input.
    angle : float
        The direction, radians counter-clockwise from +x; NaN for a profile input.
    interpolation : str
        How the heights were found: ``"none (grid lines)"``, ``"none (profile)"`` or
        ``"bilinear"``.
    gaps : str
        ``"longest"`` or ``"fill"``.
    positions : numpy.ndarray
        Each profile's offset across the direction, metres (in the map's coordinates).
    """

    heights: list
    spacing: float
    label: str
    angle: float
    interpolation: str
    gaps: str
    positions: np.ndarray

    @property
    def points(self):
        return int(sum(profile.size for profile in self.heights))


def take_profiles(surface, direction="x", gaps="longest", order=1, min_points=64):
    """The profiles of a map along a direction, or a profile as a set of one.

    Parameters
    ----------
    surface : Surface
        A map or a profile; invalid points are NaN.
    direction : {"x", "y"} or float, default "x"
        The rows (``"x"``), the columns (``"y"``), or an angle in radians
        counter-clockwise from +x: parallel sampling lines rotated exactly by it,
        spaced by the smaller grid spacing along and across, covering the map, their
        heights interpolated bilinearly. Ignored for a profile.
    gaps : {"longest", "fill"}, default "longest"
        What is kept of a profile with invalid points: its longest run of valid
        points, or all of it between its first and last valid points, the interior
        gaps filled by linear interpolation along the profile.
    order : int, default 1
        The degree of the polynomial form removed from each profile.
    min_points : int, default 64
        Profiles shorter than this (after the gap rule) are dropped.

    Returns
    -------
    ProfileSet
        The profiles, every height finite.

    Raises
    ------
    rough.InputError
        For an unknown direction or gap rule, an order below 0, or when no profile
        keeps ``min_points`` points.

    Notes
    -----
    A point whose bilinear stencil touches an invalid (NaN) point, or that lies
    outside the map, is invalid; the gap rule then applies. Along ``"x"`` the
    profiles are the rows in order of y, along ``"y"`` the columns in order of x; the
    lines at an angle θ run along ``(cos θ, sin θ)`` and are ordered by their offset
    along ``(-sin θ, cos θ)``, so at θ = 0 they are the rows (for equal spacings), and
    at 90° the columns in order of decreasing x.

    Examples
    --------
    >>> import numpy as np, rough
    >>> from rough.fractal.profiles import take_profiles
    >>> heights = np.arange(12.0).reshape(3, 4) ** 2
    >>> heights[1, 1] = np.nan
    >>> rows = take_profiles(rough.Surface(heights, 1e-3), "x", order=0, min_points=2)
    >>> [profile.size for profile in rows.heights], rows.positions.tolist()
    ([4, 2, 4], [0.0, 0.001, 0.002])
    >>> take_profiles(rough.Surface(heights, 1e-3), "x", "fill", 0, 2).heights[1].size
    4
    """
    if gaps not in GAPS:
        raise InputError(f"gaps must be one of {', '.join(GAPS)}, not {gaps!r}")
    if not (isinstance(order, (int, np.integer)) and order >= 0):
        raise InputError(f"the form's order must be a whole number from 0, not {order!r}")
    lines, positions, spacing, label, angle, interpolation = _lines(surface, direction)
    kept, where = [], []
    for line, position in zip(lines, positions):
        profile = _gap_rule(line, gaps)
        if profile.size >= max(min_points, order + 2):
            kept.append(_levelled(profile, order))
            where.append(position)
    if not kept:
        raise InputError(
            f"no profile along {label} keeps {min_points} valid points in a row (gaps: {gaps}); "
            "fill the invalid points or take another direction"
        )
    return ProfileSet(kept, spacing, label, angle, interpolation, gaps, np.array(where, dtype=np.float64))


def _lines(surface, direction):
    """``(lines, positions, spacing, label, angle, interpolation)`` of a surface."""
    heights = surface.heights
    if surface.is_profile:
        return [heights], [0.0], surface.spacing[0], "profile", math.nan, "none (profile)"
    dx, dy = surface.spacing
    if isinstance(direction, str):
        name = direction.strip().casefold()
        if name == "x":
            return list(heights), surface.positions(1), dx, "x", 0.0, "none (grid lines)"
        if name == "y":
            return list(heights.T), surface.positions(0), dy, "y", math.pi / 2, "none (grid lines)"
        raise InputError(f"a direction is x, y or an angle, not {direction!r}")
    try:
        angle = float(direction)
    except (TypeError, ValueError):
        raise InputError(f"a direction is x, y or an angle, not {direction!r}") from None
    if not math.isfinite(angle):
        raise InputError(f"the direction's angle must be a finite number, not {direction!r}")
    lines, offsets, step = _rotated_lines(heights, (dx, dy), angle)
    origin = np.array(surface.origin)
    positions = offsets + origin @ np.array([-math.sin(angle), math.cos(angle)])
    return lines, positions, step, f"{math.degrees(angle) % 180:.6g}°", angle, "bilinear"


def _rotated_lines(heights, spacing, angle):
    """Sampling lines at ``angle`` over the grid (x = j dx, y = i dy from its first
    point), every ``step`` (the smaller spacing) along and across; heights by bilinear
    interpolation, NaN where the stencil touches a NaN or leaves the grid."""
    from scipy.ndimage import map_coordinates

    ny, nx = heights.shape
    dx, dy = spacing
    step = min(dx, dy)
    along = np.array([math.cos(angle), math.sin(angle)])
    across = np.array([-along[1], along[0]])
    corners = np.array([[0, 0], [(nx - 1) * dx, 0], [0, (ny - 1) * dy], [(nx - 1) * dx, (ny - 1) * dy]])

    def steps(direction):
        projected = corners @ direction / step
        return np.arange(math.ceil(projected.min() - SNAP), math.floor(projected.max() + SNAP) + 1) * step

    s, offsets = steps(along), steps(across)
    invalid = np.isnan(heights)
    filled = np.where(invalid, 0.0, heights)
    invalid = invalid.astype(np.float64) if invalid.any() else None
    lines = []
    for part in np.array_split(offsets, max(1, math.ceil(offsets.size / LINES_PER_BLOCK))):
        x = _snapped((part[:, None] * across[0] + s[None, :] * along[0]) / dx)
        y = _snapped((part[:, None] * across[1] + s[None, :] * along[1]) / dy)
        valid = (x >= 0) & (x <= nx - 1) & (y >= 0) & (y <= ny - 1)
        coordinates = [np.clip(y, 0, ny - 1), np.clip(x, 0, nx - 1)]
        values = map_coordinates(filled, coordinates, order=1, mode="nearest")
        if invalid is not None:
            valid &= map_coordinates(invalid, coordinates, order=1, mode="nearest") == 0
        lines.extend(np.where(valid, values, np.nan))
    return lines, offsets, step


def _snapped(index):
    nearest = np.round(index)
    return np.where(np.abs(index - nearest) < SNAP, nearest, index)


def _gap_rule(line, gaps):
    """A profile's longest finite run (``"longest"``), or its span between the first
    and last finite values with interior gaps filled linearly (``"fill"``)."""
    valid = np.isfinite(line)
    if not valid.any():
        return line[:0]
    if gaps == "fill":
        where = np.flatnonzero(valid)
        span = np.arange(where[0], where[-1] + 1)
        return np.interp(span, where, line[where])
    edges = np.flatnonzero(np.diff(np.r_[0, valid.astype(np.int8), 0]))
    starts, stops = edges[::2], edges[1::2]
    longest = int(np.argmax(stops - starts))
    return np.array(line[starts[longest] : stops[longest]], dtype=np.float64)


def _levelled(profile, order):
    """The profile less its least-squares polynomial of ``order`` (Legendre basis, for
    conditioning)."""
    from numpy.polynomial import legendre

    x = np.linspace(-1.0, 1.0, profile.size)
    return profile - legendre.legval(x, legendre.legfit(x, profile, order))


# -- the pooled Whittle fit ---------------------------------------------------------------


def _periodograms(heights, spacing):
    """Each profile's periodogram of first differences, ``(f, I)``."""
    return [difference_periodogram(profile, spacing) for profile in heights]


def _pooled(periodograms, spacing, band, sampling, effect=1.0):
    """:class:`~rough.fractal.scaling.Bins` of the periodograms' ordinates in ``band``
    (``low ≤ f ≤ high``), one bin per distinct frequency holding the mean of its
    ordinates (the Whittle likelihood of equal-frequency ordinates is that of their
    mean with their count as weight), the weight divided by the design ``effect``;
    None with fewer than MIN_ORDINATES frequencies."""
    low, high = band
    frequencies = np.concatenate([f for f, _ in periodograms])
    ordinates = np.concatenate([values for _, values in periodograms])
    keep = (frequencies >= low) & (frequencies <= high)
    distinct, inverse, count = np.unique(frequencies[keep], return_inverse=True, return_counts=True)
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
        The spectral model, as for :func:`~rough.fractal.fit.fit_fractal`.
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
    >>> from rough.fractal.profiles import whittle_hurst
    >>> walk = np.cumsum(np.random.default_rng(1).standard_normal((4, 4096)), axis=1)
    >>> round(whittle_hurst(list(walk), 1e-6), 1)  # Brownian motion: H = 1/2
    0.5
    """
    heights = [heights] if isinstance(heights, np.ndarray) and heights.ndim == 1 else heights
    if not all(np.isfinite(profile).all() for profile in heights):
        raise InputError("the profiles hold invalid (NaN) heights; take them through take_profiles first")
    band = _band_of_scales(scales)
    bins = _pooled(_periodograms(heights, spacing), spacing, band, sampling)
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


@dataclasses.dataclass
class ProfileFit:
    """The result of :func:`fit_profiles`: the pooled fit of the profiles along a
    direction; lengths in metres, frequencies in 1/m.

    Attributes
    ----------
    fit : FractalFit
        The pooled fit: D = 2 - H of the profiles, C at ``resolution``, H, the band,
        the verdict, as :func:`~rough.fractal.fit.fit_fractal` gives them for one
        profile; its standard errors are the jackknife's (see ``stderr_method``).
    direction : str
        ``"x"``, ``"y"``, the angle (``"30°"``) or ``"profile"``.
    angle : float
        The direction, degrees counter-clockwise from +x; NaN for a profile input.
    profiles : int
        The number of profiles fitted.
    points : int
        Their heights in all.
    hurst_stderr : float
        The standard error of H (that of D).
    hurst_spread : float
        The standard deviation of the profiles' own H over the same band (each fitted
        alone, without a noise floor); NaN with fewer than two profiles of 8
        frequencies in the band.
    interpolation : str
        How the heights were taken (see :class:`ProfileSet`).
    gaps : str
        ``"longest"`` or ``"fill"``.
    stderr_method : str
        How the standard errors were found: a delete-one-block jackknife over blocks
        of neighbouring profiles, or (fewer than 8 profiles) the Fisher information.
    design_effect : float
        How many of the profiles count as one independent profile: the jackknife's
        variance of the exponent over the Fisher information's, in a fit of the power
        law alone over every frequency allowed, within [1, profiles] (docs/math.rst
        §1.9). The likelihood's weights were divided by it, so that the band search,
        the noise floor's test and the p-value see the information the correlated
        profiles hold, not their number; 1 for fewer than 8 profiles.
    reliability_cutoff : float or None
        The wavelength below which a tip of the radius given cannot follow the
        surface, metres (the band stops there); None without a tip radius or when it
        follows at every scale.
    kind : str
        ``"profiles"``: a 1-D fit of profiles, not of the map's 2-D spectrum.
    profile_set : ProfileSet
        The profiles fitted (their heights with the form removed), for what else is
        measured on them: their mean spectrum, other estimators.

    Notes
    -----
    ``as_dict()`` merges the fields of ``fit`` (``fractal_dimension``,
    ``amplitude_coefficient``, ``hurst``, ``band``, …) with these (``angle`` None for
    a profile; not ``profile_set``).
    """

    fit: object
    direction: str
    angle: float
    profiles: int
    points: int
    hurst_stderr: float
    hurst_spread: float
    interpolation: str
    gaps: str
    stderr_method: str
    design_effect: float = 1.0
    reliability_cutoff: float = None
    kind: str = "profiles"
    profile_set: object = dataclasses.field(default=None, repr=False)

    def as_dict(self):
        values = {name: getattr(self, name) for name in (field.name for field in dataclasses.fields(self))}
        del values["fit"], values["profile_set"]
        values["angle"] = None if math.isnan(self.angle) else self.angle
        return {**self.fit.as_dict(), **values}


def fit_profiles(
    surface_or_profile_set,
    direction="x",
    gaps="longest",
    band=None,
    resolution=None,
    sampling=None,
    noise=True,
    rolloff=False,
    level=0.01,
    order=1,
    tip_radius=None,
    spread=True,
):
    """H, D = 2 - H and C of a map's profiles along a direction, by the pooled Whittle fit.

    Parameters
    ----------
    surface_or_profile_set : Surface or ProfileSet
        A map (its profiles taken by :func:`take_profiles`), a profile (a set of
        one), or profiles already taken.
    direction, gaps, order
        As for :func:`take_profiles` (ignored for a ProfileSet).
    band : tuple of (float or None), optional
        ``(fmin, fmax)`` in 1/m; with both ends exactly that band is fitted, otherwise
        the scaling range is found as :func:`~rough.fractal.fit.fit_fractal` finds it
        for a profile, up to the Nyquist frequency of the profiles (a quarter of it
        for interpolated profiles, whose spectrum bilinear interpolation damps above
        it; 80 % of it after rough's resample).
    resolution : float, optional
        The η at which C is stated, metres; default the spacing along the profiles.
    sampling : {"point", "band-limited"}, optional
        The spectral model; default band-limited when the surface's history says rough
        made its spectrum, else point samples.
    noise, rolloff, level
        The spectral model's options and the test's level, as for
        :func:`~rough.fractal.fit.fit_fractal`.
    tip_radius : float, optional
        A tip radius, metres: the band stops at the wavelength below which such a tip
        cannot follow the surface (:func:`rough.fractal.scales.reliability_cutoff`).
    spread : bool, default True
        Fit every profile alone for ``hurst_spread`` (NaN without).

    Returns
    -------
    ProfileFit
        The pooled fit with jackknife standard errors, the per-profile spread and how
        the profiles were taken.

    Raises
    ------
    rough.InputError
        As :func:`take_profiles`, for an unknown sampling, a level outside (0, 1),
        profiles flat once their form is removed (compared with the surface's
        heights; a ProfileSet only when all its heights are zero), or fewer than 8
        frequencies in the band.

    Notes
    -----
    Invalid (NaN) points are handled by the gap rule. The likelihood's weights are
    divided by the design effect (docs/math.rst §1.9), so that the band search and
    the tests see what the correlated profiles know. The standard errors of H, D and
    C come from a delete-one-block jackknife over the profiles, sorted by position and
    cut into 16 blocks (8 at least; one profile a block between 8 and 16 profiles),
    each block's fit over the band chosen; with fewer than 8 profiles they come from
    the Fisher information, which is right only for independent profiles.

    Examples
    --------
    Rows of independent Brownian motion (H = 1/2) with a smooth trend along y:

    >>> import math, numpy as np, rough
    >>> from rough.fractal.profiles import fit_profiles
    >>> rows = np.cumsum(np.random.default_rng(2).standard_normal((64, 512)), axis=1) * 1e-7
    >>> scan = rough.Surface(rows + np.linspace(0, 1e-5, 64)[:, None], 1e-5)
    >>> result = fit_profiles(scan, "x", band=(0, math.inf))  # every frequency
    >>> result.profiles, round(result.fit.hurst, 1), result.kind
    (64, 0.5, 'profiles')
    >>> result.hurst_stderr < 0.02
    True
    """
    from .fit import SAMPLINGS

    if sampling is not None and sampling not in SAMPLINGS:
        raise InputError(f"sampling must be one of {', '.join(SAMPLINGS)}, not {sampling!r}")
    if not 0 < level < 1:
        raise InputError(f"the test's level must lie between 0 and 1, not {level}")
    given = surface_or_profile_set
    profiles = given if isinstance(given, ProfileSet) else take_profiles(given, direction, gaps, order)
    residual = np.concatenate(profiles.heights)
    refuse_flat(residual, residual if isinstance(given, ProfileSet) else given.heights[np.isfinite(given.heights)])
    made = None if isinstance(given, ProfileSet) else history_sampling(given)
    source = "option" if sampling else "history" if made else "default (point samples)"
    sampling = sampling or made or "point"
    resolution = resolution or profiles.spacing
    cutoff = _cutoff(profiles, tip_radius)
    limits = _limits(profiles, given, band, cutoff)
    periodograms = _periodograms(profiles.heights, profiles.spacing)
    if _pooled(periodograms, profiles.spacing, limits, sampling) is None:
        raise InputError("fewer than 8 frequencies in the fit band; widen --band or use longer profiles")
    blocks = neighbour_blocks(profiles.positions)
    effect = _design_effect(periodograms, blocks, profiles.spacing, limits, sampling)
    bins = _pooled(periodograms, profiles.spacing, limits, sampling, effect)
    options = Options(noise, rolloff, level)
    outcome = band_outcome(bins, BETA_RANGE, band, options)
    count = int(outcome.fit.bins.count.sum()) if outcome.fit else int(bins.count.sum())
    method = f"whittle (pooled periodograms of {len(profiles.heights)} profiles)"
    settings = Settings(method, "none (first differences)", sampling, source, 0.0, count)
    fit = from_outcome(outcome, "profile", resolution, settings)
    errors = _uncertainty(profiles, periodograms, blocks, outcome, fit, sampling, options, spread)
    fit = dataclasses.replace(
        fit,
        fractal_dimension_stderr=errors["hurst"],
        amplitude_coefficient_stderr=errors["amplitude"],
        reliability_cutoff=cutoff,
        scale_dependent=_by_scale(profiles, cutoff) if fit.verdict == "no power-law range" else None,
    )
    announce(fit, level)
    return ProfileFit(
        fit=fit,
        direction=profiles.label,
        angle=math.degrees(profiles.angle) % 180 if math.isfinite(profiles.angle) else math.nan,
        profiles=len(profiles.heights),
        points=profiles.points,
        hurst_stderr=errors["hurst"],
        hurst_spread=errors["spread"],
        interpolation=profiles.interpolation,
        gaps=profiles.gaps,
        stderr_method=errors["method"],
        design_effect=effect,
        reliability_cutoff=cutoff,
        profile_set=profiles,
    )


def _by_scale(profiles, cutoff):
    """The profiles' roughness against scale (where no band is a power law), from the
    tip's cut-off up."""
    from .scales import scale_dependent

    return {**scale_dependent(profiles.heights, profiles.spacing, cutoff=cutoff), "direction": profiles.label}


def _cutoff(profiles, tip_radius):
    if tip_radius is None:
        return None
    from .scales import reliability_cutoff

    return reliability_cutoff(profiles.heights, profiles.spacing, tip_radius)


def _limits(profiles, surface, band, cutoff):
    """``(low, high)``: the frequencies the fit may use, 1/m."""
    nyquist = 0.5 / profiles.spacing
    top = nyquist * (INTERPOLATED_TOP if profiles.interpolation == "bilinear" else 1.0)
    history = getattr(surface, "history", ())
    if any(entry.get("command") == "resample" for entry in history):
        top = min(top, RESAMPLED_TOP * nyquist)
    low, high = band or (None, None)
    high = top if high is None else high
    if cutoff is not None:
        high = min(high, 1.0 / cutoff)
    return (0.0 if low is None else low), high


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
        bins = _pooled([periodograms[i] for i in np.flatnonzero(left)], spacing, band, sampling)
        if bins is not None:
            fits.append(fit_spectrum(bins, BETA_RANGE, noise, rolloff))
    return fits if len(fits) >= MIN_BLOCKS else None


def jackknife_variance(values):
    """The delete-one jackknife variance of the estimates ``values`` (one per left-out
    block; along the first axis)."""
    values = np.asarray(values, dtype=np.float64)
    count = values.shape[0]
    return (count - 1) / count * np.sum((values - values.mean(axis=0)) ** 2, axis=0)


def _design_effect(periodograms, blocks, spacing, band, sampling):
    """How many profiles count as one independent profile: the jackknife's variance of
    the exponent over the Fisher information's, in the power law's fit (no floor) over
    every frequency of ``band``; between 1 and the number of profiles (1 without
    blocks)."""
    if blocks is None:
        return 1.0
    whole = fit_spectrum(_pooled(periodograms, spacing, band, sampling), BETA_RANGE, False)
    if at_bound(whole.exponent, BETA_RANGE):
        return 1.0
    replicates = _replicates(periodograms, blocks, spacing, band, sampling, False, False)
    if replicates is None:
        return 1.0
    ratio = jackknife_variance([fit.exponent for fit in replicates]) / whole.covariance[1, 1]
    return float(min(max(ratio, 1.0), len(periodograms)))


def _uncertainty(profiles, periodograms, blocks, outcome, fit, sampling, options, spread=True):
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
        bins = _pooled([periodogram], spacing, band, sampling)
        if bins is not None and np.any(bins.density > 0):
            values.append((fit_spectrum(bins, BETA_RANGE, False).exponent - 1.0) / 2.0)
    return float(np.std(values, ddof=1)) if len(values) > 1 else math.nan


# -- the profile rose ---------------------------------------------------------------------------

#: The keys of each direction's record in :class:`ProfileRose`.
RECORD_FIELDS = (
    "angle",
    "hurst",
    "hurst_stderr",
    "fractal_dimension",
    "fractal_dimension_stderr",
    "amplitude_coefficient",
    "amplitude_coefficient_stderr",
    "band",
    "profiles",
    "verdict",
)


@dataclasses.dataclass
class ProfileRose:
    """The result of :func:`profile_rose`: H(θ), D(θ) and C(θ) from the profiles along
    each direction; angles in degrees, lengths in metres, frequencies in 1/m.

    Attributes
    ----------
    directions : list of dict
        One record a direction θ = 0, step, …, 180° - step: ``angle`` (degrees,
        counter-clockwise from +x: the direction along the profiles, in which their
        heights vary, as the 2-D rose's θ), ``hurst``, ``hurst_stderr``,
        ``fractal_dimension`` (D = 2 - H of the profiles), its standard error,
        ``amplitude_coefficient`` (C at ``resolution``), its standard error, ``band``
        (``[fmin, fmax]``, or None), ``profiles`` (the number fitted) and ``verdict``
        (``power law``, ``at bound``, ``no power-law range``, or ``no profiles: …``).
    step : float
        The spacing of the directions, degrees.
    gaps : str
        ``"longest"`` or ``"fill"``.
    interpolation : str
        ``"bilinear"``: every direction's heights are interpolated alike (exact on the
        grid lines at 0° and 90° for equal spacings).
    resolution : float
        The η at which C is stated, metres.
    band : tuple of float or None
        The band given for every direction, 1/m; None: each direction's own
        automatic band.
    stderr_method : str
        How the standard errors were found (see :class:`ProfileFit`).
    kind : str
        ``"profiles"``: from 1-D profiles, not the 2-D spectrum's sectors
        (:func:`rough.fractal.rose.rose`).

    Notes
    -----
    ``as_dict()`` gives the fields as a JSON-able dict.
    """

    directions: list
    step: float
    gaps: str
    interpolation: str
    resolution: float
    band: tuple
    stderr_method: str
    kind: str = "profiles"

    def as_dict(self):
        values = dataclasses.asdict(self)
        values["band"] = None if self.band is None else list(self.band)
        return values


def profile_rose(
    surface,
    step=math.radians(15),
    gaps="longest",
    band=None,
    resolution=None,
    sampling=None,
    noise=True,
    rolloff=False,
    level=0.01,
    order=1,
    tip_radius=None,
):
    """H(θ), D(θ) and C(θ) of a map from its profiles along each direction.

    Parameters
    ----------
    surface : Surface
        A map; invalid (NaN) points are handled by the gap rule.
    step : float, default 15° (in radians)
        The spacing of the directions, radians; it must divide 180° and be at most 90°.
    gaps, band, sampling, noise, rolloff, level, order, tip_radius
        As for :func:`fit_profiles`; a ``band`` with both ends gives every direction
        the same band (recommended for comparing directions), otherwise each
        direction's band is found on its own profiles.
    resolution : float, optional
        The η at which C is stated, metres; default the smaller spacing.

    Returns
    -------
    ProfileRose
        One record per direction.

    Raises
    ------
    rough.InputError
        For a profile, or a step out of range; a direction without profiles of 64
        points is recorded as such, not raised.

    Notes
    -----
    Every direction, the grid lines at 0° and 90° included, is taken through
    :func:`take_profiles` with its angle: bilinear interpolation, the default band
    stopping at a quarter of the Nyquist frequency, so that the directions compare.

    Examples
    --------
    >>> import math
    >>> from rough.fractal.profiles import profile_rose
    >>> from rough.fractal.synth import synthesize_map
    >>> scan = synthesize_map((128, 128), (1e-6, 1e-6), 2.5, amplitude=1e-7, seed=3)
    >>> result = profile_rose(scan, step=math.radians(45), band=(2e4, 1.2e5))
    >>> [record["angle"] for record in result.directions], result.kind
    ([0.0, 45.0, 90.0, 135.0], 'profiles')
    """
    if surface.is_profile:
        raise InputError("a rose needs a map (a direction in the plane); this is a profile")
    count = math.pi / step if 0 < step <= math.pi / 2 else 0.5
    if abs(count - round(count)) > 1e-6:
        raise InputError(f"the step must divide 180° and be at most 90°, not {math.degrees(step):g}°")
    resolution = resolution or min(surface.spacing)
    options = dict(band=band, resolution=resolution, sampling=sampling, noise=noise, rolloff=rolloff, level=level)
    records, methods = [], []
    for index in range(round(count)):
        angle = round(math.degrees(index * step), 9)
        try:
            result = fit_profiles(
                surface, index * step, gaps, order=order, tip_radius=tip_radius, spread=False, **options
            )
        except InputError as error:
            records.append(_empty_record(angle, f"no profiles: {error}"))
            continue
        records.append(_record(angle, result))
        methods.append(result.stderr_method)
    method = next((text for text in methods if not text.startswith("none")), "none (no fit)")
    return ProfileRose(records, round(math.degrees(step), 9), gaps, "bilinear", resolution, band, method)


def _record(angle, result):
    fit = result.fit
    return {
        "angle": angle,
        "hurst": fit.hurst,
        "hurst_stderr": result.hurst_stderr,
        "fractal_dimension": fit.fractal_dimension,
        "fractal_dimension_stderr": fit.fractal_dimension_stderr,
        "amplitude_coefficient": fit.amplitude_coefficient,
        "amplitude_coefficient_stderr": fit.amplitude_coefficient_stderr,
        "band": None if fit.band is None else list(fit.band),
        "profiles": result.profiles,
        "verdict": fit.verdict,
    }


def _empty_record(angle, verdict):
    record = dict.fromkeys(RECORD_FIELDS, math.nan)
    return {**record, "angle": angle, "band": None, "profiles": 0, "verdict": verdict}
