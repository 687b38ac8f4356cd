"""ISO 4287/4288 profile parameters, and Tse & Cruden's Z2 and JRC.

Everything is computed on the data as given, about the mean of the valid points
(no levelling, no filter: detrend or filter first if you want them), over the
valid (non-NaN) points only (:mod:`rough.metrology.heights`):

- Rp, Rv and Rz are taken in each of ``sampling_lengths`` equal sampling lengths and
  averaged over them (ISO 4287/4288; Rz is Rp + Rv, not the old ten-point Rz); Rku is
  the kurtosis (3 for a Gaussian), not the excess;
- RSm is the mean width of the profile elements between upward mean-line
  crossings, with ISO 4287's discrimination (peaks and valleys of at least 10 % of
  Rz, applied as a hysteresis band; elements of at least 1 % of the sampling length);
- peak density counts the peaks that cross a band of ±5 % of Rz about the mean line
  (``peak_band``; ISO 4287/Amd.1's RPc rule: a peak counts when the profile rises
  above the band after being below it), per metre of evaluation length;
- Z2 is Tse & Cruden's RMS first derivative of the profile sampled at
  ``jrc_spacing`` (0.5 mm by default), and JRC = 32.2 + 32.47 log10(Z2).

A map is evaluated as a set of profiles with :func:`map_profiles` and
:func:`combined`.
"""

import math

import numpy as np

from ..errors import InputError
from ..surface import Surface
from ..units import format_length
from .heights import amplitude, centred, slopes

SAMPLING_TOLERANCE = 0.01  # a profile within 1 % of a whole number of sampling lengths holds that many
# key: (unit, what it is). Units: "m", "1/m", "1" (dimensionless), "%", "deg".
PROFILE = {
    "Ra": ("m", "arithmetic mean deviation"),
    "Rq": ("m", "root mean square deviation"),
    "Rsk": ("1", "skewness"),
    "Rku": ("1", "kurtosis (3 for a Gaussian)"),
    "Rp": ("m", "maximum peak height, mean over sampling lengths"),
    "Rv": ("m", "maximum valley depth, mean over sampling lengths"),
    "Rz": ("m", "maximum height Rp + Rv, mean over sampling lengths"),
    "Rt": ("m", "total height over the evaluation length"),
    "RSm": ("m", "mean width of the profile elements"),
    "Rdq": ("1", "root mean square slope"),
    "peak_density": ("1/m", "peaks crossing a ±5 % Rz band about the mean line, per length"),
    "Z2": ("1", "Tse & Cruden RMS first derivative at the JRC spacing"),
    "JRC": ("1", "joint roughness coefficient, 32.2 + 32.47 log10(Z2)"),
}


def profile_parameters(
    surface, sampling_lengths=None, slope="2point", jrc_spacing=0.5e-3, peak_band=0.05, sampling_length=None
):
    """ISO 4287/4288 parameters of a profile, and Tse & Cruden's Z2 and JRC.

    On the data as given, about the mean of the valid points (no levelling, no
    filter: detrend or filter first if you want them).

    Parameters
    ----------
    surface : Surface
        A profile. NaN points are left out: amplitude parameters use the valid
        points, slopes pairs of neighbouring valid points, RSm and the peak count
        close up the gaps, and Z2 interpolates linearly between valid points.
    sampling_lengths : int, optional
        The number of sampling lengths over which Rp, Rv and Rz are taken and
        averaged (ISO 4287/4288). Without ``sampling_length``: that many equal
        sections (5 by default). With it: that many sampling lengths in the middle
        of the profile (by default every whole one it holds).
    slope : {"2point", "7point"}, default "2point"
        Forward differences (SurfaceTopography's and surfalize's definition), or
        ISO 4287's seven-point derivative on interior points, for Rdq.
    jrc_spacing : float, default 0.5e-3
        The spacing in metres at which the profile is point-sampled for Z2 (the data
        spacing when that is coarser).
    peak_band : float, default 0.05
        Half-width of the band about the mean line for the peak count, as a fraction
        of Rz (ISO 4287/Amd.1's RPc rule).
    sampling_length : float, optional
        The sampling length lr in metres; ISO 4288 takes lr = λc, the cut-off of
        the roughness filter. See :func:`sampling_sections`.

    Returns
    -------
    dict of str to float
        Keyed as :data:`PROFILE`: Ra, Rq, Rt, Rp, Rv, Rz, RSm (m); Rsk, Rku, Rdq,
        Z2, JRC (pure numbers); ``peak_density`` (1/m). NaN where a parameter is
        undefined: Rsk and Rku of a constant profile, RSm with no complete profile
        element, Z2 over fewer than three JRC spacings, JRC unless Z2 > 0; Rp, Rv,
        Rz, RSm and ``peak_density`` of a profile shorter than one
        ``sampling_length``.

    Raises
    ------
    rough.InputError
        For a profile with no valid points, an unknown ``slope``, fewer than 7
        points for the seven-point slope, more equal sampling lengths than half the
        points, or more sampling lengths of ``sampling_length`` than the profile
        holds.

    See Also
    --------
    rough.metrology.parameters : The same with a cut-off, for maps, and with warnings.

    Notes
    -----
    Rz is Rp + Rv averaged over the sampling lengths, not the ten-point Rz; Rku is
    the kurtosis (3 for a Gaussian), not the excess. RSm is the mean width of the
    profile elements between upward mean-line crossings, with ISO 4287's 10 % of Rz
    height discrimination applied as a hysteresis band and elements narrower than
    1 % of the sampling length merged. JRC = 32.2 + 32.47 log10(Z2).

    Examples
    --------
    A sine of amplitude a = 1 µm and wavelength 100 µm over 40 whole periods:
    Rq = a/√2, Ra = 2a/π, Rku = 1.5, Rz = 2a, RSm = the wavelength, and Rdq close to
    the RMS of the slope, 2πa/(λ√2) = 0.0444:

    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology import profile_parameters
    >>> x = np.arange(4000) * 1e-6  # 4 mm at 1 µm
    >>> sine = rough.Surface(1e-6 * np.sin(2 * np.pi * x / 100e-6), 1e-6)
    >>> values = profile_parameters(sine)
    >>> print(f"Rq {values['Rq'] * 1e6:.4f} µm, Ra {values['Ra'] * 1e6:.3f} µm, Rku {values['Rku']:.3f}")
    Rq 0.7071 µm, Ra 0.636 µm, Rku 1.500
    >>> print(f"Rz {values['Rz'] * 1e6:.3f} µm, RSm {values['RSm'] * 1e6:.1f} µm, Rdq {values['Rdq']:.4f}")
    Rz 2.000 µm, RSm 100.0 µm, Rdq 0.0444

    Invalid points are left out: a whole period of them leaves Rq as it was.

    >>> sine.heights[100:200] = np.nan
    >>> f"{profile_parameters(sine)['Rq'] * 1e6:.4f} µm"
    '0.7071 µm'
    """
    z = surface.heights
    dx = surface.spacing[0]
    levels = centred(z)
    moments = amplitude(z)
    sections = sampling_sections(z.size, dx, sampling_length, sampling_lengths)
    rp, rv = _per_sampling_length(levels, sections)
    rz = rp + rv
    length = z.size * dx
    lr = sampling_length if sampling_length is not None else length / len(sections)
    slope_values = slopes(z, dx, slope)
    z2 = _z2(surface, jrc_spacing)
    return {
        "Ra": moments["a"],
        "Rq": moments["q"],
        "Rsk": moments["sk"],
        "Rku": moments["ku"],
        "Rp": rp,
        "Rv": rv,
        "Rz": rz,
        "Rt": moments["p"] + moments["v"],
        "RSm": mean_element_width(levels, dx, rz, lr),
        "Rdq": _rms(slope_values),
        "peak_density": peak_count(levels, peak_band * rz) / length if sections else math.nan,
        "Z2": z2,
        "JRC": joint_roughness_coefficient(z2),
    }


def map_profiles(surface, along):
    """The profiles of a map along ``x`` (its rows) or ``y`` (its columns) that have at
    least two valid points, as profile Surfaces."""
    if along not in ("x", "y"):
        raise InputError(f"along must be x or y, not {along!r}")
    rows = surface.heights if along == "x" else surface.heights.T
    spacing = surface.spacing[0 if along == "x" else 1]
    profiles = [Surface(row, (spacing,)) for row in rows if np.count_nonzero(~np.isnan(row)) > 1]
    if not profiles:
        raise InputError(f"no profile along {along} has two valid points")
    return profiles


def combined(each, keys, quadratic=()):
    """One value per key from the dicts ``each``: the mean over the finite values (the
    quadratic mean for ``quadratic`` keys), NaN when none is finite."""
    means = {}
    for key in keys:
        values = np.array([parameters[key] for parameters in each])
        finite = values[np.isfinite(values)]
        if not finite.size:
            means[key] = math.nan
        else:
            means[key] = float(np.sqrt(np.mean(finite**2)) if key in quadratic else np.mean(finite))
    return means


def _rms(values):
    finite = values[np.isfinite(values)]
    return float(math.sqrt(np.mean(finite**2))) if finite.size else math.nan


def sampling_sections(points, spacing, sampling_length=None, count=None):
    """The sampling lengths of a profile of ``points`` samples ``spacing`` apart, as
    ``(start, stop)`` index ranges.

    Without ``sampling_length``: ``count`` (default 5) equal sections of the whole
    profile. With it (ISO 4288: lr = λc): ``count`` sampling lengths of that length,
    by default every whole one the profile holds, taken in the middle of the profile
    (what is left over is dropped equally at both ends). A profile within 1 % of a
    whole number of sampling lengths holds that many, split equally (instruments
    store whole samples per sampling length, and the trimmed ends of a filter round
    to whole samples). An empty list when the profile is shorter than one sampling
    length.

    Raises
    ------
    rough.InputError
        For fewer than one or more than ``points // 2`` equal sections, a sampling
        length of fewer than two samples, or more sampling lengths than the profile
        holds.

    Examples
    --------
    A 10 mm profile at 1.5 µm holds four sampling lengths of λc = 2.5 mm:

    >>> from rough.metrology.profile import sampling_sections
    >>> sampling_sections(6664, 1.5e-6, 2.5e-3)
    [(0, 1666), (1666, 3332), (3332, 4998), (4998, 6664)]
    >>> sampling_sections(10, 1.0, None, 2)
    [(0, 5), (5, 10)]
    """
    if sampling_length is None:
        count = 5 if count is None else count
        if count < 1 or count > points // 2:
            raise InputError(f"cannot split {points} points into {count} sampling lengths")
        return _equal_parts(0, points, count)
    per = sampling_length / spacing
    if not per >= 2:
        raise InputError(f"a sampling length of {format_length(sampling_length)} holds fewer than two samples")
    whole = math.floor(points / per + SAMPLING_TOLERANCE)
    if count is None:
        count = whole
    elif not 1 <= count <= whole:
        raise InputError(f"the profile holds {whole} sampling lengths of {format_length(sampling_length)}, not {count}")
    span = min(points, round(count * per))
    return _equal_parts((points - span) // 2, span, count) if count else []


def _equal_parts(start, length, count):
    """``count`` consecutive index ranges over ``length`` points from ``start``, as
    ``numpy.array_split`` cuts them (the first ``length % count`` one point longer)."""
    sizes = np.full(count, length // count)
    sizes[: length % count] += 1
    bounds = start + np.concatenate(([0], np.cumsum(sizes)))
    return [(int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:])]


def _per_sampling_length(centred, sections):
    """Rp and Rv in each sampling length (``(start, stop)`` index ranges), averaged
    over those with valid points; NaN when there are none."""
    peaks, valleys = [], []
    for start, stop in sections:
        part = centred[start:stop]
        part = part[~np.isnan(part)]
        if part.size:
            peaks.append(part.max())
            valleys.append(-part.min())
    if not peaks:
        return math.nan, math.nan
    return float(np.mean(peaks)), float(np.mean(valleys))


def mean_element_width(centred, spacing, rz, sampling_length):
    """RSm: the mean width of the profile elements, each a peak and the valley after
    it, from one upward crossing of the mean line to the next. ISO 4287's height
    discrimination (a peak must rise 10 % of Rz above the mean line and a valley
    fall as far below) is applied as a hysteresis band: only the upward crossing
    between a dip below -10 % Rz and a rise above +10 % Rz bounds an element. Then
    elements narrower than 1 % of the sampling length merge with the next. NaN gaps
    are closed up; NaN when there is no complete element."""
    values = centred[~np.isnan(centred)]
    band = 0.1 * rz
    side = np.where(values > band, 1, np.where(values < -band, -1, 0))
    marked = np.flatnonzero(side)
    rises = marked[1:][(side[marked][:-1] < 0) & (side[marked][1:] > 0)]
    if rises.size < 2:
        return math.nan
    index = np.arange(values.size)
    last_below = np.maximum.accumulate(np.where(values <= 0, index, -1))[rises]
    crossings = last_below + values[last_below] / (values[last_below] - values[last_below + 1])
    kept = [crossings[0]]
    for crossing in crossings[1:]:
        if (crossing - kept[-1]) * spacing >= 0.01 * sampling_length:
            kept.append(crossing)
    return float(np.mean(np.diff(kept)) * spacing) if len(kept) > 1 else math.nan


def peak_count(centred, band):
    """Peaks that cross a band of ±``band`` about the mean line (ISO 4287/Amd.1 RPc):
    a peak counts each time the profile rises above +band after being below -band.
    NaN points are skipped."""
    values = centred[~np.isnan(centred)]
    side = np.sign(values) * (np.abs(values) > band)
    side = side[side != 0]
    return int(np.count_nonzero((side[:-1] < 0) & (side[1:] > 0)))


def joint_roughness_coefficient(z2):
    """Tse & Cruden's JRC = 32.2 + 32.47 log10(Z2); NaN unless Z2 > 0."""
    return 32.2 + 32.47 * math.log10(z2) if z2 > 0 else math.nan


def _z2(surface, jrc_spacing):
    """Z2 of the profile point-sampled every ``jrc_spacing`` (linear interpolation
    between valid points; the data spacing when that is coarser)."""
    dx = surface.spacing[0]
    x = surface.positions(0)
    valid = ~np.isnan(surface.heights)
    step = max(jrc_spacing, dx)
    samples = np.arange(x[valid][0], x[valid][-1] + dx / 2, step) if valid.sum() > 1 else np.array([])
    if samples.size < 3:
        return math.nan
    heights = np.interp(samples, x[valid], surface.heights[valid])
    return float(math.sqrt(np.mean(np.diff(heights) ** 2)) / step)
