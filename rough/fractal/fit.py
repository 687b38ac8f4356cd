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
"""

import dataclasses
import logging
import math

import numpy as np

from ..errors import InputError
from . import model
from .psd import periodogram, ring_spectrum, windowed_map
from .scaling import at_bound, decades

log = logging.getLogger("rough")
METHODS = ("whittle", "variogram", "madogram", "loglog")
SAMPLINGS = ("point", "band-limited")
BETA_RANGE = (1.0 + 1e-6, 3.0 - 1e-6)
LOWEST_RING = 4
RESAMPLED_TOP = 0.8
EVIDENCE = 1.5  # log-likelihood units in favour of band-limited data before point samples are given up
FLAT = 1e-9  # RMS residual below this fraction of the largest height is rounding, not roughness
TIP_SPAN = 8  # a tip's cut-off must leave this many wavelengths of the scan length to fit


@dataclasses.dataclass
class FractalFit:
    """The result of :func:`fit_fractal`; lengths in metres, frequencies in 1/m.

    Attributes
    ----------
    fractal_dimension : float
        D of a profile, in (1, 2), or the surface dimension Ds of a map, in (2, 3).
    fractal_dimension_stderr : float
        Its standard error: from the Fisher information (Whittle), or from 8 blocks
        of the profile (``variogram``, ``madogram``, ``loglog``).
    amplitude_coefficient : float
        The amplitude coefficient C at ``resolution``, metres; for maps, the C of the
        profiles through the map, so that a map and its profiles share one C.
    amplitude_coefficient_stderr : float
        Its standard error, metres; NaN for the cross-check methods.
    resolution : float
        The resolution η at which C is stated, metres.
    psd_prefactor : float
        The spectrum's prefactor in SI units: A = C η^(2D-3) (G at f = 1 m⁻¹) for a
        profile, C2 for a map.
    hurst : float
        The Hurst exponent H: 2 - D for a profile, 3 - Ds for a map.
    band : tuple of float
        ``(fmin, fmax)``, the frequencies fitted, 1/m.
    method : str
        How D was estimated (``whittle``, ``variogram``, ``madogram``, ``loglog``, or
        the ring-binned Whittle fit for maps).
    window : str
        The window applied before the transform.
    sampling : str
        ``"point"`` (power above the Nyquist frequency folds back) or
        ``"band-limited"``.
    frequencies_used : int
        Periodogram ordinates in the fit.
    structure_function_coefficient : float
        Ganti & Bhushan's structure-function coefficient C_S, metres
        (docs/math.rst §1.2).
    profile_dimension : float or None
        For maps, Ds - 1, the D of the profiles through the map; None for profiles.
    verdict : str
        ``"power law"`` (D strictly inside the fractal range), ``"at bound"`` (the
        exponent sits on the edge of the range: D is a bound, not an estimate, and
        its standard error is None) or ``"no power-law range"`` (no band of a decade
        or more keeps its local exponent within the tolerance, docs/math.rst §1.8:
        D, C and their errors are NaN, and ``scale_dependent`` describes the surface).
    at_bound : bool
        Whether the verdict is ``"at bound"``.
    p_value : float
        The goodness-of-fit test's p-value over the fit band (see ``test``), a
        diagnostic that does not choose the band; NaN for the cross-check methods.
    test : str
        The goodness-of-fit test (docs/math.rst §1.7).
    fit_band : tuple of float
        The frequencies in the likelihood, 1/m: ``band`` is this band up to the
        noise crossover.
    noise_rms : float or None
        The RMS of the white noise floor, metres; None when the likelihood ratio
        finds no floor.
    noise_crossover : float or None
        The frequency where the power law meets the noise floor, 1/m; None when
        it does not within the fit band.
    rolloff_wavelength : float or None
        The wavelength 1/fc of the fitted Gaussian roll-off, metres; None unless
        ``rolloff=True``.
    sampling_source : str
        Where ``sampling`` came from: ``option``, ``history``, ``likelihood`` (both
        models fitted, the likelier kept) or ``maps: band`` (aliasing is not modelled
        for maps; the default band stops below it).
    hint : str or None
        At a bound or without a power-law range: where the spectrum's local exponent
        comes nearest a fractal's, as a band to try (for a band found by the search);
        for a band given, at a bound, which side of the fractal range the spectrum
        lies on (never another band: following a hint ends there).
    band_rule : str
        How the band was chosen: ``"given"``, or the effect-size rule of the search
        (docs/math.rst §1.8).
    scale_dependent : dict or None
        Without a power-law range: the RMS height, slope and curvature against scale
        (:func:`rough.fractal.scales.scale_dependent`: lists ``scale`` m,
        ``rms_height`` m, ``rms_slope``, ``rms_curvature`` 1/m, and ``direction``,
        ``"profile"`` or ``"x"`` for a map's rows), from the reliability cut-off up;
        None otherwise.
    reliability_cutoff : float or None
        With ``tip_radius``: the wavelength below which the tip cannot follow the
        surface (:func:`rough.fractal.scales.reliability_cutoff`), metres; the fit
        left out the frequencies above its inverse. None without a tip radius or
        when the tip follows the surface at every scale.

    Notes
    -----
    ``as_dict()`` gives the fields as a JSON-able dict (``band`` as a list, and no
    ``profile_dimension`` for a profile, no ``scale_dependent`` with a power law or a
    bound, no ``reliability_cutoff`` without one).

    Examples
    --------
    >>> import rough
    >>> fit = rough.fit_fractal(rough.read(rough.sample("rock-profile.tsv")))  # D = 1.3
    >>> print(f"D = {fit.fractal_dimension:.3f} ± {fit.fractal_dimension_stderr:.3f}, H = {fit.hurst:.3f}")
    D = 1.305 ± 0.016, H = 0.695
    >>> print(f"C = {fit.amplitude_coefficient * 1e9:.0f} nm at η = {fit.resolution * 1e6:.1f} µm")
    C = 260 nm at η = 30.9 µm
    >>> sorted(fit.as_dict())[:3]
    ['amplitude_coefficient', 'amplitude_coefficient_stderr', 'at_bound']
    """

    fractal_dimension: float
    fractal_dimension_stderr: float
    amplitude_coefficient: float
    amplitude_coefficient_stderr: float
    resolution: float
    psd_prefactor: float
    hurst: float
    band: tuple
    method: str
    window: str
    sampling: str
    frequencies_used: int
    structure_function_coefficient: float
    profile_dimension: float = None
    verdict: str = "power law"
    at_bound: bool = False
    p_value: float = math.nan
    test: str = ""
    fit_band: tuple = None
    noise_rms: float = None
    noise_crossover: float = None
    rolloff_wavelength: float = None
    sampling_source: str = "option"
    hint: str = None
    band_rule: str = "given"
    scale_dependent: dict = None
    reliability_cutoff: float = None

    def as_dict(self):
        values = dataclasses.asdict(self)
        values["band"] = None if self.band is None else list(self.band)
        values["fit_band"] = None if self.fit_band is None else list(self.fit_band)
        for name in ("profile_dimension", "scale_dependent", "reliability_cutoff"):
            if values[name] is None:
                del values[name]
        return values


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
):
    """The fractal dimension D (Ds for maps) and amplitude coefficient C of a surface.

    Parameters
    ----------
    surface : Surface
        A gap-free profile or map: invalid (NaN) points must have been filled (see
        :func:`rough.fractal.resample.fill_invalid`).
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

    Returns
    -------
    FractalFit
        D (or Ds), C, their standard errors, and what the fit used; without a
        power-law range, the roughness against scale instead.

    Raises
    ------
    rough.InputError
        For invalid points, an unknown method or sampling, a sector for a profile, a
        method other than Whittle for a map, a surface that is flat once its form is
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

    >>> from rough.fractal.resample import fill_invalid
    >>> scan = rough.read(rough.sample("rock-map.x3p"))
    >>> try:
    ...     fit_fractal(scan)
    ... except rough.InputError as error:
    ...     print(error)
    the spectrum needs gap-free data: this surface has invalid points (fill them with --fill)
    >>> fit = fit_fractal(fill_invalid(scan))
    >>> print(f"Ds = {fit.fractal_dimension:.2f} ± {fit.fractal_dimension_stderr:.2f}, D = {fit.profile_dimension:.2f}")
    Ds = 2.34 ± 0.03, D = 1.34
    """
    from ..metrology import detrend

    if method not in METHODS:
        raise InputError(f"method must be one of {', '.join(METHODS)}, not {method!r}")
    if np.isnan(surface.heights).any():
        raise InputError("the spectrum needs gap-free data: this surface has invalid points (fill them with --fill)")
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
        cross_check = {"variogram": _variogram, "madogram": _madogram, "loglog": _loglog}[method]
        fit = cross_check(levelled, surface.spacing[0], band, resolution, sampling)
    elif surface.is_profile:
        fit = _whittle_profile(levelled, surface, band, resolution, (sampling, source), options)
    else:
        del levelled
        fit = _whittle_map(surface, order, band, resolution, (sampling, source or "maps: band"), sector, options)
    fit.reliability_cutoff = cutoff
    if sector is not None:
        return fit
    if fit.verdict == "no power-law range":
        fit.scale_dependent = _roughness_by_scale(surface, order, cutoff)
    return announce(fit, level)


def tip_cutoff(levelled, surface, tip_radius):
    """The reliability cut-off of a tip over the levelled heights (a map's rows), m, or
    None; refused when the tip follows the surface at no scale."""
    from .scales import reliability_cutoff

    heights = levelled if surface.is_profile else np.atleast_2d(levelled)
    cutoff = reliability_cutoff(heights, surface.spacing[0], tip_radius)
    length = heights.shape[-1] * surface.spacing[0]
    if cutoff is not None and cutoff > length / TIP_SPAN:
        raise InputError(
            f"a tip of radius {tip_radius:g} m cannot follow this surface below {cutoff:.4g} m, more than "
            f"1/{TIP_SPAN} of the scan's length along x ({length:.4g} m): too few scales are left to fit"
        )
    if cutoff is not None:
        log.warning(
            f"a tip of radius {tip_radius:g} m cannot follow the surface below {cutoff:.4g} m (the curvature "
            f"criterion): frequencies above {1e-3 / cutoff:.4g}/mm are left out of the fit"
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
    from ..metrology import detrend
    from .scales import scale_dependent

    table = scale_dependent(detrend(surface, order=order).heights, surface.spacing[0], cutoff=cutoff)
    return {**table, "direction": "profile" if surface.is_profile else "x"}


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


def band_outcome(bins, exponent_range, band, options):
    """The fit over ``band`` when both its ends are given, else over the scaling range
    found inside ``bins`` (see :mod:`rough.fractal.scaling`)."""
    from .scaling import fit_band, scaling_range

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


def _whittle_profile(heights, surface, band, resolution, sampling, options):
    from .scaling import profile_bins, scaling_ranges

    spacing = surface.spacing[0]
    frequencies, ordinates = difference_periodogram(heights, spacing)
    top = default_top(surface, 0.5 / spacing, sampling[0])
    keep = _in_band(frequencies, ((band or (None, None))[0], top if band is None or band[1] is None else band[1]))
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


Settings = dataclasses.make_dataclass("Settings", ["method", "window", "sampling", "source", "spread", "count"])


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
    from .scaling import conclude, fit_spectrum, profile_bins

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


def from_outcome(outcome, kind, resolution, settings):
    """A :class:`FractalFit` from a scaling outcome (see :mod:`rough.fractal.scaling`)."""
    from .scaling import BAND_RULE, TEST_NAME

    profile = kind == "profile"
    fit = outcome.fit
    common = {
        "resolution": resolution,
        "method": settings.method,
        "window": settings.window,
        "sampling": settings.sampling,
        "sampling_source": settings.source,
        "frequencies_used": settings.count,
        "verdict": outcome.verdict,
        "test": TEST_NAME,
        "p_value": outcome.p_value,
        "band_rule": BAND_RULE if outcome.automatic else "given",
    }
    if fit is None:
        nan = math.nan
        return FractalFit(
            nan,
            nan,
            nan,
            nan,
            psd_prefactor=nan,
            hurst=nan,
            band=None,
            structure_function_coefficient=nan,
            profile_dimension=None if profile else nan,
            hint=outcome.hint,
            **common,
        )
    values = _dimension_and_amplitude(fit, resolution, profile)
    bound = outcome.verdict == "at bound"
    dimension_error = None if bound else math.hypot(values["dimension_error"], settings.spread)
    crossover = fit.crossover()
    return FractalFit(
        fractal_dimension=values["dimension"],
        fractal_dimension_stderr=dimension_error,
        amplitude_coefficient=values["amplitude"],
        amplitude_coefficient_stderr=None if bound else values["amplitude_error"],
        psd_prefactor=fit.prefactor,
        hurst=(2.0 if profile else 3.0) - values["dimension"],
        band=outcome.scaling_range,
        structure_function_coefficient=values["amplitude"]
        / model.structure_factor(values["dimension"] - (0.0 if profile else 1.0)),
        profile_dimension=None if profile else values["dimension"] - 1.0,
        at_bound=bound,
        fit_band=outcome.band,
        noise_rms=math.sqrt(fit.noise_variance) if fit.noise_variance else None,
        noise_crossover=crossover if math.isfinite(crossover) and crossover < outcome.band[1] else None,
        rolloff_wavelength=1.0 / fit.rolloff if fit.rolloff else None,
        hint=outcome.hint,
        **common,
    )


def _dimension_and_amplitude(fit, resolution, profile):
    """D (or Ds), C at η and their standard errors from a spectral fit: for a profile
    β = 5 - 2D and A is G's prefactor; for a map α = 8 - 2Ds and C2 is P2's."""
    if profile:
        dimension = (5.0 - fit.exponent) / 2.0
        amplitude = model.amplitude(fit.prefactor, dimension, resolution)
        gradient = np.array([1.0, math.log(resolution)])
    else:
        dimension = (8.0 - fit.exponent) / 2.0
        amplitude = model.map_amplitude(fit.prefactor, dimension, resolution)
        gradient = np.array([1.0, math.log(resolution) - _map_factor_slope(dimension)])
    covariance = fit.covariance
    return {
        "dimension": dimension,
        "dimension_error": math.sqrt(max(covariance[1, 1], 0.0)) / 2,
        "amplitude": amplitude,
        "amplitude_error": amplitude * math.sqrt(max(gradient @ covariance @ gradient, 0.0)),
    }


def refuse_flat(residual, heights):
    """Refuse a surface with no roughness left once its form is removed (a constant or
    a plane): its spectrum is rounding noise, and any D fitted to it is meaningless."""
    if not np.linalg.norm(residual) / math.sqrt(residual.size) > FLAT * np.max(np.abs(heights)):
        raise InputError("the surface is flat once its form is removed: there is no roughness to fit")


UNDEFINED_CHECKED = ("amplitude_coefficient", "psd_prefactor", "structure_function_coefficient")


def announce(fit, level=0.01):
    """One warning for a verdict other than a power law, one naming every result that
    came out undefined (NaN or infinite) although a power law was fitted, and an info
    line when the goodness-of-fit diagnostic falls below ``level``."""
    dimension = "D" if fit.profile_dimension is None else "Ds"
    if fit.verdict == "at bound":
        log.warning(
            f"{dimension} = {fit.fractal_dimension:g} is at the edge of the fractal range: a bound, not an "
            f"estimate{'; ' + fit.hint if fit.hint else ''}"
        )
    elif fit.verdict == "no power-law range":
        log.warning(
            f"no power-law range: {fit.hint or 'no band of a decade keeps its local exponent'}; the RMS height, "
            f"slope and curvature against scale describe the surface instead"
        )
        return fit
    if fit.p_value < level:
        kept = "" if fit.band_rule == "given" else "; the local exponent stays within the band rule's tolerance"
        log.info(
            f"the χ² diagnostic rejects an exact power law over the band (p = {fit.p_value:.2g} < {level:g}){kept}"
        )
    values = {name: getattr(fit, name) for name in UNDEFINED_CHECKED}
    values["band"] = min(fit.band, default=math.nan) if fit.band else math.nan
    undefined = [name for name, value in values.items() if value is None or not math.isfinite(value)]
    if undefined:
        log.warning(
            f"undefined for this surface: {', '.join(undefined)} (outside the range of float64 arithmetic at "
            f"this spacing and height scale)"
        )
    return fit


def _in_band(frequencies, band):
    low, high = band or (None, None)
    keep = np.ones(frequencies.shape, bool)
    if low is not None:
        keep &= frequencies >= low
    if high is not None:
        keep &= frequencies <= high
    return keep


def _band_of(frequencies):
    return (float(frequencies.min()), float(frequencies.max()))


# -- maps: ring-binned Whittle -------------------------------------------------------------

MAP_RANGE = (BETA_RANGE[0] + 1.0, BETA_RANGE[1] + 1.0)


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


def _whittle_map(surface, order, band, resolution, sampling, sector, options):
    from .scaling import ring_bins

    step, low, high = map_band(surface, band, sampling[0])
    field, power = windowed_map(surface, order)
    refuse_flat(field, surface.heights)
    rings = ring_spectrum(field, power, surface.spacing, low, high, step, sector)
    del field
    if rings["count"].size < 4:
        raise InputError(f"only {rings['count'].size} frequency rings in the fit band; widen --band")
    outcome = band_outcome(ring_bins(rings, surface.spacing), MAP_RANGE, band, options)
    count = int(outcome.fit.bins.count.sum()) if outcome.fit else int(rings["count"].sum())
    method = "whittle (ring-binned 2-D periodogram)" + ("" if sector is None else ", sector")
    settings = Settings(method, "hann (periodic)", sampling[0], sampling[1], 0.0, count)
    return from_outcome(outcome, "map", resolution, settings)


def ring_fit(bins, resolution, options):
    """A sector's fit (rose): Ds and C (at η = ``resolution``) with standard errors
    (None at a bound), the noise RMS (m, None without a floor) and whether the
    exponent sits at the edge of the fractal range."""
    from .scaling import fit_spectrum

    fit = fit_spectrum(bins, MAP_RANGE, options.noise, options.rolloff)
    values = _dimension_and_amplitude(fit, resolution, profile=False)
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


def _map_factor_slope(surface_dimension):
    """d log K(Ds) / dα, for the error of C (α = 8 - 2Ds)."""
    from scipy.special import digamma

    alpha = 8.0 - 2.0 * surface_dimension
    return 0.5 * (digamma(alpha / 2) - digamma((alpha - 1) / 2))


# -- profiles: cross-check methods -----------------------------------------------------------


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


def _variogram(heights, spacing, band, resolution, sampling):
    return _lag_result(heights, spacing, resolution, "variogram", sampling)


def _madogram(heights, spacing, band, resolution, sampling):
    return _lag_result(heights, spacing, resolution, "madogram", sampling)


def _loglog_estimate(heights, spacing, band):
    """docs/math.rst §1.4: a least-squares line through the log-binned Hann periodogram over
    the band (default: leaving out k ≤ 2 and the top quarter below Nyquist).
    Returns ``(β, A, band used, frequencies used)``."""
    from .psd import log_bins

    frequencies, density, _ = periodogram(heights, spacing, "hann")
    low, high = band or (3 / (heights.size * spacing), 0.75 * 0.5 / spacing)
    keep = _in_band(frequencies, (low, high)) & (frequencies > 0)
    centres, means, _ = log_bins(frequencies[keep], density[keep])
    slope, intercept = np.polyfit(np.log10(centres), np.log10(means), 1)
    return -slope, 10.0**intercept, _band_of(frequencies[keep]), int(keep.sum())


def _loglog(heights, spacing, band, resolution, sampling):
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
