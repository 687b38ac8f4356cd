"""What ``rough info`` reports: the facts of a surface, in SI units."""

import numpy as np


def summary(surface):
    """Shape, spacing, size, valid points, height range and RMS height of a surface.

    NaN points are counted as invalid and left out of every statistic. ``rms_height``
    (Rq for a profile, Sq for a map) is taken about the mean of the valid points, with
    no levelling. Lengths are in metres; ``points``/``spacing``/``size`` list x first.
    Returns None for the statistics when no point is valid.
    """
    heights = surface.heights
    valid = heights[~np.isnan(heights)]
    stats = {"min": None, "max": None, "mean": None, "rms": None}
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
        "points": int(heights.size),
        "valid_points": int(valid.size),
        "z_min": stats["min"],
        "z_max": stats["max"],
        "z_mean": stats["mean"],
        "Rq" if surface.is_profile else "Sq": stats["rms"],
        "units": {"xy": surface.units.xy, "z": surface.units.z},
        "metadata": dict(surface.metadata),
        "history": list(surface.history),
    }
