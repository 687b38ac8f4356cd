"""ISO 25178-2 areal parameters of a map: the height parameters (Sa … Sz), the
hybrid ones (Sdq, Sdr) and the spatial ones (Sal, Str, Std, from
:mod:`rough.metrology.spatial`).

Everything is computed on the data as given, about the mean of the valid points
(no levelling, no filter: detrend or filter first if you want them), over the
valid (non-NaN) points only.
"""

import math

import numpy as np

from .heights import BLOCK, amplitude, check_slope, slopes
from .spatial import autocorrelation_lengths, texture_direction

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
        product per lag over the mean square. See :func:`~rough.metrology.spatial.autocorrelation`.

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
    check_slope(slope, min(z.shape))
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
