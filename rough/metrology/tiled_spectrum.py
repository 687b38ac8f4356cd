"""Sal, Str and Std of a map read a strip at a time, from spectra of square tiles
(:func:`rough.metrology.tiled_parameters`): stated estimators, not the whole map's
values.

Each tile (``tile`` × ``tile`` points, at most :data:`MOST_TILES` of them spread
evenly over the map) gives the power spectrum of its heights about the global mean
(zero at invalid points), zero-padded to twice its size, and that of its valid-point
mask. Their sums, transformed back (Wiener–Khinchin), are the sums of the products,
and the numbers, of the pairs of valid points at each lag within a tile: the mean
product per lag (``acf="per-lag"``), or that times the whole map's overlap at the
lag (``"iso"``). Lags reach :data:`REACH` of a tile, where enough pairs remain;
Sal and Str are NaN, with the reason, when the autocorrelation does not fall to 0.2
within it. Std is read from the mean Hann-windowed tile spectrum as
:func:`rough.metrology.spatial.angular_spectrum` reads the whole map's.
"""

import math

import numpy as np
from scipy import fft
from scipy.ndimage import map_coordinates

from ..errors import InputError
from .choices import ACFS

TILE = 512  # points along each side of a spectrum tile, at most
REACH = 0.25  # the longest lag used, as a fraction of a tile
MOST_TILES = 256  # tiles per map, spread evenly over it
THRESHOLD = 0.2  # the autocorrelation level of Sal and Str (ISO 25178-2)
DIRECTIONS = 360


def check_acf(acf):
    if acf not in ACFS:
        raise InputError(f"acf must be one of {', '.join(ACFS)}, not {acf!r}")


def tile_size(shape, rows):
    """The side of a spectrum tile: a power of two up to :data:`TILE`, no larger than
    the map or a strip."""
    side = min(TILE, *shape, max(rows, 8))
    return 1 << max(3, int(math.log2(side)))


def estimated(tile):
    """How each spatial parameter is estimated, for the tiled report."""
    lags = f"lags up to {int(REACH * tile)} points"
    acf = f"autocorrelation of the mean power spectrum of {tile} × {tile}-point tiles (Wiener–Khinchin), {lags}"
    return {
        "Sal": acf,
        "Str": acf,
        "Std": f"angular spectrum of the mean Hann-windowed {tile} × {tile}-point tile spectrum",
    }


def _used(index, total):
    """Whether the tile numbered ``index`` of ``total`` (row-major) is one of the at
    most :data:`MOST_TILES` used."""
    stride = max(1, math.ceil(total / MOST_TILES))
    return index % stride == 0


def strip_spectra(heights, mean, constant, tile, first, shape):
    """The summed spectra of the whole tiles of a strip (``heights``, whose first row
    is ``first`` of a map of ``shape``), flat: the padded power of the deviations,
    of the valid mask, and the Hann-windowed power of the deviations."""
    padded, half = 2 * tile, tile // 2 + 1
    sums = [np.zeros((padded, tile + 1)), np.zeros((padded, tile + 1)), np.zeros((tile, half))]
    across, down = shape[1] // tile, shape[0] // tile
    window = np.outer(np.hanning(tile), np.hanning(tile))
    full = None
    for top in range(0, heights.shape[0] - tile + 1, tile):
        for left in range(0, across * tile, tile):
            index = (first + top) // tile * across + left // tile
            if (first + top) // tile >= down or not _used(index, across * down):
                continue
            block = heights[top : top + tile, left : left + tile]
            valid = ~np.isnan(block)
            deviation = np.zeros(block.shape) if constant else np.where(valid, block - mean, 0.0)
            sums[0] += _power(deviation, padded)
            if valid.all():
                full = _power(np.ones(block.shape), padded) if full is None else full
                sums[1] += full
            else:
                sums[1] += _power(valid.astype(np.float64), padded)
            sums[2] += _power(deviation * window, tile)
    return np.concatenate([part.reshape(-1) for part in sums])


def _power(block, size):
    transform = fft.rfft2(block, s=(size, size))
    return transform.real**2 + transform.imag**2


def spatial(spectra, spacing, tile, shape, acf):
    """``({Sal, Str, Std}, reasons)`` from the summed tile spectra."""
    padded, half = 2 * tile, tile // 2 + 1
    power, pairs, hann = np.split(spectra, [padded * (tile + 1), 2 * padded * (tile + 1)])
    products = fft.irfft2(power.reshape(padded, tile + 1), s=(padded, padded))
    pairs = np.rint(fft.irfft2(pairs.reshape(padded, tile + 1), s=(padded, padded)))
    nan = {"Sal": math.nan, "Str": math.nan, "Std": math.nan}
    if not (pairs[0, 0] > 0 and products[0, 0] > 0):
        return nan, {}  # a constant map: "no height variation"
    with np.errstate(invalid="ignore", divide="ignore"):
        correlation = np.where(pairs > 0, products / pairs, np.nan)
    correlation /= correlation[0, 0]
    if acf == "iso":
        lags = [np.abs(np.fft.fftfreq(padded, 1.0 / padded))] * 2
        within = [1 - lag / tile for lag in lags]
        whole = [1 - lag / n for lag, n in zip(lags, shape)]
        with np.errstate(invalid="ignore", divide="ignore"):
            correlation *= pairs / pairs[0, 0] / np.outer(*within) * np.outer(*whole)
    values, reasons = _lengths(np.fft.fftshift(correlation), spacing, tile)
    values["Std"] = _direction(np.fft.fftshift(hann.reshape(tile, half), axes=0), spacing, tile)
    return values, reasons


def _lengths(correlation, spacing, tile):
    """Sal and Str from the autocorrelation (centred at ``[tile, tile]``), along
    :data:`DIRECTIONS` rays out to :data:`REACH` of a tile."""
    dx, dy = spacing
    angles = np.linspace(0, np.pi, DIRECTIONS, endpoint=False)
    cos, sin = np.cos(angles), np.sin(angles)
    span = REACH * tile
    reach = np.minimum(span * dx / np.maximum(np.abs(cos), 1e-12), span * dy / np.maximum(sin, 1e-12))
    step = min(dx, dy) / 4
    radii = np.arange(0.0, reach.max() + step / 2, step)
    rows = tile + np.outer(sin, radii) / dy
    columns = tile + np.outer(cos, radii) / dx
    along = map_coordinates(correlation, [rows.ravel(), columns.ravel()], order=1, cval=np.nan).reshape(rows.shape)
    along[radii[None, :] > reach[:, None]] = np.inf  # beyond the reach: never a fall
    fallen = np.nan_to_num(along, nan=np.inf) <= THRESHOLD
    found = fallen.any(axis=1)
    first = np.argmax(fallen, axis=1)
    decay = np.full(DIRECTIONS, np.nan)
    k = np.flatnonzero(found & (first > 0))
    before, at = along[k, first[k] - 1], along[k, first[k]]
    decay[k] = radii[first[k] - 1] + (before - THRESHOLD) / (before - at) * step
    reach_text = f"{int(span)} points, a quarter of the {tile}-point spectrum tiles"
    reasons = {}
    if not np.isfinite(decay).any():
        reason = f"the autocorrelation stays above {THRESHOLD:g} within the lags tiles measure ({reach_text})"
        return {"Sal": math.nan, "Str": math.nan}, {"Sal": reason, "Str": reason}
    fastest = float(np.nanmin(decay))
    if not np.isfinite(decay).all():
        reasons["Str"] = (
            f"the autocorrelation stays above {THRESHOLD:g} within the lags tiles measure ({reach_text}) in some "
            f"direction; Str < {fastest / float(np.max(reach[~np.isfinite(decay)])):.3g}"
        )
        return {"Sal": fastest, "Str": math.nan}, reasons
    slowest = float(np.max(decay))
    return {"Sal": fastest, "Str": fastest / slowest if slowest > 0 else math.nan}, reasons


def _direction(power, spacing, tile):
    """Std from the mean tile power (fy = 0 at row ``tile // 2``): the lay
    perpendicular to the wavevector of the largest angular power."""
    dx, dy = spacing
    dfx, dfy = 1 / (tile * dx), 1 / (tile * dy)
    step = min(dfx, dfy)
    radii = np.arange(2 * step, min(0.5 / dx, 0.5 / dy), step)
    angles = np.linspace(0, 180, DIRECTIONS, endpoint=False)
    fx, fy = np.outer(np.cos(np.radians(angles)), radii), np.outer(np.sin(np.radians(angles)), radii)
    side = np.where(fx < 0, -1.0, 1.0)  # |F(-f)| = |F(f)|: onto the half plane fx ≥ 0
    coordinates = [(tile // 2 + side * fy / dfy).ravel(), (side * fx / dfx).ravel()]
    spectrum = map_coordinates(power, coordinates, order=1).reshape(fx.shape).sum(axis=1) * step
    if not spectrum.max() > 0:
        return math.nan
    return float((angles[np.argmax(spectrum)] + 90.0) % 180.0)
