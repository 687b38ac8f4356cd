"""Fractal surfaces by spectral synthesis in one transform (docs/math.rst §2.2-2.3).

The whole length (or area) is made in one inverse FFT (maps in single precision,
profiles in double; a map's is done in blocks of columns, then rows, bit for bit
scipy's irfft2, so that Ctrl-C stops it within a block): the coefficients are those of
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
fell short of their eq. (2) Rq (docs/math.rst §2.5).
"""

import logging
import math
import os
import secrets
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ..errors import InputError
from ..progress import progress
from ..surface import HEIGHT_LIMIT, Surface, Units, check_size
from . import model

log = logging.getLogger("rough")
ROWS_PER_BLOCK = 256
POINTS_PER_BLOCK = 2**20  # a profile's coefficients per block
PAPER_FRAGMENT = 128
PAPER_RESOLUTION = 0.0309e-3


def synthesize_profile(points, spacing, dimension, amplitude=None, rq=None, resolution=None, seed=None, rolloff=None):
    """A fractal profile by spectral synthesis of the whole length in one transform.

    The coefficients are those of the FFT of white Gaussian noise (no DC term, a
    real Nyquist term) shaped by the square root of ``G(f) = C η^(2D-3) f^-(5-2D)``,
    so the realised spectrum has exactly the requested expectation.

    Parameters
    ----------
    points : int
        The number of samples.
    spacing : float
        The sample spacing, metres.
    dimension : float
        The fractal dimension D, in (1, 2).
    amplitude : float, optional
        The amplitude coefficient C at ``resolution``, metres. Give this or ``rq``.
    rq : float, optional
        The RMS height, metres: the realisation (its mean removed) is scaled to this
        Rq exactly. Give this or ``amplitude``.
    resolution : float, optional
        The resolution η at which ``amplitude`` is stated, metres; default the
        spacing.
    seed : int, optional
        The random seed; the same seed gives bit-identical heights. Default: a fresh
        random seed, recorded in the history.
    rolloff : float, optional
        A wavelength, metres, beyond which the spectrum is flat: the profile is
        self-affine only below that scale.

    Returns
    -------
    Surface
        A gap-free profile (heights in metres) of period ``points * spacing``,
        band-limited at the Nyquist frequency, with a title and a ``synth`` history
        entry recording every parameter and the seed.

    Raises
    ------
    rough.InputError
        For D outside (1, 2), both or neither of ``amplitude`` and ``rq``, an
        ``amplitude``, ``rq`` or ``resolution`` that is not positive, more points
        than rough's limit (2²⁸), or heights beyond ±100 km (HEIGHT_LIMIT).
        ``points`` and ``spacing`` are not checked: give at least two points and a
        positive spacing.

    See Also
    --------
    synthesize_map : The same for maps.
    synthesize_fragments : The paper's method, for comparison.

    Notes
    -----
    For a profile, ``E[Rq²] = Σ G(f_k)/L + G(f_N)/(2L)`` exactly over the harmonics
    ``f_k = k/L`` of the length L (docs/math.rst §2.5): the paper's eq. (2), an
    integral, is not what a finite realisation's variance is.

    Examples
    --------
    >>> import numpy as np
    >>> from rough.fractal.synth import synthesize_profile
    >>> profile = synthesize_profile(4096, 10e-6, 1.5, rq=1e-6, seed=7)  # 41 mm at 10 µm
    >>> profile
    <Surface profile 4096 points, spacing (1e-05) m, 1 history entries>
    >>> f"{np.std(profile.heights) * 1e6:.6f} µm"  # exactly the Rq asked for
    '1.000000 µm'
    >>> profile.metadata["title"]
    'synthetic fractal, D = 1.5, Rq 1 µm, seed 7'
    >>> again = synthesize_profile(4096, 10e-6, 1.5, rq=1e-6, seed=7)
    >>> bool(np.array_equal(profile.heights, again.heights))  # the same seed, the same heights
    True

    Given C, a fit finds it back (within about one standard error):

    >>> from rough.fractal.fit import fit_fractal
    >>> fit = fit_fractal(synthesize_profile(4096, 10e-6, 1.5, amplitude=100e-9, seed=7))
    >>> print(f"C = {fit.amplitude_coefficient * 1e9:.0f} ± {fit.amplitude_coefficient_stderr * 1e9:.0f} nm")
    C = 105 ± 5 nm
    """
    beta = model.profile_exponent(dimension)
    resolution = _amplitude_choice(amplitude, rq, resolution, spacing)
    check_size((points,), "the profile")
    seed = _seed(seed)
    generator = np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed)))
    blocks, pieces = _blocks(points // 2 + 1, POINTS_PER_BLOCK), _blocks(points, POINTS_PER_BLOCK)
    log.info(f"a profile of {points} points in {len(pieces)} blocks, one inverse FFT")
    with progress(total=2 * len(blocks) + 1 + len(pieces), description="synth", unit="step") as bar:
        spectrum = _white_profile_spectrum(points, generator, blocks, bar.update)
        scale = model.prefactor(amplitude or 1.0, dimension, resolution)
        for part in blocks:
            spectrum[part] *= _profile_filter(points, spacing, beta, scale, rolloff=rolloff, part=part)
            bar.update()
        heights = np.fft.irfft(spectrum, points)  # one call: Ctrl-C waits for it (seconds at 2^26 points)
        bar.update()
        heights = _scaled(heights, rq, pieces, bar.update)
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
    rough.fractal.rose.rose : Measure D and C against direction.

    Examples
    --------
    >>> import numpy as np
    >>> from rough.fractal.fit import fit_fractal
    >>> from rough.fractal.synth import synthesize_map
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
    resolution = _amplitude_choice(amplitude, rq, resolution, min(spacing))
    check_size((ny, nx), "the map")
    seed = _seed(seed)
    blocks = _blocks(ny, ROWS_PER_BLOCK)
    log.info(f"a {nx} × {ny} map in {len(blocks)} blocks of {ROWS_PER_BLOCK} rows, one inverse FFT")
    columns = _blocks(nx // 2 + 1, max(1, -(-ROWS_PER_BLOCK * (nx // 2 + 1) // ny)))
    with progress(total=4 * len(blocks) + len(columns), description="synth", unit="step") as bar:
        spectrum = _white_map_spectrum(nx, ny, seed, bar.update)
        pairs = spectrum.view(np.float32).reshape(ny, nx // 2 + 1, 2)
        for rows in blocks:
            gain = _map_filter(nx, ny, dx, dy, dimension, amplitude or 1.0, resolution, anisotropy, rolloff, rows)
            pairs[rows] *= gain[..., np.newaxis]
            bar.update()
        heights = _inverse_transform(spectrum, nx, columns, blocks, bar.update)
        spectrum = pairs = None
        heights = _scaled(heights, rq, blocks, bar.update)
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
    """A fractal profile by the paper's method, kept for comparison.

    Independent ``fragment``-point syntheses (each periodic, with no wavelength
    longer than the fragment), each shifted to start where the previous one ended.
    A warning says that this drops every wavelength longer than a fragment, so the
    profile's Rq falls well short of the paper's eq. (2) (docs/math.rst §2.5).

    Parameters
    ----------
    points : int
        The number of samples.
    spacing : float
        The sample spacing, metres (the paper's encoder resolution is 30.9 µm).
    dimension : float
        The fractal dimension D, in (1, 2).
    amplitude : float, optional
        The amplitude coefficient C at ``resolution``, metres. Give this or ``rq``.
    rq : float, optional
        The RMS height, metres, to which the whole profile is scaled exactly.
    resolution : float, optional
        The η at which ``amplitude`` is stated, metres; default the spacing.
    seed : int, optional
        The random seed; default a fresh one, recorded in the history.
    fragment : int, default 128
        Points per fragment, as in the paper.
    as_printed : bool, default False
        Also apply the printed (k+1) index shift of the paper's formula.

    Returns
    -------
    Surface
        A gap-free profile, heights in metres, with a ``synth`` history entry
        recording ``fragments``.

    Raises
    ------
    rough.InputError
        As :func:`synthesize_profile`.

    See Also
    --------
    synthesize_profile : Whole-length synthesis, the default.

    Examples
    --------
    With the same C, the fragments hold far less height variation than the
    whole-length synthesis:

    >>> import numpy as np
    >>> from rough.fractal.synth import synthesize_fragments, synthesize_profile
    >>> paper = synthesize_fragments(2048, 30.9e-6, 1.3, amplitude=260e-9, seed=1)
    >>> whole = synthesize_profile(2048, 30.9e-6, 1.3, amplitude=260e-9, seed=1)
    >>> f"Rq {np.std(paper.heights) * 1e6:.0f} µm against {np.std(whole.heights) * 1e6:.0f} µm"
    'Rq 148 µm against 611 µm'
    >>> paper.history[-1]["parameters"]["fragments"]
    128
    """
    beta = model.profile_exponent(dimension)
    resolution = _amplitude_choice(amplitude, rq, resolution, spacing)
    check_size((points,), "the profile")
    check_size((fragment,), "a fragment")
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
        "falls well short of eq. (2) (docs: Mathematics §2.5); use the default whole-length synthesis",
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


def _white_profile_spectrum(n, generator, blocks=None, step=None):
    """The rfft of n unit white-noise samples, drawn directly: E|Z_k|² = n. Drawn in
    ``blocks`` of coefficients (the same numbers as in one draw), calling ``step()``
    after each."""
    spectrum = np.empty(n // 2 + 1, dtype=np.complex128)
    flat = spectrum.view(np.float64)
    for part in blocks or [slice(None)]:
        generator.standard_normal(out=flat[2 * (part.start or 0) : None if part.stop is None else 2 * part.stop])
        spectrum[part] *= math.sqrt(n / 2)
        if step is not None:
            step()
    spectrum[0] = 0.0
    if n % 2 == 0:
        spectrum[-1] = spectrum[-1].real * math.sqrt(2)
    return spectrum


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
    from scipy import fft

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


def _profile_filter(n, spacing, beta, scale, shift=0, rolloff=None, part=slice(None)):
    """sqrt(G(f_k) / (2Δx)) with G = scale · f^-β (flat below 1/rolloff); zero at
    k = 0 unless shifted. ``part``: a slice of the coefficients (element for element
    the same values)."""
    index = np.arange(n // 2 + 1, dtype=np.float64)[part] + shift
    frequencies = index / (n * spacing)
    if rolloff is not None:
        frequencies = np.where(index > 0, np.maximum(frequencies, 1 / rolloff), 0.0)
    with np.errstate(divide="ignore"):
        gain = np.sqrt(scale * frequencies**-beta / (2 * spacing))
    gain[~np.isfinite(gain)] = 0.0
    return gain


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
    from scipy.special import gammaln

    alpha = 8.0 - 2.0 * dimensions.astype(np.float64)
    log_factor = gammaln(alpha / 2) - gammaln((alpha - 1) / 2) - math.log(2 * math.sqrt(math.pi))
    return (log_amplitude + (2.0 * dimensions - 5.0) * math.log(resolution) + log_factor).astype(np.float32)


def _scaled(heights, rq, blocks=None, step=None):
    """``heights`` with their mean removed and scaled to RMS ``rq`` (None: as they are),
    in place, in ``blocks`` of the first axis, calling ``step()`` after each. No
    temporary array: the mean square is one dot product of the heights with themselves."""
    blocks = blocks or [slice(None)]
    if rq is not None:
        mean = heights.mean()
        for part in blocks:
            heights[part] -= mean
        flat = heights.reshape(-1)
        factor = rq / math.sqrt(float(flat @ flat) / flat.size)
    for part in blocks:
        if rq is not None:
            heights[part] *= factor
        if step is not None:
            step()
    return heights


def _blocks(count, size):
    """Slices of ``size`` along an axis of ``count`` (at least one)."""
    return [slice(start, min(start + size, count)) for start in range(0, max(count, 1), size)]


def _done(future):
    """True once ``future`` is done (raising its error), False after waiting 0.1 s for
    it: a wait with a timeout, so that Ctrl-C gets through."""
    from concurrent.futures import TimeoutError as Pending

    try:
        future.result(timeout=0.1)
    except Pending:
        return False
    return True


def _parameters(**values):
    return {key: value for key, value in values.items() if value is not None and value is not False}


def _surface(heights, spacing, parameters):
    """The synthesised surface; an InputError when its heights reach beyond
    ±HEIGHT_LIMIT, where rough refuses to read them back."""
    reach = max(-float(heights.min()), float(heights.max()))
    if not reach <= HEIGHT_LIMIT:
        from ..units import format_length

        raise InputError(
            f"the synthesised heights reach {format_length(reach)}, beyond ±{format_length(HEIGHT_LIMIT)}, "
            "which no surface reaches and rough does not read back: give a smaller --rq or --amplitude"
        )
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
