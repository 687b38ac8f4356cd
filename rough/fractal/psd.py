"""Power spectra: the normalised periodogram, log binning, and conversions between
spectral conventions (docs/conventions.rst ("Fractal conventions")).

rough's canonical profile PSD is one-sided in cycles per metre, ``Rq² = ∫ G(f) df``:
``G_k = 2 Δx |Z_k|² / (N U)`` for 0 < k < N/2 (DC and Nyquist not doubled), with Z the
DFT of the windowed heights and U = mean(w²) the window's power, so that
``Σ G_k Δf = mean((w z)²) / U`` (Parseval). Maps use the two-sided
``P2 = Δx Δy |Z|² / (Nx Ny U)``, ``Sq² = ∬ P2``.

Other conventions of the same spectrum (all functions of frequency f in 1/m):
- SurfaceTopography's ``C1D(q) = G(q/2π)/2`` at q = 2πf (Rq² = (1/π) ∫₀^∞ C1D dq);
- Gwyddion's ``W1(k) = G(k/2π)/(2π)`` at k = 2πf (Rq² = ∫₀^∞ W1 dk);
- Ganti & Bhushan's two-sided angular ``P(ω) = G(ω/2π)/(4π)`` (Rq² = ∫_-∞^∞ P dω).
"""

import math

import numpy as np
from scipy import fft

from ..errors import InputError
from ..metrology import detrend
from ..metrology.form import form_factors

WINDOWS = ("hann", "none")


def periodogram(heights, spacing, window="hann"):
    """``(f, G, parseval)`` of a gap-free profile: the one-sided periodogram at
    f_k = k/(NΔx), k = 0 … N/2, and Σ G Δf divided by mean((w z)²)/U (1 to rounding)."""
    if window not in WINDOWS:
        raise InputError(f"window must be one of {', '.join(WINDOWS)}, not {window!r}")
    n = heights.size
    weights = np.hanning(n) if window == "hann" else np.ones(n)
    power = np.mean(weights**2)
    transform = np.fft.rfft(heights * weights)
    density = 2.0 * spacing * np.abs(transform) ** 2 / (n * power)
    density[0] /= 2.0
    if n % 2 == 0:
        density[-1] /= 2.0
    frequencies = np.arange(density.size) / (n * spacing)
    parseval = density.sum() / (n * spacing) / (np.mean((heights * weights) ** 2) / power)
    return frequencies, density, float(parseval)


def log_bins(frequencies, density, per_decade=10, minimum=1):
    """Average ``density`` in logarithmic frequency bins (``per_decade`` per decade,
    a bin merged with the next until it holds ``minimum`` ordinates), leaving out
    f = 0. Frequencies must ascend. Returns ``(geometric mean frequency, mean
    density, count)`` per bin."""
    keep = frequencies > 0
    f, g = frequencies[keep], density[keep]
    decade_index = np.floor(np.log10(f) * per_decade + 1e-9).astype(int)
    groups = np.split(np.arange(f.size), np.flatnonzero(np.diff(decade_index)) + 1)
    bins, members = [], []
    for group in groups:
        members.extend(group)
        if len(members) >= minimum:
            bins.append(members)
            members = []
    if members:
        if bins:
            bins[-1].extend(members)
        else:
            bins.append(members)
    centres = np.array([np.exp(np.mean(np.log(f[b]))) for b in bins])
    return centres, np.array([g[b].mean() for b in bins]), np.array([len(b) for b in bins])


def periodic_hann(n):
    """The DFT-even Hann window 0.5 - 0.5 cos(2πj/n): in frequency it is exactly the
    three-tap filter (-1/4, 1/2, -1/4), so its smoothing of a spectrum is known."""
    return 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(n) / n)


def windowed_map(surface, order=1, rows_per_block=256):
    """``(field, power)``: the map less its polynomial form of ``order``, times the 2-D
    periodic Hann window, in float32 (computed a block of rows at a time, so no
    full-size temporaries); ``power`` is the window's mean square."""
    along_y, coefficients, along_x = form_factors(surface, order)
    ny, nx = surface.heights.shape
    window_y, window_x = periodic_hann(ny), periodic_hann(nx)
    along_x_terms = coefficients @ along_x.T
    field = np.empty((ny, nx), dtype=np.float32)
    for start in range(0, ny, rows_per_block):
        rows = slice(start, min(start + rows_per_block, ny))
        field[rows] = (surface.heights[rows] - along_y[rows] @ along_x_terms) * window_y[rows, np.newaxis] * window_x
    return field, float(np.mean(window_y**2) * np.mean(window_x**2))


def ring_spectrum(field, power, spacing, low, high, step, sector=None, rows_per_block=256):
    """The two-sided 2-D periodogram of a windowed map (see :func:`windowed_map`),
    averaged over rings one ``step`` wide between ``low`` and ``high`` (1/m), leaving
    out the axis lines. With ``sector=(angle, width)`` (radians) only wavevectors
    within width/2 of the angle (mod π) count. Per ring: count, mean density (m⁴),
    mean and variance of log |f|, and the window's smoothing terms ``window_a`` =
    <(sx² fx² + sy² fy²)/|f|⁴>, ``window_b`` = <(sx² + sy²)/|f|²> (sx, sy the frequency
    steps)."""
    sectors = None if sector is None else (sector[0], math.pi, 1, sector[1])
    return sector_spectra(field, power, spacing, low, high, step, sectors, rows_per_block)[0]


def sector_spectra(field, power, spacing, low, high, step, sectors=None, rows_per_block=256, transform=None):
    """Ring spectra (as :func:`ring_spectrum`) for several direction sectors from one
    FFT: ``sectors = (first angle, angular step, count, width)`` in radians gives
    sectors centred at first + k·step (mod π), each taking the wavevectors within
    width/2 of its centre (sectors overlap when the width exceeds the step). Returns
    one ring dictionary per sector (one in all without sectors). Works a block of rows
    at a time; pass ``transform`` (the field's rfft2) to reuse one."""
    ny, nx = field.shape
    dx, dy = spacing
    transform = fft.rfft2(field, workers=-1) if transform is None else transform
    scale = dx * dy / (nx * ny * power)
    fx = np.arange(1, (nx + 1) // 2) / (nx * dx)
    fy = np.fft.fftfreq(ny, dy)
    sx2, sy2 = (1 / (nx * dx)) ** 2, (1 / (ny * dy)) ** 2
    rings = int(high / step) + 2
    groups = 1 if sectors is None else sectors[2]
    stride = rings + 1
    sums = np.zeros((6, groups * stride + 1))
    # Without sectors, rows +fy and -fy have the same geometry: take them in pairs.
    paired = sectors is None
    last = ny // 2 + 1 if paired else ny
    for start in range(1, last, rows_per_block):
        rows = np.arange(start, min(start + rows_per_block, last))
        partners = (ny - rows) % ny
        weight = np.where(paired & (partners != rows), 2.0, 1.0)[:, np.newaxis]
        squared = fy[rows, np.newaxis] ** 2 + fx**2
        radius = np.sqrt(squared)
        keep = (radius >= low) & (radius <= high)
        ring = np.floor(radius / step).astype(np.int64)
        power_here = _power(transform[rows, 1 : (nx + 1) // 2])
        if paired:
            power_here += np.where(partners != rows, 1.0, 0.0)[:, np.newaxis] * _power(
                transform[partners, 1 : (nx + 1) // 2]
            )
        log_radius = np.log(radius)
        columns = [
            np.broadcast_to(weight, radius.shape).ravel(),
            (power_here * scale).ravel(),
            (weight * log_radius).ravel(),
            (weight * log_radius**2).ravel(),
            (weight * (sx2 * fx**2 + sy2 * fy[rows, np.newaxis] ** 2) / squared**2).ravel(),
            np.broadcast_to(weight * (sx2 + sy2) / squared, radius.shape).ravel(),
        ]
        for group, member in _memberships(np.arctan2(fy[rows, np.newaxis], fx), sectors):
            index = np.where(keep & member, group * stride + ring, groups * stride).ravel()
            for row, values in enumerate(columns):
                sums[row] += np.bincount(index, values, minlength=groups * stride + 1)
    results = []
    for group in range(groups):
        part = sums[:, group * stride : group * stride + rings]
        used = part[0] > 0
        counts = part[0][used]
        means = part[1:, used] / counts
        results.append(
            {
                "count": counts.astype(np.int64),
                "density": means[0],
                "log_radius": means[1],
                "log_spread": np.maximum(means[2] - means[1] ** 2, 0.0),
                "window_a": means[3],
                "window_b": means[4],
                "window_factor": window_variance_factor(ny, nx),
            }
        )
    return results


def _memberships(angle, sectors):
    """``(sector index array, membership mask)`` pairs, one per pass, covering each
    wavevector's sectors: a wavevector at angle φ lies in sector k when φ is within
    width/2 of first + k·step, modulo π."""
    if sectors is None:
        yield 0, True
        return
    first, step, count, width = sectors
    if abs(width - step) < 1e-12 and abs(count * step - np.pi) < 1e-9:
        yield np.rint((angle - first) / step).astype(np.int64) % count, True  # sectors tile the half plane
        return
    offset = (angle - first + width / 2) % np.pi
    top = np.floor(offset / step).astype(np.int64)
    for back in range(int(width // step) + 1):
        index = top - back
        centre = first + index * step
        member = (index >= 0) & (np.abs((angle - centre + np.pi / 2) % np.pi - np.pi / 2) <= width / 2 + 1e-12)
        yield np.where(member, index % count, 0), member


def _power(block):
    return block.real.astype(np.float64) ** 2 + block.imag.astype(np.float64) ** 2


def window_variance_factor(ny, nx):
    """How much the Hann window's correlation between neighbouring ordinates inflates
    the variance of a ring average: (N Σw⁴ / (Σw²)²) for each axis."""
    factor = 1.0
    for n in (ny, nx):
        w = periodic_hann(n)
        factor *= n * np.sum(w**4) / np.sum(w**2) ** 2
    return factor


def binned_spectrum(surface, order=1, per_decade=10):
    """The spectrum of a gap-free surface after removing its form (polynomial of
    ``order``), log-binned for output: profiles the Hann periodogram G (m³), maps the
    ring-averaged periodic-Hann P2 (m⁴). Returns ``{"frequency", "density", "count"}``
    (lists; 1/m) and, for profiles, ``"parseval"`` (Σ G Δf over the windowed power)."""
    if surface.is_profile:
        levelled = detrend(surface, order=order)
        frequencies, density, parseval = periodogram(levelled.heights, surface.spacing[0])
        centres, means, counts = log_bins(frequencies, density, per_decade)
        return {
            "frequency": centres.tolist(),
            "density": means.tolist(),
            "count": counts.tolist(),
            "parseval": parseval,
        }
    ny, nx = surface.heights.shape
    step = max(1 / (nx * surface.spacing[0]), 1 / (ny * surface.spacing[1]))
    field, power = windowed_map(surface, order)
    rings = ring_spectrum(field, power, surface.spacing, step, min(0.5 / d for d in surface.spacing), step)
    return binned_rings(rings, per_decade)


def binned_rings(rings, per_decade=10):
    """A ring spectrum (see :func:`ring_spectrum`) in ``per_decade`` logarithmic bins:
    ``{"frequency", "density", "count"}`` (lists; 1/m, m⁴, ordinates)."""
    frequencies = np.exp(rings["log_radius"])
    groups = np.floor(np.log10(frequencies) * per_decade + 1e-9).astype(int)
    result = {"frequency": [], "density": [], "count": []}
    for group in np.unique(groups):
        members = groups == group
        weights = rings["count"][members]
        result["frequency"].append(float(np.exp(np.average(rings["log_radius"][members], weights=weights))))
        result["density"].append(float(np.average(rings["density"][members], weights=weights)))
        result["count"].append(int(weights.sum()))
    return result


def profile_spectrum(heights, spacing, per_decade=10):
    """The mean Hann periodogram G (m³, one-sided) of several gap-free profiles, in
    logarithmic bins, with the spread of the profiles about it.

    Parameters
    ----------
    heights : list of 1-D arrays
        Profiles with their form removed (e.g. :attr:`ProfileSet.heights
        <rough.fractal.profile_set.ProfileSet>`), m; NaN is not allowed.
    spacing : float
        The sampling step along the profiles, m.
    per_decade : int, default 10
        Bins per decade of frequency.

    Returns
    -------
    dict
        Lists per bin: ``frequency`` (geometric mean, 1/m), ``density`` (the mean of
        every profile's ordinates in the bin, m³), ``count`` (ordinates), ``profiles``
        (profiles with an ordinate there) and ``log_spread`` (the SD over profiles of
        log10 of each profile's own bin mean, decades; NaN with one profile).

    Examples
    --------
    >>> import numpy as np
    >>> walks = [np.cumsum(np.random.default_rng(k).standard_normal(256)) * 1e-9 for k in range(8)]
    >>> spectrum = profile_spectrum(walks, 1e-6)
    >>> spectrum["profiles"][-1], 0.0 < spectrum["log_spread"][-1] < 0.5  # eight profiles, within half a decade
    (8, True)
    """
    groups = {}
    for profile in heights:
        frequencies, density, _ = periodogram(profile, spacing)
        keep = frequencies > 0
        index = np.floor(np.log10(frequencies[keep]) * per_decade + 1e-9).astype(int)
        for key in np.unique(index):
            chosen = index == key
            groups.setdefault(int(key), []).append((frequencies[keep][chosen], density[keep][chosen]))
    result = {"frequency": [], "density": [], "count": [], "profiles": [], "log_spread": []}
    for key in sorted(groups):
        parts = groups[key]
        frequencies = np.concatenate([f for f, _ in parts])
        density = np.concatenate([g for _, g in parts])
        means = np.log10([g.mean() for _, g in parts])
        result["frequency"].append(float(np.exp(np.mean(np.log(frequencies)))))
        result["density"].append(float(density.mean()))
        result["count"].append(int(density.size))
        result["profiles"].append(len(parts))
        result["log_spread"].append(float(np.std(means, ddof=1)) if len(parts) > 1 else math.nan)
    return result


def to_surfacetopography(frequencies, density):
    """SurfaceTopography's 1-D PSD: ``(q, C1D)`` with q = 2πf and C1D = G/2."""
    return 2 * np.pi * np.asarray(frequencies), np.asarray(density) / 2


def to_gwyddion(frequencies, density):
    """Gwyddion's one-sided angular PSDF: ``(k, W1)`` with k = 2πf and W1 = G/(2π)."""
    return 2 * np.pi * np.asarray(frequencies), np.asarray(density) / (2 * np.pi)


def to_ganti_bhushan(frequencies, density):
    """Ganti & Bhushan's two-sided angular PSD: ``(ω, P)`` with ω = 2πf, P = G/(4π)."""
    return 2 * np.pi * np.asarray(frequencies), np.asarray(density) / (4 * np.pi)


def from_surfacetopography(q, c1d):
    return np.asarray(q) / (2 * np.pi), 2 * np.asarray(c1d)


def from_gwyddion(k, w1):
    return np.asarray(k) / (2 * np.pi), 2 * np.pi * np.asarray(w1)


def from_ganti_bhushan(omega, p):
    return np.asarray(omega) / (2 * np.pi), 4 * np.pi * np.asarray(p)
