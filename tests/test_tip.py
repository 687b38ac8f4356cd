"""Probe size: the path a round tip traces, and the ISO 16610-41 closing envelope."""

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from rough import Surface
from rough.errors import InputError
from rough.metrology.tip import PRESETS, closing_envelope, tip_profile, traced

from conftest import assert_one_line_error, rough

DX = 1e-5
heights = arrays(np.float64, st.integers(5, 120), elements=st.floats(-1e-3, 1e-3))


def profile(z, dx=DX):
    return Surface(np.asarray(z, dtype=float), (dx,))


def positions(n, dx=DX):
    return (np.arange(n) - n // 2) * dx


# -- the traced profile ----------------------------------------------------------------------


@pytest.mark.parametrize("shape", [(301,), (40, 50)])
def test_a_flat_surface_is_unchanged(shape):
    flat = Surface(np.full(shape, 2e-4), (DX,) * len(shape))
    assert np.array_equal(traced(flat, 1e-4).heights, flat.heights)
    assert np.array_equal(closing_envelope(flat, 1e-4).heights, flat.heights)


def test_a_sine_gentler_than_the_tip_keeps_its_shape():
    """Crest radius 1/(A k²) = 0.51 mm > r = 0.1 mm: the tip touches the crests and the
    troughs exactly and in between its apex follows the rolling-ball offset curve of
    the sine, x - r h'/√(1+h'²), h + r/√(1+h'²) - r; the closing gives the sine back."""
    wavelength, amplitude, radius = 2e-3, 0.2e-3, 1e-4
    k = 2 * math.pi / wavelength
    assert 1 / (amplitude * k * k) > 5 * radius
    x = np.arange(4000) * 1e-6
    z = amplitude * np.sin(k * x)
    path = traced(profile(z, 1e-6), radius).heights
    inner = slice(200, -200)
    assert path[inner].max() == pytest.approx(amplitude, abs=1e-12)
    assert path[inner].min() == pytest.approx(-amplitude, abs=1e-12)
    slope = amplitude * k * np.cos(k * x)
    offset_x = x - radius * slope / np.sqrt(1 + slope**2)
    offset_z = z + radius / np.sqrt(1 + slope**2) - radius
    expected = np.interp(x, offset_x, offset_z)
    grid_error = (1 / radius + amplitude * k * k) * (1e-6) ** 2 / 4
    assert np.abs(path - expected)[inner].max() < grid_error + 1e-12
    np.testing.assert_allclose(
        closing_envelope(profile(z, 1e-6), radius).heights[inner], z[inner], atol=grid_error + 1e-12
    )


@pytest.mark.parametrize("radius", [2e-4, 2.37e-4])
def test_a_spike_becomes_an_arc_of_the_tip_radius_with_its_apex_on_the_spike(radius):
    z = np.zeros(201)
    z[100] = 1e-3
    path = traced(profile(z), radius).heights
    x = positions(201)
    arc = 1e-3 - (radius - np.sqrt(np.maximum(radius**2 - x**2, 0)))
    expected = np.where(np.abs(x) <= radius, np.maximum(arc, 0.0), 0.0)
    np.testing.assert_allclose(path, expected, atol=1e-18)
    assert path[100] == 1e-3


def test_a_v_groove_narrower_than_the_tip_is_bridged_at_the_rims():
    """A groove 0.2 mm wide and 0.5 mm deep under a 0.3 mm tip: the tip rests on both
    rims, its apex r - √(r² - (w/2)²) below them, far above the groove's bottom."""
    radius, half_width, depth = 3e-4, 1e-4, 5e-4
    x = positions(401)
    z = np.where(np.abs(x) < half_width, -depth * (1 - np.abs(x) / half_width), 0.0)
    path = traced(profile(z), radius).heights
    bridge = -(radius - math.sqrt(radius**2 - half_width**2))
    assert path[200] == pytest.approx(bridge, abs=1e-15)
    assert path.min() == pytest.approx(bridge, abs=1e-15)
    assert bridge > -depth


@settings(max_examples=60, deadline=None)
@given(z=heights, radius=st.floats(1e-5, 3e-4), extra=st.floats(1e-6, 3e-4))
def test_the_path_never_dips_below_the_surface_and_a_bigger_tip_never_rides_lower(z, radius, extra):
    small = traced(profile(z), radius).heights
    large = traced(profile(z), radius + extra).heights
    assert (small >= z).all()
    assert (large >= small).all()


def test_a_ball_on_a_map_traces_a_spherical_cap_in_physical_units():
    """Unequal spacing: the footprint is a circle in metres, not in samples."""
    z = np.zeros((61, 81))
    z[30, 40] = 1e-3
    radius = 2e-4
    surface = Surface(z, (1e-5, 2e-5))
    path = traced(surface, radius).heights
    yy, xx = np.mgrid[-30:31, -40:41]
    distance = np.hypot(xx * 1e-5, yy * 2e-5)
    cap = np.where(
        distance <= radius, np.maximum(1e-3 - radius + np.sqrt(np.maximum(radius**2 - distance**2, 0)), 0), 0
    )
    np.testing.assert_allclose(path, cap, atol=1e-18)


# -- the closing envelope ----------------------------------------------------------------------


@pytest.mark.parametrize("radius", [2e-4, 2.37e-4])
def test_the_envelope_keeps_a_spike_and_fillets_the_valleys_beside_it(radius):
    """The nearest grid position where the tip rests on the floor is R + 1 samples from
    the spike (R = ⌊r/Δx⌋): between, the envelope is the arc of radius r about that
    apex, the lower quarter of the tip."""
    z = np.zeros(201)
    z[100] = 1e-3
    envelope = closing_envelope(profile(z), radius).heights
    assert envelope[100] == 1e-3
    reach = (math.floor(radius / DX) + 1) * DX
    d = np.abs(positions(201))
    fillet = np.where((d > 0) & (d <= reach), radius - np.sqrt(np.maximum(radius**2 - (reach - d) ** 2, 0)), 0.0)
    fillet[100] = 1e-3
    np.testing.assert_allclose(envelope, fillet, atol=1e-15)


@settings(max_examples=60, deadline=None)
@given(z=heights, radius=st.floats(1e-5, 3e-4))
def test_the_envelope_never_lies_below_the_surface_and_is_idempotent(z, radius):
    once = closing_envelope(profile(z), radius).heights
    twice = closing_envelope(profile(once), radius).heights
    assert (once >= z).all()
    np.testing.assert_allclose(twice, once, rtol=0, atol=1e-15)


@settings(max_examples=10, deadline=None)
@given(
    z=arrays(np.float64, st.tuples(st.integers(5, 30), st.integers(5, 30)), elements=st.floats(-1e-4, 1e-4)),
    radius=st.floats(2e-5, 1e-4),
)
def test_map_envelope_bounds_and_idempotence(z, radius):
    surface = Surface(z, (1e-5, 1.5e-5))
    path = traced(surface, radius).heights
    once = closing_envelope(surface, radius).heights
    assert (path >= z).all() and (once >= z).all() and (once <= path).all()
    np.testing.assert_allclose(
        closing_envelope(Surface(once, surface.spacing), radius).heights, once, rtol=0, atol=1e-15
    )


def test_invalid_points_never_touch_the_tip_and_stay_invalid():
    z = np.zeros(101)
    z[50] = 1e-3
    z[[20, 51]] = np.nan
    path = traced(profile(z), 1e-4).heights
    assert np.isnan(path[[20, 51]]).all() and np.isfinite(np.delete(path, [20, 51])).all()
    clean = z.copy()
    clean[[20, 51]] = -1.0  # far below: no contact either
    np.testing.assert_array_equal(np.delete(path, [20, 51]), np.delete(traced(profile(clean), 1e-4).heights, [20, 51]))
    assert np.isnan(closing_envelope(profile(z), 1e-4).heights[[20, 51]]).all()


def test_tips_below_the_sampling_change_nothing():
    assert tip_profile(4e-6, (1e-5,)).size == 1
    z = np.random.default_rng(2).normal(size=50) * 1e-5
    assert np.array_equal(traced(profile(z), 4e-6).heights, z)


@pytest.mark.parametrize("shape", [(7,), (5, 6)])
def test_a_tip_wider_than_the_scan_gives_what_the_unclipped_tip_gives(shape):
    """Offsets past every sample never touch: clipping the kernel to the data changes nothing."""
    from scipy import ndimage

    z = np.random.default_rng(3).normal(size=shape) * 1e-5
    radius, spacing = 3e-4, (DX,) * len(shape)
    assert tip_profile(radius, spacing, shape).shape == tuple(2 * n - 1 for n in shape)
    full = tip_profile(radius, spacing)
    full = full - full[tuple(n // 2 for n in full.shape)]
    expected = ndimage.grey_dilation(z, structure=full, mode="constant", cval=-np.inf)
    np.testing.assert_allclose(traced(Surface(z, spacing), radius).heights, expected, rtol=0, atol=1e-18)


def test_a_tip_that_would_take_hours_is_refused_with_a_hint():
    nano = Surface(np.zeros((3000, 3000)), (1e-9, 1e-9))
    with pytest.raises(InputError, match="coarser spacing"):
        traced(nano, 5e-6)


# -- the commands --------------------------------------------------------------------------------


def test_detrend_tip_and_envelope_commands():
    source = rough(
        "synth",
        "--length",
        "5mm",
        "--spacing",
        "10um",
        "--dimension",
        "1.3",
        "--rq",
        "0.1mm",
        "--seed",
        "4",
        check=True,
    ).stdout
    raw = json.loads(rough("features", "--json", input=source, check=True).stdout)
    path = rough("detrend", "--tip", "fingernail", input=source, check=True).stdout
    felt = json.loads(rough("features", "--json", input=path, check=True).stdout)
    assert felt["Rdq"] < raw["Rdq"]  # the tip cannot follow the steepest, finest slopes
    history = json.loads(rough("info", "--json", input=path, check=True).stdout)["history"]
    assert history[-1]["command"] == "tip" and history[-1]["parameters"] == {"radius": 0.0005}
    envelope = rough("detrend", "--envelope", "0.2mm", "--order", "1", input=source, check=True).stdout
    assert "envelope radius=0.0002" in rough("info", input=envelope, check=True).stdout.decode()
    assert_one_line_error(rough("detrend", "--tip", "1mm", "--envelope", "1mm", input=source), "not both")
    assert_one_line_error(rough("detrend", "--tip", "knuckle", input=source), "not a length")
    assert PRESETS == {"needle": 0.05e-3, "fingernail": 0.5e-3, "fingertip": 8e-3}


def test_render_with_a_fingertip_feels_a_smoother_surface():
    source = rough(
        "synth", "--length", "20mm", "--dimension", "1.275", "--rq", "0.2781mm", "--seed", "1", check=True
    ).stdout
    bare = json.loads(rough("render", "--json", input=source, check=True).stdout)["runs"][0]
    finger = json.loads(rough("render", "--json", "--tip", "fingertip", input=source, check=True).stdout)["runs"][0]
    assert finger["F_x_rms"] < bare["F_x_rms"]
