"""Fractal surfaces by spectral synthesis in one transform (docs/math.rst §2.2-2.3).

The whole length (or area, :mod:`rough.fractal.synth_map`) is made in one inverse FFT
(profiles in double precision): the coefficients are those of
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
import secrets

import numpy as np

from ..errors import InputError
from ..progress import progress
from ..surface import HEIGHT_LIMIT, Surface, Units, check_size
from ..units import format_length
from . import model

log = logging.getLogger("rough")
POINTS_PER_BLOCK = 2**20  # a profile's coefficients per block
PAPER_FRAGMENT = 128


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
    rough.fractal.synthesize_map : The same for maps.
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
    resolution = amplitude_choice(amplitude, rq, resolution, spacing)
    check_size((points,), "the profile")
    seed = seed_or_random(seed)
    generator = np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed)))
    blocks, pieces = slices(points // 2 + 1, POINTS_PER_BLOCK), slices(points, POINTS_PER_BLOCK)
    log.info(f"a profile of {points} points in {len(pieces)} blocks, one inverse FFT")
    with progress(total=2 * len(blocks) + 1 + len(pieces), description="synth", unit="step") as bar:
        spectrum = _white_profile_spectrum(points, generator, blocks, bar.update)
        scale = model.prefactor(amplitude or 1.0, dimension, resolution)
        for part in blocks:
            spectrum[part] *= _profile_filter(points, spacing, beta, scale, rolloff=rolloff, part=part)
            bar.update()
        heights = np.fft.irfft(spectrum, points)  # one call: Ctrl-C waits for it (seconds at 2^26 points)
        bar.update()
        heights = scaled(heights, rq, pieces, bar.update)
    parameters = given_parameters(
        points=points,
        spacing=spacing,
        dimension=dimension,
        amplitude=amplitude,
        rq=rq,
        resolution=resolution,
        seed=seed,
        rolloff=rolloff,
    )
    return synthetic_surface(heights, (spacing,), parameters)


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
    resolution = amplitude_choice(amplitude, rq, resolution, spacing)
    check_size((points,), "the profile")
    check_size((fragment,), "a fragment")
    seed = seed_or_random(seed)
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
    heights = scaled(np.concatenate(pieces)[:points], rq)
    log.warning(
        "fragments of %d points (%s) drop every wavelength longer than a fragment: the profile's Rq "
        "falls well short of eq. (2) (docs: Mathematics §2.5); use the default whole-length synthesis",
        fragment,
        format_length(fragment * spacing, 4),
    )
    parameters = given_parameters(
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
    return synthetic_surface(heights, (spacing,), parameters)


def amplitude_choice(amplitude, rq, resolution, spacing):
    """The resolution η of the amplitude coefficient (default ``spacing``), after checking
    that one of C and Rq is given and every length given is positive."""
    if (amplitude is None) == (rq is None):
        raise InputError("give the amplitude coefficient (--amplitude) or the RMS height (--rq), one of the two")
    for name, value in (("amplitude", amplitude), ("rq", rq), ("resolution", resolution)):
        if value is not None and not value > 0:
            raise InputError(f"{name} must be a positive length, not {value}")
    return spacing if resolution is None else resolution


def seed_or_random(seed):
    """``seed`` as an int, or a fresh random one (recorded in the history) for None."""
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


def scaled(heights, rq, blocks=None, step=None):
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


def slices(count, size):
    """Slices of ``size`` along an axis of ``count`` (at least one)."""
    return [slice(start, min(start + size, count)) for start in range(0, max(count, 1), size)]


def given_parameters(**values):
    """The synthesis parameters given (not None or False), for the history."""
    return {key: value for key, value in values.items() if value is not None and value is not False}


def synthetic_surface(heights, spacing, parameters):
    """The synthesised surface; an InputError when its heights reach beyond
    ±HEIGHT_LIMIT, where rough refuses to read them back."""
    reach = max(-float(heights.min()), float(heights.max()))
    if not reach <= HEIGHT_LIMIT:
        raise InputError(
            f"the synthesised heights reach {format_length(reach)}, beyond ±{format_length(HEIGHT_LIMIT)}, "
            "which no surface reaches and rough does not read back: give a smaller --rq or --amplitude"
        )
    surface = Surface(heights, spacing, units=Units("m", "m"), metadata={"title": _title(parameters, len(spacing))})
    return surface.derive("synth", parameters)


def _title(parameters, ndim):
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
