"""The material-ratio (Abbott–Firestone) curve and the parameters built on it:
ISO 13565-2 (Rk, Rpk, Rvk, Mr1, Mr2, A1, A2), ISO 13565-3 (Rpq, Rvq, Rmq), ISO 4287
and ISO 21920-2 (Rmr(c), Rmc(mr), Rδc), and ISO 25178-2:2021's areal counterparts
(Smr(c), Smc(mr), Sdc, Sk, Spk, Svk, Smr1, Smr2, Sxp; Vm, Vv, Vmp, Vmc, Vvc, Vvv).

The curve. The ``n`` valid heights about their mean, sorted from the highest down,
``h_0 ≥ … ≥ h_(n-1)``, placed at material ratios ``mr_k = 100 k / (n - 1)`` % and
joined by straight lines: ``h(0 %)`` is the highest point and ``h(100 %)`` the
lowest. The mean is that of the sorted heights, so the curve and every parameter
below depend on the valid heights only, not on their order nor on where invalid
points lie. Smc(mr) reads the curve; Smr(c) inverts it, and where several points
share the height ``c`` (quantised data) it counts them all as material (the largest
ratio); a point within the heights' rounding of ``c`` is at ``c``. The heights'
rounding is ``ROUNDING`` (64 eps) times the largest absolute height as given: what
storing and centring them leaves, with a wide margin. Sampling the curve at every
point, rather than in classes, makes every parameter exact for the data; surfalize
samples it at 10 000 classes.

The core (ISO 13565-2 §4; ISO 25178-2:2021 Annex B). The *central region* is the
40 % wide window of material ratio whose secant drops least. Windows whose drops
exceed the least by no more than the heights' rounding are tied (quantised heights
tie windows exactly, and rounding alone would choose), and the central region is the
first of them, at the lowest material ratio, as ISO 13565-2 takes the first of equal
windows. The *equivalent straight line* is the least-squares line ``h = a + b·mr``
through the curve's points in that window (the secant itself when the window holds
fewer than two points). It meets 0 % at ``c1 = a`` and 100 % at ``c2 = a + 100 b``:
Sk = c1 - c2, Smr1 = Smr(c1), Smr2 = Smr(c2). A1 is the area between the curve and
the level ``c1`` over ``0 … Smr1`` and A2 that between the level ``c2`` and the curve
over ``Smr2 … 100 %`` (both in height × %, integrated exactly on the
piecewise-linear curve); Spk = 2 A1 / Smr1 and Svk = 2 A2 / (100 % - Smr2), the
heights of triangles of equal area, and 0 when Smr1 = 0 or Smr2 = 100 %.

Volumes (ISO 25178-2 §4.4), per unit area, in m³/m² (1 m³/m² = 10⁶ ml/m²):
``Vm(mr) = ∫_0^mr (h(q) - h(mr)) dq / 100 %``, the material above the level
``h(mr)``, and ``Vv(mr) = ∫_mr^100 (h(mr) - h(q)) dq / 100 %``, the void below it.
Vmp = Vm(p), Vmc = Vm(q) - Vm(p), Vvc = Vv(p) - Vv(q), Vvv = Vv(q), with p = 10 %
and q = 80 % by default. Sxp = Smc(2.5 %) - Smc(50 %); Sdc(mr1, mr2) = Smc(mr1) -
Smc(mr2).

The normal-probability curve (ISO 13565-3). Heights against the standard normal
deviate of their material ratio (Hazen positions ``(k + ½)/n``), within ±3 standard
deviations. A stratified surface gives two straight lines: the plateau (upper) and
the valley (lower) process. rough fits both at once, as the continuous two-line
least-squares fit whose break minimises the residual (of breaks whose residuals
exceed the least by no more than ``ROUNDING`` times the sum of squared heights, the
one at the lowest deviate): Rpq and Rvq are the slopes of the plateau and valley
lines (the Rq of each process), Rmq the material ratio of the break, in %. ISO
13565-3 fixes the two regions by other rules; on an exact two-process surface both
give its two Rq and its transition.

Every function here uses the valid (non-NaN) points only.
"""

import dataclasses
import functools
import math

import numpy as np
from scipy.special import ndtr, ndtri

from ..compiled import compiled
from ..errors import InputError
from .heights import BLOCK, ROUNDING, valid_values
from .profile import combined, map_profiles

CENTRAL_REGION = 40.0  # % of material ratio, ISO 13565-2 and ISO 25178-2
PROBABILITY_RANGE = 3.0  # standard deviations either side of the mean, ISO 13565-3
LEAST_REGION = 0.05  # fraction of the points each line of the probability fit spans at least
COMPILED_SUMS = 1 << 22  # points from which the fit's running sums are one compiled pass

PROFILE_FUNCTIONAL = {
    "Rmr": ("%", "material ratio Rmr(c) at the height c"),
    "Rmc": ("m", "height at the material ratio, Rmc(mr)"),
    "Rdc": ("m", "height difference Rδc between two material ratios"),
    "Rk": ("m", "core roughness depth"),
    "Rpk": ("m", "reduced peak height"),
    "Rvk": ("m", "reduced valley depth"),
    "Mr1": ("%", "material ratio at the top of the core"),
    "Mr2": ("%", "material ratio at the bottom of the core"),
    "A1": ("m·%", "area of the peaks, Rpk·Mr1/2"),
    "A2": ("m·%", "area of the valleys, Rvk·(100 % - Mr2)/2"),
    "Rpq": ("m", "plateau root mean square roughness (ISO 13565-3)"),
    "Rvq": ("m", "valley root mean square roughness (ISO 13565-3)"),
    "Rmq": ("%", "material ratio at the plateau-to-valley transition (ISO 13565-3)"),
}
AREAL_FUNCTIONAL = {
    "Smr": ("%", "areal material ratio Smr(c) at the height c"),
    "Smc": ("m", "inverse areal material ratio Smc(mr)"),
    "Sdc": ("m", "height difference between two material ratios"),
    "Sk": ("m", "core height"),
    "Spk": ("m", "reduced peak height"),
    "Svk": ("m", "reduced dale height"),
    "Smr1": ("%", "material ratio at the top of the core (Smrk1 in the 2021 edition)"),
    "Smr2": ("%", "material ratio at the bottom of the core (Smrk2 in the 2021 edition)"),
    "Sxp": ("m", "peak extreme height Smc(2.5 %) - Smc(50 %)"),
    "Vm": ("m3/m2", "material volume Vm(mr)"),
    "Vv": ("m3/m2", "void volume Vv(mr)"),
    "Vmp": ("m3/m2", "peak material volume Vm(p)"),
    "Vmc": ("m3/m2", "core material volume Vm(q) - Vm(p)"),
    "Vvc": ("m3/m2", "core void volume Vv(p) - Vv(q)"),
    "Vvv": ("m3/m2", "dale void volume Vv(q)"),
    "Spq": ("m", "plateau root mean square height (ISO 13565-3 on the areal curve)"),
    "Svq": ("m", "dale root mean square height (ISO 13565-3 on the areal curve)"),
    "Smq": ("%", "material ratio at the plateau-to-dale transition"),
}


@dataclasses.dataclass(frozen=True)
class Core:
    """The ISO 13565-2 construction on a material-ratio curve (heights in metres
    about the mean, ratios in %).

    Attributes
    ----------
    top, bottom : float
        Where the equivalent straight line meets 0 % and 100 %: ``c1`` and ``c2``.
    slope : float
        Its gradient, metres per %.
    window : tuple of float
        The central region, ``(start, start + 40)`` %.
    mr1, mr2 : float
        Smr(c1) and Smr(c2), %.
    peak_area, valley_area : float
        A1 and A2, m·%.
    """

    top: float
    bottom: float
    slope: float
    window: tuple
    mr1: float
    mr2: float
    peak_area: float
    valley_area: float

    @property
    def height(self):
        """Sk (Rk): ``top - bottom``, metres."""
        return self.top - self.bottom

    @property
    def reduced_peak(self):
        """Spk (Rpk): ``2 A1 / Smr1``, metres; 0 when no material lies above the core."""
        return 2.0 * self.peak_area / self.mr1 if self.mr1 > 0 else 0.0

    @property
    def reduced_valley(self):
        """Svk (Rvk): ``2 A2 / (100 - Smr2)``, metres; 0 when no void lies below the core."""
        return 2.0 * self.valley_area / (100.0 - self.mr2) if self.mr2 < 100 else 0.0


@dataclasses.dataclass(frozen=True)
class ProbabilityFit:
    """ISO 13565-3's two lines on the normal-probability material-ratio curve.

    Attributes
    ----------
    plateau, valley : float
        Slopes of the upper and lower line, metres per standard deviation (Rpq, Rvq).
    transition : float
        Material ratio at their intersection, % (Rmq).
    deviate : float
        The standard normal deviate of the intersection.
    height : float
        The height of the intersection, metres about the mean.
    """

    plateau: float
    valley: float
    transition: float
    deviate: float
    height: float


class MaterialRatioCurve:
    """The material-ratio curve of a surface's valid heights about their mean.

    Parameters
    ----------
    surface : Surface or array_like
        A profile or map, or an array of heights in metres; NaN points are left
        out. At least two valid points.

    Raises
    ------
    rough.InputError
        With fewer than two valid points.

    Examples
    --------
    Heights spread evenly from -1 to +1 µm: the curve is a straight line, so the
    core holds all of it (Rk = 2 µm, Rpk = Rvk = 0), half the material lies above the
    mean, and ten per cent above 0.8 µm:

    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology import MaterialRatioCurve
    >>> ramp = rough.Surface(np.linspace(-1e-6, 1e-6, 1001), 1e-6)
    >>> curve = MaterialRatioCurve(ramp)
    >>> round(float(curve.ratio_at(0.0)), 9), round(float(curve.height_at(10.0)) * 1e6, 9)
    (50.0, 0.8)
    >>> core = curve.core()
    >>> round(core.height * 1e6, 9), core.reduced_peak, core.reduced_valley
    (2.0, 0.0, 0.0)
    """

    def __init__(self, surface):
        heights, _ = valid_values(np.asarray(getattr(surface, "heights", surface), dtype=np.float64))
        if heights.size < 2:
            raise InputError("the material-ratio curve needs at least two valid points")
        ordered = np.negative(heights)  # one new array: sorted ascending, it runs from the highest point down
        ordered.sort()
        self._rounding = ROUNDING * max(abs(float(ordered[0])), abs(float(ordered[-1])))
        ordered -= ordered.sum() / ordered.size  # the mean of the sorted heights: the same for any order of the points
        np.negative(ordered, out=ordered)
        ordered += 0.0  # -0.0 to 0.0
        self.heights = ordered
        self.ratios = np.linspace(0.0, 100.0, heights.size)

    @functools.cached_property
    def _integral(self):
        """``∫_0^ratios[i] h(q) dq`` at every point of the curve (height × %), by the
        trapezium rule; made when first needed."""
        integral = np.empty(self.heights.size)
        integral[0] = 0.0
        steps = integral[1:]  # the trapezia, then summed in place
        np.add(self.heights[:-1], self.heights[1:], out=steps)
        for start in range(0, steps.size, BLOCK):  # the widths without a temporary as long as the curve
            steps[start : start + BLOCK] *= np.diff(self.ratios[start : start + BLOCK + 1])
        steps /= 2
        np.cumsum(steps, out=steps)
        return integral

    def ratio_at(self, height):
        """Smr(c) (Rmr(c)): the material ratio in % at ``height`` metres about the mean;
        0 above the highest point, 100 at and below the lowest. Points at exactly
        ``height`` count as material."""
        return self._ratio(height, "right")

    def _ratio(self, height, side):
        """The curve's ratio at ``height``: where it leaves that level (``side="right"``,
        every point at the height counted) or first reaches it (``"left"``)."""
        c = np.asarray(height, dtype=np.float64)
        level = c + (1 if side == "left" else -1) * self._rounding  # a point within rounding of c is at c
        after = np.searchsorted(-self.heights, -level, side=side) - 1  # the last point above (or at) the height
        inner = np.clip(after, 0, self.heights.size - 2)
        upper, lower = self.heights[inner], self.heights[inner + 1]
        with np.errstate(invalid="ignore", divide="ignore"):
            fraction = np.clip(np.where(upper > lower, (upper - c) / (upper - lower), 0.0), 0.0, 1.0)
        ratio = self.ratios[inner] + fraction * (self.ratios[inner + 1] - self.ratios[inner])
        return np.where(after < 0, 0.0, np.where(after >= self.heights.size - 1, 100.0, ratio))

    def height_at(self, ratio):
        """Smc(mr) (Rmc(mr)): the height in metres about the mean at the material ratio
        ``ratio`` %, in [0, 100]."""
        _check_ratio(ratio)
        return np.interp(ratio, self.ratios, self.heights)

    def _area_above(self, ratio):
        """``∫_0^ratio h(q) dq`` on the piecewise-linear curve (height × %)."""
        k = np.clip(np.searchsorted(self.ratios, ratio, side="right") - 1, 0, self.ratios.size - 2)
        return self._integral[k] + (ratio - self.ratios[k]) * (self.heights[k] + self.height_at(ratio)) / 2

    def _excess(self, ratio, level):
        """``∫_0^ratio (h(q) - level) dq``: the curve above ``level`` up to ``ratio`` (height × %)."""
        return max(0.0, float(self._area_above(ratio) - ratio * level))

    def _deficit(self, ratio, level):
        """``∫_ratio^100 (level - h(q)) dq``: the curve below ``level`` from ``ratio`` (height × %)."""
        return max(0.0, float((100.0 - ratio) * level - (self._integral[-1] - self._area_above(ratio))))

    def material_volume(self, ratio):
        """Vm(mr): the material above the height Smc(mr), per unit area, m³/m²."""
        return self._excess(ratio, self.height_at(ratio)) / 100.0

    def void_volume(self, ratio):
        """Vv(mr): the void below the height Smc(mr), per unit area, m³/m²."""
        return self._deficit(ratio, self.height_at(ratio)) / 100.0

    def core(self):
        """The ISO 13565-2 construction: the 40 % central region of least secant
        gradient, its least-squares equivalent straight line and the areas A1, A2.

        Of windows whose drops differ from the least by no more than the rounding of
        the heights (:data:`ROUNDING` times the largest absolute height as given),
        the first, at the lowest material ratio, is the central region.

        Returns
        -------
        Core
        """
        n = self.heights.size
        points, fifths = divmod(2 * (n - 1), 5)  # the window spans points + fifths/5 intervals of the curve
        first = self._central_region(points, fifths)
        start = float(self.ratios[first])
        if points:
            slope, top, bottom = _central_line(self.heights[first : first + points + 1], first, n)
        else:  # fewer than two points in the window (fewer than four in all): the secant
            slope = -float(self._drops(first, first + 1, points, fifths)[0]) / CENTRAL_REGION
            top = float(self.heights[first]) - slope * start
            bottom = top + 100.0 * slope
        mr1, mr2 = float(self._ratio(top, "left")), float(self._ratio(bottom, "right"))
        peak_area, valley_area = self._excess(mr1, top), self._deficit(mr2, bottom)
        return Core(top, bottom, slope, (start, start + CENTRAL_REGION), mr1, mr2, peak_area, valley_area)

    def _central_region(self, points, fifths):
        """The first point of the central region: of the windows starting at every
        point up to 60 %, the first whose secant drop is within :attr:`_rounding` of
        the least (drops that close are equal to the precision of the heights)."""
        windows = (3 * (self.heights.size - 1)) // 5 + 1
        blocks = [(top, min(top + BLOCK, windows)) for top in range(0, windows, BLOCK)]
        least = min(float(self._drops(top, stop, points, fifths).min()) for top, stop in blocks)
        tied = (self._drops(top, stop, points, fifths) <= least + self._rounding for top, stop in blocks)
        return next(top + int(np.argmax(close)) for (top, _), close in zip(blocks, tied) if close.any())

    def _drops(self, top, stop, points, fifths):
        """The secant drops ``h(mr) - h(mr + 40 %)`` of the windows starting at the
        points ``top … stop - 1``, ``points + fifths/5`` points long: the same sum of
        two non-negative differences of sorted heights for every window."""
        h = self.heights
        end = h[top + points : stop + points]
        drops = h[top:stop] - end
        if fifths:
            drops += fifths / 5 * (end - h[top + points + 1 : stop + points + 1])
        return drops

    def probability(self):
        """ISO 13565-3: the continuous two-line least-squares fit to the heights against
        the normal deviate of their material ratio, within ±3 standard deviations,
        each line spanning at least 5 % of those points.

        Returns
        -------
        ProbabilityFit
            NaN throughout when fewer than 40 points lie within ±3 standard deviations.
        """
        n = self.heights.size
        deviates = np.arange(n, dtype=np.float64)
        deviates += 0.5
        deviates /= n
        ndtri(deviates, out=deviates)  # ascending, as the heights reversed
        inside = slice(
            np.searchsorted(deviates, -PROBABILITY_RANGE, side="left"),
            np.searchsorted(deviates, PROBABILITY_RANGE, side="right"),
        )
        deviates, heights = deviates[inside], self.heights[::-1][inside]
        if deviates.size < 40:
            return ProbabilityFit(math.nan, math.nan, math.nan, math.nan, math.nan)
        return _two_lines(deviates, heights)


def _check_ratio(ratio):
    if not np.all((np.asarray(ratio) >= 0) & (np.asarray(ratio) <= 100)):
        raise InputError(f"a material ratio must lie between 0 and 100 %, not {ratio}")


def _central_line(heights, first, n):
    """The least-squares line through the ``m`` points ``first …`` of a curve of ``n``,
    ``heights`` (sorted from the highest down), as ``(slope, top, bottom)``: metres
    per %, and its heights at 0 % and 100 %. Its gradient per point is
    ``Σ (i - i0)(h_i - h_(m-1-i)) / Σ (i - i0)²`` over the first half of the window
    about its centre ``i0``: exact offsets and differences of one sign, so no
    cancellation, and exactly 0 on a level window."""
    m = heights.size
    offsets = np.arange(m // 2) - (m - 1) / 2
    gaps = heights[: m // 2] - heights[::-1][: m // 2]
    per_point = float(np.sum(offsets * gaps)) / (m * (m * m - 1) / 12)
    centre, level = first + (m - 1) / 2, float(heights.mean())
    return per_point * (n - 1) / 100, level - per_point * centre, level + per_point * (n - 1 - centre)


def _two_lines(q, h):
    """The continuous broken line ``h = a + v·min(q - b, 0) + p·max(q - b, 0)`` of least
    squares over the breaks ``b`` at the points' deviates (q ascending): every break
    on a grid of at most 1024, then every break between the best one's neighbours.
    The moments' running sums are kept only at those breaks (one moment at a time)."""
    n = q.size
    least = max(2, int(LEAST_REGION * n))
    stride = max(1, (n - 2 * least) // 1024)
    coarse = np.arange(least, n - least, stride)
    ends = np.append(coarse, n)
    sums = _sums_at(q, h, ends)
    tolerance = ROUNDING * float(sums["hh"][-1])  # residuals this close are equal to the precision of the sums
    residual, _ = _broken_lines(q, sums, ends)
    best = _first_least(residual, tolerance)
    before = max(0, best - 1)  # the window starts at a coarse break, whose running sums are known
    fine = np.arange(coarse[before], min(n - least, coarse[best] + stride + 1))
    window = slice(fine[0], fine[-1])
    sums = {name: _running(values, sums[name][before], sums[name][-1]) for name, values in _moments(q, h, window)}
    residual, coefficients = _broken_lines(q, sums, np.append(fine, n))
    best = _first_least(residual, tolerance)
    intercept, valley, plateau = coefficients[best]
    deviate = float(q[fine[best]])
    return ProbabilityFit(float(plateau), float(valley), float(100.0 * ndtr(-deviate)), deviate, float(intercept))


def _sums_at(q, h, ends):
    """The running sums of the moments of :func:`_moments` at the indices ``ends - 1``
    (increasing): a cumulative sum of each moment in turn, or on :data:`COMPILED_SUMS`
    points or more one compiled pass over all five, with the same additions in the
    same order (numba, :func:`rough.compiled.compiled`)."""
    if q.size >= COMPILED_SUMS:
        return dict(zip(("q", "qq", "h", "qh", "hh"), compiled(_running_sums)(q, h, ends)))
    sums = {}
    for name, values in _moments(q, h):
        sums[name] = _cumulative(values)[ends - 1]
        del values  # before the next moment is made
    return sums


def _running_sums(q, h, ends):
    """Rows q, q², h, qh, h² of the running sums at ``ends - 1``, each added up from
    the first point on as ``np.cumsum`` does. Plain Python, compiled by
    :func:`_sums_at`."""
    table = np.empty((5, ends.size))
    sq, sqq, sh, sqh, shh = q[0], q[0] * q[0], h[0], q[0] * h[0], h[0] * h[0]
    k = 0
    for i in range(ends[-1]):
        if i:
            a, b = q[i], h[i]
            sq, sqq, sh, sqh, shh = sq + a, sqq + a * a, sh + b, sqh + a * b, shh + b * b
        while k < ends.size and ends[k] - 1 == i:
            table[0, k], table[1, k], table[2, k], table[3, k], table[4, k] = sq, sqq, sh, sqh, shh
            k += 1
    return table


def _first_least(values, tolerance):
    """The index of the first of ``values`` within ``tolerance`` of the least."""
    return int(np.argmax(values <= values.min() + tolerance))


def _cumulative(values):
    """The running sums of ``values``, in place when they are a temporary of ours."""
    return np.cumsum(values, out=values if values.base is None else None)


def _running(values, before, total):
    """Running sums over ``values`` continuing from ``before`` (the sum of everything
    earlier), then the overall ``total``: the same sums, in the same order of
    additions, as one cumulative sum over the whole."""
    running = np.empty(values.size + 2)
    running[0] = before
    running[1:-1] = values
    running[1] += before
    np.cumsum(running[1:-1], out=running[1:-1])
    running[-1] = total
    return running


def _broken_lines(q, sums, ends):
    """Residual sums of squares and coefficients (a, v, p) of the broken line at each
    break index of ``ends[:-1]`` (``ends[-1]`` is the number of points), from the
    moments' running sums at those indices (``sums[name][i]``: the sum over the
    points before ``ends[i]``)."""
    n, breaks = ends[-1], ends[:-1]
    b = q[breaks]
    low = {name: total[:-1] for name, total in sums.items()}  # points below the break
    high = {name: total[-1] - total[:-1] for name, total in sums.items()}
    count_low, count_high = breaks.astype(float), n - breaks.astype(float)
    # Normal equations in the columns 1, u = min(q - b, 0), w = max(q - b, 0).
    su, sw = low["q"] - b * count_low, high["q"] - b * count_high
    suu = low["qq"] - 2 * b * low["q"] + b * b * count_low
    sww = high["qq"] - 2 * b * high["q"] + b * b * count_high
    suh, swh = low["qh"] - b * low["h"], high["qh"] - b * high["h"]
    zero = np.zeros_like(b)
    matrix = np.stack(
        [
            np.stack([np.full_like(b, float(n)), su, sw], -1),
            np.stack([su, suu, zero], -1),
            np.stack([sw, zero, sww], -1),
        ],
        axis=-2,
    )
    rhs = np.stack([np.full_like(b, sums["h"][-1]), suh, swh], axis=-1)
    coefficients = np.linalg.solve(matrix, rhs[..., None])[..., 0]
    return sums["hh"][-1] - np.sum(coefficients * rhs, axis=-1), coefficients


def _moments(q, h, window=slice(None)):
    """``(name, values)`` of the moments q, q², h, qh, h² over ``window``, one at a time."""
    q, h = q[window], h[window]
    yield "q", q
    yield "qq", q * q
    yield "h", h
    yield "qh", q * h
    yield "hh", h * h


def functional_parameters(
    surface, height=0.0, ratio=10.0, dc_ratios=(10.0, 80.0), volume_ratios=(10.0, 80.0), along=None
):
    """Material-ratio parameters of a profile (ISO 13565-2/-3, ISO 4287) or a map
    (ISO 25178-2:2021), in SI units.

    On the data as given, about the mean of the valid points (filter or detrend
    first: ISO 13565-2 expects the roughness profile).

    Parameters
    ----------
    surface : Surface
        A profile or map; NaN points are left out of the curve.
    height : float, default 0
        The height c of Smr(c) / Rmr(c), metres about the mean.
    ratio : float, default 10
        The material ratio mr of Smc(mr) / Rmc(mr) and of Vm(mr), Vv(mr), in %.
    dc_ratios : tuple of float, default (10, 80)
        mr1 < mr2 of Sdc(mr1, mr2) / Rδc, %.
    volume_ratios : tuple of float, default (10, 80)
        p < q of Vmp, Vmc, Vvc, Vvv, % (ISO 25178-2's defaults).
    along : {None, "x", "y"}, optional
        A map's profiles in that direction: the profile parameters of each profile
        with at least two valid points, averaged over the profiles where they are
        defined.

    Returns
    -------
    dict of str to float
        Keyed as :data:`PROFILE_FUNCTIONAL` for a profile (or a map with ``along``)
        and :data:`AREAL_FUNCTIONAL` for a map. Rpq, Rvq and Rmq (Spq, Svq, Smq)
        are NaN with fewer than 40 points within ±3 standard deviations.

    Raises
    ------
    rough.InputError
        For fewer than two valid points, a ratio outside 0–100 %, or ratio pairs
        not in increasing order.

    Examples
    --------
    Gaussian heights of σ = 1 µm: about half the material lies above the mean, the
    core is 2.57σ deep for an exact Gaussian and Vmp is σ·(φ(z) - 0.1 z) with
    z = Φ⁻¹(0.9), 0.0474 µm; this sample of 65 536 points comes close:

    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology import functional_parameters
    >>> rng = np.random.default_rng(1)
    >>> scan = rough.Surface(1e-6 * rng.standard_normal((256, 256)), 1e-6)
    >>> values = functional_parameters(scan)
    >>> print(f"Smr {values['Smr']:.1f} %, Sk {values['Sk'] * 1e6:.2f} µm, Vmp {values['Vmp'] * 1e6:.4f} µm")
    Smr 49.9 %, Sk 2.56 µm, Vmp 0.0484 µm
    """
    for low, high in (dc_ratios, volume_ratios):
        _check_ratio([low, high])
        if not low < high:
            raise InputError(f"material ratios must be given in increasing order, not {low} and {high}")
    _check_ratio(ratio)
    settings = {"height": height, "ratio": ratio, "dc_ratios": dc_ratios, "volume_ratios": volume_ratios}
    if surface.is_profile:
        return _profile(MaterialRatioCurve(surface), **settings)
    if along is None:
        return _areal(MaterialRatioCurve(surface), **settings)
    return _mean_over_profiles(surface, along, settings)


def _profile(curve, height, ratio, dc_ratios, volume_ratios):
    fit, core = curve.probability(), curve.core()  # the fit's scratch goes before core() makes the integral
    return {
        "Rmr": float(curve.ratio_at(height)),
        "Rmc": float(curve.height_at(ratio)),
        "Rdc": float(curve.height_at(dc_ratios[0]) - curve.height_at(dc_ratios[1])),
        "Rk": core.height,
        "Rpk": core.reduced_peak,
        "Rvk": core.reduced_valley,
        "Mr1": core.mr1,
        "Mr2": core.mr2,
        "A1": core.peak_area,
        "A2": core.valley_area,
        "Rpq": fit.plateau,
        "Rvq": fit.valley,
        "Rmq": fit.transition,
    }


def _areal(curve, height, ratio, dc_ratios, volume_ratios):
    values = _profile(curve, height, ratio, dc_ratios, volume_ratios)
    p, q = volume_ratios
    names = {"Rmr": "Smr", "Rmc": "Smc", "Rdc": "Sdc", "Rk": "Sk", "Rpk": "Spk", "Rvk": "Svk", "Mr1": "Smr1"}
    names |= {"Mr2": "Smr2", "Rpq": "Spq", "Rvq": "Svq", "Rmq": "Smq"}
    areal = {names[key]: value for key, value in values.items() if key in names}
    areal.update(
        Sxp=float(curve.height_at(2.5) - curve.height_at(50.0)),
        Vm=curve.material_volume(ratio),
        Vv=curve.void_volume(ratio),
        Vmp=curve.material_volume(p),
        Vmc=curve.material_volume(q) - curve.material_volume(p),
        Vvc=curve.void_volume(p) - curve.void_volume(q),
        Vvv=curve.void_volume(q),
    )
    return {key: areal[key] for key in AREAL_FUNCTIONAL}


def _mean_over_profiles(surface, along, settings):
    each = [_profile(MaterialRatioCurve(profile), **settings) for profile in map_profiles(surface, along)]
    return combined(each, PROFILE_FUNCTIONAL)
