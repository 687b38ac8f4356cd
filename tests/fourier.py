"""Band-limited fractal profiles and maps by plain Fourier synthesis, written
independently of rough's synthesis (the way SurfaceTopography's ``fourier_synthesis``
and most papers make them): complex Gaussian amplitudes with variance ∝ |q|^-exponent
on the DFT grid, no power above the Nyquist frequency, an inverse FFT. The result
is periodic and band-limited: its sampled spectrum has no fold."""

import numpy as np


def fourier_profile(n, hurst, rng, spacing=1.0):
    """n samples of a band-limited profile with G(f) ∝ f^-(1+2H) for 0 < f ≤ 1/(2Δ)."""
    q = np.fft.rfftfreq(n, spacing)
    amplitude = np.zeros(q.size)
    amplitude[1:] = q[1:] ** (-(1 + 2 * hurst) / 2)
    modes = amplitude * (rng.standard_normal(q.size) + 1j * rng.standard_normal(q.size))
    if n % 2 == 0:
        modes[-1] = modes[-1].real * np.sqrt(2)
    return np.fft.irfft(modes, n)


def fourier_map(n, hurst, rng, spacing=1.0):
    """An n × n band-limited isotropic map with P2 ∝ |q|^-(2+2H), inside the Nyquist
    square."""
    qx = np.fft.rfftfreq(n, spacing)
    qy = np.fft.fftfreq(n, spacing)
    radius = np.hypot(qy[:, None], qx[None, :])
    radius[0, 0] = np.inf
    amplitude = radius ** (-(2 + 2 * hurst) / 2)
    modes = amplitude * (rng.standard_normal(radius.shape) + 1j * rng.standard_normal(radius.shape))
    return np.fft.irfft2(modes, (n, n))
