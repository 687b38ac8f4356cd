"""Roughness against scale, for surfaces that follow no single power law, and the
scale below which a stylus tip cannot follow a surface (docs/math.rst §1.8).

At each scale λ (a whole number of spacings):

- the RMS height of the profile cut into windows of length λ, each less its own
  mean and tilt (the variable bandwidth method of Jacobs, Junge & Pastewka,
  *Surf. Topogr.: Metrol. Prop.* 5 (2017) 013001; SurfaceTopography's
  ``variable_bandwidth``): ∝ λ^H for a self-affine profile;
- the RMS slope, the first difference at step λ over λ: ∝ λ^(H-1);
- the RMS curvature, the central second difference at step λ over λ²: ∝ λ^(H-2)
  (Sanner et al., *Appl. Surf. Sci. Adv.* 7 (2022) 100190, SurfaceTopography's
  ``scale_dependent_statistical_property``, whose "distance" is the stencil's whole
  length 2λ).

Values are pooled over all the profiles given (the rows of a map, or its columns).
"""

import math

import numpy as np

from ..errors import InputError

PER_DECADE = 10
SAFETY = 0.5  # SurfaceTopography's safety factor: a tip fails where the curvature reaches -SAFETY/R


def scale_dependent(heights, spacing, scales=None, cutoff=None):
    """RMS height, slope and curvature of profiles against scale.

    Parameters
    ----------
    heights : list of 1-D arrays (or one 1-D array, or a 2-D array of rows)
        The profiles, metres, every value finite (form removed or not: each window
        loses its own mean and tilt, and differences ignore a constant).
    spacing : float
        The sampling interval along the profiles, metres.
    scales : tuple of float, optional
        ``(λmin, λmax)`` in metres; default from 2 spacings to a third of the
        longest profile. The scales are whole numbers of spacings, 10 per decade.
    cutoff : float, optional
        A tip's reliability cut-off (:func:`reliability_cutoff`), metres: without
        ``scales``, the scales start at half of it (the step of the second difference
        whose stencil it is), not below 2 spacings.

    Returns
    -------
    dict
        Lists ``scale`` (m), ``rms_height`` (m), ``rms_slope`` (1) and
        ``rms_curvature`` (1/m), one value per scale, pooled over the profiles long
        enough for it (a window of λ for the height, 2λ for the curvature).

    Raises
    ------
    rough.InputError
        For NaN or infinite heights, a spacing that is not positive, or profiles too
        short for any scale in the range (fewer than 5 points).
    """
    groups = _groups(heights)
    if not spacing > 0:
        raise InputError(f"the spacing must be positive, not {spacing}")
    longest = max(group.shape[1] for group in groups)
    table = {"scale": [], "rms_height": [], "rms_slope": [], "rms_curvature": []}
    for step in _steps(longest, spacing, scales, cutoff):
        usable = [group for group in groups if group.shape[1] > 2 * step]
        if not usable:
            continue
        length = step * spacing
        table["scale"].append(float(length))
        table["rms_height"].append(_pooled(_window_residuals(group, step + 1) for group in usable))
        table["rms_slope"].append(_pooled(_difference(group, step, 1) / length for group in usable))
        table["rms_curvature"].append(_pooled(_difference(group, step, 2) / length**2 for group in usable))
    return table


def scale_dependent_roughness(surface, direction="x"):
    """:func:`scale_dependent` of a surface: a profile, or a map's rows (``"x"``) or
    columns (``"y"``).

    Parameters
    ----------
    surface : Surface
        A gap-free profile or map: fill invalid (NaN) points first (see
        :func:`rough.fractal.fill_invalid`).
    direction : {"x", "y"}, default "x"
        For a map, the profiles along x (rows) or y (columns); ignored for a profile.

    Returns
    -------
    dict
        As :func:`scale_dependent`, with ``direction`` (``"x"``, ``"y"`` or
        ``"profile"``).

    Raises
    ------
    rough.InputError
        For invalid points, an unknown direction, or too few points.
    """
    if direction not in ("x", "y"):
        raise InputError(f"the direction must be x or y, not {direction!r}")
    if np.isnan(surface.heights).any():
        raise InputError("scale-dependent roughness needs gap-free data: fill the invalid points first (--fill)")
    if surface.is_profile:
        return {**scale_dependent(surface.heights, surface.spacing[0]), "direction": "profile"}
    along_x = direction == "x"
    rows = surface.heights if along_x else surface.heights.T
    return {**scale_dependent(rows, surface.spacing[0 if along_x else 1]), "direction": direction}


def reliability_cutoff(heights, spacing, tip_radius):
    """The scale below which a round tip of ``tip_radius`` cannot follow the surface.

    SurfaceTopography's ``scanning_probe_reliability_cutoff`` (Sanner et al. 2022): the
    length 2λ of the central second-difference stencil at which the most negative
    curvature ``min (z(x+λ) - 2z(x) + z(x-λ)) / λ²`` over the profiles reaches
    ``-SAFETY / R`` (a tip cannot image a summit sharper than itself; the safety factor
    1/2 is theirs, from simulated scans). λ runs over whole spacings and is refined by
    linear interpolation of the curvature between them (theirs interpolates the heights).

    Parameters
    ----------
    heights : list of 1-D arrays (or one 1-D array, or a 2-D array of rows)
        The profiles along the scan direction, metres, every value finite.
    spacing : float
        The sampling interval along them, metres.
    tip_radius : float
        The tip radius R, metres.

    Returns
    -------
    float or None
        The cut-off wavelength 2λ in metres; None when the tip follows the surface
        at every scale (the criterion holds already at λ = one spacing); the longest
        scale tried (half the longest profile) when it fails at every scale.

    Raises
    ------
    rough.InputError
        For NaN heights, a spacing or radius that is not positive, or profiles shorter
        than 3 points.
    """
    groups = _groups(heights)
    if not (spacing > 0 and tip_radius > 0):
        raise InputError(f"the spacing and the tip radius must be positive, not {spacing} and {tip_radius}")
    target = -SAFETY / tip_radius
    longest = max(group.shape[1] for group in groups)
    previous = None
    for step in range(1, (longest - 1) // 2 + 1):
        curvature = min(
            float(np.min(_difference(group, step, 2))) / (step * spacing) ** 2
            for group in groups
            if group.shape[1] > 2 * step
        )
        if curvature > target:
            if previous is None:
                return None
            step_before, before = previous
            return float(2 * spacing * (step_before + (target - before) / (curvature - before)))
        previous = (step, curvature)
    return float(2 * spacing * previous[0])


def _groups(heights):
    """The profiles as 2-D float64 arrays of rows of equal length, refusing NaN and
    profiles all shorter than 5 points."""
    if isinstance(heights, (list, tuple)):
        rows = [np.asarray(row, dtype=np.float64) for row in heights]
    else:
        rows = list(np.atleast_2d(np.asarray(heights, dtype=np.float64)))
    if not rows or max(row.size for row in rows) < 5:
        raise InputError("scale-dependent statistics need profiles of at least 5 points")
    if not all(np.isfinite(row).all() for row in rows):
        raise InputError("scale-dependent statistics need finite heights: fill the invalid points first (--fill)")
    lengths = sorted({row.size for row in rows})
    return [np.array([row for row in rows if row.size == length]) for length in lengths]


def _difference(group, step, order):
    """The forward (order 1) or central (order 2) difference at ``step`` points along
    the rows of ``group``."""
    if order == 1:
        return group[:, step:] - group[:, :-step]
    return group[:, 2 * step :] - 2 * group[:, step:-step] + group[:, : -2 * step]


def _steps(longest, spacing, scales, cutoff=None):
    """Whole numbers of spacings, 10 per decade, from 2 (or half the cut-off, or λmin)
    to a third of the longest profile (or λmax)."""
    low, high = scales or (max(2 * spacing, (cutoff or 0.0) / 2), longest * spacing / 3)
    first = max(1, math.ceil(low / spacing - 1e-9))
    last = min((longest - 1) // 2, math.floor(high / spacing + 1e-9))
    if last < first:
        raise InputError(
            f"no scale between {low:g} m and {high:g} m fits these profiles ({longest} points at {spacing:g} m)"
        )
    count = max(2, round(math.log10(last / first) * PER_DECADE) + 1)
    return np.unique(np.round(np.geomspace(first, last, count)).astype(np.int64))


def _window_residuals(group, points):
    """The rows of ``group`` cut into windows of ``points`` points (the remainder at the
    end left out), each less its least-squares line."""
    usable = group.shape[1] // points * points
    windows = group[:, :usable].reshape(-1, points)
    x = np.arange(points) - (points - 1) / 2
    centred = windows - windows.mean(axis=1, keepdims=True)
    tilt = centred @ x / (x @ x)
    return centred - tilt[:, None] * x


def _pooled(parts):
    """The RMS of all the values of ``parts`` together."""
    total, count = 0.0, 0
    for values in parts:
        total += float(np.sum(np.square(values)))
        count += values.size
    return math.sqrt(total / count)
