"""Fractal maps by spectral synthesis of the whole area in one inverse FFT
(docs/math.rst §2.3), in single precision and in blocks of columns, then rows, bit for
bit scipy's irfft2, so that Ctrl-C stops it within a block; the white noise is drawn
in fixed blocks of rows with their own seeded generators, so that ``--seed`` gives
bit-identical output whatever the number of threads (the profile's synthesis, and
what both share: :mod:`rough.fractal.synth`).
"""

import logging
import math
import os
from concurrent.futures import ThreadPoolExecutor
from concurrent.futures import TimeoutError as Pending

import numpy as np
from scipy import fft
from scipy.special import gammaln

from ..errors import InputError
from ..progress import progress
from ..surface import check_size
from . import model
from .synth import amplitude_choice, given_parameters, scaled, seed_or_random, slices, synthetic_surface

log = logging.getLogger("rough")
ROWS_PER_BLOCK = 256


def synthesize_map(
    points, spacing, dimension, amplitude=None, rq=None, resolution=None, seed=None, anisotropy=None, rolloff=None
):
    """A fractal map by spectral synthesis of the whole area in one transform.

    The spectrum is ``P2 = C2 |f|^-(8-2Ds)``, with C2 set by the profile-equivalent
    amplitude coefficient C (a map and its profiles share one C). The map is made
    in single precision, far below any spectrum's dynamic range, and returned as
    float64.

    Parameters
    ----------
    points : tuple of int
        ``(nx, ny)``, the number of samples along x and y.
    spacing : tuple of float
        ``(dx, dy)``, metres.
    dimension : float
        The surface dimension Ds, in (2, 3); ignored with ``anisotropy``.
    amplitude : float, optional
        The profile-equivalent amplitude coefficient C at ``resolution``, metres.
        Give this or ``rq`` (or ``anisotropy``).
    rq : float, optional
        The RMS height Sq, metres: the realisation (its mean removed) is scaled to
        this exactly.
    resolution : float, optional
        The η at which C is stated, metres; default the smaller spacing.
    seed : int, optional
        The random seed; the same seed gives bit-identical heights, whatever the
        number of threads. Default: a fresh random seed, recorded in the history.
    anisotropy : tuple of float, optional
        ``(Ds1, C1, Ds2, C2, angle)``: Ds and C (metres) along the wavevector
        direction ``angle`` (radians from +x, counter-clockwise: the direction in
        which heights vary) and along the direction at right angles. In between, Ds
        and log C follow cos²/sin² of the angle, so the spectrum is
        ``P2 = C2(θ) |f|^-(8-2Ds(θ))``. Not with ``rq``.
    rolloff : float, optional
        A wavelength, metres, beyond which the spectrum is flat.

    Returns
    -------
    Surface
        A gap-free map, heights ``z[y, x]`` in metres of shape ``(ny, nx)``,
        periodic and band-limited, with a title and a ``synth`` history entry.

    Raises
    ------
    rough.InputError
        For Ds outside (2, 3), both or neither of ``amplitude`` and ``rq``,
        ``anisotropy`` with ``rq``, an ``amplitude``, ``rq`` or ``resolution`` that
        is not positive, more points than rough's limit (16384 × 16384), or heights
        beyond ±100 km (HEIGHT_LIMIT).
        ``points`` and ``spacing`` are not checked.

    See Also
    --------
    synthesize_profile : The same for profiles.
    rough.fractal.rose : Measure D and C against direction.

    Examples
    --------
    >>> import numpy as np
    >>> from rough.fractal.fit import fit_fractal
    >>> from rough.fractal.synth_map import synthesize_map
    >>> scan = synthesize_map((256, 128), (10e-6, 10e-6), 2.4, amplitude=100e-9, seed=3)
    >>> scan.heights.shape, scan.heights.dtype  # z[y, x]
    ((128, 256), dtype('float64'))
    >>> fit = fit_fractal(scan)
    >>> print(f"Ds = {fit.fractal_dimension:.2f} ± {fit.fractal_dimension_stderr:.2f}")
    Ds = 2.44 ± 0.02
    >>> sq = synthesize_map((64, 64), (10e-6, 10e-6), 2.4, rq=1e-6, seed=3)
    >>> f"{np.std(sq.heights) * 1e6:.6f} µm"  # exactly the Sq asked for
    '1.000000 µm'
    """
    nx, ny = points
    dx, dy = spacing
    if anisotropy is not None:
        dimension, amplitude = anisotropy[0], anisotropy[1]
        model.check_dimension(anisotropy[2], profile=False)
        if rq is not None:
            raise InputError("give the anisotropy's C values or --rq, not both")
    model.check_dimension(dimension, profile=False)
    resolution = amplitude_choice(amplitude, rq, resolution, min(spacing))
    check_size((ny, nx), "the map")
    seed = seed_or_random(seed)
    blocks = slices(ny, ROWS_PER_BLOCK)
    log.info(f"a {nx} × {ny} map in {len(blocks)} blocks of {ROWS_PER_BLOCK} rows, one inverse FFT")
    columns = slices(nx // 2 + 1, max(1, -(-ROWS_PER_BLOCK * (nx // 2 + 1) // ny)))
    with progress(total=4 * len(blocks) + len(columns), description="synth", unit="step") as bar:
        spectrum = _white_map_spectrum(nx, ny, seed, bar.update)
        pairs = spectrum.view(np.float32).reshape(ny, nx // 2 + 1, 2)
        for rows in blocks:
            gain = _map_filter(nx, ny, dx, dy, dimension, amplitude or 1.0, resolution, anisotropy, rolloff, rows)
            pairs[rows] *= gain[..., np.newaxis]
            bar.update()
        heights = _inverse_transform(spectrum, nx, columns, blocks, bar.update)
        spectrum = pairs = None
        heights = scaled(heights, rq, blocks, bar.update)
    if anisotropy is None:
        shape = {"dimension": dimension, "amplitude": amplitude}
    else:
        shape = {"anisotropy": [*anisotropy[:4], math.degrees(anisotropy[4])]}
    parameters = given_parameters(
        points=[nx, ny], spacing=[dx, dy], **shape, rq=rq, resolution=resolution, seed=seed, rolloff=rolloff
    )
    return synthetic_surface(heights, (dx, dy), parameters)


def _white_map_spectrum(nx, ny, seed, step=None):
    """The rfft2 of an ny × nx unit white-noise field, drawn directly: E|Z|² = nx·ny
    everywhere; the kx = 0 and kx = nx/2 columns are the FFTs of real noise, so they
    are Hermitian. Rows are drawn in fixed blocks with their own seeded generators.
    Single precision: its rounding (6e-8) is far below any spectrum's dynamic range,
    and it halves the memory and time of the map's synthesis. Calls ``step()`` after
    each block; Ctrl-C cancels the blocks not started."""
    columns = nx // 2 + 1
    spectrum = np.empty((ny, columns), dtype=np.complex64)
    flat = spectrum.view(np.float32)
    blocks = [slice(start, min(start + ROWS_PER_BLOCK, ny)) for start in range(0, ny, ROWS_PER_BLOCK)]
    sequences = np.random.SeedSequence(seed).spawn(len(blocks) + 1)

    def fill(index):
        generator = np.random.Generator(np.random.PCG64(sequences[index]))
        generator.standard_normal(out=flat[blocks[index]], dtype=np.float32)
        flat[blocks[index]] *= np.float32(math.sqrt(nx * ny / 2))

    pool = ThreadPoolExecutor(max_workers=os.cpu_count() or 1)
    try:
        for future in [pool.submit(fill, index) for index in range(len(blocks))]:
            while not _done(future):
                pass
            if step is not None:
                step()
    finally:
        pool.shutdown(wait=False, cancel_futures=True)
    special = np.random.Generator(np.random.PCG64(sequences[-1]))
    for column in (0, nx // 2) if nx % 2 == 0 else (0,):
        spectrum[:, column] = np.fft.fft(special.standard_normal(ny) * math.sqrt(nx))
    spectrum[0, 0] = 0.0
    return spectrum


def _inverse_transform(spectrum, nx, columns, rows, step):
    """scipy's ``irfft2(spectrum, (ny, nx))`` in float64, in blocks (Ctrl-C waits for
    one block, not the whole transform): the inverse transforms along y over blocks of
    ``columns`` (in place), then along x over blocks of ``rows``, scaled by 1/(nx ny)
    last, as pocketfft's irfft2 does: the same float32 results bit for bit (checked
    against irfft2 on even and odd sizes and block splits: tests/test_progress.py)."""
    ny = spectrum.shape[0]
    for part in columns:
        spectrum[:, part] = fft.ifft(spectrum[:, part], axis=0, norm="forward", workers=-1)
        step()
    scale = np.float32(np.longdouble(1) / np.longdouble(nx * ny))  # pocketfft's T(1 / (long double) n)
    heights = np.empty((ny, nx))
    for part in rows:
        piece = fft.irfft(spectrum[part], nx, axis=1, norm="forward", workers=-1)
        piece *= scale
        heights[part] = piece
        step()
    return heights


def _map_filter(nx, ny, dx, dy, dimension, amplitude, resolution, anisotropy, rolloff=None, rows=slice(None)):
    """sqrt(P2(f) / (Δx Δy)) on the rfft2 grid, in float32, zero at f = 0 (and flat
    below 1/rolloff). ``rows``: a slice of the grid's rows (element for element the
    same values)."""
    fx = (np.arange(nx // 2 + 1) / (nx * dx)).astype(np.float32)
    fy = np.fft.fftfreq(ny, dy).astype(np.float32)[rows]
    origin = (rows.start or 0) == 0  # the block holds f = 0
    squared = fy[:, np.newaxis] ** 2 + fx[np.newaxis, :] ** 2
    if rolloff is not None:
        np.maximum(squared, np.float32(rolloff**-2), out=squared)
    if origin:
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
    if origin:
        gain[0, 0] = 0.0
    return gain


def _log_map_prefactor(log_amplitude, dimensions, resolution):
    """log C2 for arrays of log C and Ds (the vectorised form of model.map_prefactor)."""
    alpha = 8.0 - 2.0 * dimensions.astype(np.float64)
    log_factor = gammaln(alpha / 2) - gammaln((alpha - 1) / 2) - math.log(2 * math.sqrt(math.pi))
    return (log_amplitude + (2.0 * dimensions - 5.0) * math.log(resolution) + log_factor).astype(np.float32)


def _done(future):
    """True once ``future`` is done (raising its error), False after waiting 0.1 s for
    it: a wait with a timeout, so that Ctrl-C gets through."""
    try:
        future.result(timeout=0.1)
    except Pending:
        return False
    return True
