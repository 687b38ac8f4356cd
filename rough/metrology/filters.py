"""The ISO 16610-21 Gaussian profile filter and its areal form, ISO 16610-61.

Weighting function ``s(x) = exp(-π (x / (α λc))²) / (α λc)`` with
``α = √(ln 2 / π)``, so that the mean line transmits ``exp(-π (α λc / λ)²)`` of a
sine of wavelength λ: 50 % at the cut-off λc. The kernel is sampled at the data
spacing, truncated at ``|x| ≤ λc`` (the weight there is 7e-7 of the peak) and
normalised to sum 1, so a constant passes unchanged. Maps use the separable
product of the profile kernel along x and y.

The filter is a normalised convolution: the mean line at each point is the weighted
mean of the *valid* points within reach, ``w = (s * z·v) / (s * v)`` with ``v`` the
validity mask. NaN points therefore neither spread nor bias the mean line, and
near the ends the kernel is renormalised over the data that exist (the zero-order
end correction of ISO 16610-28).

Ends: ``ends="trim"`` (the default) drops λc/2 at each end, the region where ISO
16610-21 regards the filter as unreliable; ``ends="correct"`` keeps the full length
with the renormalised kernel.
"""

import dataclasses
import math

import numpy as np

from ..errors import InputError
from ..units import format_length

ALPHA = math.sqrt(math.log(2.0) / math.pi)
ENDS = ("trim", "correct")


def gaussian_kernel(spacing, cutoff):
    """The sampled ISO 16610-21 weighting function, truncated at ±λc, summing to 1."""
    half = int(np.floor(cutoff / spacing))
    x = np.arange(-half, half + 1) * spacing
    weights = np.exp(-np.pi * (x / (ALPHA * cutoff)) ** 2)
    return weights / weights.sum()


def transmission(wavelength, cutoff):
    """The mean line's amplitude transmission of a sine of ``wavelength``."""
    return np.exp(-np.pi * (ALPHA * cutoff / np.asarray(wavelength, dtype=float)) ** 2)


def mean_line(surface, cutoff):
    """The Gaussian mean line (waviness) of ``surface`` at cut-off ``cutoff``
    (metres), at every point, as an array; NaN where the input is NaN."""
    from scipy.signal import oaconvolve

    heights = surface.heights
    _check_cutoff(surface, cutoff)
    valid = ~np.isnan(heights)
    numerator = np.where(valid, heights, 0.0)
    denominator = valid.astype(np.float64)
    for axis in range(heights.ndim):
        spacing = surface.spacing[heights.ndim - 1 - axis]
        kernel = gaussian_kernel(spacing, cutoff)
        if kernel.size == 1:
            continue
        shape = [1] * heights.ndim
        shape[axis] = kernel.size
        kernel = kernel.reshape(shape)
        numerator = oaconvolve(numerator, kernel, mode="same", axes=axis)
        denominator = oaconvolve(denominator, kernel, mode="same", axes=axis)
    with np.errstate(invalid="ignore", divide="ignore"):
        line = numerator / denominator
    return np.where(valid & (denominator > 1e-9), line, np.nan)


def split(surface, cutoff, keep="roughness", ends="trim"):
    """The roughness (``surface`` minus its Gaussian mean line) or the waviness (the
    mean line) of ``surface``, as a new surface with a history entry. ``ends`` is
    ``"trim"`` (drop λc/2 at each end) or ``"correct"`` (keep the full length)."""
    if keep not in ("roughness", "waviness"):
        raise InputError(f"keep must be roughness or waviness, not {keep!r}")
    if ends not in ENDS:
        raise InputError(f"ends must be one of {', '.join(ENDS)}, not {ends!r}")
    line = mean_line(surface, cutoff)
    result = surface.heights - line if keep == "roughness" else line
    filtered = surface.derive(
        "filter",
        {
            "standard": "ISO 16610-21" if surface.is_profile else "ISO 16610-61",
            "cutoff": cutoff,
            "keep": keep,
            "ends": ends,
        },
        heights=result,
    )
    if ends == "correct":
        return filtered
    margins = [int(np.ceil(cutoff / 2 / d - 1e-9)) for d in filtered.spacing]
    if any(n - 2 * m < 2 for n, m in zip(filtered.points, margins)):
        raise InputError(
            f"the data are too short for a cut-off of {format_length(cutoff)} once λc/2 is trimmed "
            "at each end (use --ends correct or a shorter cut-off)"
        )
    index = tuple(slice(m, n - m) for n, m in zip(reversed(filtered.points), reversed(margins)))
    origin = tuple(o + m * d for o, m, d in zip(filtered.origin, margins, filtered.spacing))
    return dataclasses.replace(filtered, heights=filtered.heights[index], origin=origin)


def _check_cutoff(surface, cutoff):
    if not cutoff > 0:
        raise InputError(f"the cut-off must be a positive length, not {cutoff!r}")
    shortest = min(n * d for n, d in zip(surface.points, surface.spacing))
    if cutoff > shortest:
        raise InputError(
            f"the cut-off {format_length(cutoff)} is longer than the data ({format_length(shortest)}); "
            "the filter needs at least one cut-off length"
        )
    if cutoff < 2 * max(surface.spacing):
        raise InputError(
            f"the cut-off {format_length(cutoff)} is shorter than two samples "
            f"({format_length(max(surface.spacing))} spacing)"
        )
