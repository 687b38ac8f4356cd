"""Band-limited resampling to a new spacing (profiles along x, maps along both axes).

The ratio of old to new spacing is taken as a fraction up/down (to within 1e-9, with
denominators up to 1000) and applied with scipy's polyphase filter
(``resample_poly``): upsample by ``up``, low-pass with a Kaiser-windowed FIR at the
lower of the two Nyquist frequencies, keep every ``down``-th sample. Coarsening
therefore removes what the new spacing cannot hold instead of folding it back
(aliasing); the top ~20 % below the new Nyquist frequency are attenuated by the
filter's transition band, so fit fractal parameters below that.

Refining (a smaller spacing) interpolates band-limited: it adds no power above the
old Nyquist frequency, so a refined fractal surface is smooth at the new small
scales rather than continued with synthetic roughness (synthesise for that).

Ends are padded by linear extrapolation of the data (``padtype='line'``). Invalid
points must be filled first (``fill=True``: linear interpolation along profiles,
biharmonic inpainting for maps); the points that fall where data were missing are
set back to NaN in the result.
"""

import fractions
import math

import numpy as np

from ..errors import InputError
from ..surface import check_size

MAX_DENOMINATOR = 1000


def resample(surface, spacing, fill=False):
    """``surface`` at the new ``spacing`` (metres; one value, or (dx, dy) for maps)."""
    from scipy.signal import resample_poly

    targets = tuple(np.broadcast_to(np.asarray(spacing, dtype=float), (surface.heights.ndim,)))
    if not all(t > 0 and np.isfinite(t) for t in targets):
        raise InputError(f"the new spacing must be positive, not {spacing}")
    invalid = np.isnan(surface.heights)
    if invalid.any() and not fill:
        raise InputError("the surface has invalid points; resampling needs them filled first (--fill)")
    ratios = [_ratio(old, new) for old, new in zip(surface.spacing, targets)]
    shape = surface.heights.shape
    for axis, (ratio, new) in enumerate(zip(ratios, targets)):
        if shape[-1 - axis] * ratio < 2:
            raise InputError(f"a spacing of {new:g} m leaves fewer than two points along {'xy'[axis]}")
    check_size([math.ceil(n * ratio) for n, ratio in zip(shape, reversed(ratios))], "the resampled surface")
    heights = filled(surface) if invalid.any() else surface.heights
    new_spacing = []
    for axis, (old, ratio) in enumerate(zip(surface.spacing, ratios)):
        array_axis = heights.ndim - 1 - axis
        heights = resample_poly(heights, ratio.numerator, ratio.denominator, axis=array_axis, padtype="line")
        new_spacing.append(old / float(ratio))
    if invalid.any():
        heights = np.where(_nearest_invalid(invalid, surface.spacing, new_spacing, heights.shape), np.nan, heights)
    return surface.derive(
        "resample", {"spacing": new_spacing, "filled": bool(invalid.any())}, heights=heights, spacing=tuple(new_spacing)
    )


def _ratio(old, new):
    """old/new spacing as a fraction of integers up to MAX_DENOMINATOR (the polyphase
    filter is 20 taps per unit of either: larger ones would outgrow the data)."""
    ratio = fractions.Fraction(old / new).limit_denominator(MAX_DENOMINATOR)
    if abs(float(ratio) - old / new) > 1e-9 * old / new:
        raise InputError(f"cannot resample {old:g} m to {new:g} m exactly with a ratio of small integers")
    if ratio.numerator > MAX_DENOMINATOR:
        raise InputError(
            f"cannot refine {old:g} m to {new:g} m in one step (more than {MAX_DENOMINATOR}×); "
            "resample in steps, or synthesise the fine scales"
        )
    return ratio


def fill_invalid(surface):
    """``surface`` with its invalid points filled (see :func:`filled`), recorded as a
    ``fill`` step; unchanged when every point is valid."""
    if not np.isnan(surface.heights).any():
        return surface
    return surface.derive("fill", {}, heights=filled(surface))


def filled(surface):
    """The heights with invalid points filled: linear interpolation along a profile,
    scikit-image's biharmonic inpainting in a map."""
    heights = surface.heights
    invalid = np.isnan(heights)
    if invalid.all():
        raise InputError("no valid points to fill from")
    if heights.ndim == 1:
        index = np.arange(heights.size)
        return np.interp(index, index[~invalid], heights[~invalid])
    from skimage.restoration import inpaint_biharmonic

    return inpaint_biharmonic(np.where(invalid, 0.0, heights), invalid)


def _nearest_invalid(invalid, old_spacing, new_spacing, shape):
    """Which new samples lie nearest to an old invalid one."""
    index = []
    for axis in range(invalid.ndim):
        spatial = invalid.ndim - 1 - axis
        positions = np.arange(shape[axis]) * new_spacing[spatial] / old_spacing[spatial]
        index.append(np.clip(np.rint(positions).astype(int), 0, invalid.shape[axis] - 1))
    return invalid[np.ix_(*index)]
