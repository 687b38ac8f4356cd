"""The heights of a surface about the mean of its valid points: centring, the
amplitude moments, local slopes and the amplitude density, which the profile, areal,
spatial and functional parameters are built on.

Everything is over the valid (non-NaN) points only: amplitude moments use the valid
points, so a scan with dropouts gives the values of its valid points; slopes use
pairs of neighbouring valid points, by default forward differences
(``slope="2point"``, the definition of SurfaceTopography's ``rms_gradient`` and
surfalize's Rdq), or ISO 4287's seven-point derivative (``slope="7point"``).
"""

import fractions
import math

import numpy as np
from scipy.ndimage import correlate1d

from ..errors import InputError
from .choices import SLOPES

SEVEN_POINT = np.array([1.0, -9.0, 45.0, 0.0, -45.0, 9.0, -1.0]) / 60.0
MAGNITUDE = 1e60  # m: heights up to this keep every power and sum the parameters take within float64
ROUNDING = 64 * np.finfo(float).eps  # relative: deviations this small are the rounding of the mean (measured ≤ 2.3 eps)
BLOCK = 1 << 16  # points per block when streaming through a map: cache-sized, no full-size temporaries


def valid_values(heights):
    """``(values, their sum)``: the valid points of ``heights`` as a flat array (a view,
    without a copy, when there is no NaN) and their sum, the very one ``values.sum()``
    and ``values.mean()`` take."""
    values = heights.reshape(-1)
    with np.errstate(over="ignore", invalid="ignore"):  # a sum beyond float64 is refused by centring
        total = values.sum()
        if not math.isfinite(total):
            values = values[~np.isnan(values)]
            total = values.sum()
    return values, total


def centring(heights):
    """``(mean, count, constant)`` of the valid points of ``heights``: their mean and
    number, and whether they differ from that mean only by its rounding (a constant
    surface, whose deviations count as exactly zero). Reads a NaN-free array without
    copying it.

    Raises
    ------
    rough.InputError
        For a height beyond ±1e60 m (:data:`MAGNITUDE`), where the powers and sums
        that the parameters take would overflow float64 (to inf or NaN).
    """
    values, total = valid_values(heights)
    if not values.size:
        return math.nan, 0, False
    top, bottom = float(values.max()), float(values.min())
    if not max(top, -bottom) <= MAGNITUDE:
        raise InputError(
            f"a height of {top if top > -bottom else bottom:.6g} m is beyond ±{MAGNITUDE:g} m, where the "
            "parameters' sums of powers overflow: the data are damaged, or their unit is wrong"
        )
    mean = total / values.size
    return mean, values.size, max(top - mean, mean - bottom) <= ROUNDING * abs(mean)


def centred(heights):
    """``heights`` less the mean of their valid points (NaN stays NaN); exactly zero
    where they differ from that mean only by its rounding (a constant surface)."""
    mean, count, constant = centring(heights)
    if not count:
        return heights
    if constant:
        return np.where(np.isnan(heights), np.nan, 0.0)
    return heights - mean


def amplitude(heights):
    """Mean-removed moments of the valid points of ``heights`` (any shape; NaN points
    left out): Ra, Rq, Rsk, Rku (NaN for a constant surface), and the height range
    (max, min) about the mean. Streams through the points a block at a time, with no
    full-size temporaries."""
    mean, count, constant = centring(heights)
    if count == 0:
        raise InputError("no valid points: nothing to evaluate")
    if constant:
        return {"a": 0.0, "q": 0.0, "sk": math.nan, "ku": math.nan, "p": 0.0, "v": 0.0}
    flat = heights.reshape(-1)
    sums = []
    for start in range(0, flat.size, BLOCK):
        deviation = flat[start : start + BLOCK] - mean
        if count < flat.size:
            deviation = deviation[~np.isnan(deviation)]
        squared = deviation * deviation
        sums.append((np.abs(deviation).sum(), squared.sum(), (squared * deviation).sum(), (squared * squared).sum()))
    absolute, square, cube, fourth = (math.fsum(column) / count for column in zip(*sums))
    rq = math.sqrt(square)
    return {
        "a": absolute,
        "q": rq,
        "sk": cube / rq**3 if rq > 0 else math.nan,
        "ku": fourth / rq**4 if rq > 0 else math.nan,
        "p": float(np.nanmax(flat) - mean),
        "v": 0.0 - float(np.nanmin(flat) - mean),
    }


def slopes(heights, spacing, method="2point", axis=-1):
    """Local slopes dz/dx along ``axis`` (NaN where a point needed is invalid):
    forward differences, or ISO 4287's seven-point formula on interior points."""
    check_slope(method, heights.shape[axis])
    if method == "2point":
        return np.diff(heights, axis=axis) / spacing
    derivative = correlate1d(heights, SEVEN_POINT[::-1], axis=axis, mode="constant", cval=np.nan) / spacing
    return np.take(derivative, range(3, heights.shape[axis] - 3), axis=axis)


def check_slope(method, points):
    """Refuse an unknown slope method, and the seven-point slope along fewer than 7 points."""
    if method not in SLOPES:
        raise InputError(f"slope method must be one of {', '.join(SLOPES)}, not {method!r}")
    if method == "7point" and points < 7:
        raise InputError("the seven-point slope needs at least 7 points along each axis")


def amplitude_density(surface, bins=50):
    """The amplitude probability density of the heights about their mean.

    Parameters
    ----------
    surface : Surface
        A profile or map; only its valid (non-NaN) points are counted.
    bins : int, default 50
        The number of equal-width height bins, spanning the valid heights.

    Returns
    -------
    centres : numpy.ndarray
        The bin centres, metres, about the mean of the valid heights.
    density : numpy.ndarray
        The probability density in 1/m (a histogram normalised so that it integrates
        to 1 over the bins).

    Examples
    --------
    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology import amplitude_density
    >>> scan = rough.read(rough.sample("rock-map.x3p"))  # 6 invalid points
    >>> centres, density = amplitude_density(scan, bins=20)
    >>> centres.shape, density.shape
    ((20,), (20,))
    >>> round(float(np.sum(density) * (centres[1] - centres[0])), 9)  # integrates to 1
    1.0
    """
    values = np.sort(surface.heights[~np.isnan(surface.heights)])  # the mean, and so the bins, order-free
    density, edges = np.histogram(values - values.mean(), bins=bins, density=True)
    return (edges[:-1] + edges[1:]) / 2, density


SUBNORMAL = 1074  # every float64 is a whole multiple of 2^-1074


def exact_sum(values):
    """The exact sum of float64 ``values`` as an integer multiple of 2^-1074: each
    mantissa, split into two 26-bit halves, is summed per exponent (integers below
    2^53, so exactly), then shifted into place. So the mean is the correctly rounded
    one whatever the strips and the order of the points."""
    total = 0
    for start in range(0, values.size, 1 << 20):  # a block at a time: no temporaries as large as the values
        fraction, exponent = np.frexp(values[start : start + (1 << 20)])
        if not exponent.size:
            continue
        mantissa = (fraction * 2.0**53).astype(np.int64)
        high = mantissa >> 26
        low = mantissa - (high << 26)
        lowest = int(exponent.min())
        index = exponent - lowest
        for k, (upper, lower) in enumerate(zip(np.bincount(index, weights=high), np.bincount(index, weights=low))):
            if upper or lower:
                total += ((int(upper) << 26) + int(lower)) << (k + lowest - 53 + SUBNORMAL)
    return total


def strip_extent(values):
    """``{count, sum, low, high}`` of one strip's valid heights (no NaN): the exact
    sum of :func:`exact_sum`, the extremes NaN for an empty strip. Strips combine by
    adding counts and sums (:func:`exact_mean`) and taking the extremes of the rest."""
    if not values.size:
        return {"count": 0, "sum": 0, "low": math.nan, "high": math.nan}
    return {"count": values.size, "sum": exact_sum(values), "low": float(values.min()), "high": float(values.max())}


def exact_mean(total, count):
    """The correctly rounded mean of ``count`` values whose :func:`exact_sum` is
    ``total`` (NaN when there are none).

    >>> values = np.array([0.1, 0.2, 0.3])
    >>> exact_mean(exact_sum(values), 3) == 0.2
    True
    """
    return float(fractions.Fraction(total, count << SUBNORMAL)) if count else math.nan
