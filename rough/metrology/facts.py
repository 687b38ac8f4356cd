"""What ``rough info`` reports: the facts of a surface, in SI units."""

import math

import numpy as np

from .. import tasks
from ..io.tiled import TiledSurface
from .heights import exact_mean, strip_extent


def summary(surface, *, budget=None, jobs=1, scheduler=None):
    """Shape, spacing, size, valid points, height range and RMS height of a surface.

    NaN points are counted as invalid and left out of every statistic. ``rms_height``
    (Rq for a profile, Sq for a map) is taken about the mean of the valid points, with
    no levelling. Lengths are in metres; ``points``/``spacing``/``size`` list x first.
    Returns None for the statistics when no point is valid. A
    :class:`~rough.io.TiledSurface` is read a strip at a time (twice: the mean, then
    the squares about it, in strips sized by the memory ``budget`` in bytes, on
    ``jobs`` processes or a Dask ``scheduler``: :func:`rough.tasks.map_ordered`); its
    facts equal those of the map read whole, to rounding.
    """
    if isinstance(surface, TiledSurface):
        count, stats = _tiled_statistics(surface, budget, {"jobs": jobs, "scheduler": scheduler})
    else:
        valid = surface.heights[~np.isnan(surface.heights)]
        count, stats = valid.size, {"min": None, "max": None, "mean": None, "rms": None}
        if valid.size:
            mean = valid.mean()
            stats = {
                "min": float(valid.min()),
                "max": float(valid.max()),
                "mean": float(mean),
                "rms": float(np.sqrt(np.mean((valid - mean) ** 2))),
            }
    return {
        "kind": surface.kind,
        "shape": list(surface.points),
        "spacing": list(surface.spacing),
        "size": list(surface.size),
        "origin": list(surface.origin),
        "points": int(math.prod(surface.points)),
        "valid_points": int(count),
        "z_min": stats["min"],
        "z_max": stats["max"],
        "z_mean": stats["mean"],
        "Rq" if surface.is_profile else "Sq": stats["rms"],
        "units": {"xy": surface.units.xy, "z": surface.units.z},
        "metadata": dict(surface.metadata),
        "history": list(surface.history),
    }


def _tiled_statistics(tiled, budget, run):
    """(valid points, {min, max, mean, rms}) of a map read a strip at a time."""
    rows = tiled.strip_rows(budget)
    strips = [(tiled, first, rows) for first in range(0, tiled.shape[0], rows)]
    parts = [part for part in tasks.map_ordered(_strip_extent, strips, **run) if part["count"]]
    count = sum(part["count"] for part in parts)
    if not count:
        return 0, {"min": None, "max": None, "mean": None, "rms": None}
    mean = exact_mean(sum(part["sum"] for part in parts), count)
    squares = math.fsum(tasks.map_ordered(_strip_squares, [(*strip, mean) for strip in strips], **run))
    low = min(part["low"] for part in parts)
    high = max(part["high"] for part in parts)
    return count, {"min": low, "max": high, "mean": mean, "rms": math.sqrt(squares / count)}


def _strip_extent(item):
    return strip_extent(_valid(*item))


def _strip_squares(item):
    tiled, first, rows, mean = item
    deviation = _valid(tiled, first, rows) - mean
    return math.fsum(np.square(deviation))


def _valid(tiled, first, rows):
    heights = tiled.read(slice(first, first + rows))
    return heights[~np.isnan(heights)]
