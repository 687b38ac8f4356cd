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

log = logging.getLogger("rough")
METHODS = ("whittle", "variogram", "madogram", "loglog")
SAMPLINGS = ("point", "band-limited")
BETA_RANGE = (1.0 + 1e-6, 3.0 - 1e-6)
LOWEST_RING = 8
RESAMPLED_TOP = 0.8
FLAT = 1e-9  # RMS residual below this fraction of the largest height is rounding, not roughness


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

    Notes
    -----
    ``as_dict()`` gives the fields as a JSON-able dict (``band`` as a list, and no
    ``profile_dimension`` for a profile).

    Examples
    --------
    >>> import rough
    >>> fit = rough.fit_fractal(rough.read(rough.sample("rock-profile.tsv")))  # D = 1.3
    >>> print(f"D = {fit.fractal_dimension:.3f} ± {fit.fractal_dimension_stderr:.3f}, H = {fit.hurst:.3f}")
    D = 1.305 ± 0.016, H = 0.695
    >>> print(f"C = {fit.amplitude_coefficient * 1e9:.0f} nm at η = {fit.resolution * 1e6:.1f} µm")
    C = 260 nm at η = 30.9 µm
    >>> sorted(fit.as_dict())[:3]
    ['amplitude_coefficient', 'amplitude_coefficient_stderr', 'band']
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

    def as_dict(self):
        values = dataclasses.asdict(self)
        values["band"] = list(self.band)
        if self.profile_dimension is None:
            del values["profile_dimension"]
        return values


def sampling_of(surface):
    """``"band-limited"`` when rough made the surface's spectrum (synth, resample),
    ``"point"`` otherwise."""
    made = {entry.get("command") for entry in surface.history}
    return "band-limited" if made & {"synth", "resample"} else "point"


def default_top(surface, nyquist, sampling):
    """The default top of the fit band: 80 % of the Nyquist frequency after rough's
    resample (its anti-aliasing filter rolls off above that), the Nyquist frequency
    for other band-limited data, and half of it for point-sampled maps."""
    if any(entry.get("command") == "resample" for entry in surface.history):
        return RESAMPLED_TOP * nyquist
    return nyquist if sampling == "band-limited" or surface.is_profile else nyquist / 2


def fit_fractal(surface, band=None, resolution=None, method="whittle", order=1, sampling=None, sector=None):
    """The fractal dimension D (Ds for maps) and amplitude coefficient C of a surface.

    Parameters
    ----------
    surface : Surface
        A gap-free profile or map: invalid (NaN) points must have been filled (see
        :func:`rough.fractal.resample.fill_invalid`).
    band : tuple of (float or None), optional
        ``(fmin, fmax)`` in 1/m, either end None for its default: from the lowest
        frequency (maps: the eighth ring) up to the Nyquist frequency for profiles
        and band-limited maps, half of it for point-sampled maps, and 80 % of it
        after rough's resample.
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
        resampling make). Default: read from the surface's history.
    sector : tuple of float, optional
        Maps only: ``(angle, width)`` in radians, to fit only the wavevectors within
        ``width/2`` of ``angle`` (mod 180°).

    Returns
    -------
    FractalFit
        D (or Ds), C, their standard errors, and what the fit used.

    Raises
    ------
    rough.InputError
        For invalid points, an unknown method or sampling, a sector for a profile, a
        method other than Whittle for a map, a surface that is flat once its form is
        removed, or too few frequencies (8) or rings (4) in the band.

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
    Ds = 2.33 ± 0.04, D = 1.33
    """
    from ..metrology import detrend

    if method not in METHODS:
        raise InputError(f"method must be one of {', '.join(METHODS)}, not {method!r}")
    if np.isnan(surface.heights).any():
        raise InputError("the spectrum needs gap-free data: this surface has invalid points (fill them with --fill)")
    sampling = sampling or sampling_of(surface)
    if sampling not in SAMPLINGS:
        raise InputError(f"sampling must be one of {', '.join(SAMPLINGS)}, not {sampling!r}")
    resolution = resolution or min(surface.spacing)
    if surface.is_profile:
        if sector is not None:
            raise InputError("a direction (sector) needs a map")
        fitter = {"whittle": _whittle_profile, "variogram": _variogram, "madogram": _madogram, "loglog": _loglog}[
            method
        ]
        if method == "whittle" and (band is None or band[1] is None):
            band = ((band or (None, None))[0], default_top(surface, 0.5 / surface.spacing[0], sampling))
        levelled = detrend(surface, order=order).heights
        refuse_flat(levelled, surface.heights)
        return _announce_undefined(fitter(levelled, surface.spacing[0], band, resolution, sampling))
    if method != "whittle":
        raise InputError(f"maps are fitted by the Whittle method only, not {method}")
    fit = _whittle_map(surface, order, band, resolution, sampling, sector)
    return fit if sector is not None else _announce_undefined(fit)


# -- profiles: Whittle on the differences ------------------------------------------------


def _whittle_profile(heights, spacing, band, resolution, sampling):
    differences = np.diff(heights)
    m = differences.size
    transform = np.fft.rfft(differences)
    k = np.arange(1, (m - 1) // 2 + 1)
    frequencies = k / (m * spacing)
    ordinates = spacing / m * np.abs(transform[k]) ** 2
    keep = _in_band(frequencies, band)
    if keep.sum() < 8:
        raise InputError(f"only {keep.sum()} frequencies in the fit band; widen --band or use more points")
    u, ordinates = k[keep] / m, ordinates[keep]
    shape = _difference_shape(u, spacing, sampling)

    def profile_likelihood(beta):
        log_shape = shape(beta)
        return len(u) * math.log(np.mean(ordinates * np.exp(-log_shape))) + log_shape.sum()

    beta = _minimise(profile_likelihood)
    if at_fractal_edge(beta):
        warn_at_edge()
    scale = np.mean(ordinates * np.exp(-shape(beta)))  # = 2A
    derivative = (shape(beta + 1e-5) - shape(beta - 1e-5)) / 2e-5
    covariance = np.linalg.inv(np.array([[len(u), derivative.sum()], [derivative.sum(), (derivative**2).sum()]]))
    return _result(
        beta,
        covariance,
        scale / 2,
        resolution,
        _band_of(frequencies[keep]),
        "whittle",
        "none (first differences)",
        sampling,
        len(u),
    )


def _difference_shape(u, spacing, sampling):
    """log of the differences' spectrum over 2A, as a function of β (vectorised
    over the normalised frequencies u = fΔ in (0, 1/2))."""
    sine = np.log(np.sin(np.pi * u) ** 2)
    log_u = np.log(u)
    grid = np.linspace(u.min(), u.max(), 257) if u.size > 257 else u

    def shape(beta):
        base = -beta * log_u
        if sampling == "point":
            folded = model.aliased_sum(beta, grid) - grid**-beta
            base = base + np.log1p(np.interp(u, grid, folded) * u**beta)
        return sine + beta * math.log(spacing) + base

    return shape


def _minimise(function):
    from scipy.optimize import minimize_scalar

    result = minimize_scalar(function, bounds=BETA_RANGE, method="bounded", options={"xatol": 1e-7})
    return float(result.x)


def refuse_flat(residual, heights):
    """Refuse a surface with no roughness left once its form is removed (a constant or
    a plane): its spectrum is rounding noise, and any D fitted to it is meaningless."""
    if not np.linalg.norm(residual) / math.sqrt(residual.size) > FLAT * np.max(np.abs(heights)):
        raise InputError("the surface is flat once its form is removed: there is no roughness to fit")


def at_fractal_edge(beta):
    """Whether a fitted profile exponent β (or map α - 1) sits at the end of (1, 3)."""
    return min(abs(beta - b) for b in BETA_RANGE) < 1e-3


def warn_at_edge(where="", dimension="D at 1 or 2"):
    log.warning(
        f"the fitted exponent is at the edge of the fractal range ({dimension}){where}: the data do not "
        "follow a fractal power law in this band (see --band)"
    )


UNDEFINED_CHECKED = ("fractal_dimension", "amplitude_coefficient", "psd_prefactor", "structure_function_coefficient")


def _result(beta, covariance, prefactor, resolution, band, method, window, sampling, count):
    dimension = (5.0 - beta) / 2.0
    amplitude = model.amplitude(prefactor, dimension, resolution)
    gradient = np.array([1.0, math.log(resolution)])
    log_error = math.sqrt(max(gradient @ covariance @ gradient, 0.0))
    fit = FractalFit(
        fractal_dimension=dimension,
        fractal_dimension_stderr=math.sqrt(max(covariance[1, 1], 0.0)) / 2,
        amplitude_coefficient=amplitude,
        amplitude_coefficient_stderr=amplitude * log_error,
        resolution=resolution,
        psd_prefactor=prefactor,
        hurst=2.0 - dimension,
        band=band,
        method=method,
        window=window,
        sampling=sampling,
        frequencies_used=count,
        structure_function_coefficient=amplitude / model.structure_factor(dimension),
    )
    return fit


def _announce_undefined(fit):
    """One warning naming every result that came out undefined (NaN or infinite)."""
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


def _whittle_map(surface, order, band, resolution, sampling, sector):
    step, low, high = map_band(surface, band, sampling)
    field, power = windowed_map(surface, order)
    refuse_flat(field, surface.heights)
    rings = ring_spectrum(field, power, surface.spacing, low, high, step, sector)
    del field
    if rings["count"].size < 4:
        raise InputError(f"only {rings['count'].size} frequency rings in the fit band; widen --band")
    fit = ring_fit(rings, resolution)
    if fit["at_edge"]:
        warn_at_edge(dimension="Ds at 2 or 3")
    surface_dimension, amplitude = fit["dimension"], fit["amplitude"]
    return FractalFit(
        fractal_dimension=surface_dimension,
        fractal_dimension_stderr=fit["dimension_error"],
        amplitude_coefficient=amplitude,
        amplitude_coefficient_stderr=fit["amplitude_error"],
        resolution=resolution,
        psd_prefactor=fit["prefactor"],
        hurst=3.0 - surface_dimension,
        band=(float(low), float(high)),
        method="whittle (ring-binned 2-D periodogram)" + ("" if sector is None else ", sector"),
        window="hann (periodic)",
        sampling=sampling,
        frequencies_used=int(rings["count"].sum()),
        structure_function_coefficient=amplitude / model.structure_factor(surface_dimension - 1.0),
        profile_dimension=surface_dimension - 1.0,
    )


def ring_fit(rings, resolution):
    """Ds and C (at η = ``resolution``) with standard errors from ring means, and
    whether the exponent sits at the edge of the fractal range."""
    alpha, prefactor, covariance = _fit_rings(rings)
    dimension = (8.0 - alpha) / 2.0
    amplitude = model.map_amplitude(prefactor, dimension, resolution)
    gradient = np.array([1.0, math.log(resolution) - _map_factor_slope(dimension)])
    return {
        "dimension": dimension,
        "dimension_error": math.sqrt(max(covariance[1, 1], 0.0)) / 2,
        "amplitude": amplitude,
        "amplitude_error": amplitude * math.sqrt(max(gradient @ covariance @ gradient, 0.0)),
        "prefactor": float(prefactor),
        "frequencies_used": int(rings["count"].sum()),
        "at_edge": at_fractal_edge(alpha - 1.0),
    }


def _fit_rings(rings):
    """Gamma (binned Whittle) fit of C2 |f|^-α to ring means. The expected mean of a
    ring is C2 · exp(-α μ + α² σ²/2) (μ, σ² the mean and variance of log |f| in the
    ring) times the window's smoothing, 1 + (α(α+2) a - α b)/6 to second order, with
    a = <(sx² fx² + sy² fy²)/|f|⁴> and b = <(sx² + sy²)/|f|²> (sx, sy the frequency
    steps). Returns ``(α, C2, covariance of (log C2, α))``."""
    dof = rings["count"] / rings["window_factor"]
    means = rings["density"]

    def log_shape(alpha):
        smoothing = 1.0 + (alpha * (alpha + 2.0) * rings["window_a"] - alpha * rings["window_b"]) / 6.0
        return -alpha * rings["log_radius"] + 0.5 * alpha**2 * rings["log_spread"] + np.log(smoothing)

    def profile_likelihood(alpha):
        shape = log_shape(alpha)
        return dof.sum() * math.log(np.sum(dof * means * np.exp(-shape)) / dof.sum()) + np.sum(dof * shape)

    alpha = _minimise(lambda beta: profile_likelihood(beta + 1.0)) + 1.0
    prefactor = float(np.sum(dof * means * np.exp(-log_shape(alpha))) / dof.sum())
    derivative = (log_shape(alpha + 1e-5) - log_shape(alpha - 1e-5)) / 2e-5
    fisher = np.array([[dof.sum(), np.sum(dof * derivative)], [np.sum(dof * derivative), np.sum(dof * derivative**2)]])
    return alpha, prefactor, np.linalg.inv(fisher)


def _map_factor_slope(surface_dimension):
    """d log K(Ds) / dα, for the error of C (α = 8 - 2Ds)."""
    from scipy.special import digamma

    alpha = 8.0 - 2.0 * surface_dimension
    return 0.5 * (digamma(alpha / 2) - digamma((alpha - 1) / 2))


# -- profiles: cross-check methods -----------------------------------------------------------


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
        np.zeros((2, 2)),
        model.prefactor(amplitude, dimension, resolution),
        resolution,
        (1 / (2 * spacing), 1 / spacing),
        statistic,
        "none",
        sampling,
        2,
    )
    fit.fractal_dimension_stderr = error
    fit.amplitude_coefficient_stderr = math.nan
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
        np.zeros((2, 2)),
        prefactor,
        resolution,
        used,
        "loglog (log-binned, band-limited)",
        "hann",
        sampling,
        count,
    )
    fit.fractal_dimension_stderr = _blocks(heights, lambda part: (5.0 - _loglog_estimate(part, spacing, None)[0]) / 2)
    fit.amplitude_coefficient_stderr = math.nan
    return fit
