"""Regridding unevenly spaced profiles (rough.io.regrid): exact on straight lines,
accurate up to the ends, and band-limited regridding does not alias."""

import numpy as np
import pytest

from rough.io.regrid import regrid

UNEVEN = np.sort(np.concatenate([[0.0, 200.0], np.random.default_rng(1).uniform(0, 200, 4000)]))


@pytest.mark.parametrize("method", ["linear", "bandlimited"])
def test_a_straight_line_is_kept_exactly(method):
    heights = regrid(UNEVEN, 3e-6 * UNEVEN - 1e-6, 1.0, method)
    np.testing.assert_allclose(heights, 3e-6 * np.arange(201) - 1e-6, rtol=0, atol=1e-18)


@pytest.mark.parametrize("method", ["linear", "bandlimited"])
def test_a_trended_wave_well_below_the_new_nyquist_is_kept_up_to_the_ends(method):
    """The ends are where a periodic FFT filter rings if the profile's ends do not meet."""
    heights = regrid(UNEVEN, np.sin(2 * np.pi * UNEVEN / 20) + 0.01 * UNEVEN, 1.0, method)
    grid = np.arange(heights.size)
    error = heights - (np.sin(2 * np.pi * grid / 20) + 0.01 * grid)
    assert np.abs(error).max() < 0.01


def test_band_limited_regridding_removes_what_the_new_grid_cannot_hold():
    """A wave of 1.25 steps of the new grid: linear sampling aliases it, the band-limited
    method removes it."""
    wave = np.sin(2 * np.pi * UNEVEN / 1.25)
    assert regrid(UNEVEN, wave, 1.0, "linear").std() > 0.3
    assert regrid(UNEVEN, wave, 1.0, "bandlimited").std() < 0.05
