"""Haptic rendering: the contact physics, friction, the servo loop and the command."""

import json
import math
import time

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from rough import Surface
from rough.errors import InputError
from rough.fractal.resampling import resample
from rough.fractal.synth import synthesize_fragments, synthesize_profile
from rough.render import DynamicStylus, QuasiStatic, Settings, Track, clamp, forces, run, simulate, write_trace
from rough.render.device import Capabilities
from rough.render.friction import CoulombViscous, Dahl, Karnopp, parse_friction
from rough.render.loop import LoopStalled, _Watchdog

from conftest import assert_one_line_error, rough

K = 1280.0
finite = st.floats(-1e-2, 1e-2, allow_nan=False)


# -- the contact law ----------------------------------------------------------------------


@pytest.mark.parametrize("model", [QuasiStatic(), DynamicStylus()], ids=["quasi-static", "dynamic"])
def test_lateral_force_resists_the_climb_and_helps_the_descent(model):
    for slope, sign in ((0.5, -1), (-0.5, 1)):
        model.reset()
        fx, fy, contact = model.step(0.0, 0.0, slope, 0.0, -1e-3, 0.02, 0.0, 0.0)
        assert contact and fy > 0
        assert np.sign(fx) == sign  # moving +x: pushed back uphill, pulled along downhill
        assert abs(fx) == pytest.approx(abs(slope) * (fy if isinstance(model, QuasiStatic) else K * 1e-3), rel=1e-3)


@given(h=finite, y=finite, slope=st.floats(-5, 5), stiffness=st.floats(1.0, 1e5))
def test_quasi_static_force_is_stiffness_times_penetration_and_zero_out_of_contact(h, y, slope, stiffness):
    fx, fy, contact = QuasiStatic(stiffness).step(0.0, h, slope, 0.0, y, 0.02, 0.0, 0.0)
    if y > h:
        assert (fx, fy, contact) == (0.0, 0.0, False)
    else:
        assert contact and fy == pytest.approx(stiffness * (h - y)) and fx == pytest.approx(-fy * slope)


@given(fx=st.floats(-100, 100), fy=st.floats(-100, 100), limit=st.floats(0.1, 20))
def test_clamp_scales_both_components_and_keeps_the_direction(fx, fy, limit):
    cx, cy = clamp(fx, fy, limit)
    assert math.hypot(cx, cy) <= limit * (1 + 1e-12)
    assert cx * fy - cy * fx == pytest.approx(0.0, abs=1e-9 * (1 + abs(fx) + abs(fy)))
    assert cx * fx + cy * fy >= 0
    if math.hypot(fx, fy) <= limit:
        assert (cx, cy) == (fx, fy)


def test_dynamic_stylus_out_of_contact_feels_only_its_own_spring():
    stylus = DynamicStylus()
    stylus.reset(2e-3)
    fx, fy, contact = stylus.step(0.0, 0.0, 0.3, 0.0, 2e-3, 0.02, 0.0, 0.0)
    assert (fx, fy, contact) == (0.0, 0.0, False)


def slot_track():
    """A flat profile at 0.0309 mm with a 2 mm slot, 0.7 mm deep, with vertical walls."""
    heights = np.zeros(400)
    heights[150:215] = -0.7e-3
    return Track(heights, 30.9e-6)


def ticks_out_of_contact(model, track, speed, y=-0.78e-3, period=1e-3):
    model.reset()
    lost = 0
    for k in range(int(track.length / speed / period)):
        x = speed * k * period
        h, slope, curvature = track.at(x)
        lost += not model.step(x, h, slope, curvature, y, speed, 0.0, 0.0)[2]
    return lost


def test_dynamic_stylus_skips_a_sharp_valley_at_120_mm_s_but_not_at_20():
    """docs/math.rst §5.5: with M = 1.85 g the stylus cannot follow a sharp edge at speed. The
    hand is held 0.78 mm (1 N) below the rim and the slot is shallower than that, so the
    quasi-static law never loses contact: only the stylus's inertia can."""
    track = slot_track()
    assert ticks_out_of_contact(DynamicStylus(), track, 0.120) >= 1
    assert ticks_out_of_contact(DynamicStylus(), track, 0.020) == 0
    assert ticks_out_of_contact(QuasiStatic(), track, 0.120) == 0


@pytest.mark.parametrize("mass", [1.85e-9, 1.85e-3], ids=["literal 1.85e-6 g", "1.85 g"])
@pytest.mark.parametrize("stiffness", [1280.0, 1e6])
def test_dynamic_stylus_is_stable_at_1_khz_for_the_stiffest_parameters(mass, stiffness):
    """Free flight after a hand step, 10 s at 1 kHz: no growth, settles on the hand."""
    stylus = DynamicStylus(stiffness=stiffness, mass=mass, damping=0.046, period=1e-3)
    stylus.reset(1e-3)
    far_below = -1.0
    offsets = []
    for _ in range(10000):
        stylus.step(0.0, far_below, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        offsets.append(stylus.position)
    offsets = np.abs(offsets)
    assert np.isfinite(offsets).all() and offsets.max() <= 1e-3 * (1 + 1e-9)
    assert offsets[-1] < 1e-6


def test_dynamic_stylus_reduces_to_the_quasi_static_law_without_mass_and_damping():
    track = Track.from_surface(resample(synthesize_profile(2048, 30.9e-6, 1.3, rq=0.1e-3, seed=3), 0.1545e-3))
    light = simulate(track, 0.02, DynamicStylus(mass=1e-12, damping=0.0))
    plain = simulate(track, 0.02, QuasiStatic())
    np.testing.assert_allclose(light.trace["F_y"], plain.trace["F_y"], atol=1e-6)
    np.testing.assert_allclose(light.trace["F_x"], plain.trace["F_x"], atol=1e-6)


# -- friction -----------------------------------------------------------------------------


def test_coulomb_opposes_the_motion():
    friction = CoulombViscous(level=0.3, viscous=2.0)
    assert friction.force(True, 0.0, 0.01, 1e-3) == pytest.approx(-0.32)
    assert friction.force(True, 0.0, -0.01, 1e-3) == pytest.approx(0.32)
    assert friction.force(False, 0.0, 0.01, 1e-3) == 0.0


def test_karnopp_sticks_breaks_away_at_the_static_level_slips_at_coulomb_and_sticks_again():
    friction = Karnopp(static=0.8, coulomb=0.5, viscous=0.0, band=2e-3, stiffness=1000.0, damping=0.0)
    x, held = 0.0, []
    for _ in range(100):  # creeping at 0.1 mm/s, inside the stick band: the spring loads
        x += 1e-7
        held.append(friction.force(True, x, 1e-4, 1e-3))
    assert held[-1] == pytest.approx(-1000.0 * (x - 1e-7))  # anchored where it first stuck
    while True:
        x += 1e-5
        force = friction.force(True, x, 1e-4, 1e-3)
        if friction.anchor is None:
            break
        assert abs(force) <= 0.8
    assert force == pytest.approx(-0.5)  # breakaway at |k Δx| > 0.8 N, then Coulomb
    assert friction.force(True, x + 1e-4, 0.05, 1e-3) == pytest.approx(-0.5)
    friction.force(True, x + 2e-4, 1e-3, 1e-3)
    assert friction.anchor == pytest.approx(x + 2e-4)  # slow again: stuck


def test_dahl_approaches_the_coulomb_level_exactly_and_never_overshoots():
    friction = Dahl(stiffness=1000.0, coulomb=0.5)
    x, forces_seen = 0.0, []
    for _ in range(200):
        x += 1e-5
        forces_seen.append(-friction.force(True, x, 0.01, 1e-3))
    expected = 0.5 * (1 - np.exp(-1000.0 * 1e-5 * np.arange(200) / 0.5))  # the first call only sets the origin
    np.testing.assert_allclose(forces_seen, expected, rtol=1e-9)
    stiff = Dahl(stiffness=1e9, coulomb=0.5)
    stiff.force(True, 0.0, 0.1, 1e-3)
    assert abs(stiff.force(True, 1e-3, 0.1, 1e-3)) <= 0.5
    assert stiff.force(True, 0.0, -0.1, 1e-3) == pytest.approx(0.5)  # reversal: full level the other way


@pytest.mark.parametrize(
    "spec,message",
    [
        ("glue:level=1N", "unknown friction model"),
        ("coulomb:level=1", "not a force"),
        ("coulomb:stiction=1N", "coulomb friction takes"),
        ("karnopp:static=0.2N,coulomb=0.5N", "static ≥ coulomb"),
    ],
)
def test_friction_specs_are_checked(spec, message):
    with pytest.raises(InputError, match=message):
        parse_friction(spec)


def test_friction_acts_along_the_surface_tangent():
    track = Track(np.arange(200) * 1e-4 * 0.5, 1e-4)  # a ramp of slope 0.5
    stroke = [(2e-3 + 2e-5 * k, 0.0, 0) for k in range(400)]  # 20 mm/s, the hand held at y = 0, under the ramp
    traces = []
    for friction in (None, parse_friction("coulomb:level=0.3N")):
        traces.append(
            run(ScriptedDevice(stroke), [track], QuasiStatic(), friction, Settings(duration=0.3, realtime=False)).trace
        )
    extra_x = traces[1]["F_x"] - traces[0]["F_x"]
    extra_y = traces[1]["F_y"] - traces[0]["F_y"]
    np.testing.assert_allclose(extra_x[20:], -0.3 / math.sqrt(1.25), rtol=1e-9)
    np.testing.assert_allclose(extra_y[20:], -0.3 * 0.5 / math.sqrt(1.25), rtol=1e-9)


# -- the simulated hand and the loop --------------------------------------------------------


def rock_track(fragments=False, seed=1):
    make = synthesize_fragments if fragments else synthesize_profile
    profile = make(round(80e-3 / 30.9e-6), 30.9e-6, 1.275, rq=0.2781e-3, seed=seed)
    return Track.from_surface(resample(profile, 0.1545e-3))


def test_the_hand_rests_on_the_surface_with_its_own_press():
    result = simulate(Track(np.zeros(2000), 1e-4), 0.02)
    assert result.trace["F_y"].mean() == pytest.approx(1.0, rel=1e-3)
    assert forces(result)["out_of_contact"] == 0.0


def test_force_spread_and_time_out_of_contact_rise_with_speed():
    """docs/math.rst §5.5 in kind, on a profile made as the paper made its stimuli (128-point
    fragments scaled to Rq 0.2781 mm, where the figures of docs/math.rst §5.5 come from). The steady hand
    follows at 20 mm/s and cannot at 120 mm/s."""
    track = rock_track(fragments=True)
    slow, fast = (forces(simulate(track, speed)) for speed in (0.02, 0.12))
    assert fast["F_y_std"] > 1.3 * slow["F_y_std"]
    assert fast["F_y_max"] > slow["F_y_max"]
    assert slow["out_of_contact"] < 0.01 < fast["out_of_contact"]


def test_whole_length_fractal_is_followed_at_every_speed():
    """The same D and Rq made over the whole length put most of their relief into long
    wavelengths that the hand rides: spread rises with speed, contact is never lost."""
    track = rock_track()
    stats = [forces(simulate(track, speed)) for speed in (0.02, 0.06, 0.12)]
    assert stats[0]["F_y_std"] < stats[1]["F_y_std"] < stats[2]["F_y_std"]
    assert all(s["out_of_contact"] == 0.0 for s in stats)


class ScriptedDevice:
    """A device that replays positions and buttons, records forces, and can fail."""

    label, velocity = "scripted", (0.0, 0.0)
    capabilities = Capabilities(needs_watchdog=False, simulated=True)

    def __init__(self, positions, fail_at=None, error=KeyboardInterrupt, stall_at=None):
        self.positions, self.fail_at, self.error, self.stall_at = positions, fail_at, error, stall_at
        self.k, self.written, self.closed, self.stopped = 0, [], False, False

    def read(self):
        if self.k == self.fail_at:
            raise self.error()
        if self.k == self.stall_at:  # stalls until the watchdog stops the device (at most 10 s)
            until = time.monotonic() + 10
            while not self.stopped and time.monotonic() < until:
                time.sleep(1e-3)
        return self.positions[min(self.k, len(self.positions) - 1)]

    def write(self, fx, fy):
        if not self.stopped:
            self.written.append((fx, fy))
        self.k += 1

    def emergency_stop(self):
        self.stopped = True
        self.written.append((0.0, 0.0))

    def zero(self):
        self.written.append((0.0, 0.0))

    def close(self):
        self.closed = True
        self.written.append((0.0, 0.0))


FLAT = Track(np.zeros(101), 1e-4)
RAISED = Track(np.full(101, 1e-3), 1e-4)


def test_force_ramps_in_over_the_ramp_time():
    device = ScriptedDevice([(5e-3, -1e-3, 0)])
    run(device, [FLAT], QuasiStatic(), None, Settings(duration=0.05, ramp=0.02, realtime=False))
    fy = np.array(device.written[:-1])[:, 1]
    np.testing.assert_allclose(fy[:20], K * 1e-3 * np.arange(20) / 20)
    np.testing.assert_allclose(fy[20:], K * 1e-3)


def test_the_trigger_switches_surfaces_on_each_press():
    presses = [0] * 10 + [1] * 5 + [0] * 10 + [1] * 5 + [0] * 10
    device = ScriptedDevice([(5e-3, 0.0, b) for b in presses])
    result = run(device, [FLAT, RAISED], QuasiStatic(), None, Settings(duration=0.04, realtime=False))
    h = result.trace["h"]
    assert result.switches == 2
    assert (h[:10] == 0).all() and (h[10:25] == 1e-3).all() and (h[25:] == 0).all()


@pytest.mark.parametrize("error,ended_by", [(KeyboardInterrupt, "interrupt"), (OSError, None)])
def test_ctrl_c_and_errors_leave_the_force_at_zero(error, ended_by):
    device = ScriptedDevice([(5e-3, -1e-3, 0)], fail_at=30, error=error)
    if ended_by is None:
        with pytest.raises(error):
            run(device, [FLAT], QuasiStatic(), None, Settings(duration=1.0, realtime=False))
    else:
        result = run(device, [FLAT], QuasiStatic(), None, Settings(duration=1.0, realtime=False))
        assert result.ended_by == ended_by and result.ticks == 30 and result.trace.size == 30
    assert device.closed and device.written[-1] == (0.0, 0.0) and device.written[-2][1] > 0


def test_the_watchdog_zeroes_the_force_when_the_loop_stalls():
    device = ScriptedDevice([(5e-3, -1e-3, 0)], stall_at=40)
    device.capabilities = Capabilities(needs_watchdog=True)
    with pytest.raises(LoopStalled, match="stalled"):
        run(device, [FLAT], QuasiStatic(), None, Settings(duration=2.0, watchdog=0.05, realtime=True))
    assert device.stopped and device.closed
    assert device.written[-1] == (0.0, 0.0) and len(device.written) < 60


class FakeClock:
    """A controllable clock for the real-time loop: each reading costs ``step`` seconds
    and a sleep advances it exactly (so the pacing logic is tested, not the machine)."""

    def __init__(self, step=1e-6):
        self.now, self.step = 0.0, step

    def perf_counter(self):
        self.now += self.step
        return self.now

    def sleep(self, seconds):
        self.now += max(seconds, 0.0)


class SlowDevice(ScriptedDevice):
    """Its read at tick ``slow_at`` takes ``delay`` seconds of the fake clock."""

    def __init__(self, clock, slow_at, delay):
        super().__init__([(5e-3, -1e-3, 0)])
        self.clock, self.slow_at, self.delay = clock, slow_at, delay

    def read(self):
        if self.k == self.slow_at:
            self.clock.sleep(self.delay)
        return super().read()


@pytest.fixture
def fake_clock(monkeypatch):
    clock = FakeClock()
    monkeypatch.setattr(time, "perf_counter", clock.perf_counter)
    monkeypatch.setattr(time, "sleep", clock.sleep)
    return clock


def test_the_real_time_loop_keeps_its_rate(fake_clock):
    device = ScriptedDevice([(5e-3, -1e-3, 0)])
    timing = run(device, [FLAT], QuasiStatic(), None, Settings(duration=0.3, realtime=True)).timing()
    assert timing["ticks"] == 300 and timing["missed_deadlines"] == 0
    assert timing["rate"] == pytest.approx(1000.0, rel=1e-4)
    assert timing["jitter_max"] < 5e-6 and timing["max_lateness"] < 5e-6  # a few readings of the clock


def test_a_late_tick_skips_the_deadlines_it_missed(fake_clock):
    """A read that takes 3.5 periods: the loop does not try to catch up with a burst of
    ticks; it counts the two deadlines it missed and resumes on the grid."""
    device = SlowDevice(fake_clock, slow_at=100, delay=3.5e-3)
    result = run(device, [FLAT], QuasiStatic(), None, Settings(duration=0.3, realtime=True))
    timing = result.timing()
    assert timing["ticks"] == 300 and timing["missed_deadlines"] == 2
    # the tick after the slow read starts at once, 0.5 ms after its (latest) deadline;
    # the next one waits for its deadline on the grid again
    assert timing["max_lateness"] == pytest.approx(0.5e-3, abs=1e-5)
    late = np.flatnonzero(result.starts - result.deadlines > 5e-6)
    assert late.tolist() == [101]
    assert timing["wall_time"] == pytest.approx(0.301, abs=2e-5)  # the last tick starts at 301 ms: two slots skipped


def test_the_watchdog_trips_when_the_tick_stops_for_longer_than_its_timeout():
    device = ScriptedDevice([(5e-3, -1e-3, 0)])
    watchdog = _Watchdog(device, 2e-3)
    assert not watchdog.look(0.0)  # the first look notes the tick
    watchdog.tick = 1
    assert not watchdog.look(1.0e-3)  # the tick moved: the count starts again
    assert not watchdog.look(2.9e-3) and not device.stopped  # 1.9 ms without a tick
    assert watchdog.look(3.1e-3) and device.stopped and device.written[-1] == (0.0, 0.0)


def test_trace_files(tmp_path):
    result = simulate(Track(np.linspace(0, 1e-4, 50), 1e-4), 0.02)
    write_trace(result, tmp_path / "trace.tsv")
    lines = (tmp_path / "trace.tsv").read_text().splitlines()
    assert lines[0] == "t\tx\ty_i\th\tF_x\tF_y\tcontact" and len(lines) == result.trace.size + 1
    back = np.genfromtxt(tmp_path / "trace.tsv", names=True, delimiter="\t")
    np.testing.assert_allclose(back["F_y"], result.trace["F_y"], rtol=1e-8)
    write_trace(result, tmp_path / "trace.npy")
    np.testing.assert_array_equal(np.load(tmp_path / "trace.npy"), result.trace)


def test_tracks_need_gap_free_profiles_and_maps_give_a_row():
    with pytest.raises(InputError, match="--fill"):
        Track([0.0, np.nan, 0.0, 1.0], 1e-4)
    heights = np.arange(12.0).reshape(3, 4) * 1e-6
    track = Track.from_surface(Surface(heights, (1e-4, 2e-4)), row=4e-4)
    np.testing.assert_array_equal(track.heights, heights[2])
    assert track.at(-1e-9)[0] == -math.inf and track.at(3e-4)[0] == pytest.approx(11e-6)


@settings(max_examples=50)
@given(st.lists(st.floats(-1e-3, 1e-3), min_size=3, max_size=40), st.floats(0, 1))
def test_track_lookup_interpolates_between_nodes(heights, fraction):
    track = Track(heights, 1e-4)
    x = fraction * track.length
    assert track.at(x)[0] == pytest.approx(np.interp(x, np.arange(len(heights)) * 1e-4, heights), abs=1e-15)
    assert track.at(x)[1] == pytest.approx(
        np.interp(x, np.arange(len(heights)) * 1e-4, np.gradient(heights, 1e-4)), abs=1e-9
    )


# -- the command ----------------------------------------------------------------------------


def test_render_command_with_several_speeds(tmp_path):
    profile = rough(
        "synth", "--length", "20mm", "--dimension", "1.275", "--rq", "0.2781mm", "--seed", "1", check=True
    ).stdout
    result = rough(
        "render",
        "--speed",
        "20mm/s",
        "--speed",
        "120mm/s",
        "--trace",
        tmp_path / "f-{speed}.tsv",
        "--plot",
        tmp_path / "forces.png",
        "--json",
        "--friction",
        "dahl:stiffness=1N/mm,coulomb=0.2N",
        input=profile,
        check=True,
    )
    runs = json.loads(result.stdout)["runs"]
    assert [r["speed"] for r in runs] == [0.02, 0.12]
    assert {"rate", "jitter_p99"}.isdisjoint(runs[0])  # unpaced: no timing to report
    assert {"F_y_std", "out_of_contact", "realtime_factor", "ticks"} <= set(runs[0])
    for label in ("20mm_s", "120mm_s"):
        assert (tmp_path / f"f-{label}.tsv").read_text().startswith("t\tx\ty_i\th\tF_x\tF_y\tcontact\n")
    assert (tmp_path / "forces.png").read_bytes()[:4] == b"\x89PNG"


def test_render_dynamic_realtime_reports_timing():
    profile = rough("synth", "--length", "5mm", "--dimension", "1.3", "--rq", "0.1mm", "--seed", "2", check=True).stdout
    report = json.loads(
        rough(
            "render", "--model", "dynamic", "--realtime", "--duration", "0.2s", "--json", input=profile, check=True
        ).stdout
    )["runs"][0]
    assert report["ticks"] == 200 and report["rate"] == pytest.approx(1000, rel=0.05)
    assert {"jitter_p50", "jitter_p99", "jitter_max", "missed_deadlines"} <= set(report)


def test_render_refusals(tmp_path):
    profile = rough("synth", "--length", "5mm", "--dimension", "1.3", "--rq", "0.1mm", "--seed", "2", check=True).stdout
    assert_one_line_error(
        rough("render", "--speed", "1mm/s", "--speed", "2mm/s", "--trace", "t.tsv", input=profile), "{speed}"
    )
    assert_one_line_error(rough("render", "--friction", "glue", input=profile), "unknown friction model")
    assert_one_line_error(rough("render", "--stiffness", "3kg", input=profile), "not a stiffness")
    assert_one_line_error(rough("render", "--device", "usb", input=profile), "sim, hid or hid:VID:PID")
    Surface(np.array([0.0, np.nan, 1e-6, 0.0]), (1e-4,)).write(tmp_path / "gap.x3p")
    assert_one_line_error(rough("render", tmp_path / "gap.x3p"), "--fill")
    assert rough("render", "--fill", tmp_path / "gap.x3p").returncode == 0


def test_render_without_a_joystick_says_so():
    profile = rough("synth", "--length", "5mm", "--dimension", "1.3", "--rq", "0.1mm", "--seed", "2", check=True).stdout
    result = rough("render", "--device", "hid:dead:beef", "--duration", "1s", input=profile)
    assert_one_line_error(result, "no force-feedback joystick found", status=1)


# -- faults: the force stays bounded and goes to zero ----------------------------------------------


class TimedDevice(ScriptedDevice):
    """Records when each force was written."""

    def __init__(self, *args, spin_at=None, **kwargs):
        super().__init__(*args, **kwargs)
        self.times, self.spin_at = [], spin_at

    def read(self):
        if self.k == self.spin_at:
            until = time.monotonic() + 10
            while not self.stopped and time.monotonic() < until:  # stuck in Python code, holding the interpreter
                pass
        return super().read()

    def write(self, fx, fy):
        self.times.append(time.monotonic())
        super().write(fx, fy)

    def emergency_stop(self):
        self.times.append(time.monotonic())
        super().emergency_stop()

    def close(self):
        self.times.append(time.monotonic())
        super().close()


@settings(max_examples=30, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.floats(-1.0, 1.0) | st.sampled_from([math.nan, math.inf, -math.inf]),
            st.floats(-1.0, 1.0) | st.sampled_from([math.nan, math.inf, -math.inf]),
        ),
        min_size=2,
        max_size=40,
    ),
    st.floats(0.5, 20.0),
)
def test_every_written_force_is_finite_and_within_the_limit(positions, limit):
    """Wild positions (deep in the surface, NaN, infinite) and friction: no force beyond
    the limit, nothing non-finite ever reaches the device."""
    device = ScriptedDevice([(x * 1e-2, y * 1e-2, 0) for x, y in positions])
    friction = parse_friction("karnopp:static=5N,coulomb=3N,viscous=100N*s/m")
    run(
        device,
        [RAISED],
        QuasiStatic(stiffness=1e6),
        friction,
        Settings(duration=len(positions) * 1e-3, max_force=limit, realtime=False),
    )
    forces_written = np.array(device.written)
    assert np.isfinite(forces_written).all()
    assert (np.hypot(forces_written[:, 0], forces_written[:, 1]) <= limit * (1 + 1e-12)).all()


class Exploding(QuasiStatic):
    def __init__(self, at):
        super().__init__()
        self.at, self.calls = at, 0

    def step(self, *arguments):
        self.calls += 1
        if self.calls > self.at:
            raise RuntimeError("model failure")
        return super().step(*arguments)


def test_an_exception_zeroes_the_force_at_once(monkeypatch):
    """The zero follows the failing step before the loop reads its clock again: no tick
    passes (ordering against the loop's clock, not wall time, so a busy machine cannot
    fail it)."""
    device, model = TimedDevice([(5e-3, -1e-3, 0)]), Exploding(25)
    clock, readings = time.perf_counter, []
    monkeypatch.setattr(time, "perf_counter", lambda: readings.append((len(device.written), model.calls)) or clock())
    with pytest.raises(RuntimeError):
        run(device, [FLAT], model, None, Settings(duration=1.0, realtime=True, watchdog=1.0))
    assert len(device.written) == 26 and device.written[24][1] > 0 and device.written[25] == (0.0, 0.0)
    assert (25, 25) in readings  # the failing tick was paced by the clock
    # between the failure and the zero the clock is read once, for the wall-time total;
    # waiting for another tick would read it at least three times (start, pace, stamp)
    assert readings.count((25, 26)) <= 1


def test_a_stalled_loop_is_zeroed_by_its_watchdog():
    """The loop gets stuck in Python code, holding the interpreter; the watchdog thread
    still gets it and zeroes the force, and nothing is written after. (How soon is the
    watchdog's own logic, tested against a controllable clock above; bench/bench_render.py
    measures it on the machine.)"""
    device = TimedDevice([(5e-3, -1e-3, 0)], spin_at=30)
    device.capabilities = Capabilities(needs_watchdog=True)
    with pytest.raises(LoopStalled):
        run(device, [FLAT], QuasiStatic(), None, Settings(duration=2.0, watchdog=2e-3, realtime=True))
    stop = device.written.index((0.0, 0.0))
    assert stop == 30 and all(f[1] > 0 for f in device.written[:30])
    assert all(f == (0.0, 0.0) for f in device.written[30:])


def test_a_vanished_joystick_leaves_no_force():
    """Reads fail (the device is going away) while writes still arrive: the zero is
    written in the same tick; when writes fail too, closing does not raise."""
    from virtual_joystick import FakeHandle, PidJoystick

    from rough.render.hid import DeviceGone, Joystick

    device = PidJoystick()
    handle = FakeHandle(device)
    handle.move(0.5, 0.2, 0)
    stick = Joystick(handle, device.descriptor, 8.9, 0.0, 0.01, 1e-3, 4e-3)
    original = handle.read
    calls = {"n": 0}

    def failing_read(size, timeout=0):
        calls["n"] += 1
        if calls["n"] > 40:
            raise OSError("read error")
        return original(size, timeout)

    handle.read = failing_read
    with pytest.raises(DeviceGone):
        run(stick, [RAISED], QuasiStatic(), None, Settings(duration=1.0, watchdog=1.0))
    assert device.force() == (0.0, 0.0) and handle.closed


@pytest.mark.parametrize("stick_span, expected", [((0.08,), (1e-2, 4e-3)), ((0.08, 0.02), (0.08, 0.02))])
def test_the_stick_spans_the_tracks_unless_both_spans_are_given(monkeypatch, stick_span, expected):
    """render and experiment open the joystick through one function: a single
    --stick-span value falls back to the tracks' own spans (it used to crash experiment)."""
    from virtual_joystick import FakeHandle, PidJoystick

    from rough.render import hid
    from rough.render.session import open_joystick

    device = PidJoystick()
    handle = FakeHandle(device)
    handle.move(0.5, 0.5, 0)
    monkeypatch.setattr(hid, "find_joystick", lambda spec: (handle, device.descriptor, "virtual"))
    ramp = Track(np.linspace(0, 1e-3, 101), 1e-4)
    joystick, label = open_joystick("hid", [RAISED, ramp], 8.9, stick_span)
    assert label == "virtual" and (joystick.x_span, joystick.y_span) == pytest.approx(expected)
    assert joystick.y_centre == pytest.approx(1e-3)
    joystick.close()


@settings(max_examples=200, deadline=None)
@given(
    stiffness=st.one_of(st.just(0.0), st.floats(1e-2, 1e4)),
    damping=st.floats(0.0, 100.0),
    mass=st.floats(1e-3, 1.0),
    period=st.floats(1e-5, 1e-2),
)
@example(stiffness=7450.875, damping=8.8643, mass=0.001, period=0.009052)
def test_the_zero_order_hold_is_scipys_matrix_exponential(stiffness, damping, mass, period):
    """The pure-Python exponential (scipy's expm wakes BLAS threads that spin for 0.1 s)
    agrees with scipy.linalg.expm to 1e-11 of each column's largest entry. Against a
    60-digit reference (mpmath) on 400 random holds of these ranges, rough is within
    1.7e-13 and scipy within 1.2e-12 (at the 180 corners of the ranges, 8e-13 and
    3.4e-13): the bound leaves room for both errors."""
    from scipy.linalg import expm

    from rough.render.contact import zero_order_hold

    augmented = np.array([[0, 1, 0], [-stiffness / mass, -damping / mass, 1 / mass], [0, 0, 0]]) * period
    expected = expm(augmented)[:2]
    p11, p12, p21, p22, g1, g2 = zero_order_hold(stiffness, damping, mass, period)
    got = np.array([[p11, p12, g1], [p21, p22, g2]])
    scale = np.abs(expected).max(axis=0)
    assert (np.abs(got - expected).max(axis=0) <= 1e-11 * scale).all()


def test_a_stiff_heavily_damped_hold_is_right_to_the_last_digits():
    """Issue 31: Γ2 of this hold was 1.4e-11 off (its column's scale 1e-11 off) when
    read from the squared exponential; from Φ12/m it keeps Φ12's accuracy. The
    reference is mpmath's expm at 60 digits of the same matrix."""
    from rough.render.contact import zero_order_hold

    reference = [
        0.00022822030649272550014,
        2.8801116857299564291e-8,
        -0.21459352156413189109,
        -0.000027081433665435027608,
        0.00013418179471451437241,
        0.000028801116857299564291,
    ]
    got = zero_order_hold(7450.875, 8.8643, 0.001, 0.009052)
    assert got == pytest.approx(reference, rel=1e-13, abs=0)


def test_the_zero_order_hold_of_a_free_mass_is_exact():
    from rough.render.contact import zero_order_hold

    p11, p12, p21, p22, g1, g2 = zero_order_hold(0.0, 0.0, 0.5, 0.01)
    assert (p11, p12, p21, p22) == (1.0, 0.01, 0.0, 1.0)
    assert g1 == pytest.approx(0.01**2 / (2 * 0.5), rel=1e-15) and g2 == pytest.approx(0.01 / 0.5, rel=1e-15)


def test_a_simulated_run_wakes_no_blas_threads(monkeypatch):
    """scipy's expm (BLAS) leaves OpenBLAS threads spinning on another core for about
    0.1 s, which doubled the CPU time of a short simulated run: the hand and stylus
    steps are computed without it."""
    import scipy.linalg

    def refused(*args, **kwargs):
        raise AssertionError("scipy.linalg.expm called")

    monkeypatch.setattr(scipy.linalg, "expm", refused)
    for model in (QuasiStatic(), DynamicStylus()):
        assert simulate(FLAT, 0.02, model, lateral_stiffness=500.0).ticks == 500
