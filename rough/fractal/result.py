"""The result of a fractal fit: :class:`FractalFit`, made from a spectral fit's outcome
(D or Ds, C at the resolution η and their standard errors), and the warnings it gives.
"""

import dataclasses
import logging
import math

import numpy as np
from scipy.special import digamma

from . import model
from .scaling import BAND_RULE, TEST_NAME

log = logging.getLogger("rough")


@dataclasses.dataclass
class FractalFit:
    """The result of :func:`~rough.fractal.fit_fractal`; lengths in metres, frequencies in 1/m.

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


Settings = dataclasses.make_dataclass("Settings", ["method", "window", "sampling", "source", "spread", "count"])


def from_outcome(outcome, kind, resolution, settings):
    """A :class:`FractalFit` from a scaling outcome (see :mod:`rough.fractal.scaling`)."""
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
    values = dimension_and_amplitude(fit, resolution, profile)
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


def dimension_and_amplitude(fit, resolution, profile):
    """D (or Ds), C at η and their standard errors from a spectral fit: for a profile
    β = 5 - 2D and A is G's prefactor; for a map α = 8 - 2Ds and C2 is P2's."""
    if profile:
        dimension = (5.0 - fit.exponent) / 2.0
        amplitude = model.amplitude(fit.prefactor, dimension, resolution)
        gradient = np.array([1.0, math.log(resolution)])
    else:
        dimension = (8.0 - fit.exponent) / 2.0
        amplitude = model.map_amplitude(fit.prefactor, dimension, resolution)
        gradient = np.array([1.0, math.log(resolution) - map_factor_slope(dimension)])
    covariance = fit.covariance
    return {
        "dimension": dimension,
        "dimension_error": math.sqrt(max(covariance[1, 1], 0.0)) / 2,
        "amplitude": amplitude,
        "amplitude_error": amplitude * math.sqrt(max(gradient @ covariance @ gradient, 0.0)),
    }


def map_factor_slope(surface_dimension):
    """d log K(Ds) / dα, for the error of C (α = 8 - 2Ds)."""
    alpha = 8.0 - 2.0 * surface_dimension
    return 0.5 * (digamma(alpha / 2) - digamma((alpha - 1) / 2))


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
