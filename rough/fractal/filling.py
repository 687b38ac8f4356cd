"""Filling invalid (NaN) points: linear interpolation along a profile, scikit-image's
biharmonic inpainting in a map (what ``--fill`` does before a spectrum or a
resampling, which need gap-free data).
"""

import numpy as np
from skimage.restoration import inpaint_biharmonic

from ..errors import InputError


def fill_invalid(surface):
    """A surface with its invalid (NaN) points filled.

    Linear interpolation along a profile (the ends take the nearest valid value);
    scikit-image's biharmonic inpainting in a map.

    Parameters
    ----------
    surface : Surface
        A profile or map with at least one valid point.

    Returns
    -------
    Surface
        With no NaN left, recorded as a ``fill`` history entry; the same surface,
        unchanged, when every point is valid.

    Raises
    ------
    rough.InputError
        When no point is valid.

    Examples
    --------
    >>> import numpy as np
    >>> import rough
    >>> from rough.fractal.filling import fill_invalid
    >>> heights = np.array([0.0, 1.0, np.nan, 3.0, np.nan, np.nan, 6.0]) * 1e-6
    >>> (fill_invalid(rough.Surface(heights, 10e-6)).heights * 1e6).round(9).tolist()  # µm
    [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
    >>> scan = rough.read(rough.sample("rock-map.x3p"))
    >>> filled = fill_invalid(scan)
    >>> int(np.isnan(filled.heights).sum()), filled.history[-1]["command"]
    (0, 'fill')
    """
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
    return inpaint_biharmonic(np.where(invalid, 0.0, heights), invalid)
