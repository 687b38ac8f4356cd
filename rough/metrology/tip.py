"""Probe size: what a round tip of radius r traces over a surface, and the ISO
16610-41 closing envelope.

A tip touches from above. With ``s(o) = r - √(r² - |o|²)`` the height of the tip's
surface above its apex at the lateral offset o (a disk for profiles, a ball for maps):

* the **traced** surface (the path of the apex, what a stylus of tip radius r records
  and what a hand holding such a probe feels) is the grey dilation
  ``T(p) = max_o [z(p + o) - s(o)]``, over offsets |o| <= r on the sample grid;
* the **closing envelope** (ISO 16610-41's closing filter with a disk or ball) is its
  erosion by the same tip, ``C(p) = min_o [T(p + o) + s(o)]``: the lowest surface the
  tip cannot tell from the measured one, the best estimate of the material surface
  from a traced one. It never lies below the surface and is idempotent.

Both are exact on the sample grid (every offset within r, unequal x and y spacing
handled through physical distances), computed by brute force in compiled code:
scipy.ndimage's grey morphology with the non-flat structuring element for profiles,
scikit-image's rolling-ball kernel for maps, in bands of rows on all cores. The cost
is one comparison per point and tip offset, so it grows as (r/Δx)² for maps; an exact
envelope sweep (O(N·r/Δx)) would need compiled code of our own and would not beat the
vectorised brute force at tips of ~100 samples.

Invalid points (NaN) never touch the tip; results are NaN where the input is.
Beyond the ends there is no surface: a tip over an end rests on the points inside.
"""

import logging
import math

import numpy as np

from ..errors import InputError

log = logging.getLogger("rough")

PRESETS = {"needle": 0.05e-3, "fingernail": 0.5e-3, "fingertip": 8e-3}
SECONDS_PER_COMPARISON = {1: 5e-10, 2: 4e-10}  # measured on the 2-core build machine, for the estimate only
MAX_SECONDS = 3600


def tip_profile(radius, spacing, shape=None):
    """``√(r² - |o|²)`` on the grid of offsets within the radius (1-D or 2-D, metres),
    -inf outside the disk. ``spacing`` is (dx,) or (dx, dy). With the data's ``shape``
    ((n,) or (ny, nx)) offsets that reach past every sample are left out: they never
    touch the surface, and a tip far wider than the scan stays small."""
    if not radius > 0:
        raise InputError(f"the tip radius must be positive, not {radius} m")
    axes = [np.arange(-reach, reach + 1) * d for reach, d in zip(_reach(radius, spacing, shape), spacing)]
    squared = axes[0] ** 2 if len(axes) == 1 else axes[1][:, None] ** 2 + axes[0][None, :] ** 2
    inside = squared <= radius * radius * (1 + 1e-12)  # offsets on the rim count, whatever the rounding
    return np.where(inside, np.sqrt(np.maximum(radius * radius - squared, 0.0)), -np.inf)


def traced(surface, radius):
    """The path of the apex of a round tip drawn over a surface.

    What a stylus of this tip radius records, and what a hand holding such a probe
    feels: the grey dilation ``T(p) = max_o [z(p + o) - s(o)]`` over the offsets
    ``|o| <= r`` on the sample grid, with ``s(o) = r - √(r² - |o|²)`` the height of the
    tip's surface above its apex (a disk for profiles, a ball for maps).

    Parameters
    ----------
    surface : Surface
        A profile or map; NaN points never touch the tip.
    radius : float
        The tip radius r, metres (``PRESETS`` has ``needle`` 0.05 mm, ``fingernail``
        0.5 mm and ``fingertip`` 8 mm).

    Returns
    -------
    Surface
        The traced heights in metres, never below the surface, with a ``tip`` history
        entry; NaN where the input is NaN.

    Raises
    ------
    rough.InputError
        For a radius that is not positive, or a tip so wide for the spacing that one
        pass would take more than an hour (a warning past ten seconds).

    See Also
    --------
    closing_envelope : The best estimate of the material surface under a trace.

    Notes
    -----
    Exact on the sample grid (unequal x and y spacing handled through physical
    distances), by brute force: the cost grows as (r/Δx)² per point for maps.
    Beyond the ends there is no surface: a tip over an end rests on the points
    inside.

    Examples
    --------
    A 10 µm spike under a 0.5 mm tip is felt as a cap of the tip's radius: 50 µm
    away the apex is still 10 - (r - √(r² - (50 µm)²)) = 7.49 µm high.

    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology.tip import traced
    >>> heights = np.zeros(101)
    >>> heights[50] = 10e-6  # one spike in a flat 1 mm profile at 10 µm spacing
    >>> path = traced(rough.Surface(heights, 10e-6), 0.5e-3)
    >>> (path.heights[45:56:5] * 1e6).round(2).tolist()  # µm, at -50, 0, +50 µm
    [7.49, 10.0, 7.49]
    >>> path.history[-1]["command"], path.history[-1]["parameters"]
    ('tip', {'radius': 0.0005})
    """
    heights = _dilate(surface.heights, radius, surface.spacing)
    return surface.derive("tip", {"radius": radius}, heights=heights)


def closing_envelope(surface, radius):
    """The ISO 16610-41 closing envelope of a surface, with a disk or ball.

    The erosion of the traced surface by the same tip, ``C(p) = min_o [T(p + o) +
    s(o)]``: the lowest surface the tip cannot tell from the measured one, and so the
    best estimate of the material surface from a traced one.

    Parameters
    ----------
    surface : Surface
        A profile (closed with a disk) or map (with a ball); NaN points never touch
        the tip.
    radius : float
        The disk's or ball's radius, metres.

    Returns
    -------
    Surface
        The envelope in metres, with an ``envelope`` history entry. It never lies
        below the surface and is idempotent; NaN where the input is NaN.

    Raises
    ------
    rough.InputError
        For a radius that is not positive, or a tip too wide to compute within an
        hour.

    See Also
    --------
    traced : The path of the apex (the dilation alone).

    Examples
    --------
    A 0.5 mm disk cannot enter a pit 30 µm wide and 50 µm deep: resting on its rims,
    20 µm from the centre, it reaches r - √(r² - (20 µm)²) = 0.40 µm down.

    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology.tip import closing_envelope
    >>> heights = np.zeros(101)  # 1 mm at 10 µm
    >>> heights[49:52] = -50e-6
    >>> heights[10] = np.nan
    >>> envelope = closing_envelope(rough.Surface(heights, 10e-6), 0.5e-3)
    >>> (envelope.heights[48:53] * 1e6).round(2).tolist()  # µm
    [0.0, -0.3, -0.4, -0.3, 0.0]
    >>> bool(np.isnan(envelope.heights[10]))  # invalid stays invalid
    True

    On a map it never lies below the valid points, and closing again changes nothing:

    >>> scan = rough.read(rough.sample("rock-map.x3p"))
    >>> envelope = closing_envelope(scan, 0.5e-3)
    >>> bool(np.all(envelope.heights[scan.valid] >= scan.heights[scan.valid]))
    True
    >>> again = closing_envelope(envelope, 0.5e-3)
    >>> bool(np.nanmax(np.abs(again.heights - envelope.heights)) < 1e-15)
    True
    """
    path = _dilate(surface.heights, radius, surface.spacing)
    # exactly, the closing never lies below the surface; the clamp only removes rounding
    heights = np.fmax(_erode(path, radius, surface.spacing), surface.heights)
    return surface.derive("envelope", {"radius": radius}, heights=np.where(np.isnan(surface.heights), np.nan, heights))


def _reach(radius, spacing, shape):
    """Half-width of the tip in samples along x (and y), at most one less than the data's length."""
    reach = [math.floor(radius / d) for d in spacing]
    if shape is not None:
        reach = [min(r, n - 1) for r, n in zip(reach, reversed(shape))]
    return reach


def _lowering(radius, spacing, shape):
    """``-s(o)``: 0 at the apex, -inf outside the tip."""
    kernel = tip_profile(radius, spacing, shape)
    return kernel - kernel[tuple(n // 2 for n in kernel.shape)]


def _dilate(heights, radius, spacing):
    """max_o [z(p + o) - s(o)] with NaN ignored; NaN where the input is NaN."""
    _check_cost(heights, radius, spacing)
    lowering = _lowering(radius, spacing, heights.shape)
    invalid = np.isnan(heights)
    surface = np.where(invalid, -np.inf, heights)
    if heights.ndim == 1:
        from scipy import ndimage

        path = ndimage.grey_dilation(surface, structure=lowering, mode="constant", cval=-np.inf)
    else:
        path = -_rolling_ball(-surface, lowering)
    return np.where(invalid | ~np.isfinite(path), np.nan, np.fmax(path, heights))


def _erode(path, radius, spacing):
    """min_o [T(p + o) + s(o)] over the finite points of the traced path ``T``."""
    lowering = _lowering(radius, spacing, path.shape)
    known = np.where(np.isnan(path), np.inf, path)
    if path.ndim == 1:
        from scipy import ndimage

        return ndimage.grey_erosion(known, structure=lowering, mode="constant", cval=np.inf)
    return _rolling_ball(known, lowering)


def _rolling_ball(image, lowering):
    """min_o [image(p + o) + s(o)] (scikit-image's exact rolling-ball kernel), in bands
    of rows on all cores (the kernel releases the GIL); +inf in ``image`` never limits,
    and offsets outside the tip are left out."""
    import os
    from concurrent.futures import ThreadPoolExecutor

    from skimage.restoration import rolling_ball

    kernel = np.where(np.isfinite(lowering), lowering, np.inf)
    halo, rows = kernel.shape[0] // 2, image.shape[0]
    bands = max(1, min(os.cpu_count() or 1, rows // max(halo, 16)))
    edges = np.linspace(0, rows, bands + 1).astype(int)

    def band(start, stop):
        low, high = max(0, start - halo), min(rows, stop + halo)
        return rolling_ball(image[low:high], kernel=kernel)[start - low : stop - low]

    with ThreadPoolExecutor(bands) as pool:
        return np.vstack(list(pool.map(band, edges[:-1], edges[1:])))


def _check_cost(heights, radius, spacing):
    """Warn when a pass takes more than ten seconds; refuse past an hour."""
    reach = _reach(radius, spacing, heights.shape)
    box = math.prod(2 * r + 1 for r in reach)
    disk = math.pi * math.prod(radius / d for d in spacing) if heights.ndim == 2 else box
    kernel_points = min(box, disk)
    seconds = heights.size * kernel_points * SECONDS_PER_COMPARISON[heights.ndim]
    size = f"a {radius * 1e3:g} mm tip spans about {kernel_points:.0f} samples of this surface"
    if seconds > MAX_SECONDS:
        raise InputError(
            f"{size}: one pass would take about {seconds / 3600:.0f} h; resample the surface to a coarser spacing first"
        )
    if seconds > 10:
        log.warning(
            f"{size}: this takes about {seconds:.0f} s per pass (resample to a coarser spacing for a quicker answer)"
        )
