"""Profiles from ``(x, z)`` points: kept as they are when x is evenly spaced, otherwise
regridded on request (``--regrid SPACING``) and refused without it.

x counts as evenly spaced when every point lies within ``TOLERANCE`` of a step of the
line through the first and the last; the spacing is that line's slope (the mean step)
and the origin the first x. Regridding is recorded in the surface's history.

The default method is linear: every new height lies between its two neighbours read,
so it cannot ring or overshoot, and on a nearly even profile (one x of 960 off by a
fifth of a step) it changes Rq by less than 0.1 %. ``bandlimited`` is for coarsening: it also
removes what the new grid cannot hold (an ideal low-pass, which rings at steps in the
heights), and is the same as linear when the new spacing is no coarser than the
median step of x.
"""

import math

import numpy as np

from ..errors import FormatError, InputError
from ..surface import Surface, Units, check_size, history_entry

TOLERANCE = 1e-3  # of a step
METHODS = ("linear", "bandlimited")


def profile_from_points(x, z, options, *, units=Units(), metadata=None, history=None):
    """A profile Surface from positions ``x`` and heights ``z`` (metres; NaN heights
    are invalid points).

    Evenly spaced x gives the profile as it is; otherwise ``options.regrid``
    (``(spacing, method)``) interpolates it onto a regular grid from the first to the
    last x, and without it the data are refused with a hint. Points are sorted by x;
    repeated x values are refused.

    >>> from rough.io import ReadOptions
    >>> profile_from_points([0.0, 1.0, 2.0], [0.0, 1.0, 4.0], ReadOptions()).spacing
    (1.0,)
    >>> uneven = profile_from_points([0, 1, 3], [0, 1, 3], ReadOptions(regrid=(0.5, "linear")))
    >>> uneven.heights.tolist(), uneven.history[-1]["command"]
    ([0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0], 'regrid')
    """
    x, z = np.asarray(x, dtype=np.float64), np.asarray(z, dtype=np.float64)
    order = np.argsort(x, kind="stable")
    x, z = x[order], z[order]
    if len(x) < 2:
        raise FormatError("a profile needs at least two points to have a spacing")
    if not np.isfinite(x).all():
        raise FormatError("x positions must be finite numbers")
    steps = np.diff(x)
    if not (steps > 0).all():
        raise FormatError(f"{int((steps <= 0).sum())} repeated x positions; a profile needs one height per position")
    metadata, history = dict(metadata or {}), list(history or [])
    step = (x[-1] - x[0]) / (len(x) - 1)
    if np.abs(x - (x[0] + step * np.arange(len(x)))).max() <= TOLERANCE * step:
        return Surface(z, (float(step),), (float(x[0]),), units, metadata, history)
    if options.regrid is None:
        raise FormatError(
            f"x values are not evenly spaced (steps from {steps.min():.6g} m to {steps.max():.6g} m); "
            "give --regrid SPACING to interpolate onto a regular grid"
        )
    spacing, method = options.regrid
    heights = regrid(x, z, spacing, method)
    history.append(history_entry("regrid", {"spacing": spacing, "method": method, "points_read": len(x)}))
    return Surface(heights, (spacing,), (float(x[0]),), units, metadata, history)


def option(value):
    """``(spacing, method)`` from a ``--regrid`` value: a spacing in metres, or a
    ``(spacing, method)`` pair (method default ``"linear"``). Raises InputError
    for a spacing that is not a positive length or an unknown method.

    >>> option(5e-7), option((5e-7, "bandlimited"))
    ((5e-07, 'linear'), (5e-07, 'bandlimited'))
    """
    spacing, method = value if isinstance(value, (tuple, list)) else (value, "linear")
    try:
        spacing = float(spacing)
    except (TypeError, ValueError):
        spacing = math.nan
    if not spacing > 0:
        raise InputError(f"the regrid spacing must be a positive length, got {value!r}")
    if method not in METHODS:
        raise InputError(f"unknown regrid method {method!r} (use {' or '.join(METHODS)})")
    return spacing, method


def regrid(x, z, spacing, method="linear"):
    """Heights at ``x[0] + spacing * k`` (k = 0 … up to ``x[-1]``) from points ``(x, z)``
    with increasing x.

    ``linear`` interpolates between neighbours: it cannot ring. ``bandlimited``, for
    coarsening, interpolates linearly onto the grid of ``spacing / m`` nearest to the
    median step of x from below (m whole; the data's own grid when ``spacing`` is a
    multiple of it, so no height is smoothed by the interpolation), then removes what
    lies above the new grid's Nyquist frequency (an ideal low-pass filter by FFT, after
    the line through the ends is taken out and before it is put back, so that the ends
    do not ring) and keeps every m-th point; with m = 1 (a spacing no coarser than the
    median step) there is nothing to remove and it is linear. Invalid (NaN) heights are
    skipped, and an interval of the new grid with no valid point near it is NaN.
    """
    spacing, method = option((spacing, method))
    count = int(np.floor((x[-1] - x[0]) / spacing * (1 + 1e-12))) + 1
    if count < 2:
        raise FormatError(f"a regrid spacing of {spacing:.6g} m leaves fewer than two points")
    check_size((count,), "the regridded profile")
    valid = np.isfinite(z)
    target = x[0] + spacing * np.arange(count)
    factor = int(np.ceil(spacing / np.median(np.diff(x)) * (1 - 1e-9)))
    if method == "linear" or factor <= 1:
        heights = np.interp(target, x[valid], z[valid])
    else:
        check_size((count * factor,), "the band-limited regrid's working grid")
        fine = np.interp(x[0] + spacing / factor * np.arange((count - 1) * factor + 1), x[valid], z[valid])
        line = np.linspace(fine[0], fine[-1], len(fine))  # removed so that the ends meet: no ringing at the wrap
        spectrum = np.fft.rfft(fine - line)
        spectrum[np.fft.rfftfreq(len(fine), spacing / factor) > 0.5 / spacing] = 0
        heights = (np.fft.irfft(spectrum, len(fine)) + line)[::factor]
    return np.where(_near_valid(target, x[valid], spacing, x), heights, np.nan)


def _near_valid(target, valid_x, spacing, x):
    """Grid points that have a valid point within the larger of one new step and the
    local gap between input points."""
    gap = np.max(np.diff(x)) if len(x) > 1 else spacing
    index = np.clip(np.searchsorted(valid_x, target), 1, len(valid_x) - 1)
    nearest = np.minimum(np.abs(target - valid_x[index - 1]), np.abs(valid_x[index] - target))
    return nearest <= max(spacing, gap)
