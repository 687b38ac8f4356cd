"""Scattered points gridded: X3P point clouds, irregular grids and grids rotated in
their placement become a map on a square grid, on request (``--regrid SPACING``).

A module of its own so that scipy's interpolation loads only when points are gridded
(:mod:`rough.io.x3p` reaches it through the lazy ``rough.io`` package).
"""

import logging

import numpy as np
from scipy.interpolate import griddata
from scipy.spatial import QhullError

from ..errors import FormatError
from ..surface import check_size, history_entry

log = logging.getLogger("rough")


def grid_points(x, y, z, options, what):
    """Points interpolated linearly (Delaunay triangles, ``scipy.interpolate.griddata``)
    onto a square grid of ``options.regrid``'s spacing over their extent; NaN outside
    their convex hull. ``what`` names the points in messages. Returns ``(heights,
    spacing, origin, notes, history steps)``."""
    if options.regrid is None:
        raise FormatError(
            f"{what}: give --regrid SPACING to grid it (rough reads point clouds and irregular grids only gridded)"
        )
    spacing, method = options.regrid
    if len(z) < 3:
        raise FormatError(f"{what} has {len(z)} valid points; gridding needs at least three")
    spans = [(float(v.max() - v.min()) / spacing) * (1 + 1e-12) for v in (x, y)]
    check_size([span + 1 for span in spans[::-1]], "the gridded surface")
    nx, ny = (int(np.floor(span)) + 1 for span in spans)
    if min(nx, ny) < 2:
        raise FormatError(f"a regrid spacing of {spacing:.6g} m leaves fewer than two points across {what}")
    gx, gy = x.min() + spacing * np.arange(nx), y.min() + spacing * np.arange(ny)
    try:
        heights = griddata((x, y), z, (gx[np.newaxis, :], gy[:, np.newaxis]), method="linear")
    except (QhullError, ValueError) as error:
        raise FormatError(f"cannot triangulate {what} ({str(error).strip().splitlines()[0]})") from None
    if method != "linear":
        log.info("a map is regridded linearly; band-limited regridding applies to profiles")
    step = history_entry("regrid", {"spacing": spacing, "method": "linear", "points_read": len(z)})
    return heights, (spacing, spacing), (float(x.min()), float(y.min())), {}, [step]
