"""ISO 4287/4288 profile parameters and ISO 25178-2 areal parameters.

Everything is computed on the data as given, about the mean of the valid points
(no levelling, no filter: detrend or filter first if you want them), over the
valid (non-NaN) points only:

- amplitude parameters (Ra, Rq, Rsk, Rku, Rt; Sa, Sq, Ssk, Sku, Sp, Sv, Sz) use the
  valid points, so a scan with dropouts gives the values of its valid points;
- slopes use pairs of neighbouring valid points; by default forward differences
  (``slope="2point"``, the definition of SurfaceTopography's ``rms_gradient`` and
  surfalize's Rdq), or ISO 4287's seven-point derivative (``slope="7point"``);
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
  ``jrc_spacing`` (0.5 mm by default), and JRC = 32.2 + 32.47 log10(Z2);
- Sal and Str come from the autocorrelation function over pairs of valid points
  only (no filling): by default ISO 25178-2's, the sum of the products of the
  pairs at each lag over the sum of the squares (``acf="iso"``), or the mean product
  of the pairs at each lag over the mean square (``acf="per-lag"``, surfalize's and
  the statistician's unbiased estimate); Std from the Hann-windowed power
  spectrum; Std is the direction of the lay (the ridges), counter-clockwise from
  +x, in [0°, 180°).
"""

import logging
import math

import numpy as np

from ..errors import InputError
from ..units import format_length

log = logging.getLogger("rough")

SLOPES = ("2point", "7point")
ACFS = ("iso", "per-lag")
SEVEN_POINT = np.array([1.0, -9.0, 45.0, 0.0, -45.0, 9.0, -1.0]) / 60.0
MAGNITUDE = 1e60  # m: heights up to this keep every power and sum the parameters take within float64
SAMPLING_TOLERANCE = 0.01  # a profile within 1 % of a whole number of sampling lengths holds that many
ROUNDING = 64 * np.finfo(float).eps  # relative: deviations this small are the rounding of the mean (measured ≤ 2.3 eps)
BLOCK = 1 << 16  # points per block when streaming through a map: cache-sized, no full-size temporaries
FFT_BLOCK = 1 << 18  # points per block of 1-D transforms: few calls, a few MB of scratch

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
AREAL = {
    "Sa": ("m", "arithmetic mean height"),
    "Sq": ("m", "root mean square height"),
    "Ssk": ("1", "skewness"),
    "Sku": ("1", "kurtosis (3 for a Gaussian)"),
    "Sp": ("m", "maximum peak height"),
    "Sv": ("m", "maximum pit depth"),
    "Sz": ("m", "maximum height Sp + Sv"),
    "Sdq": ("1", "root mean square gradient"),
    "Sdr": ("%", "developed interfacial area ratio"),
    "Sal": ("m", "autocorrelation length (ACF decays to 0.2)"),
    "Str": ("1", "texture aspect ratio (1 isotropic, → 0 directional)"),
    "Std": ("deg", "texture (lay) direction from +x"),
}


def valid_values(heights):
    """``(values, their sum)``: the valid points of ``heights`` as a flat array (a view,
    without a copy, when there is no NaN) and their sum, the very one ``values.sum()``
    and ``values.mean()`` take."""
    values = heights.reshape(-1)
    with np.errstate(over="ignore", invalid="ignore"):  # a sum beyond float64 is refused by centring
        total = values.sum()
        if not math.isfinite(total):
            values = values[~np.isnan(values)]
            total = values.sum()
    return values, total


def centring(heights):
    """``(mean, count, constant)`` of the valid points of ``heights``: their mean and
    number, and whether they differ from that mean only by its rounding (a constant
    surface, whose deviations count as exactly zero). Reads a NaN-free array without
    copying it.

    Raises
    ------
    rough.InputError
        For a height beyond ±1e60 m (:data:`MAGNITUDE`), where the powers and sums
        that the parameters take would overflow float64 (to inf or NaN).
    """
    values, total = valid_values(heights)
    if not values.size:
        return math.nan, 0, False
    top, bottom = float(values.max()), float(values.min())
    if not max(top, -bottom) <= MAGNITUDE:
        raise InputError(
            f"a height of {top if top > -bottom else bottom:.6g} m is beyond ±{MAGNITUDE:g} m, where the "
            "parameters' sums of powers overflow: the data are damaged, or their unit is wrong"
        )
    mean = total / values.size
    return mean, values.size, max(top - mean, mean - bottom) <= ROUNDING * abs(mean)


def centred(heights):
    """``heights`` less the mean of their valid points (NaN stays NaN); exactly zero
    where they differ from that mean only by its rounding (a constant surface)."""
    mean, count, constant = centring(heights)
    if not count:
        return heights
    if constant:
        return np.where(np.isnan(heights), np.nan, 0.0)
    return heights - mean


def amplitude(heights):
    """Mean-removed moments of the valid points of ``heights`` (any shape; NaN points
    left out): Ra, Rq, Rsk, Rku (NaN for a constant surface), and the height range
    (max, min) about the mean. Streams through the points a block at a time, with no
    full-size temporaries."""
    mean, count, constant = centring(heights)
    if count == 0:
        raise InputError("no valid points: nothing to evaluate")
    if constant:
        return {"a": 0.0, "q": 0.0, "sk": math.nan, "ku": math.nan, "p": 0.0, "v": 0.0}
    flat = heights.reshape(-1)
    sums = []
    for start in range(0, flat.size, BLOCK):
        deviation = flat[start : start + BLOCK] - mean
        if count < flat.size:
            deviation = deviation[~np.isnan(deviation)]
        squared = deviation * deviation
        sums.append((np.abs(deviation).sum(), squared.sum(), (squared * deviation).sum(), (squared * squared).sum()))
    absolute, square, cube, fourth = (math.fsum(column) / count for column in zip(*sums))
    rq = math.sqrt(square)
    return {
        "a": absolute,
        "q": rq,
        "sk": cube / rq**3 if rq > 0 else math.nan,
        "ku": fourth / rq**4 if rq > 0 else math.nan,
        "p": float(np.nanmax(flat) - mean),
        "v": 0.0 - float(np.nanmin(flat) - mean),
    }


def slopes(heights, spacing, method="2point", axis=-1):
    """Local slopes dz/dx along ``axis`` (NaN where a point needed is invalid):
    forward differences, or ISO 4287's seven-point formula on interior points."""
    _check_slope(method, heights.shape[axis])
    if method == "2point":
        return np.diff(heights, axis=axis) / spacing
    from scipy.ndimage import correlate1d

    derivative = correlate1d(heights, SEVEN_POINT[::-1], axis=axis, mode="constant", cval=np.nan) / spacing
    return np.take(derivative, range(3, heights.shape[axis] - 3), axis=axis)


def _check_slope(method, points):
    """Refuse an unknown slope method, and the seven-point slope along fewer than 7 points."""
    if method not in SLOPES:
        raise InputError(f"slope method must be one of {', '.join(SLOPES)}, not {method!r}")
    if method == "7point" and points < 7:
        raise InputError("the seven-point slope needs at least 7 points along each axis")


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


def areal_parameters(surface, slope="2point", threshold=0.2, acf="iso"):
    """ISO 25178-2 areal parameters of a map.

    On the data as given, about the mean of the valid points (no levelling, no
    filter: detrend or filter first if you want them).

    Parameters
    ----------
    surface : Surface
        A map. NaN points are left out: amplitude parameters use the valid points,
        gradients pairs of neighbouring valid points, the autocorrelation pairs of
        valid points only (no filling); for Std's spectrum they are set to the mean.
    slope : {"2point", "7point"}, default "2point"
        Forward differences, or ISO 4287's seven-point derivative, for Sdq and Sdr.
    threshold : float, default 0.2
        The autocorrelation level that defines Sal and Str.
    acf : {"iso", "per-lag"}, default "iso"
        The autocorrelation function of Sal and Str: ISO 25178-2's (the products
        of the pairs at each lag summed, over the sum of the squares) or the mean
        product per lag over the mean square. See :func:`autocorrelation`.

    Returns
    -------
    dict of str to float
        Keyed as :data:`AREAL`: Sa, Sq, Sp, Sv, Sz, Sal (m); Ssk, Sku, Sdq, Str (pure
        numbers); Sdr (%); Std (degrees). NaN where a parameter is undefined: Ssk,
        Sku, Sal, Str and Std of a constant map; Str when the autocorrelation does not
        fall to ``threshold`` within half the map in some direction (with a warning
        giving its upper bound).

    Raises
    ------
    rough.InputError
        For a map with no valid points, an unknown ``slope`` or ``acf``, or fewer
        than 7 points along an axis for the seven-point slope.

    See Also
    --------
    rough.metrology.parameters : The same with a cut-off, and with warnings.

    Notes
    -----
    Sal is the shortest lag at which the autocorrelation falls to ``threshold`` and
    Str that over the longest such lag among all directions, over lags up to half
    the map. Std is the lay direction (where the ridges run), counter-clockwise from
    +x in [0°, 180°), perpendicular to the wavevector of the largest angular power of
    the Hann-windowed spectrum.

    Examples
    --------
    A tilted plane has Sdq equal to its slope and Sdr = 100 (√(1 + slope²) - 1) %:

    >>> import math
    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology import areal_parameters
    >>> y, x = np.mgrid[0:64, 0:64] * 10e-6  # 0.64 mm square at 10 µm
    >>> values = areal_parameters(rough.Surface(0.01 * x, 10e-6))
    >>> round(values["Sdq"], 9), round(values["Sdr"], 9), round(100 * (math.sqrt(1 + 0.01**2) - 1), 9)
    (0.01, 0.004999875, 0.004999875)

    Grooves that run along y (heights vary along x, wavelength 160 µm, 1 µm
    amplitude) have Sq ≈ 1/√2 µm and lay direction 90°; their texture outlasts half
    the map along y, so Str is undefined:

    >>> rng = np.random.default_rng(0)
    >>> grooves = 1e-6 * np.sin(2 * np.pi * x / 160e-6) + 0.05e-6 * rng.standard_normal(x.shape)
    >>> values = areal_parameters(rough.Surface(grooves, 10e-6))
    >>> print(f"Sq {values['Sq'] * 1e6:.2f} µm, Std {values['Std']:.0f}°, Str {values['Str']}")
    Sq 0.71 µm, Std 90°, Str nan

    On the sample map (Sq 0.1 mm by design), over its valid points:

    >>> values = areal_parameters(rough.read(rough.sample("rock-map.x3p")))
    >>> print(f"Sq {values['Sq'] * 1e6:.1f} µm, Sal {values['Sal'] * 1e3:.2f} mm, Str {values['Str']:.2f}")
    Sq 100.0 µm, Sal 0.80 mm, Str 0.73
    """
    moments = amplitude(surface.heights)
    sdq, sdr = gradient_means(surface, slope)
    sal, str_ratio = autocorrelation_lengths(surface, threshold, acf=acf)
    return {
        "Sa": moments["a"],
        "Sq": moments["q"],
        "Ssk": moments["sk"],
        "Sku": moments["ku"],
        "Sp": moments["p"],
        "Sv": moments["v"],
        "Sz": moments["p"] + moments["v"],
        "Sdq": sdq,
        "Sdr": sdr,
        "Sal": sal,
        "Str": str_ratio,
        "Std": texture_direction(surface),
    }


def gradient_means(surface, slope="2point"):
    """Sdq and Sdr (%) of a map: the RMS of |∇z| and the mean of √(1 + |∇z|²) - 1 over
    the points where both slopes are valid (forward differences from the point, or
    ISO 4287's seven-point derivative on interior points); NaN where there are none.
    Works a block of rows at a time."""
    z = surface.heights
    dx, dy = surface.spacing
    _check_slope(slope, min(z.shape))
    before = 0 if slope == "2point" else 3  # the rows a point's slope along y needs before it ...
    after = max(before, 1)  # ... and after it
    sums, count = [], 0
    rows_per_block = max(1, BLOCK // z.shape[1])
    for top in range(before, z.shape[0] - after, rows_per_block):
        bottom = min(top + rows_per_block, z.shape[0] - after)
        gx = slopes(z[top:bottom], dx, slope, axis=1)
        gy = slopes(z[top - before : bottom + after], dy, slope, axis=0)
        squared = gx**2 + gy[:, :-1] ** 2 if slope == "2point" else gx**2 + gy[:, 3:-3] ** 2
        squared = squared[~np.isnan(squared)]
        sums.append((squared.sum(), (np.sqrt(1.0 + squared) - 1.0).sum()))
        count += squared.size
    if not count:
        return math.nan, math.nan
    square, developed = (math.fsum(column) / count for column in zip(*sums))
    return math.sqrt(square), 100.0 * developed


def map_profiles(surface, along):
    """The profiles of a map along ``x`` (its rows) or ``y`` (its columns) that have at
    least two valid points, as profile Surfaces."""
    from ..surface import Surface

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


def amplitude_density(surface, bins=50):
    """The amplitude probability density of the heights about their mean.

    Parameters
    ----------
    surface : Surface
        A profile or map; only its valid (non-NaN) points are counted.
    bins : int, default 50
        The number of equal-width height bins, spanning the valid heights.

    Returns
    -------
    centres : numpy.ndarray
        The bin centres, metres, about the mean of the valid heights.
    density : numpy.ndarray
        The probability density in 1/m (a histogram normalised so that it integrates
        to 1 over the bins).

    Examples
    --------
    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology import amplitude_density
    >>> scan = rough.read(rough.sample("rock-map.x3p"))  # 6 invalid points
    >>> centres, density = amplitude_density(scan, bins=20)
    >>> centres.shape, density.shape
    ((20,), (20,))
    >>> round(float(np.sum(density) * (centres[1] - centres[0])), 9)  # integrates to 1
    1.0
    """
    values = np.sort(surface.heights[~np.isnan(surface.heights)])  # the mean, and so the bins, order-free
    density, edges = np.histogram(values - values.mean(), bins=bins, density=True)
    return (edges[:-1] + edges[1:]) / 2, density


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

    >>> from rough.metrology.parameters import sampling_sections
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


def autocorrelation(surface, acf="iso"):
    """The normalised autocorrelation of the mean-removed valid heights ``z``, over
    pairs of valid points only, on lags up to half the map in each direction.

    Parameters
    ----------
    surface : Surface
        A map; NaN points are in no pair (no filling).
    acf : {"iso", "per-lag"}, default "iso"
        ``iso``: ISO 25178-2's ``∬ z(x, y) z(x - tx, y - ty) dx dy / ∬ z² dx dy`` over
        the definition area, the sum of the products of the pairs at each lag over
        the sum of the squares; it falls towards 0 as the overlap shrinks.
        ``per-lag``: the mean product of the pairs at each lag over the mean
        square (the unbiased estimate that surfalize uses); noisier at long lags,
        NaN where no pair is valid.

    Returns
    -------
    acf : numpy.ndarray
        ``acf[j, i]`` at lag ``(lag_x[i], lag_y[j])``; 1 at zero lag; NaN for a
        constant map.
    lag_x, lag_y : numpy.ndarray
        The lags in metres, -nx//2 … nx//2 and -ny//2 … ny//2 spacings.

    Notes
    -----
    Computed through zero-padded FFTs a block at a time, only the lags needed (one
    half plane; the other is its mirror image), so that it never holds more than
    about 2.7 times the map's size.

    Examples
    --------
    Heights alternating +1, -1 along x: at a lag of one spacing every pair has
    product -1, so the per-lag ACF is -1 and ISO's is -(nx - 1)/nx.

    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology.parameters import autocorrelation
    >>> stripes = rough.Surface(np.tile([1.0, -1.0], (4, 4)), 1.0)  # 4 × 8
    >>> float(autocorrelation(stripes, "per-lag")[0][2, 5]), float(autocorrelation(stripes)[0][2, 5])
    (-1.0, -0.875)
    """
    if acf not in ACFS:
        raise InputError(f"acf must be one of {', '.join(ACFS)}, not {acf!r}")
    z = surface.heights
    ny, nx = z.shape
    hy, hx = ny // 2, nx // 2
    mean, count, constant = centring(z)
    products = _half_correlation(lambda rows: _deviation(z[rows], mean, constant), z.shape)
    result = np.empty((2 * hy + 1, 2 * hx + 1))
    with np.errstate(invalid="ignore", divide="ignore"):
        if acf == "iso":
            result[hy:] = products
        else:
            np.divide(products, _pair_counts(z, count), out=result[hy:])
        result[hy:] /= result[hy, hx]
    result[:hy] = result[:hy:-1, ::-1]  # the autocorrelation of a real field: acf(-l) = acf(l)
    return result, np.arange(-hx, hx + 1) * surface.spacing[0], np.arange(-hy, hy + 1) * surface.spacing[1]


def _pair_counts(z, count):
    """The number of pairs of valid points at each lag of :func:`autocorrelation`'s
    half plane (``count`` valid points in all); NaN where there is none."""
    ny, nx = z.shape
    if count == z.size:
        return np.outer(ny - np.arange(ny // 2 + 1.0), nx - np.abs(np.arange(-(nx // 2), nx // 2 + 1.0)))
    pairs = np.rint(_half_correlation(lambda rows: (~np.isnan(z[rows])).astype(np.float64), z.shape))
    pairs[pairs == 0] = np.nan  # no pair of valid points at this lag (not the rounding of the FFTs)
    return pairs


def _deviation(heights, mean, constant):
    """A block of heights less their mean, zero at invalid points (and everywhere on a
    constant surface)."""
    if constant:
        return np.zeros_like(heights)
    return np.where(np.isnan(heights), 0.0, heights - mean)


def _half_correlation(field, shape):
    """The circular autocorrelation of a map (``field(rows)`` gives a block of its rows)
    zero-padded to ``1.5 ×`` its shape (so that no lag up to half the map wraps round),
    at lags 0 … ny//2 along y and -nx//2 … nx//2 along x. Row transforms, column
    transforms and the inverse are taken a block at a time, the inverse only over the
    lags kept, so that the padded spectrum is never whole in memory."""
    from scipy import fft

    ny, nx = shape
    py = fft.next_fast_len(ny + ny // 2 + 1, real=True)
    px = fft.next_fast_len(nx + nx // 2 + 1, real=True)
    width, hy, hx = px // 2 + 1, ny // 2, nx // 2
    rows_per_block, columns_per_block = max(1, FFT_BLOCK // px), max(1, FFT_BLOCK // py)
    along_x = np.empty((ny, width), dtype=complex)
    padded = np.zeros((min(rows_per_block, ny), px))
    for top in range(0, ny, rows_per_block):
        rows = slice(top, top + rows_per_block)
        block = padded[: min(ny, top + rows_per_block) - top]
        block[:, :nx] = field(rows)
        along_x[rows] = fft.rfft(block, axis=1, workers=-1)
    del padded
    padded = np.zeros((py, min(columns_per_block, width)), dtype=complex)
    lagged = np.empty((hy + 1, width), dtype=complex)
    for left in range(0, width, columns_per_block):
        columns = slice(left, left + columns_per_block)
        block = padded[:, : min(width, left + columns_per_block) - left]
        block[:ny] = along_x[:, columns]
        block[ny:] = 0
        parts = fft.fft(block, axis=0, workers=-1, overwrite_x=True).view(np.float64)
        np.square(parts, out=parts)
        lagged[:, columns] = fft.rfft(parts[:, 0::2] + parts[:, 1::2], axis=0, workers=-1)[: hy + 1]
    del along_x, padded, parts
    # the power is real: its inverse transform along y is the conjugate of the forward one
    correlation = fft.irfft(np.conj(lagged, out=lagged), n=px, axis=1, workers=-1)
    correlation /= py
    return np.concatenate([correlation[:, px - hx :], correlation[:, : hx + 1]], axis=1)


def autocorrelation_lengths(surface, threshold=0.2, directions=360, acf="iso"):
    """Sal (the shortest lag at which the ACF falls to ``threshold``) and Str (Sal over
    the longest such decay length among all directions), with the autocorrelation
    ``acf`` of :func:`autocorrelation` (ISO 25178-2's by default). Lags reach half the
    map along each axis; Str is NaN when the ACF does not fall to ``threshold``
    within that in some direction (the texture is longer than half the map); both
    are NaN for a constant surface."""
    acf, lag_x, lag_y = autocorrelation(surface, acf)
    dx, dy = surface.spacing
    centre = ((acf.shape[0] - 1) / 2, (acf.shape[1] - 1) / 2)
    finest = min(dx, dy) / 4
    decay, reaches, rays = np.full(directions, np.nan), np.empty(directions), []
    for k, angle in enumerate(np.linspace(0, np.pi, directions, endpoint=False)):
        reach = reaches[k] = min(lag_x[-1] / max(abs(math.cos(angle)), 1e-12), lag_y[-1] / max(math.sin(angle), 1e-12))
        step = max(finest, reach / (4 * max(acf.shape)))  # at most 4 samples a lag when dx and dy differ wildly
        radii = np.arange(0, reach + step / 2, step)
        rays.append((radii, step, [centre[0] + radii * math.sin(angle) / dy, centre[1] + radii * math.cos(angle) / dx]))
    for k, along in _first_falls(acf, rays, threshold):
        radii, step, _ = rays[k]
        i = np.flatnonzero(along <= threshold)[0]
        decay[k] = radii[i - 1] + (along[i - 1] - threshold) / (along[i - 1] - along[i]) * step
    fastest = float(np.nanmin(decay)) if np.isfinite(decay).any() else math.nan
    slowest = float(np.max(decay)) if np.isfinite(decay).all() else math.nan
    if np.isnan(slowest) and np.isfinite(fastest):
        log.warning(
            "Str is undefined: the autocorrelation stays above %g out to half the map in some direction "
            "(the texture runs longer than that); Str < %.3g",
            threshold,
            fastest / np.max(reaches[np.isnan(decay)]),
        )
    return fastest, fastest / slowest if slowest > 0 else math.nan


def _first_falls(acf, rays, threshold, first=64):
    """``(k, values)`` for each ray ``k`` (radii, step, grid coordinates) along which the
    ACF falls to ``threshold``: its bilinear values from the centre to the first
    point at or below it. All rays are interpolated in one call per round, a stretch
    at a time (doubling), so that a short decay costs little."""
    from scipy.ndimage import map_coordinates

    done, seen, length = {k: 0 for k in range(len(rays))}, {k: [] for k in range(len(rays))}, first
    while done:
        pieces = {k: (start, min(start + length, rays[k][0].size)) for k, start in done.items()}
        coordinates = np.concatenate(
            [np.array([axis[a:b] for axis in rays[k][2]]) for k, (a, b) in pieces.items()], axis=1
        )
        values = np.split(map_coordinates(acf, coordinates, order=1), np.cumsum([b - a for a, b in pieces.values()]))
        for (k, (a, b)), piece in zip(pieces.items(), values):
            seen[k].append(piece)
            if (piece <= threshold).any():
                yield k, np.concatenate(seen.pop(k))
                del done[k]
            elif b == rays[k][0].size:
                del done[k], seen[k]
            else:
                done[k] = b
        length *= 2


def angular_spectrum(surface, directions=360):
    """The angular power spectrum of the mean-removed map (Hann-windowed, NaN points
    set to the mean): ``(wavevector angles in degrees, power)``, integrating
    ``|F|²`` along each radius as ISO 25178-2 does, up to the smaller Nyquist
    frequency and leaving out the lowest two frequencies."""
    from scipy import fft
    from scipy.ndimage import map_coordinates

    z = surface.heights
    ny, nx = z.shape
    mean, _, constant = centring(z)
    window_y, window_x = np.hanning(ny), np.hanning(nx)
    field = np.empty((ny, nx))
    rows_per_block = max(1, BLOCK // nx)
    for top in range(0, ny, rows_per_block):
        rows = slice(top, top + rows_per_block)
        field[rows] = _deviation(z[rows], mean, constant) * np.outer(window_y[rows], window_x)
    transform = fft.rfft2(field, workers=-1)
    del field
    power = np.empty(transform.shape)  # |F|², shifted along y so that fy = 0 is row ny // 2
    shift = ny // 2
    for target, source in ((slice(shift, ny), slice(0, ny - shift)), (slice(0, shift), slice(ny - shift, ny))):
        power[target] = transform[source].real ** 2 + transform[source].imag ** 2
    del transform
    dfx, dfy = 1 / (nx * surface.spacing[0]), 1 / (ny * surface.spacing[1])
    nyquist = min(0.5 / surface.spacing[0], 0.5 / surface.spacing[1])
    step = min(dfx, dfy)
    radii = np.arange(2 * step, nyquist, step)
    angles = np.linspace(0, 180, directions, endpoint=False)
    coordinates = np.empty((2, directions, radii.size))
    for k, angle in enumerate(np.radians(angles)):
        fx, fy = radii * math.cos(angle), radii * math.sin(angle)
        flip = np.where(fx < 0, -1.0, 1.0)  # |F(-f)| = |F(f)|: fold onto the kx ≥ 0 half plane
        coordinates[:, k] = [ny // 2 + flip * fy / dfy, flip * fx / dfx]
    along = map_coordinates(power, coordinates.reshape(2, -1), order=1).reshape(directions, radii.size)
    return angles, along.sum(axis=1) * step


def texture_direction(surface):
    """Std: the lay direction, perpendicular to the wavevector of the largest
    angular power, in degrees counter-clockwise from +x, in [0, 180); NaN for a
    constant surface."""
    angles, spectrum = angular_spectrum(surface)
    if not spectrum.max() > 0:
        return math.nan
    return float((angles[np.argmax(spectrum)] + 90.0) % 180.0)
