"""The spatial parameters of ISO 25178-2: the autocorrelation lengths Sal and Str,
and the texture direction Std.

Sal and Str come from the autocorrelation function over pairs of valid points only
(no filling): by default ISO 25178-2's, the sum of the products of the pairs at each
lag over the sum of the squares (``acf="iso"``), or the mean product of the pairs at
each lag over the mean square (``acf="per-lag"``, surfalize's and the statistician's
unbiased estimate); Std from the Hann-windowed power spectrum; Std is the direction
of the lay (the ridges), counter-clockwise from +x, in [0°, 180°).
"""

import logging
import math

import numpy as np
from scipy import fft
from scipy.ndimage import map_coordinates

from ..errors import InputError
from .choices import ACFS
from .filters import FFT_BLOCK
from .heights import BLOCK, centring

log = logging.getLogger("rough")


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
    >>> from rough.metrology.spatial import autocorrelation
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
