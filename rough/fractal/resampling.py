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
biharmonic inpainting for maps, :mod:`rough.fractal.filling`); the points that fall
where data were missing are set back to NaN in the result.
"""

import fractions
import math

import numpy as np
from scipy.signal import resample_poly

from ..errors import InputError
from ..surface import check_size
from .filling import filled

MAX_DENOMINATOR = 1000


def resample(surface, spacing, fill=False):
    """A surface at a new spacing, by band-limited (polyphase) resampling.

    Profiles are resampled along x, maps along both axes. Coarsening removes what
    the new spacing cannot hold instead of folding it back (aliasing); refining
    interpolates band-limited and adds no power above the old Nyquist frequency.

    Parameters
    ----------
    surface : Surface
        A profile or map.
    spacing : float or tuple of float
        The new spacing, metres: one value, or ``(dx, dy)`` for maps. The ratio of
        old to new spacing must be a fraction of integers up to 1000 (to within
        1e-9).
    fill : bool, default False
        Fill invalid (NaN) points first (see :func:`~rough.fractal.fill_invalid`); without it a
        surface with invalid points is refused.

    Returns
    -------
    Surface
        Heights in metres at the new spacing, with a ``resample`` history entry
        (which :func:`~rough.fractal.fit_fractal` reads to treat the result as
        band-limited). With ``fill``, the new points nearest to an old invalid one
        are set back to NaN.

    Raises
    ------
    rough.InputError
        For a spacing that is not positive, invalid points without ``fill``, a ratio
        that is not a fraction of small integers or refines more than 1000×, fewer
        than two points left along an axis, or a result past rough's size limit.

    Notes
    -----
    scipy's ``resample_poly``: upsample by ``up``, low-pass with a Kaiser-windowed
    FIR at the lower of the two Nyquist frequencies, keep every ``down``-th sample;
    the ends are padded by linear extrapolation. The top ~20 % below the new Nyquist
    frequency are attenuated by the filter's transition band, so fit fractal
    parameters below that.

    Examples
    --------
    The sample profile at five times its spacing (the paper's 0.1545 mm):

    >>> import numpy as np
    >>> import rough
    >>> from rough.fractal.resampling import resample
    >>> scan = rough.read(rough.sample("rock-profile.tsv"))  # 2048 points at 30.9 µm
    >>> coarse = resample(scan, 0.1545e-3)
    >>> coarse.points, coarse.spacing, coarse.history[-1]["command"]
    ((410,), (0.0001545,), 'resample')

    A sine well below the new Nyquist frequency keeps its amplitude:

    >>> x = np.arange(1000) * 1e-6
    >>> sine = rough.Surface(1e-6 * np.sin(2 * np.pi * x / 100e-6), 1e-6)  # λ = 100 µm
    >>> coarse = resample(sine, 5e-6)
    >>> coarse.points, f"{np.max(np.abs(coarse.heights)) * 1e6:.2f} µm"
    ((200,), '1.00 µm')

    Invalid points must be filled, and come back as NaN:

    >>> scan = rough.read(rough.sample("rock-map.x3p"))  # a 3 × 2 patch of NaN at 50 µm
    >>> coarse = resample(scan, 100e-6, fill=True)
    >>> coarse.points, int(np.isnan(coarse.heights).sum())
    ((64, 48), 2)
    """
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


def _nearest_invalid(invalid, old_spacing, new_spacing, shape):
    """Which new samples lie nearest to an old invalid one."""
    index = []
    for axis in range(invalid.ndim):
        spatial = invalid.ndim - 1 - axis
        positions = np.arange(shape[axis]) * new_spacing[spatial] / old_spacing[spatial]
        index.append(np.clip(np.rint(positions).astype(int), 0, invalid.shape[axis] - 1))
    return invalid[np.ix_(*index)]
