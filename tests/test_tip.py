"""Probe size: the path a round tip traces, and the ISO 16610-41 closing envelope."""

import json
import math
from unittest import mock

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from rough import Surface
from rough.compiled import compiled
from rough.errors import InputError
from rough.metrology import tip
from rough.metrology.tip import PRESETS, closing_envelope, tip_profile, traced

from conftest import assert_one_line_error, rough

DX = 1e-5
heights = arrays(np.float64, st.integers(5, 120), elements=st.floats(-1e-3, 1e-3))


def profile(z, dx=DX):
    return Surface(np.asarray(z, dtype=float), (dx,))


def positions(n, dx=DX):
    return (np.arange(n) - n // 2) * dx


# -- the traced profile ----------------------------------------------------------------------


def test_offsets_on_the_rim_count_whatever_the_rounding():
    """0.3 mm / 0.1 mm is 2.9999999999999996 in floating point: the points 0.3 mm away
    still touch the tip's equator, r below its apex."""
    z = np.zeros(21)
    z[10] = 1e-3
    path = traced(profile(z, 1e-4), 0.3e-3).heights
    assert path[7] == path[13] == pytest.approx(1e-3 - 0.3e-3, abs=1e-18)
    assert path[6] == path[14] == 0
    assert tip_profile(0.3e-3, (1e-4, 1e-4)).shape == (7, 7)


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


def test_a_tip_that_would_take_hours_is_refused_with_a_hint(monkeypatch):
    """20000 × 20000 points at 1 nm under a 5 µm tip: 5001 rows of the tip, each swept
    (about 37 ns per point) over 4·10^8 points, on two cores. The estimate comes before
    any work, so the heights can be a broadcast zero."""
    monkeypatch.setattr(tip, "_cores", lambda: 2)
    nano = Surface(np.broadcast_to(0.0, (20000, 20000)), (1e-9, 1e-9))
    with pytest.raises(InputError, match=r"about 10 h; resample the surface to a coarser spacing"):
        traced(nano, 5e-6)


def test_a_tip_wider_than_the_scan_is_refused_past_a_minute(monkeypatch):
    """The fingertip over 2048 × 2048 points at 1 µm: clipped to the scan, 2048 rows of
    ±2047 samples, all swept: about 3 minutes on two cores."""
    monkeypatch.setattr(tip, "_cores", lambda: 2)
    scan = Surface(np.broadcast_to(0.0, (2048, 2048)), (1e-6, 1e-6))
    with pytest.raises(
        InputError, match="wider than the 2.048 mm × 2.048 mm scan, and one pass would take about 3 min"
    ):
        traced(scan, PRESETS["fingertip"])


def test_the_cost_grows_as_the_tips_area_for_small_tips_and_as_its_width_for_big_ones():
    """The estimate behind the warnings and refusals: rows of the tip up to ~220 samples
    wide are maximised over directly (their cost grows with their width), wider ones are
    swept (a fixed cost per point)."""

    def per_point(radius):
        reach = math.floor(radius / 1e-5)
        rows = np.arange(reach + 1) * 1e-5
        return tip._seconds_per_point(np.floor(np.sqrt(np.maximum(radius**2 - rows**2, 0)) / 1e-5))

    assert per_point(0.4e-3) / per_point(0.2e-3) == pytest.approx(4, rel=0.1)  # 41 and 21 rows, all direct
    assert per_point(40e-3) / per_point(20e-3) == pytest.approx(2, rel=0.05)  # nearly all rows swept
    assert tip._swept(np.array([0, 100, 400, 4000])).tolist() == [False, False, True, True]


# -- exact on the grid: the brute force, written plainly -----------------------------------------


def brute_force(z, radius, spacing):
    """T(p) = max over every grid offset o within the tip of z(p + o) - s(o), by brute force:
    an offset counts when |o|² <= r² (1 + 1e-12), as in ``tip_profile``, and s(o) is
    computed as the module does (√(r²) - √(r² - |o|²)), so that the maxima can be compared
    bit for bit. NaN never touches; beyond the ends there is nothing."""
    z = np.asarray(z, dtype=float)
    grid = np.where(np.isnan(z), -np.inf, z).reshape(-1, z.shape[-1])
    dx, dy = spacing[0], (spacing[1] if len(spacing) == 2 else 0.0)
    rows, columns = grid.shape
    path = np.full(grid.shape, -np.inf)
    for j in range(-(rows - 1), rows):
        for i in range(-(columns - 1), columns):
            squared = (j * dy) * (j * dy) + (i * dx) * (i * dx)
            if squared > radius * radius * (1 + 1e-12):
                continue
            lowering = math.sqrt(max(radius * radius - squared, 0.0)) - math.sqrt(radius * radius)
            target = path[max(0, -j) : rows - max(0, j), max(0, -i) : columns - max(0, i)]
            source = grid[max(0, j) : rows + min(0, j), max(0, i) : columns + min(0, i)]
            np.maximum(target, source + lowering, out=target)
    path = path.reshape(z.shape)
    return np.where(np.isnan(z) | ~np.isfinite(path), np.nan, np.fmax(path, z))


def brute_force_envelope(z, radius, spacing):
    """The closing: the brute-force erosion, min over the same offsets of T(p + o) + s(o)
    over the valid points of T = brute_force(z), never below z, NaN where z is."""
    path = brute_force(z, radius, spacing)
    return np.where(np.isnan(z), np.nan, np.fmax(-brute_force(-path, radius, spacing), z))


MODES = {
    "chosen": None,  # each row of the tip the quicker way, as in use
    "direct": lambda widths: np.zeros(len(widths), dtype=bool),  # every row maximised over directly
    "swept": lambda widths: np.ones(len(widths), dtype=bool),  # every row swept
}


def in_mode(mode):
    return mock.patch.object(tip, "_swept", MODES[mode] or tip._swept)


def random_heights(shape, seed, invalid=0.15, step=None, scale=2e-5):
    rng = np.random.default_rng(seed)
    z = rng.normal(size=shape) * scale
    if step:
        z = np.round(z / step) * step  # many equal heights: ties everywhere
    z[rng.random(shape) < invalid] = np.nan
    return z


CASES = {
    "map, unequal spacing": ((17, 23), (1e-5, 1.7e-5), 9.3e-5, {}),
    "map, heights on a coarse step": ((15, 31), (1e-5, 0.6e-5), 8e-5, {"step": 1e-5}),
    "map, offsets exactly on the rim": ((14, 14), (1e-5, 1e-5), 5e-5, {}),  # (3, 4) Δx: on the rim
    "map, tip below one spacing": ((9, 11), (1e-5, 2e-5), 0.6e-5, {}),
    "map, tip within one row": ((9, 11), (1e-5, 2e-5), 1.5e-5, {}),
    "map, tip wider than the scan": ((12, 9), (1e-5, 1.3e-5), 2e-4, {}),
    "map, one row": ((1, 40), (1e-5, 1e-5), 6e-5, {}),
    "map, one column": ((40, 1), (1e-5, 1e-5), 6e-5, {}),
    "map, mostly invalid": ((16, 16), (1e-5, 1e-5), 7e-5, {"invalid": 0.8}),
    "profile": ((300,), (1e-5,), 3.3e-4, {}),
    "profile, heights on a coarse step": ((300,), (1e-5,), 2.1e-4, {"step": 2e-5}),
    "profile, tip below one spacing": ((50,), (1e-5,), 0.9e-5, {}),
    "profile, r/Δx rounded below 3": ((40,), (1e-4,), 0.3e-3, {"scale": 1e-3}),  # the rim reaches higher points
    "profile, tip wider than the scan": ((15,), (1e-5,), 1e-3, {}),
}


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("case", CASES)
def test_traced_and_the_envelope_are_the_brute_force_exactly(case, mode):
    shape, spacing, radius, options = CASES[case]
    z = random_heights(shape, seed=sorted(CASES).index(case), **options)
    surface = Surface(z, spacing)
    with in_mode(mode):
        path = traced(surface, radius).heights
        envelope = closing_envelope(surface, radius).heights
    np.testing.assert_array_equal(path, brute_force(z, radius, spacing))
    np.testing.assert_array_equal(envelope, brute_force_envelope(z, radius, spacing))


@settings(max_examples=300, deadline=None)
@given(
    shape=st.one_of(st.tuples(st.integers(1, 90)), st.tuples(st.integers(1, 14), st.integers(1, 30))),
    aspect=st.floats(0.25, 4),
    samples=st.one_of(st.floats(0.3, 25), st.integers(1, 25).map(float)),  # whole numbers: offsets on the rim
    seed=st.integers(0, 2**32 - 1),
    invalid=st.sampled_from([0.0, 0.1, 0.6]),
    step=st.sampled_from([None, 1e-5]),
    mode=st.sampled_from(sorted(MODES)),
)
def test_traced_is_the_brute_force_for_any_surface_and_tip(shape, aspect, samples, seed, invalid, step, mode):
    """Exact but where two offsets' sums tie within a rounding error (the sweep may
    then settle on either)."""
    spacing = (1e-5,) if len(shape) == 1 else (1e-5, 1e-5 * aspect)
    radius = samples * 1e-5
    z = random_heights(shape, seed, invalid, step)
    with in_mode(mode):
        path = traced(Surface(z, spacing), radius).heights
    expected = brute_force(z, radius, spacing)
    np.testing.assert_array_equal(np.isnan(path), np.isnan(expected))
    scale = max(np.nanmax(np.abs(z)), 1e-300) if np.isfinite(z).any() else 1.0
    np.testing.assert_allclose(path, expected, rtol=0, atol=1e-12 * scale)


@pytest.mark.parametrize("radii, spacing", [(1.0, 1.0), (0.0, 1.0), (0.3, 1.0), (3.0, 1.0), (1.0, 0.5), (1.0, 2.0)])
def test_the_sweep_settles_each_crossing_on_the_sums_whatever_the_estimate(radii, spacing):
    """Where two semicircles cross is estimated in closed form, then settled by comparing
    the sums themselves: a wrong estimate (from wrong radii or spacing, given to the
    compiled loop directly) costs time, never exactness."""
    radius, grid = 2.2e-4, (1e-5, 1.5e-5)
    for step in (None, 1e-5):
        z = random_heights((9, 150), seed=5, step=step)
        quadrant = tip._quadrant(radius, grid, z.shape)
        rows = np.arange(len(quadrant)) * grid[1]
        widths = np.isfinite(quadrant).sum(axis=1) - 1
        image, path = np.where(np.isnan(z), -np.inf, z), np.empty_like(z)
        estimates = (radii * radius**2 - rows**2, spacing * grid[0])
        compiled(tip._rows)(image, quadrant, widths, np.ones(len(rows), dtype=bool), *estimates, 1, 0, len(z), path)
        path = np.where(np.isnan(z) | ~np.isfinite(path), np.nan, np.fmax(path, z))
        np.testing.assert_array_equal(path, brute_force(z, radius, grid))


def test_a_profile_is_scipys_grey_morphology_bit_for_bit():
    """scipy.ndimage's non-flat grey dilation and erosion by the disk (tip_profile's
    values less the apex) give a profile's path and envelope to the bit, signed zeros
    included."""
    from scipy import ndimage

    rng = np.random.default_rng(5)
    z = rng.normal(size=3000) * 1e-5
    z[z > 1.5e-5] = 0.0
    z[z < -1.5e-5] = -0.0
    z[rng.random(z.size) < 0.03] = np.nan
    disk = tip_profile(2e-4, (1e-6,), z.shape)
    lowering = disk - disk[disk.size // 2]
    path = ndimage.grey_dilation(np.where(np.isnan(z), -np.inf, z), structure=lowering, mode="constant", cval=-np.inf)
    path = np.where(np.isnan(z) | ~np.isfinite(path), np.nan, np.fmax(path, z))
    known = np.where(np.isnan(path), np.inf, path)
    eroded = ndimage.grey_erosion(known, structure=lowering, mode="constant", cval=np.inf)
    closed = np.where(np.isnan(z), np.nan, np.fmax(eroded, z))
    for mode in MODES:
        with in_mode(mode):
            assert traced(profile(z, 1e-6), 2e-4).heights.tobytes() == path.tobytes()
            assert closing_envelope(profile(z, 1e-6), 2e-4).heights.tobytes() == closed.tobytes()


@pytest.mark.parametrize("shape", [(9001,), (3, 5000)])
def test_tiles_and_chunks_give_the_brute_force(monkeypatch, shape):
    """Long rows are cut into tiles (with margins of the tip's width), the tiles into
    chunks; a point's result does not depend on the cut."""
    monkeypatch.setattr(tip, "CHUNK_SECONDS", 1e-7)  # a task a chunk
    z = random_heights(shape, seed=11)
    spacing = (1e-5,) * len(shape)
    for mode in MODES:
        with in_mode(mode):
            np.testing.assert_array_equal(traced(Surface(z, spacing), 9.5e-5).heights, brute_force(z, 9.5e-5, spacing))


@pytest.mark.parametrize(
    "spacing, shape", [((1e-5,), None), ((1e-5,), (7,)), ((1e-5, 1.3e-5), None), ((1.3e-5, 1e-5), (6, 40))]
)
def test_the_quadrant_is_tip_profiles_values_less_the_apex(spacing, shape):
    radius = 1.23e-4
    full = tip_profile(radius, spacing, shape)
    centre = tuple(n // 2 for n in full.shape)
    expected = (
        (full - full[centre])[centre[0] :, centre[-1] :]
        if len(spacing) == 2
        else (full - full[centre])[None, centre[0] :]
    )
    np.testing.assert_array_equal(tip._quadrant(radius, spacing, shape), expected)


def test_ctrl_c_stops_the_workers_after_their_current_chunk(monkeypatch):
    """The main thread waits with a timeout; Ctrl-C there (here: from the progress bar's
    first update) leaves the queued chunks undone, and the workers stop."""
    import threading
    import time

    monkeypatch.setattr(tip, "CHUNK_SECONDS", 1e-7)  # a row a chunk: 400 chunks
    kernel, calls = compiled(tip._rows), []

    def slow(*args):  # about 10 ms a chunk
        if args[-3] < args[-2]:
            calls.append(args[-3])
            time.sleep(0.01)
        return kernel(*args)

    class Interrupted:
        n = 0

        def __init__(self, **options):
            pass

        def __enter__(self):
            return self

        def __exit__(self, *exception):
            return False

        def update(self, n):
            raise KeyboardInterrupt

    monkeypatch.setattr(tip, "compiled", lambda function: slow)
    monkeypatch.setattr(tip, "progress", Interrupted)
    before = threading.active_count()
    with pytest.raises(KeyboardInterrupt):
        traced(Surface(random_heights((400, 300), seed=3), (1e-5, 1e-5)), 1e-4)
    for _ in range(500):  # the workers end after their current chunk
        if threading.active_count() <= before:
            break
        time.sleep(0.01)
    assert threading.active_count() <= before
    assert len(calls) < 200


# -- the commands --------------------------------------------------------------------------------


def test_detrend_tip_and_envelope_commands():
    source = rough(
        "synth",
        "--length",
        "5mm",
        "--step",
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
