"""Profiles taken from a map along a direction (docs/math.rst §1.9), as the
fault-roughness literature measures them.

``"x"`` takes the rows, ``"y"`` the columns, an angle θ (radians, counter-clockwise
from +x) parallel sampling lines rotated exactly by θ, spaced by the smaller grid
spacing along and across and covering the map, their heights interpolated bilinearly
(a point whose interpolation stencil touches an invalid point is invalid). Gaps: each
profile's longest run of valid points (``"longest"``), or its interior gaps filled
linearly (``"fill"``, the invalid ends trimmed); profiles shorter than ``min_points``
are dropped, and each keeps its polynomial form of ``order`` removed.
"""

import dataclasses
import math

import numpy as np
from numpy.polynomial import legendre
from scipy.ndimage import map_coordinates

from ..errors import InputError
from .choices import GAPS

SNAP = 1e-9  # grid indices this close to an integer are taken as that integer
LINES_PER_BLOCK = 256  # sampling lines interpolated at a time


@dataclasses.dataclass
class ProfileSet:
    """Profiles taken from a surface along one direction (see :func:`take_profiles`).

    Attributes
    ----------
    heights : list of numpy.ndarray
        One 1-D float64 array per profile, every value finite, metres, its polynomial
        form of the given order removed.
    spacing : float
        The spacing along the profiles, metres.
    label : str
        ``"x"``, ``"y"``, the angle (``"30°"``) or ``"profile"`` for a profile input.
    angle : float
        The direction, radians counter-clockwise from +x; NaN for a profile input.
    interpolation : str
        How the heights were found: ``"none (grid lines)"``, ``"none (profile)"`` or
        ``"bilinear"``.
    gaps : str
        ``"longest"`` or ``"fill"``.
    positions : numpy.ndarray
        Each profile's offset across the direction, metres (in the map's coordinates).
    """

    heights: list
    spacing: float
    label: str
    angle: float
    interpolation: str
    gaps: str
    positions: np.ndarray

    @property
    def points(self):
        return int(sum(profile.size for profile in self.heights))


def take_profiles(surface, direction="x", gaps="longest", order=1, min_points=64):
    """The profiles of a map along a direction, or a profile as a set of one.

    Parameters
    ----------
    surface : Surface
        A map or a profile; invalid points are NaN.
    direction : {"x", "y"} or float, default "x"
        The rows (``"x"``), the columns (``"y"``), or an angle in radians
        counter-clockwise from +x: parallel sampling lines rotated exactly by it,
        spaced by the smaller grid spacing along and across, covering the map, their
        heights interpolated bilinearly. Ignored for a profile.
    gaps : {"longest", "fill"}, default "longest"
        What is kept of a profile with invalid points: its longest run of valid
        points, or all of it between its first and last valid points, the interior
        gaps filled by linear interpolation along the profile.
    order : int, default 1
        The degree of the polynomial form removed from each profile.
    min_points : int, default 64
        Profiles shorter than this (after the gap rule) are dropped.

    Returns
    -------
    ProfileSet
        The profiles, every height finite.

    Raises
    ------
    rough.InputError
        For an unknown direction or gap rule, an order below 0, or when no profile
        keeps ``min_points`` points.

    Notes
    -----
    A point whose bilinear stencil touches an invalid (NaN) point, or that lies
    outside the map, is invalid; the gap rule then applies. Along ``"x"`` the
    profiles are the rows in order of y, along ``"y"`` the columns in order of x; the
    lines at an angle θ run along ``(cos θ, sin θ)`` and are ordered by their offset
    along ``(-sin θ, cos θ)``, so at θ = 0 they are the rows (for equal spacings), and
    at 90° the columns in order of decreasing x.

    Examples
    --------
    >>> import numpy as np, rough
    >>> from rough.fractal.profile_set import take_profiles
    >>> heights = np.arange(12.0).reshape(3, 4) ** 2
    >>> heights[1, 1] = np.nan
    >>> rows = take_profiles(rough.Surface(heights, 1e-3), "x", order=0, min_points=2)
    >>> [profile.size for profile in rows.heights], rows.positions.tolist()
    ([4, 2, 4], [0.0, 0.001, 0.002])
    >>> take_profiles(rough.Surface(heights, 1e-3), "x", "fill", 0, 2).heights[1].size
    4
    """
    if gaps not in GAPS:
        raise InputError(f"gaps must be one of {', '.join(GAPS)}, not {gaps!r}")
    if not (isinstance(order, (int, np.integer)) and order >= 0):
        raise InputError(f"the form's order must be a whole number from 0, not {order!r}")
    lines, positions, spacing, label, angle, interpolation = _lines(surface, direction)
    kept, where = [], []
    for line, position in zip(lines, positions):
        profile = _gap_rule(line, gaps)
        if profile.size >= max(min_points, order + 2):
            kept.append(_levelled(profile, order))
            where.append(position)
    if not kept:
        raise InputError(
            f"no profile along {label} keeps {min_points} valid points in a row (gaps: {gaps}); "
            "fill the invalid points or take another direction"
        )
    return ProfileSet(kept, spacing, label, angle, interpolation, gaps, np.array(where, dtype=np.float64))


def _lines(surface, direction):
    """``(lines, positions, spacing, label, angle, interpolation)`` of a surface."""
    heights = surface.heights
    if surface.is_profile:
        return [heights], [0.0], surface.spacing[0], "profile", math.nan, "none (profile)"
    dx, dy = surface.spacing
    if isinstance(direction, str):
        name = direction.strip().casefold()
        if name == "x":
            return list(heights), surface.positions(1), dx, "x", 0.0, "none (grid lines)"
        if name == "y":
            return list(heights.T), surface.positions(0), dy, "y", math.pi / 2, "none (grid lines)"
        raise InputError(f"a direction is x, y or an angle, not {direction!r}")
    try:
        angle = float(direction)
    except (TypeError, ValueError):
        raise InputError(f"a direction is x, y or an angle, not {direction!r}") from None
    if not math.isfinite(angle):
        raise InputError(f"the direction's angle must be a finite number, not {direction!r}")
    lines, offsets, step = _rotated_lines(heights, (dx, dy), angle)
    origin = np.array(surface.origin)
    positions = offsets + origin @ np.array([-math.sin(angle), math.cos(angle)])
    return lines, positions, step, f"{math.degrees(angle) % 180:.6g}°", angle, "bilinear"


def _rotated_lines(heights, spacing, angle):
    """Sampling lines at ``angle`` over the grid (x = j dx, y = i dy from its first
    point), every ``step`` (the smaller spacing) along and across; heights by bilinear
    interpolation, NaN where the stencil touches a NaN or leaves the grid."""
    ny, nx = heights.shape
    dx, dy = spacing
    step = min(dx, dy)
    along = np.array([math.cos(angle), math.sin(angle)])
    across = np.array([-along[1], along[0]])
    corners = np.array([[0, 0], [(nx - 1) * dx, 0], [0, (ny - 1) * dy], [(nx - 1) * dx, (ny - 1) * dy]])

    def steps(direction):
        projected = corners @ direction / step
        return np.arange(math.ceil(projected.min() - SNAP), math.floor(projected.max() + SNAP) + 1) * step

    s, offsets = steps(along), steps(across)
    invalid = np.isnan(heights)
    filled = np.where(invalid, 0.0, heights)
    invalid = invalid.astype(np.float64) if invalid.any() else None
    lines = []
    for part in np.array_split(offsets, max(1, math.ceil(offsets.size / LINES_PER_BLOCK))):
        x = _snapped((part[:, None] * across[0] + s[None, :] * along[0]) / dx)
        y = _snapped((part[:, None] * across[1] + s[None, :] * along[1]) / dy)
        valid = (x >= 0) & (x <= nx - 1) & (y >= 0) & (y <= ny - 1)
        coordinates = [np.clip(y, 0, ny - 1), np.clip(x, 0, nx - 1)]
        values = map_coordinates(filled, coordinates, order=1, mode="nearest")
        if invalid is not None:
            valid &= map_coordinates(invalid, coordinates, order=1, mode="nearest") == 0
        lines.extend(np.where(valid, values, np.nan))
    return lines, offsets, step


def _snapped(index):
    nearest = np.round(index)
    return np.where(np.abs(index - nearest) < SNAP, nearest, index)


def _gap_rule(line, gaps):
    """A profile's longest finite run (``"longest"``), or its span between the first
    and last finite values with interior gaps filled linearly (``"fill"``)."""
    valid = np.isfinite(line)
    if not valid.any():
        return line[:0]
    if gaps == "fill":
        where = np.flatnonzero(valid)
        span = np.arange(where[0], where[-1] + 1)
        return np.interp(span, where, line[where])
    edges = np.flatnonzero(np.diff(np.r_[0, valid.astype(np.int8), 0]))
    starts, stops = edges[::2], edges[1::2]
    longest = int(np.argmax(stops - starts))
    return np.array(line[starts[longest] : stops[longest]], dtype=np.float64)


def _levelled(profile, order):
    """The profile less its least-squares polynomial of ``order`` (Legendre basis, for
    conditioning)."""
    x = np.linspace(-1.0, 1.0, profile.size)
    return profile - legendre.legval(x, legendre.legfit(x, profile, order))
