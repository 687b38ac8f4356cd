"""Scale dependence of the RMS height: Rq measured over shorter and shorter
evaluation lengths (the slides' "σ ∝ L^(1/2)", Sayles & Thomas 1978; in general
σ ∝ L^(2-D) for a self-affine profile, MATH.md §4.6).

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
    """``{"length": [...], "Rq": [...], "windows": [...], "hurst", "fractal_dimension"}``
    with lengths in metres (x side for maps) and Rq (Sq for maps) in metres."""
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
