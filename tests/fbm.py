"""Exact fractional Brownian motion by the Davies-Harte method, written independently
of rough's synthesis: circulant embedding of the fractional Gaussian noise
autocovariance, then a cumulative sum. The samples are point samples of fBm, so
their spectrum is the aliased one."""

import numpy as np


def fbm(n, hurst, rng, spacing=1.0, scale=1.0):
    """n samples of fBm with Var[B(t)] = scale² t^(2H) at t = 0, Δ, 2Δ, ..."""
    lags = np.arange(n)
    gamma = 0.5 * (np.abs(lags + 1) ** (2 * hurst) - 2 * np.abs(lags) ** (2 * hurst) + np.abs(lags - 1) ** (2 * hurst))
    row = np.concatenate([gamma, gamma[-2:0:-1]])
    eigenvalues = np.fft.fft(row).real
    if eigenvalues.min() < -1e-10 * eigenvalues.max():
        raise ValueError("circulant embedding is not positive definite")
    size = row.size
    noise = rng.standard_normal(size) + 1j * rng.standard_normal(size)
    increments = np.fft.fft(np.sqrt(np.clip(eigenvalues, 0, None) / size) * noise).real[: n - 1]
    return np.concatenate([[0.0], np.cumsum(increments)]) * scale * spacing**hurst
