"""Maps felt through the lateral gradient field, and strokes like a hand's: the ramp's
exact forces, the anisotropy the spectrum predicts, back-and-forth strokes that stay
on the surface, maps on a joystick, and the device interface every device honours."""

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rough import Surface
from rough.fractal.synth_map import _map_filter, synthesize_map
from rough.render import (
    GradientField,
    MapTrack,
    Settings,
    SimulatedHand,
    Stroke,
    Track,
    along_and_across,
    forces,
    parse_friction,
    run,
    simulate,
)
from rough.render.device import Device, HeldOpen, Workspace, open_device, parse_device

from conftest import assert_one_line_error, rough

SLOPE, SPACING, LOAD = 0.2, 0.1e-3, 1.5


def ramp(nx=81, ny=41):
    """h = SLOPE × x over an nx × ny map at SPACING."""
    x = np.arange(nx) * SPACING
    return MapTrack(np.tile(SLOPE * x, (ny, 1)), (SPACING, SPACING))


# -- the ramp: what the model says, to rounding ---------------------------------------------------


def test_strokes_along_the_climb_feel_the_force_against_it():
    result = simulate(ramp(), 0.02, model=GradientField(LOAD), direction=0.0)
    trace = result.trace
    assert trace.dtype.names == ("t", "x", "y", "h", "F_x", "F_y", "contact")
    assert trace["contact"].all()
    np.testing.assert_allclose(trace["F_x"], -LOAD * SLOPE, rtol=1e-12)
    assert np.abs(trace["F_y"]).max() < 1e-15
    along, across = along_and_across(trace)
    np.testing.assert_allclose(along, -LOAD * SLOPE, rtol=1e-12)  # against the climb
    assert np.abs(across).max() < 1e-15


def test_strokes_across_the_slope_feel_nothing_along_them_and_the_push_down_the_slope():
    result = simulate(ramp(41, 81), 0.02, model=GradientField(LOAD), direction=math.pi / 2)
    along, across = along_and_across(result.trace)
    assert np.abs(along).max() < 1e-15 * LOAD / SPACING  # cos(π/2) is 6e-17, not 0
    np.testing.assert_allclose(across, LOAD * SLOPE, rtol=1e-12)  # towards -x: down the slope
    np.testing.assert_allclose(result.trace["F_x"], -LOAD * SLOPE, rtol=1e-12)


def test_back_and_forth_over_the_ramp_the_force_keeps_pushing_down_the_slope():
    track = ramp()
    settings = Settings(realtime=False, duration=3 * track.chord(0.0)[2] / 0.02)
    trace = simulate(track, 0.02, model=GradientField(LOAD), settings=settings).trace
    along, _ = along_and_across(trace)
    climbing = np.diff(trace["x"], append=np.nan) > 0
    descending = np.diff(trace["x"], append=np.nan) < 0
    assert climbing.sum() > 400 and descending.sum() > 400 and trace["contact"].all()
    np.testing.assert_allclose(along[climbing], -LOAD * SLOPE, rtol=1e-12)
    np.testing.assert_allclose(along[descending], LOAD * SLOPE, rtol=1e-12)


def test_friction_on_a_map_acts_against_the_motion():
    flat = MapTrack(np.zeros((21, 21)), (SPACING, SPACING))
    friction = parse_friction("coulomb:level=0.3N")
    trace = simulate(flat, 0.02, friction=friction, direction=math.radians(30)).trace
    along, across = along_and_across(trace)
    np.testing.assert_allclose(along, -0.3, rtol=1e-12)
    assert np.abs(across).max() < 1e-12


# -- anisotropy: the ratio the spectrum predicts ---------------------------------------------------


def predicted_ratio(shape, spacing, anisotropy):
    """RMS of the central-difference ∂h/∂y over RMS of ∂h/∂x for synth's anisotropic
    spectrum: sqrt(Σ P(f) sin²(2π f_y dy)/dy² / Σ P(f) sin²(2π f_x dx)/dx²), with P the
    square of synth's filter gain on the whole grid of frequencies."""
    ny, nx = shape
    dx, dy = spacing
    gain = _map_filter(nx, ny, dx, dy, anisotropy[0], anisotropy[1], dx, anisotropy, None, slice(0, ny))
    power = gain.astype(np.float64) ** 2
    fx, fy = np.fft.rfftfreq(nx, dx), np.fft.fftfreq(ny, dy)
    weight = np.full(fx.size, 2.0)  # the half plane stands for both halves
    weight[0] = 1.0
    if nx % 2 == 0:
        weight[-1] = 1.0
    along_x = (power * weight * (np.sin(2 * np.pi * fx * dx) / dx) ** 2).sum()
    along_y = (power * weight * (np.sin(2 * np.pi * fy[:, None] * dy) / dy) ** 2).sum()
    return math.sqrt(along_y / along_x)


def test_the_lateral_force_across_the_lay_exceeds_the_one_along_it_as_the_spectrum_predicts():
    """Heights vary faster along y (C 10 µm there, 1 µm along x, Ds 2.3 both): the lay
    runs along x. Strokes sample the nodes (an odd number of rows puts the centre on a
    row, and the speed moves one spacing per tick), so the force's mean square along
    each axis estimates N² × the mean square central-difference gradient, whose ratio
    the spectrum gives: 1.607 for these 1025² maps. One stroke is one line of a
    fractal and scatters by about ±10 % around it, so the test pools the strokes of 16
    maps (scatter about ±3 %) and allows 8 %; the whole map's gradients agree to 3 %."""
    spacing, anisotropy = (10e-6, 10e-6), (2.3, 1e-6, 2.3, 10e-6, 0.0)
    prediction = predicted_ratio((1025, 1025), spacing, anisotropy)
    assert prediction == pytest.approx(1.607, abs=1e-3)
    squares = np.zeros((2, 2))  # [stroke along x, along y] × [F_x², F_y²]
    for seed in range(16):
        heights = synthesize_map((1025, 1025), spacing, None, anisotropy=anisotropy, seed=seed).heights
        if seed == 0:
            whole = np.std(np.gradient(heights, 10e-6, axis=0)) / np.std(np.gradient(heights, 10e-6, axis=1))
            assert whole == pytest.approx(prediction, rel=0.03)
        track = MapTrack(heights, spacing)
        for index, direction in enumerate((0.0, math.pi / 2)):
            trace = simulate(track, 10e-6 * 1000, direction=direction).trace
            squares[index] += (trace["F_x"] ** 2).sum(), (trace["F_y"] ** 2).sum()
    across_over_along = np.sqrt(squares[:, 1] / squares[:, 0])
    np.testing.assert_allclose(across_over_along, prediction, rtol=0.08)
    statistics = forces(simulate(MapTrack(heights, spacing), 0.01, direction=0.0))
    assert statistics["F_across_rms"] > statistics["F_along_rms"]  # stroking along the lay


# -- strokes like a hand's ------------------------------------------------------------------------


def test_a_minute_on_an_80mm_profile_strokes_back_and_forth_and_stays_on_the_surface(tmp_path):
    source = rough("synth", "--length", "80mm", "--dimension", "1.275", "--rq", "0.2781mm", "--seed", "3", check=True)
    profile = rough("resample", "--step", "0.1545mm", input=source.stdout, check=True).stdout
    out = rough("render", "--duration", "60s", "--json", "--trace", tmp_path / "t.npy", input=profile, check=True)
    report = json.loads(out.stdout)["runs"][0]
    trace = np.load(tmp_path / "t.npy")
    assert report["ticks"] == 60000 and trace.size == 60000
    assert np.isfinite(trace["h"]).all() and report["out_of_contact"] < 0.01
    turns = np.count_nonzero(np.diff(np.sign(np.diff(trace["x"]))) != 0)
    assert 14 <= turns <= 16  # 80 mm at 20 mm/s: a pass every 4.2 s
    assert trace["x"].min() >= 0 and trace["x"].max() <= 80e-3 + 1e-9


@settings(max_examples=60, deadline=None)
@given(
    speed=st.floats(1e-3, 0.5),
    length=st.floats(1e-3, 0.2),
    turn=st.floats(0.01, 1.0),
    period=st.sampled_from([1e-4, 1e-3, 2e-3]),
)
def test_a_stroke_stays_in_its_window_and_moves_and_turns_smoothly(speed, length, turn, period):
    stroke = Stroke(speed, period, length=length, turn=turn)
    ticks = int(min(4 * (length / speed + 2 * turn) / period, 20000))
    s, v = np.array([stroke.at(k) for k in range(ticks)]).T
    assert s.min() >= 0 and s.max() <= length
    assert np.abs(v).max() <= speed * (1 + 1e-12)
    assert np.abs(np.diff(s)).max() <= speed * period * (1 + 1e-9)
    acceleration = math.pi * speed / stroke.turn
    assert np.abs(np.diff(v)).max() <= acceleration * period * (1 + 1e-6) + 1e-15
    assert stroke.rim <= length / 4 * (1 + 1e-12)


def test_one_pass_is_the_constant_speed_stroke():
    one_way = Stroke(0.02, 1e-3)
    assert [one_way.at(k) for k in (0, 7, 1000)] == [(0.0, 0.02), (0.02 * 7 * 1e-3, 0.02), (0.02 * 1000 * 1e-3, 0.02)]
    track = Track(np.zeros(101), 1e-4)
    assert simulate(track, 0.02).trace["x"].max() == pytest.approx(track.end - 0.02e-3)


# -- maps on a joystick ----------------------------------------------------------------------------


def test_a_joystick_moves_a_point_over_the_map_and_feels_its_gradient():
    from virtual_joystick import FakeHandle, PidJoystick

    from rough.render.session import open_joystick, workspace

    heights = synthesize_map((65, 33), (0.1e-3, 0.1e-3), 2.3, rq=20e-6, seed=2).heights
    track = MapTrack(heights, (0.1e-3, 0.1e-3), origin=(1e-3, 2e-3))
    space = workspace([track])
    assert (space.x_start, space.x_span, space.y_centre, space.y_span) == pytest.approx((1e-3, 6.4e-3, 3.6e-3, 3.2e-3))
    device = PidJoystick()
    handle = FakeHandle(device)
    path = [(0.1 + 0.8 * k / 40, 0.2 + 0.6 * k / 40) for k in range(41)]
    for u, v in path:
        handle.move(u, v, 0)
    import rough.render.hid as hid

    original, hid.find_joystick = hid.find_joystick, lambda spec: (handle, device.descriptor, "virtual")
    try:
        stick, label = open_joystick("hid", [track], 8.9)
    finally:
        hid.find_joystick = original
    result = run(stick, [track], GradientField(LOAD), None, Settings(duration=0.04, watchdog=1.0))
    trace = result.trace
    assert trace.dtype.names[:3] == ("t", "x", "y") and result.device == "virtual"
    for row in trace[trace["contact"]]:
        h, gx, gy = track.at(row["x"], row["y"])
        assert (row["h"], row["F_x"], row["F_y"]) == pytest.approx((h, -LOAD * gx, -LOAD * gy), rel=1e-12, abs=1e-15)
    assert trace["contact"].sum() >= 30 and device.force() == (0.0, 0.0)


# -- the device interface ------------------------------------------------------------------------


def test_every_device_the_factory_opens_honours_the_interface():
    hand = open_device("sim", speed=0.02, start_x=0.0, start_y=0.0, period=1e-3)
    stroke = open_device("sim", surface="map", stroke=Stroke(0.02, 1e-3), start=(0, 0), direction=(1, 0), period=1e-3)
    for device in (hand, stroke, HeldOpen(hand)):
        assert isinstance(device, Device)
        assert device.capabilities.simulated and not device.capabilities.needs_watchdog
    assert hand.capabilities.damping == 2.0


def test_device_names_are_checked_before_anything_opens():
    assert parse_device("evdev:/dev/input/event3") == ("evdev", "/dev/input/event3")
    with pytest.raises(Exception, match="sim|hid"):
        parse_device("sim:3")
    with pytest.raises(Exception, match="evdev"):
        parse_device("usb")
    assert Workspace(0.0, 1.0, 0.0, 1.0, ("x",)).position(0.25, 0.5) == (0.75, 0.0)


def test_the_command_line_refuses_unknown_devices_and_mixed_surfaces(tmp_path):
    profile = Surface(np.zeros(11), (1e-4,))
    flat = Surface(np.zeros((11, 11)), (1e-4, 1e-4))
    profile.write(tmp_path / "p.x3p")
    flat.write(tmp_path / "m.x3p")
    assert_one_line_error(rough("render", "--device", "usb", tmp_path / "p.x3p"), "--device")
    assert_one_line_error(rough("render", tmp_path / "p.x3p", tmp_path / "m.x3p"), "both")


def test_a_map_renders_as_a_map_and_a_row_as_a_profile(tmp_path):
    heights = np.tile(SLOPE * np.arange(41) * SPACING, (21, 1))
    Surface(heights, (SPACING, SPACING)).write(tmp_path / "ramp.x3p")
    out = rough("render", "--direction", "90", "--trace", "-", tmp_path / "ramp.x3p", check=True).stdout.decode()
    lines = out.splitlines()
    assert lines[0].split("\t") == ["t", "x", "y", "h", "F_x", "F_y", "contact"]
    assert all(float(line.split("\t")[4]) == pytest.approx(-SLOPE) for line in lines[1:])
    row = rough("render", "--row", "1mm", "--json", tmp_path / "ramp.x3p", check=True)
    assert "F_y_mean" in json.loads(row.stdout)["runs"][0]


def test_the_simulated_hand_reports_the_velocity_of_its_stroke():
    stroke = Stroke(0.02, 1e-3, length=0.01)
    hand = SimulatedHand(0.02, 0.0, 0.0, 1e-3, stroke=stroke)
    for _ in range(600):
        hand.write(0.0, hand.press)
    assert hand.velocity[0] == stroke.at(600)[1] < 0


def test_a_wheel_feels_a_profiles_lateral_force_alone():
    from rough.render import QuasiStatic
    from rough.render.device import Capabilities
    from rough.render.session import fitted_model

    class Wheel:
        capabilities = Capabilities(axes=1)

    class Stick:
        capabilities = Capabilities(axes=2)

    contact = QuasiStatic()
    field = fitted_model(contact, Wheel(), load=LOAD)
    assert isinstance(field, GradientField) and field.load == LOAD
    assert fitted_model(contact, Stick()) is contact
    track = Track(SLOPE * np.arange(101) * SPACING, SPACING)
    feel = track.feel(field, None, 1e-3)
    assert feel(5e-3, 1.0, 0.0, 0.0, 0.0) == pytest.approx((SLOPE * 5e-3, -LOAD * SLOPE, 0.0, True))
    assert feel(-1e-3, 0.0, 0.0, 0.0, 0.0)[1:] == (0.0, 0.0, False)
