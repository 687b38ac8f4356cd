"""Scale dependence of the RMS height: Rq measured over shorter and shorter
evaluation lengths (the slides' "σ ∝ L^(1/2)", Sayles & Thomas 1978; in general
σ ∝ L^(2-D) for a self-affine profile, docs/math.rst §4.6).

The profile is cut into non-overlapping windows of each length L (halving from the
whole length down to 16 points); each window's mean is removed, and Rq(L) is the
RMS over all windows (valid points only). A line fitted to log Rq against log L
gives the Hurst exponent H and D = 2 - H for a profile (Ds = 3 - H for a map, whose
windows are squares). The fit is a cross-check of the spectral estimate, not a
substitute for it: mean removal over short windows biases H low.
"""

import numpy as np

from ..errors import InputError

MIN_WINDOW = 16


def rq_versus_length(surface):
    """Rq over shorter and shorter evaluation lengths, and the slope of log Rq on log L.

    The profile (map) is cut into non-overlapping windows (squares for maps) of each
    length L, halving from the whole length (the shorter side of a map) down to 16
    points; each window's mean is removed and Rq(L) is the RMS over all windows.

    Parameters
    ----------
    surface : Surface
        A profile or map, at least 32 points along each axis; NaN points are left
        out of each window's mean and of the RMS.

    Returns
    -------
    dict
        ``length``: the window lengths, metres (the x side for maps), longest first;
        ``Rq`` (``Sq`` for maps): the RMS height at each, metres; ``windows``: how
        many windows each; ``hurst``: the slope H of the least-squares line of log Rq
        on log L; ``fractal_dimension``: 2 - H for a profile, 3 - H for a map.

    Raises
    ------
    rough.InputError
        For fewer than 32 points along an axis.

    Notes
    -----
    For a self-affine profile σ ∝ L^(2-D) (docs/math.rst §4.6). Removing each
    window's mean biases H low over short windows, so D comes out high: treat the
    result as a cross-check of :func:`rough.fractal.fit_fractal`, not a
    substitute for it.

    Examples
    --------
    A random walk (Brownian motion, H = 0.5) has D = 1.5:

    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology import rq_versus_length
    >>> rng = np.random.default_rng(0)
    >>> walk = rough.Surface(np.cumsum(rng.standard_normal(2**14)) * 1e-7, 1e-6)
    >>> result = rq_versus_length(walk)
    >>> result["windows"][:4], round(result["fractal_dimension"], 1)
    ([1, 2, 4, 8], 1.5)

    On the sample profile (2048 points at 30.9 µm) the windows run from the whole
    63.3 mm down to 16 points:

    >>> scan = rough.read(rough.sample("rock-profile.tsv"))
    >>> result = rq_versus_length(scan)
    >>> [f"{length * 1e3:.2f}" for length in result["length"][::7]], result["windows"][-1]  # mm
    (['63.28', '0.49'], 128)
    >>> f"Rq {result['Rq'][0] * 1e6:.0f} µm over the whole length"
    'Rq 280 µm over the whole length'
    """
    heights = surface.heights
    n = min(heights.shape)
    sizes = []
    size = n
    while size >= MIN_WINDOW:
        sizes.append(size)
        size //= 2
    if len(sizes) < 2:
        raise InputError(f"Rq against length needs at least {2 * MIN_WINDOW} points along each axis")
    lengths, rms, counts = [], [], []
    for size in sizes:
        windows = _windows(heights, size)
        deviations = windows - np.nanmean(windows, axis=tuple(range(1, windows.ndim)), keepdims=True)
        rms.append(float(np.sqrt(np.nanmean(deviations**2))))
        lengths.append(size * surface.spacing[0])
        counts.append(len(windows))
    slope = float(np.polyfit(np.log(lengths), np.log(rms), 1)[0])
    return {
        "length": lengths,
        "Rq" if surface.is_profile else "Sq": rms,
        "windows": counts,
        "hurst": slope,
        "fractal_dimension": (2.0 if surface.is_profile else 3.0) - slope,
    }


def _windows(heights, size):
    """Non-overlapping windows of ``size`` points (squares for maps), stacked."""
    if heights.ndim == 1:
        count = heights.size // size
        return heights[: count * size].reshape(count, size)
    rows, columns = heights.shape[0] // size, heights.shape[1] // size
    tiles = heights[: rows * size, : columns * size].reshape(rows, size, columns, size)
    return tiles.transpose(0, 2, 1, 3).reshape(rows * columns, size, size)
