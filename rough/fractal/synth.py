"""Fractal surfaces by spectral synthesis in one transform (MATH §2.2-2.3).

The whole length (or area) is made in one inverse FFT (maps in single precision,
profiles in double): the coefficients are those of
the FFT of white Gaussian noise (independent Gaussian real and imaginary parts; the
k = 0 term zero; the Nyquist terms real), shaped by the square root of the target
spectrum, so that for a profile ``E[Rq²] = Σ G(f_k)/L + G(f_N)/(2L)`` exactly and for
a map ``E[Sq²] = Σ P2 Δfx Δfy``. The result has period L (and the spectrum stops at
the Nyquist frequency: it is band-limited). With ``rq`` the realisation is scaled so
that its Rq (Sq), mean removed, is the target.

``--seed`` makes the output bit-identical from run to run: the random numbers come
from numpy's PCG64 in fixed blocks, whatever the number of threads that draw them.

The paper's method (``fragments``) is kept for comparison: independent 128-point
syntheses at the encoder resolution, each shifted to start where the last ended. A
fragment holds no wavelength longer than itself, which is why the paper's profiles
fell short of their eq. (2) Rq (MATH §2.5).
"""

import logging
import math
import os
import secrets
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ..errors import InputError
from ..surface import Surface, Units, check_size
from . import model

log = logging.getLogger("rough")
ROWS_PER_BLOCK = 256
PAPER_FRAGMENT = 128
PAPER_RESOLUTION = 0.0309e-3


def synthesize_profile(points, spacing, dimension, amplitude=None, rq=None, resolution=None, seed=None, rolloff=None):
    """A fractal profile of ``points`` samples at ``spacing`` (metres) with fractal
    dimension D (1-2) and either the amplitude coefficient ``amplitude`` (metres, at
    ``resolution``, default the spacing) or the RMS height ``rq`` (metres). With a
    ``rolloff`` wavelength (metres) the spectrum is flat at longer wavelengths: the
    surface is self-affine only below that scale."""
    beta = model.profile_exponent(dimension)
    resolution = _amplitude_choice(amplitude, rq, resolution, spacing)
    check_size((points,), "the profile")
    seed = _seed(seed)
    generator = np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed)))
    spectrum = _white_profile_spectrum(points, generator)
    spectrum *= _profile_filter(
        points, spacing, beta, model.prefactor(amplitude or 1.0, dimension, resolution), rolloff=rolloff
    )
    heights = _scaled(np.fft.irfft(spectrum, points), rq)
    parameters = _parameters(
        points=points,
        spacing=spacing,
        dimension=dimension,
        amplitude=amplitude,
        rq=rq,
        resolution=resolution,
        seed=seed,
        rolloff=rolloff,
    )
    return _surface(heights, (spacing,), parameters)


def synthesize_map(
    points, spacing, dimension, amplitude=None, rq=None, resolution=None, seed=None, anisotropy=None, rolloff=None
):
    """A fractal map of ``points = (nx, ny)`` at ``spacing = (dx, dy)`` with surface
    dimension Ds (2-3) and the profile-equivalent amplitude coefficient ``amplitude``
    (or the RMS height ``rq``). ``anisotropy = (Ds1, C1, Ds2, C2, angle)`` gives Ds and
    C along the wavevector direction ``angle`` (radians from +x, counter-clockwise)
    and along the direction at right angles; in between, Ds and log C follow
    cos²/sin² of the angle, so the spectrum is P2 = C2(θ) |f|^-(8-2Ds(θ)). A
    ``rolloff`` wavelength makes the spectrum flat at longer wavelengths."""
    nx, ny = points
    dx, dy = spacing
    if anisotropy is not None:
        dimension, amplitude = anisotropy[0], anisotropy[1]
        model.check_dimension(anisotropy[2], profile=False)
        if rq is not None:
            raise InputError("give the anisotropy's C values or --rq, not both")
    model.check_dimension(dimension, profile=False)
    resolution = _amplitude_choice(amplitude, rq, resolution, min(spacing))
    check_size((ny, nx), "the map")
    seed = _seed(seed)
    spectrum = _white_map_spectrum(nx, ny, seed)
    pairs = spectrum.view(np.float32).reshape(ny, nx // 2 + 1, 2)
    pairs *= _map_filter(nx, ny, dx, dy, dimension, amplitude or 1.0, resolution, anisotropy, rolloff)[..., np.newaxis]
    from scipy import fft

    heights = _scaled(fft.irfft2(spectrum, (ny, nx), workers=-1, overwrite_x=True).astype(np.float64), rq)
    if anisotropy is None:
        shape = {"dimension": dimension, "amplitude": amplitude}
    else:
        shape = {"anisotropy": [*anisotropy[:4], math.degrees(anisotropy[4])]}
    parameters = _parameters(
        points=[nx, ny], spacing=[dx, dy], **shape, rq=rq, resolution=resolution, seed=seed, rolloff=rolloff
    )
    return _surface(heights, (dx, dy), parameters)


def synthesize_fragments(
    points,
    spacing,
    dimension,
    amplitude=None,
    rq=None,
    resolution=None,
    seed=None,
    fragment=PAPER_FRAGMENT,
    as_printed=False,
):
    """The paper's method: ``fragment``-point syntheses (each periodic, with no
    wavelength longer than the fragment), each shifted to start where the previous
    one ended. ``as_printed`` also applies the printed (k+1) index shift."""
    beta = model.profile_exponent(dimension)
    resolution = _amplitude_choice(amplitude, rq, resolution, spacing)
    check_size((points,), "the profile")
    seed = _seed(seed)
    generator = np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed)))
    scale = model.prefactor(amplitude or 1.0, dimension, resolution)
    shift = 1 if as_printed else 0
    pieces, end = [], 0.0
    for _ in range(math.ceil(points / fragment)):
        spectrum = _white_profile_spectrum(fragment, generator)
        spectrum *= _profile_filter(fragment, spacing, beta, scale, shift)
        piece = np.fft.irfft(spectrum, fragment)
        piece += end - piece[0]
        end = piece[-1]
        pieces.append(piece)
    heights = _scaled(np.concatenate(pieces)[:points], rq)
    log.warning(
        "fragments of %d points (%.4g mm) drop every wavelength longer than a fragment: the profile's Rq "
        "falls well short of eq. (2) (MATH §2.5); use the default whole-length synthesis",
        fragment,
        fragment * spacing * 1e3,
    )
    parameters = _parameters(
        points=points,
        spacing=spacing,
        dimension=dimension,
        amplitude=amplitude,
        rq=rq,
        resolution=resolution,
        seed=seed,
        fragments=fragment,
        as_printed=as_printed,
    )
    return _surface(heights, (spacing,), parameters)


def _amplitude_choice(amplitude, rq, resolution, spacing):
    if (amplitude is None) == (rq is None):
        raise InputError("give the amplitude coefficient (--amplitude) or the RMS height (--rq), one of the two")
    for name, value in (("amplitude", amplitude), ("rq", rq), ("resolution", resolution)):
        if value is not None and not value > 0:
            raise InputError(f"{name} must be a positive length, not {value}")
    return spacing if resolution is None else resolution


def _seed(seed):
    return secrets.randbits(63) if seed is None else int(seed)


def _white_profile_spectrum(n, generator):
    """The rfft of n unit white-noise samples, drawn directly: E|Z_k|² = n."""
    spectrum = generator.standard_normal(2 * (n // 2 + 1)).view(np.complex128) * math.sqrt(n / 2)
    spectrum[0] = 0.0
    if n % 2 == 0:
        spectrum[-1] = spectrum[-1].real * math.sqrt(2)
    return spectrum


def _white_map_spectrum(nx, ny, seed):
    """The rfft2 of an ny × nx unit white-noise field, drawn directly: E|Z|² = nx·ny
    everywhere; the kx = 0 and kx = nx/2 columns are the FFTs of real noise, so they
    are Hermitian. Rows are drawn in fixed blocks with their own seeded generators.
    Single precision: its rounding (6e-8) is far below any spectrum's dynamic range,
    and it halves the memory and time of the map's synthesis."""
    columns = nx // 2 + 1
    spectrum = np.empty((ny, columns), dtype=np.complex64)
    flat = spectrum.view(np.float32)
    blocks = [slice(start, min(start + ROWS_PER_BLOCK, ny)) for start in range(0, ny, ROWS_PER_BLOCK)]
    sequences = np.random.SeedSequence(seed).spawn(len(blocks) + 1)

    def fill(index):
        generator = np.random.Generator(np.random.PCG64(sequences[index]))
        generator.standard_normal(out=flat[blocks[index]], dtype=np.float32)
        flat[blocks[index]] *= np.float32(math.sqrt(nx * ny / 2))

    with ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        list(pool.map(fill, range(len(blocks))))
    special = np.random.Generator(np.random.PCG64(sequences[-1]))
    for column in (0, nx // 2) if nx % 2 == 0 else (0,):
        spectrum[:, column] = np.fft.fft(special.standard_normal(ny) * math.sqrt(nx))
    spectrum[0, 0] = 0.0
    return spectrum


def _profile_filter(n, spacing, beta, scale, shift=0, rolloff=None):
    """sqrt(G(f_k) / (2Δx)) with G = scale · f^-β (flat below 1/rolloff); zero at
    k = 0 unless shifted."""
    index = np.arange(n // 2 + 1, dtype=np.float64) + shift
    frequencies = index / (n * spacing)
    if rolloff is not None:
        frequencies = np.where(index > 0, np.maximum(frequencies, 1 / rolloff), 0.0)
    with np.errstate(divide="ignore"):
        gain = np.sqrt(scale * frequencies**-beta / (2 * spacing))
    gain[~np.isfinite(gain)] = 0.0
    return gain


def _map_filter(nx, ny, dx, dy, dimension, amplitude, resolution, anisotropy, rolloff=None):
    """sqrt(P2(f) / (Δx Δy)) on the rfft2 grid, in float32, zero at f = 0 (and flat
    below 1/rolloff)."""
    fx = (np.arange(nx // 2 + 1) / (nx * dx)).astype(np.float32)
    fy = np.fft.fftfreq(ny, dy).astype(np.float32)
    squared = fy[:, np.newaxis] ** 2 + fx[np.newaxis, :] ** 2
    if rolloff is not None:
        np.maximum(squared, np.float32(rolloff**-2), out=squared)
    squared[0, 0] = 1.0
    if anisotropy is None:
        alpha = model.map_exponent(dimension)
        scale = model.map_prefactor(amplitude, dimension, resolution) / (dx * dy)
        gain = np.float32(math.sqrt(scale)) * squared ** np.float32(-alpha / 4)
    else:
        ds1, c1, ds2, c2, angle = anisotropy
        weight = np.cos(np.arctan2(fy[:, np.newaxis], fx[np.newaxis, :]) - np.float32(angle)) ** 2
        dimensions = weight * np.float32(ds1) + (1 - weight) * np.float32(ds2)
        log_amplitude = weight * np.float32(math.log(c1)) + (1 - weight) * np.float32(math.log(c2))
        log_scale = _log_map_prefactor(log_amplitude, dimensions, resolution) - np.float32(math.log(dx * dy))
        gain = np.exp(np.float32(0.5) * log_scale - (np.float32(4.0) - dimensions) * np.float32(0.5) * np.log(squared))
    gain[0, 0] = 0.0
    return gain


def _log_map_prefactor(log_amplitude, dimensions, resolution):
    """log C2 for arrays of log C and Ds (the vectorised form of model.map_prefactor)."""
    from scipy.special import gammaln

    alpha = 8.0 - 2.0 * dimensions.astype(np.float64)
    log_factor = gammaln(alpha / 2) - gammaln((alpha - 1) / 2) - math.log(2 * math.sqrt(math.pi))
    return (log_amplitude + (2.0 * dimensions - 5.0) * math.log(resolution) + log_factor).astype(np.float32)


def _scaled(heights, rq):
    if rq is None:
        return heights
    centred = heights - heights.mean()
    return centred * (rq / math.sqrt(np.mean(centred * centred)))


def _parameters(**values):
    return {key: value for key, value in values.items() if value is not None and value is not False}


def _surface(heights, spacing, parameters):
    surface = Surface(heights, spacing, units=Units("m", "m"), metadata={"title": _title(parameters, len(spacing))})
    return surface.derive("synth", parameters)


def _title(parameters, ndim):
    from ..units import format_length

    seed = parameters["seed"]
    if "anisotropy" in parameters:
        ds1, c1, ds2, c2, angle = parameters["anisotropy"]
        return (
            f"synthetic anisotropic fractal, Ds = {ds1:g} and C = {format_length(c1)} along {angle:g}°, "
            f"Ds = {ds2:g} and C = {format_length(c2)} along {(angle + 90) % 180:g}°, seed {seed}"
        )
    amount = (
        f"{'Rq' if ndim == 1 else 'Sq'} {format_length(parameters['rq'])}"
        if "rq" in parameters
        else f"C {format_length(parameters['amplitude'])}"
    )
    return f"synthetic fractal, {'D' if ndim == 1 else 'Ds'} = {parameters['dimension']:g}, {amount}, seed {seed}"
