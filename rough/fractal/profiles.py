"""Profiles by direction: H, D and C of a map from its 1-D profiles along a direction
(docs/math.rst §1.9), as the fault-roughness literature measures them (Candela et al.
2009, 2012; Renard et al. 2006), and their rose over directions.

The profiles are taken by :func:`~rough.fractal.take_profiles`, fitted
together by the pooled Whittle fit (:mod:`rough.fractal.pooled`), band and all, as
:func:`~rough.fractal.fit_fractal` fits one profile, with the likelihood's weights
divided by the design effect and standard errors from a delete-one-block jackknife
over blocks of neighbouring profiles (:mod:`rough.fractal.jackknife`).
"""

import dataclasses
import math

import numpy as np

from ..errors import InputError
from .choices import SAMPLINGS
from .jackknife import design_effect, neighbour_blocks, uncertainty
from .pooled import periodograms, pooled
from .profile_set import ProfileSet, take_profiles
from .result import Settings, announce, from_outcome
from .scales import reliability_cutoff, scale_dependent
from .whittle import BETA_RANGE, RESAMPLED_TOP, Options, band_outcome, history_sampling, refuse_flat

INTERPOLATED_TOP = 0.25  # of the Nyquist frequency: bilinear interpolation damps the spectrum above it


@dataclasses.dataclass
class ProfileFit:
    """The result of :func:`fit_profiles`: the pooled fit of the profiles along a
    direction; lengths in metres, frequencies in 1/m.

    Attributes
    ----------
    fit : FractalFit
        The pooled fit: D = 2 - H of the profiles, C at ``resolution``, H, the band,
        the verdict, as :func:`~rough.fractal.fit_fractal` gives them for one
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
        the scaling range is found as :func:`~rough.fractal.fit_fractal` finds it
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
        :func:`~rough.fractal.fit_fractal`.
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
    spectra = periodograms(profiles.heights, profiles.spacing)
    blocks = neighbour_blocks(profiles.positions)
    options = Options(noise, rolloff, level)
    return pooled_fit(
        profiles, spectra, blocks, (limits, band), (sampling, source), resolution, options, spread, cutoff
    )


def pooled_fit(profiles, spectra, blocks, bands, sampling, resolution, options, spread=True, cutoff=None):
    """The pooled fit of the profiles' periodograms ``spectra`` (see
    :func:`~rough.fractal.pooled.pooled`; one per profile, or the sums of a block's in
    its first and nothing in the others) with the jackknife over ``blocks`` (indices
    into ``spectra``): a :class:`ProfileFit`. ``profiles`` is the :class:`ProfileSet`,
    or what stands for one (its ``spacing``, ``label``, ``angle``, ``interpolation``,
    ``gaps``, ``points``; ``heights`` None: no scale table without a power law);
    ``bands`` is ``(limits, band)``: the frequencies allowed and the band asked for."""
    (limits, band), (sampling, source) = bands, sampling
    if pooled(spectra, profiles.spacing, limits, sampling) is None:
        raise InputError("fewer than 8 frequencies in the fit band; widen --band or use longer profiles")
    effect = design_effect(spectra, blocks, profiles.spacing, limits, sampling)
    bins = pooled(spectra, profiles.spacing, limits, sampling, effect)
    outcome = band_outcome(bins, BETA_RANGE, band, options)
    count = int(outcome.fit.bins.count.sum()) if outcome.fit else int(bins.count.sum())
    method = f"whittle (pooled periodograms of {len(spectra)} profiles)"
    settings = Settings(method, "none (first differences)", sampling, source, 0.0, count)
    fit = from_outcome(outcome, "profile", resolution, settings)
    errors = uncertainty(profiles, spectra, blocks, outcome, fit, sampling, options, spread)
    table = fit.verdict == "no power-law range" and profiles.heights is not None
    fit = dataclasses.replace(
        fit,
        fractal_dimension_stderr=errors["hurst"],
        amplitude_coefficient_stderr=errors["amplitude"],
        reliability_cutoff=cutoff,
        scale_dependent=_by_scale(profiles, cutoff) if table else None,
    )
    announce(fit, options.level)
    return ProfileFit(
        fit=fit,
        direction=profiles.label,
        angle=math.degrees(profiles.angle) % 180 if math.isfinite(profiles.angle) else math.nan,
        profiles=len(spectra),
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
    return {**scale_dependent(profiles.heights, profiles.spacing, cutoff=cutoff), "direction": profiles.label}


def _cutoff(profiles, tip_radius):
    return None if tip_radius is None else reliability_cutoff(profiles.heights, profiles.spacing, tip_radius)


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
        (:func:`rough.fractal.rose`).

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
    >>> from rough.fractal.synth_map import synthesize_map
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
