"""The spectral model real scans fit, and the scaling range over which it holds
(docs/math.rst §1.7).

A measured spectrum is a power law only over a band: below it the form and the
length of the scan, above it the instrument (a white noise floor, the tip's or the
optics' roll-off) and the sampling. The model of the periodogram's expected value is

``S(f) = A · P(f; e) · exp(-(f/fc)²) + σ² · N(f)``

with ``P`` the power law of exponent ``e`` (for a profile's first differences
``2 sin²(πfΔ) Σ_m |f + m/Δ|^-β``, the fold left out for band-limited data; for a map's
Hann-windowed ring means ``|f|^-α`` smoothed by the window), ``N`` the spectrum of
unit white noise (``4 sin²(πfΔ) Δ`` for the differences, ``Δx Δy`` for a map), σ the
noise RMS and ``fc`` the optional roll-off frequency. ``A`` is profiled out in closed
form; ``e``, the noise-to-power ratio at the top of the band and ``fc`` are found by
the gamma (binned Whittle) likelihood of bins of periodogram ordinates.

Goodness of fit: the ordinates are grouped in bins of 10 per decade; under the
model a bin's mean over its expected value is a gamma variate of shape ``w`` (the
bin's number of independent ordinates), so ``z = Φ⁻¹(F_w(w · mean/expected))`` is a
standard normal and ``Σ z²`` is χ² with (bins − fitted parameters) degrees of
freedom. The test sees a bend that the power law does not follow (a roll-off, a
plateau, form left in) wherever it spans a few bins.

The scaling range is chosen by effect size, not by the test (which, over 10⁴–10⁶
ordinates, rejects the slight curvature of any real spectrum): it is the widest band
of at least ``min_decades`` over which the local exponent (the model's exponent
refitted over every half decade of the grid, the band's noise floor and roll-off held)
stays within ``TOLERANCE`` of the band's exponent plus ``ALLOWANCE`` of its own
standard error, with the exponent strictly inside the fractal range and the power law
above the noise floor over at least ``min_decades``. The test's p-value is kept as a
diagnostic (docs/math.rst §1.8).
"""

import dataclasses
import math

import numpy as np
from scipy.optimize import minimize, minimize_scalar
from scipy.special import chdtrc, gammainc, gammaincc, ndtri, zeta  # scipy.stats' own, without its import time

from .. import units
from ..compiled import one_blas_thread

GOF_PER_DECADE = 10
NOISE_LOG_RATIO = (-15.0, 15.0)
POWER_TEST = 13.82  # the 0.1 % point of χ²₂: a floor-only spectrum against floor plus power law
NOISE_TEST = 9.550  # the 0.1 % point of ½χ²₀ + ½χ²₁, the likelihood ratio of a parameter on its bound
TEST_NAME = "χ² of probability-integral-transformed bin means (10 bins per decade)"
TOLERANCE = 0.2  # in the exponent (β or α = 2H + 1 or 2H + 2): 0.1 in H
ALLOWANCE = 3.0  # standard errors of a local exponent added to the tolerance
WINDOW = GOF_PER_DECADE // 2  # grid bins in a local fit: half a decade
SCORING_STEPS = 8
BAND_RULE = (
    "widest band of at least a decade whose local exponents (over half a decade and over half the band) "
    "stay within 0.1 in H plus 3 standard errors of the band's"
)


@dataclasses.dataclass
class Bins:
    """Periodogram ordinates grouped in frequency bins (or one per bin).

    ``count`` ordinates, ``weight`` of them independent, with mean ``density``; the
    count-weighted means over each bin of ``log_f`` and ``log_f2`` (log f and its
    square), ``shape`` and ``shape2`` (the part of log P that does not depend on the
    exponent, and its square), ``cross`` (their product), ``f2`` (f²), ``noise`` (N)
    and the inputs of ``correction(exponent, bins)``, the smooth remaining term of
    log P evaluated at the bin's means.
    """

    count: np.ndarray
    weight: np.ndarray
    density: np.ndarray
    means: dict
    correction: object

    def __len__(self):
        return self.count.size

    @property
    def frequency(self):
        return np.exp(self.means["log_f"])

    def part(self, start, stop):
        pick = slice(start, stop)
        return Bins(
            self.count[pick],
            self.weight[pick],
            self.density[pick],
            {key: value[pick] for key, value in self.means.items()},
            self.correction,
        )

    def starts(self, per_decade=GOF_PER_DECADE):
        """Where each logarithmic bin (``per_decade`` per decade of frequency) starts."""
        index = np.floor(self.means["log_f"] / math.log(10) * per_decade + 1e-9).astype(np.int64)
        return np.flatnonzero(np.r_[True, np.diff(index) != 0])

    def grouped(self, per_decade=GOF_PER_DECADE):
        """Bins merged into ``per_decade`` logarithmic bins per decade of frequency."""
        starts = self.starts(per_decade)

        def total(values):
            return np.add.reduceat(values, starts)

        count = total(self.count)
        return Bins(
            count,
            total(self.weight),
            total(self.count * self.density) / count,
            {key: total(self.count * value) / count for key, value in self.means.items()},
            self.correction,
        )


def log_power(bins, exponent):
    """log P per bin: the exact mean of exp(shape − e·log f) over the bin for a
    lognormal spread (second moments), plus the smooth correction."""
    means = bins.means
    mean = means["shape"] - exponent * means["log_f"]
    variance = (
        means["shape2"]
        - means["shape"] ** 2
        - 2 * exponent * (means["cross"] - means["shape"] * means["log_f"])
        + exponent**2 * (means["log_f2"] - means["log_f"] ** 2)
    )
    return mean + 0.5 * np.maximum(variance, 0.0) + bins.correction(exponent, bins)


def profile_bins(frequencies, spacing, ordinates, sampling):
    """One bin per ordinate of the periodogram of a profile's first differences
    (two-sided, ``Δ/m |DFT|²``) at ``frequencies`` (1/m)."""
    u = frequencies * spacing
    shape = math.log(2.0) + np.log(np.sin(np.pi * u) ** 2)
    log_f = np.log(frequencies)
    means = {
        "log_f": log_f,
        "log_f2": log_f**2,
        "shape": shape,
        "shape2": shape**2,
        "cross": shape * log_f,
        "f2": frequencies**2,
        "noise": 4 * np.sin(np.pi * u) ** 2 * spacing,
    }

    def fold(exponent, bins):
        if sampling != "point":
            return 0.0
        u = np.exp(bins.means["log_f"]) * spacing
        grid = np.geomspace(u.min(), u.max(), 257) if u.size > 257 else u
        folded = aliased_sum(exponent, grid) * grid**exponent - 1.0
        return np.log1p(np.interp(u, grid, folded))

    ones = np.ones(frequencies.size)
    return Bins(ones.astype(np.int64), ones, ordinates, means, fold)


def aliased_sum(exponent, u):
    """Σ_m |u + m|^-exponent over all integers m, for u in (0, 1): the fold of a power
    law onto the base band (Hurwitz zeta: ζ(β, u) + ζ(β, 1 - u)). Needs exponent > 1."""
    return zeta(exponent, u) + zeta(exponent, 1.0 - u)


def ring_bins(rings, spacing):
    """One bin per ring of a map's Hann-windowed ring spectrum (see
    :func:`rough.fractal.psd.ring_spectrum`): the window's smoothing of |f|^-α to
    second order is the correction, its noise floor Δx Δy."""
    log_f, spread = rings["log_radius"], rings["log_spread"]
    zeros = np.zeros(log_f.size)
    means = {
        "log_f": log_f,
        "log_f2": log_f**2 + spread,
        "shape": zeros,
        "shape2": zeros,
        "cross": zeros,
        "f2": np.exp(2 * log_f + 2 * spread),
        "noise": np.full(log_f.size, spacing[0] * spacing[1]),
        "window_a": rings["window_a"],
        "window_b": rings["window_b"],
    }

    def smoothing(alpha, bins):
        a, b = bins.means["window_a"], bins.means["window_b"]
        return np.log(1.0 + (alpha * (alpha + 2.0) * a - alpha * b) / 6.0)

    return Bins(rings["count"], rings["count"] / rings["window_factor"], rings["density"], means, smoothing)


@dataclasses.dataclass
class SpectralFit:
    """A fit of the model to bins: the exponent, A (the power law's prefactor, SI),
    σ² (noise variance, m², 0 without a floor), fc (1/m, None without a roll-off), the
    negative log-likelihood, the covariance of (log A, e), and the bins fitted."""

    exponent: float
    prefactor: float
    noise_variance: float
    rolloff: float
    nll: float
    covariance: np.ndarray
    bins: Bins
    parameters: int

    def expected(self, bins=None):
        """The model's expected periodogram per bin."""
        bins = self.bins if bins is None else bins
        power = self.prefactor * np.exp(log_power(bins, self.exponent))
        if self.rolloff:
            power = power * np.exp(-bins.means["f2"] / self.rolloff**2)
        return power + self.noise_variance * bins.means["noise"]

    def crossover(self):
        """Where the power law meets the noise floor (1/m), from the model's two parts
        at the bins' frequencies (log-interpolated); inf without noise, and the
        lowest bin's frequency when noise dominates throughout."""
        if not self.noise_variance:
            return math.inf
        bins = self.bins
        excess = (
            np.log(self.prefactor) + log_power(bins, self.exponent) - np.log(self.noise_variance * bins.means["noise"])
        )
        if self.rolloff:
            excess = excess - bins.means["f2"] / self.rolloff**2
        below = np.flatnonzero(excess < 0)
        if below.size == 0:
            return math.inf
        first = below[0]
        if first == 0:
            return float(bins.frequency[0])
        x0, x1 = bins.means["log_f"][first - 1], bins.means["log_f"][first]
        e0, e1 = excess[first - 1], excess[first]
        return float(math.exp(x0 + (x1 - x0) * e0 / (e0 - e1)))

    def p_value(self, per_decade=GOF_PER_DECADE):
        """The goodness-of-fit test's p-value (module docstring), on the fitted bins
        merged to ``per_decade`` per decade."""
        return gof_p_value(self.bins, self.expected(), self.parameters, per_decade)


def power_law_found(fit):
    """Whether a fit with a noise floor needs its power law: the likelihood ratio
    against the floor alone passes its 0.1 % test (white noise can lend a power law
    its lowest few ordinates)."""
    if not fit.noise_variance:
        return True
    bins = fit.bins
    shape = bins.means["noise"] / bins.means["noise"][-1]
    total = bins.weight.sum()
    floor_only = total * math.log(np.sum(bins.weight * bins.density / shape) / total) + np.sum(
        bins.weight * np.log(shape)
    )
    return 2 * (floor_only - fit.nll) > POWER_TEST


def gof_p_value(bins, expected, parameters, per_decade=GOF_PER_DECADE):
    merged = bins.grouped(per_decade)
    weight = merged.weight
    ratio = merged.density * merged.count / np.add.reduceat(bins.count * expected, bins.starts(per_decade))
    freedom = len(merged) - parameters
    if freedom < 1:
        return math.nan
    lower = gammainc(weight, weight * ratio)  # the gamma distribution's cdf and survival function
    upper = gammaincc(weight, weight * ratio)
    z = np.where(lower < 0.5, ndtri(lower), -ndtri(upper))
    return float(chdtrc(freedom, np.sum(np.minimum(z**2, 1e6))))


@one_blas_thread
def fit_spectrum(bins, exponent_range, noise=True, rolloff=False):
    """The maximum-likelihood fit of the model to ``bins``: a :class:`SpectralFit`.

    ``noise`` fits a white floor, kept only when the likelihood ratio against no floor
    passes its 0.1 % test and the floor rises above the power law within the band (a
    floor that never dominates is confounded with a flatter power law; so an exact
    power law keeps the efficiency of the two-parameter fit); ``rolloff`` fits a
    Gaussian roll-off.
    """
    plain = _fit(bins, exponent_range, False, rolloff)
    if not noise:
        return plain
    floored = _fit(bins, exponent_range, True, rolloff)
    found = 2 * (plain.nll - floored.nll) > NOISE_TEST and floored.crossover() < bins.frequency[-1]
    return floored if found else plain


def _fit(bins, exponent_range, noise, rolloff):
    weight, density, total = bins.weight, bins.density, bins.weight.sum()
    noise_shape = bins.means["noise"] / bins.means["noise"][-1]
    f2 = bins.means["f2"] / bins.means["f2"][-1]

    def parts(theta):
        """The relative power part, its log, and the noise part."""
        power = log_power(bins, theta[0])
        shape = np.exp(power - power[-1])
        if rolloff:
            shape = shape * np.exp(-f2 * math.exp(-2 * theta[2]))
        return shape, power, math.exp(theta[1]) * noise_shape if noise else 0.0

    def nll(theta):
        shape, _, floor = parts(theta)
        model = shape + floor
        return total * math.log(np.sum(weight * density / model) / total) + np.sum(weight * np.log(model))

    def nll_and_gradient(theta):
        shape, power, floor = parts(theta)
        slope = (log_power(bins, theta[0] + 1e-6) - power) / 1e-6
        slope = slope - slope[-1]
        model = shape + floor
        ratio = weight * density / model
        level = ratio.sum() / total
        common = (weight - ratio / level) / model  # d nll / d model
        gradient = [np.sum(common * shape * slope), np.sum(common * floor) if noise else 0.0]
        gradient.append(np.sum(common * shape * 2 * f2 * math.exp(-2 * theta[2])) if rolloff else 0.0)
        return total * math.log(level) + np.sum(weight * np.log(model)), np.array(gradient)

    low, high = exponent_range
    if not noise and not rolloff:
        theta = [minimize_scalar(lambda e: nll([e]), bounds=(low, high), method="bounded", options={"xatol": 1e-7}).x]
    else:
        bounds = [(low, high), NOISE_LOG_RATIO, (-3.0, 3.0)]
        plain = minimize_scalar(lambda e: nll([e, NOISE_LOG_RATIO[0], 3.0]), bounds=(low, high), method="bounded")
        start = [plain.x, -4.0, 1.0]
        best = None
        for ratio in (start[1], 0.0) if noise else (start[1],):
            guess = [min(max(start[0], low + 1e-3), high - 1e-3), ratio, start[2]]
            result = minimize(nll_and_gradient, guess, jac=True, method="L-BFGS-B", bounds=bounds)
            if best is None or result.fun < best.fun:
                best = result
        theta = list(best.x)
    return _spectral_fit(bins, theta, noise, rolloff, nll(theta), lambda theta: sum(parts(theta)[::2]))


def _spectral_fit(bins, theta, noise, rolloff, nll, relative):
    """Convert the relative parameters to SI and take the covariance of (log A, e)
    from the Fisher information of the parameters fitted."""
    exponent = float(theta[0])
    shape = relative(theta)
    scale = float(np.sum(bins.weight * bins.density / shape) / bins.weight.sum())
    power = log_power(bins, exponent)
    prefactor = scale * math.exp(-power[-1])
    noise_variance = scale * math.exp(theta[1]) / bins.means["noise"][-1] if noise else 0.0
    cutoff = math.sqrt(bins.means["f2"][-1]) * math.exp(theta[2]) if rolloff else None
    fit = SpectralFit(exponent, prefactor, noise_variance, cutoff, float(nll), None, bins, 2 + noise + rolloff)
    fit.covariance = _covariance(fit)
    return fit


def _covariance(fit):
    """The inverse Fisher information of the Whittle likelihood, Σ w ∂log S ∂log S, for
    (log A, e, log σ², log fc) (those fitted), reduced to (log A, e)."""
    bins = fit.bins
    expected = fit.expected()

    def log_expected(**change):
        varied = dataclasses.replace(fit, **change)
        return np.log(varied.expected())

    step = 1e-5
    columns = [fit.prefactor * np.exp(log_power(bins, fit.exponent)) / expected * _rolled(fit)]
    columns.append(
        (log_expected(exponent=fit.exponent + step) - log_expected(exponent=fit.exponent - step)) / (2 * step)
    )
    if fit.noise_variance:
        columns.append(fit.noise_variance * bins.means["noise"] / expected)
    if fit.rolloff:
        columns.append(
            (log_expected(rolloff=fit.rolloff * (1 + step)) - log_expected(rolloff=fit.rolloff * (1 - step)))
            / (2 * step)
        )
    derivatives = np.array(columns)
    fisher = (derivatives * bins.weight) @ derivatives.T
    try:
        return np.linalg.inv(fisher)[:2, :2]
    except np.linalg.LinAlgError:
        return np.full((2, 2), np.inf)


def _rolled(fit):
    return np.exp(-fit.bins.means["f2"] / fit.rolloff**2) if fit.rolloff else 1.0


@dataclasses.dataclass
class Scaling:
    """The outcome of :func:`scaling_range`: the fit over the chosen band (None when no
    band qualified), its p-value (a diagnostic), the band fitted ``(fmin, fmax)`` and the
    scaling range (up to the noise crossover), 1/m; ``verdict`` is ``"power law"``,
    ``"at bound"`` or ``"no power-law range"``; ``best_p`` the largest p-value of any band
    tried; ``departure`` the largest local departure over the band in units of the
    allowance (at most 1 for a band found; NaN for a band given); ``automatic`` whether
    the band was searched for (a band given gets no band in its hint)."""

    fit: SpectralFit
    p_value: float
    band: tuple
    scaling_range: tuple
    verdict: str
    best_p: float
    hint: str = None
    departure: float = math.nan
    automatic: bool = True


def local_exponent(part, fit, exponent_range):
    """``(e, standard error)``: the exponent over the bins ``part`` alone, by Fisher
    scoring of the gamma likelihood from ``fit``'s exponent and level, with ``fit``'s
    noise floor and roll-off held (so a local exponent is that of the power law, not of
    the floor); e stays inside ``exponent_range``. The level is taken at the part's
    mean log frequency, so level and exponent are nearly uncorrelated. The error is that
    of the Fisher information at ``fit`` (the band's model, the null hypothesis): inf
    where the power law is lost under the floor."""
    low, high = exponent_range
    exponent = fit.exponent
    level = math.log(fit.prefactor) + _centre(part, log_power(part, exponent))
    error = None
    for _ in range(SCORING_STEPS):
        information, score = _scoring(part, fit, level, exponent, high)
        determinant = information[0, 0] * information[1, 1] - information[0, 1] ** 2
        if not determinant > 0:
            return exponent, math.inf
        if error is None:
            error = math.sqrt(information[0, 0] / determinant)
        step = np.linalg.solve(information, score)
        level -= float(np.clip(step[0], -2.0, 2.0))
        moved = float(np.clip(exponent - np.clip(step[1], -0.5, 0.5), low, high))
        if abs(moved - exponent) < 1e-4:
            return moved, error
        exponent = moved
    return exponent, error


def _centre(part, values):
    return float(np.sum(part.weight * values) / np.sum(part.weight))


def _scoring(part, fit, level, exponent, high):
    """The Fisher information and the score (gradient of the negative log-likelihood)
    of (level, e) over ``part``, ``fit``'s noise floor and roll-off held; the level is
    the power law's mean log over the part."""
    floor = fit.noise_variance * part.means["noise"]
    rolled = np.exp(-part.means["f2"] / fit.rolloff**2) if fit.rolloff else 1.0
    power = log_power(part, exponent)
    nearby = exponent + (1e-6 if exponent + 1e-6 <= high else -1e-6)
    slope = (log_power(part, nearby) - power) / (nearby - exponent)
    power, slope = power - _centre(part, power), slope - _centre(part, slope)
    signal = np.exp(level + power) * rolled
    expected = signal + floor
    share = signal / expected
    gradient = np.array([share, share * slope])
    information = (gradient * part.weight) @ gradient.T
    return information, gradient @ (part.weight * (1.0 - part.density / expected))


def departure(grid, fit, exponent_range, tolerance=TOLERANCE, limit=math.inf):
    """The largest ``|e_local - e| / (tolerance + ALLOWANCE · error)`` over the windows
    of ``grid`` (bins of 10 per decade) half a decade wide and half the band wide,
    sliding by one bin: a band qualifies when it is at most 1 (past ``limit`` the
    search stops and returns what it has). The short windows see a
    bend where the ordinates are few (a local fit is led by its densest, highest
    frequencies), the long ones a gentle drift where they are many. Windows above the
    noise crossover, where the floor swamps the power law, count with their large
    errors."""
    size = len(grid)
    if size < WINDOW:
        return math.inf
    worst = 0.0
    for window in sorted({max(WINDOW, size // 2), WINDOW}, reverse=True):
        for first in range(size - window + 1):
            exponent, error = local_exponent(grid.part(first, first + window), fit, exponent_range)
            worst = max(worst, abs(exponent - fit.exponent) / (tolerance + ALLOWANCE * error))
            if worst > limit:
                return worst
    return worst


def scaling_range(bins, exponent_range, min_decades=1.0, noise=True, rolloff=False, tolerance=TOLERANCE):
    """The widest band of ``bins`` (in decades, on a grid of 10 per decade) of at least
    ``min_decades`` over which every half-decade's local exponent stays within
    ``tolerance`` (plus ``ALLOWANCE`` standard errors) of the band's, with the exponent
    strictly inside ``exponent_range`` and the power law above the noise floor over at
    least ``min_decades``; among equally wide bands, the one with the smallest
    departure. Only when no band has its exponent inside the range is the widest such
    band with the exponent on a bound returned (verdict ``at bound``). The search fits
    the merged bins; the band chosen is fitted again on the original bins, and is kept
    only if that fit qualifies too. The goodness-of-fit p-value plays no part in the
    choice: it is a diagnostic (see :class:`Scaling`)."""
    return scaling_ranges({None: bins}, exponent_range, min_decades, noise, rolloff, tolerance)[None]


def scaling_ranges(models, exponent_range, min_decades=1.0, noise=True, rolloff=False, tolerance=TOLERANCE):
    """:func:`scaling_range` for several models of the same ordinates (``{name: bins}``,
    e.g. a profile's two sampling models), searched together from the widest band
    down: the search stops at the first width at which any model has a band with its
    exponent inside the range, and a model with none there gets ``"no power-law
    range"`` (its best band could only be narrower). Returns ``{name: Scaling}``."""
    searches = {
        name: _Search(bins, exponent_range, (noise, rolloff, tolerance), min_decades) for name, bins in models.items()
    }
    size = len(next(iter(searches.values())).grid)
    for width in range(size, WINDOW - 1, -1):
        found = {name: search.at_width(width) for name, search in searches.items()}
        if any(found.values()):
            return {
                name: outcome or search.nothing() for (name, outcome), search in zip(found.items(), searches.values())
            }
    return {name: search.conclusion() for name, search in searches.items()}


class _Search:
    """The band search of one model over its grid (see :func:`scaling_range`)."""

    def __init__(self, bins, exponent_range, model, min_decades):
        self.bins, self.exponent_range, self.model, self.min_decades = bins, exponent_range, model, min_decades
        self.grid = bins.grouped()
        self.edges = np.r_[bins.starts(), len(bins)]
        self.lowest = bins.frequency[self.edges[:-1]]
        self.highest = bins.frequency[self.edges[1:] - 1]
        self.best_p, self.bound_choice = 0.0, None

    def at_width(self, width):
        """The outcome of the best qualifying band ``width`` grid bins wide with its
        exponent inside the range, or None."""
        noise, rolloff, tolerance = self.model
        qualifying = []
        for first in range(0, len(self.grid) - width + 1):
            low, high = self.lowest[first], self.highest[first + width - 1]
            if decades(low, high) < self.min_decades:
                continue
            part = self.grid.part(first, first + width)
            fit = fit_spectrum(part, self.exponent_range, noise, rolloff)
            p = fit.p_value()
            self.best_p = max(self.best_p, p if math.isfinite(p) else 0.0)
            span = (low, min(high, fit.crossover()))
            if decades(*span) < self.min_decades or not power_law_found(fit):
                continue
            bound = at_bound(fit.exponent, self.exponent_range)
            if bound and self.bound_choice:
                continue
            worst = departure(part, fit, self.exponent_range, tolerance, limit=1.0)
            if worst > 1:
                continue
            if bound:
                self.bound_choice = (first, width)
            else:
                qualifying.append((worst, first))
        for _, first in sorted(qualifying):
            outcome = self.final(first, width)
            if outcome.verdict == "power law" and outcome.departure <= 1:
                return outcome
        return None

    def final(self, first, width):
        """The model fitted to the original bins of grid bins ``first`` … ``first +
        width``, with its departure over those grid bins."""
        noise, rolloff, tolerance = self.model
        part = self.bins.part(self.edges[first], self.edges[first + width])
        fit = fit_spectrum(part, self.exponent_range, noise, rolloff)
        outcome = conclude(fit, self.exponent_range, self.best_p, self.grid)
        outcome.departure = departure(self.grid.part(first, first + width), fit, self.exponent_range, tolerance)
        return outcome

    def nothing(self):
        hint = nearest_fractal(self.grid, self.exponent_range, self.min_decades)
        return Scaling(None, self.best_p, None, None, "no power-law range", self.best_p, hint)

    def conclusion(self):
        """After the whole search: the widest qualifying band at a bound, or nothing."""
        return self.final(*self.bound_choice) if self.bound_choice else self.nothing()


def fit_band(bins, exponent_range, noise=True, rolloff=False):
    """The model fitted to all of ``bins`` (a band the user chose), as a
    :class:`Scaling` whose verdict does not depend on the test; at a bound its hint
    names no other band (following a hint never leads to another). Where the floor
    alone explains the band, the power law is fitted without it (white noise is then
    a bound: flatter than any fractal), not as an arbitrary slope under the floor."""
    fit = fit_spectrum(bins, exponent_range, noise, rolloff)
    if not power_law_found(fit):
        fit = fit_spectrum(bins, exponent_range, False, rolloff)  # the floor alone: the band's own slope
    return conclude(fit, exponent_range, math.nan, None)


def conclude(fit, exponent_range, best_p, grid):
    """A :class:`Scaling` from a fit over its bins: the verdict from where the exponent
    lies, and at a bound the hint: from ``grid`` (the bins the search had) a band to
    try, or with ``grid`` None (a band given) which side of the range the spectrum
    lies on."""
    frequencies = fit.bins.frequency
    band = (float(frequencies[0]), float(frequencies[-1]))
    span = (band[0], float(min(band[1], max(fit.crossover(), band[0]))))
    bound = at_bound(fit.exponent, exponent_range)
    hint = None
    if bound:
        hint = nearest_fractal(grid, exponent_range) if grid is not None else _side(fit.exponent, exponent_range)
    verdict = "at bound" if bound else "power law"
    return Scaling(fit, fit.p_value(), band, span, verdict, best_p, hint, automatic=grid is not None)


def _side(exponent, exponent_range):
    steeper = abs(exponent - exponent_range[1]) < abs(exponent - exponent_range[0])
    return (
        f"over this band the spectrum is {'steeper' if steeper else 'flatter'} than any fractal's "
        f"(D at the {'lower' if steeper else 'upper'} end of its range)"
    )


def nearest_fractal(grid, exponent_range, decades=1.0):
    """A hint: the band of ``decades`` whose local exponent (a least-squares line through
    the log of the bin means, the exponent-free part of the shape taken out) comes
    nearest the middle of ``exponent_range``, and that exponent; a band to try only
    when that exponent lies inside the range."""
    log_f = grid.means["log_f"]
    level = np.log(grid.density) - grid.means["shape"]
    middle = sum(exponent_range) / 2
    best = None
    for first in range(len(grid)):
        stop = min(np.searchsorted(log_f, log_f[first] + decades * math.log(10) - 1e-9), len(grid) - 1)
        if stop - first < 3 or log_f[stop] - log_f[first] < 0.7 * decades * math.log(10):
            break
        slope = -np.polyfit(log_f[first : stop + 1], level[first : stop + 1], 1)[0]
        if best is None or abs(slope - middle) < abs(best[0] - middle):
            best = (slope, first, stop)
    if best is None:
        return "the spectrum spans less than a decade: use more points or a longer scan"
    slope, first, stop = best
    low, high = math.exp(log_f[first]), math.exp(log_f[stop])
    over = units.format_range(low, high, "1/m")
    if not exponent_range[0] < slope < exponent_range[1]:
        return f"the local exponent lies outside a fractal's range at every scale (nearest {slope:.2f}, over {over})"
    return f"the local exponent comes nearest a fractal's ({slope:.2f}) over {over}: try --band {band_text(low, high)}"


def band_text(low, high):
    """A band of spatial frequencies (1/m) as ``--band`` takes it, each end in the prefix
    that fits it, without spaces (a hint the user pastes back).

    >>> band_text(0.03347, 0.2265), band_text(7140.0, 7.167e4)
    ('33.47/km:226.5/km', '7.14/mm:71.67/mm')
    """
    return ":".join(units.format_quantity(end, "1/m", 4).replace(" ", "") for end in (low, high))


def decades(low, high):
    """How many decades from ``low`` to ``high`` (0 for an empty or reversed band)."""
    return math.log10(high / low) if high > low > 0 else 0.0


def at_bound(exponent, exponent_range):
    """Whether a fitted exponent sits on an end of its range (within 1e-3)."""
    return min(abs(exponent - bound) for bound in exponent_range) < 1e-3
