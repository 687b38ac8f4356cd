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
from scipy import fft

from ..errors import InputError
from ..units import format_length
from .choices import ENDS

FFT_BLOCK = 1 << 18  # points per block of 1-D transforms: few calls, a few MB of scratch
ALPHA = math.sqrt(math.log(2.0) / math.pi)


def gaussian_kernel(spacing, cutoff):
    """The sampled ISO 16610-21 weighting function, truncated at ±λc, summing to 1."""
    half = int(np.floor(cutoff / spacing))
    x = np.arange(-half, half + 1) * spacing
    weights = np.exp(-np.pi * (x / (ALPHA * cutoff)) ** 2)
    return weights / weights.sum()


def convolved(values, kernel, axis=-1):
    """The linear convolution of ``values`` with an odd-length ``kernel`` along ``axis``,
    centred on each point (``mode="same"``), zero beyond the ends.

    By overlap-add: each line is cut into segments of about seven kernel lengths,
    whose FFTs (``scipy.fft``) are taken together, a block of lines at a time. It is
    ``scipy.signal.oaconvolve(values, kernel, mode="same", axes=axis)`` to rounding,
    without importing ``scipy.signal`` (half a second, most of it ``scipy.stats``).

    Parameters
    ----------
    values : numpy.ndarray of float
        No NaN (a NaN spreads over its segment and the next).
    kernel : numpy.ndarray of float
        1-D, of odd length.
    axis : int, default -1
        The axis along which to convolve.

    Returns
    -------
    numpy.ndarray
        Shaped like ``values``.

    Examples
    --------
    >>> import numpy as np
    >>> from rough.metrology.filters import convolved
    >>> (convolved(np.array([0.0, 0.0, 3.0, 0.0, 0.0]), np.array([0.25, 0.5, 0.25])).round(12) + 0.0).tolist()
    [0.0, 0.75, 1.5, 0.75, 0.0]
    """
    lines = np.ascontiguousarray(np.moveaxis(values, axis, -1))
    n, width = lines.shape[-1], kernel.size
    size = fft.next_fast_len(max(8 * width, 256), real=True)
    length = size - width + 1  # new points per segment; the tail of one overlaps the next only
    count = -(-n // length)
    response = fft.rfft(kernel, size)
    flat = lines.reshape(-1, n)
    out = np.empty_like(flat)
    step = max(1, FFT_BLOCK // (count * size))
    for first in range(0, flat.shape[0], step):
        block = flat[first : first + step]
        padded = np.zeros((block.shape[0], count * length))
        padded[:, :n] = block
        spectra = fft.rfft(padded.reshape(-1, count, length), size, axis=-1, workers=-1)
        spectra *= response
        segments = fft.irfft(spectra, size, axis=-1, workers=-1)
        heads = segments[..., :length]
        heads[:, 1:, : width - 1] += segments[:, :-1, length:]
        whole = np.concatenate([heads.reshape(block.shape[0], -1), segments[:, -1, length:]], axis=-1)
        out[first : first + step] = whole[:, width // 2 : width // 2 + n]
    return np.moveaxis(out.reshape(lines.shape), -1, axis)


def transmission(wavelength, cutoff):
    """The Gaussian mean line's amplitude transmission of a sine of a given wavelength.

    ``exp(-π (α λc / λ)²)`` with ``α = √(ln 2 / π)``: 50 % at the cut-off. The
    roughness transmits the rest, one minus this.

    Parameters
    ----------
    wavelength : float or array_like of float
        Wavelength(s) λ of the sine, metres.
    cutoff : float
        The cut-off λc, metres.

    Returns
    -------
    float or numpy.ndarray
        The fraction of the amplitude that the mean line (waviness) keeps, in [0, 1],
        shaped like ``wavelength``.

    Examples
    --------
    >>> from rough.metrology import transmission
    >>> round(float(transmission(0.8e-3, 0.8e-3)), 6)  # at λ = λc
    0.5
    >>> transmission([0.08e-3, 8e-3], 0.8e-3).round(4).tolist()  # λc / 10 and 10 λc
    [0.0, 0.9931]
    """
    return np.exp(-np.pi * (ALPHA * cutoff / np.asarray(wavelength, dtype=float)) ** 2)


def mean_line(surface, cutoff):
    """The Gaussian mean line (waviness) of a surface at every point.

    ISO 16610-21 for profiles, and its separable areal form, ISO 16610-61, for maps.

    Parameters
    ----------
    surface : Surface
        A profile or map. NaN points are left out: the mean line at each point is
        the weighted mean of the valid points within reach.
    cutoff : float
        The cut-off wavelength λc, metres; at least two samples and at most the
        data's shortest side.

    Returns
    -------
    numpy.ndarray
        The mean line in metres, shaped like the heights, over the full length (the
        kernel renormalised near the ends); NaN where the input is NaN.

    Raises
    ------
    rough.InputError
        For a cut-off that is not positive, longer than the data or shorter than two
        samples.

    See Also
    --------
    split : The roughness or waviness as a surface, with the ends trimmed.
    transmission : The mean line's amplitude transmission of a sine.

    Notes
    -----
    The weighting function ``exp(-π (x / (α λc))²) / (α λc)`` is sampled at the
    spacing, truncated at ±λc and normalised; as a normalised convolution,
    ``(s * z·v) / (s * v)`` with ``v`` the validity mask, NaN points neither spread
    nor bias the mean line.

    Examples
    --------
    A sine of wavelength λc keeps half its amplitude:

    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology import mean_line
    >>> x = np.arange(4000) * 1e-6  # 4 mm at 1 µm
    >>> sine = rough.Surface(1e-6 * np.sin(2 * np.pi * x / 0.8e-3), 1e-6)
    >>> line = mean_line(sine, 0.8e-3)
    >>> f"{np.max(np.abs(line[1000:3000])) * 1e6:.3f} µm"  # away from the ends
    '0.500 µm'

    A constant passes unchanged, and an invalid point stays invalid without
    disturbing its neighbours:

    >>> heights = np.full(100, 2e-6)
    >>> heights[50] = np.nan
    >>> line = mean_line(rough.Surface(heights, 10e-6), 0.1e-3)
    >>> int(np.isnan(line).sum()), bool(np.allclose(line[~np.isnan(line)], 2e-6, rtol=1e-12, atol=0))
    (1, True)
    """
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
        numerator = convolved(numerator, kernel, axis)
        denominator = convolved(denominator, kernel, axis)
    with np.errstate(invalid="ignore", divide="ignore"):
        line = numerator / denominator
    return np.where(valid & (denominator > 1e-9), line, np.nan)


def split(surface, cutoff, keep="roughness", ends="trim"):
    """The roughness or the waviness of a surface, by the Gaussian filter.

    Parameters
    ----------
    surface : Surface
        A profile or map; NaN points are left out of the mean line (see
        :func:`mean_line`).
    cutoff : float
        The cut-off wavelength λc, metres.
    keep : {"roughness", "waviness"}, default "roughness"
        ``roughness``: the surface less its Gaussian mean line; ``waviness``: the
        mean line.
    ends : {"trim", "correct"}, default "trim"
        ``trim`` drops λc/2 at each end (rounded up to whole samples), where ISO
        16610-21 regards the filter as unreliable, and moves the origin to match;
        ``correct`` keeps the full length with the kernel renormalised over the data
        present.

    Returns
    -------
    Surface
        Heights in metres, with a ``filter`` history entry (standard, cut-off, keep,
        ends). NaN where the input is NaN.

    Raises
    ------
    rough.InputError
        For an unknown ``keep`` or ``ends``, a cut-off the data cannot take, or data
        too short to keep two points once λc/2 is trimmed at each end.

    See Also
    --------
    detrend : Form removal, then this filter.

    Examples
    --------
    A long wave (8 mm, 10 µm) and a short one (80 µm, 1 µm), split at λc = 0.8 mm:
    the waviness keeps 99.31 % of the long wave, and the roughness the short wave
    with the 0.69 % of the long one that the mean line misses.

    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology import split
    >>> x = np.arange(8000) * 1e-6  # 8 mm at 1 µm
    >>> long, short = 10e-6 * np.sin(2 * np.pi * x / 8e-3), 1e-6 * np.sin(2 * np.pi * x / 80e-6)
    >>> scan = rough.Surface(long + short, 1e-6)
    >>> waviness = split(scan, 0.8e-3, keep="waviness")
    >>> roughness = split(scan, 0.8e-3)
    >>> roughness.points, f"{roughness.origin[0] * 1e3:.1f} mm"  # 0.4 mm trimmed at each end
    ((7200,), '0.4 mm')
    >>> f"{np.max(np.abs(waviness.heights)) * 1e6:.2f} µm"
    '9.93 µm'
    >>> f"{np.max(np.abs(roughness.heights - short[400:-400])) * 1e6:.3f} µm"
    '0.069 µm'
    """
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
