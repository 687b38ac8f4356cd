"""The HID PID driver without hardware: report encoding checked against hid-tools'
decoding of the same descriptor, and the whole joystick protocol against a virtual
device in-process (tests/test_hid_guest.py runs it through a real kernel)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pid_descriptor import Layout, descriptor
from virtual_joystick import FakeHandle, PidJoystick

from rough.render import QuasiStatic, Settings, Track, run
from rough.render.hid import DeviceGone, Joystick
from rough.render.pid import MAGNITUDE, PidDescriptor, PidError

SMALL = Layout(
    axis_bits=10,
    axis_range=(0, 1023),
    buttons=4,
    magnitude_bits=8,
    magnitude_range=(-127, 127),
    max_effects=15,
    ids={
        "input": 4,
        "state": 9,
        "set_effect": 2,
        "constant": 3,
        "operation": 6,
        "free": 7,
        "control": 8,
        "gain": 10,
        "create": 5,
        "load": 6,
        "pool": 7,
    },
)
LAYOUTS = [Layout(), SMALL]
PLAIN_JOYSTICK = bytes.fromhex(  # X, Y and buttons, a vendor output report: no PID page
    "05 01 09 04 a1 01 85 01 09 30 09 31 16 01 80 26 ff 7f 75 10 95 02 81 02"
    "05 09 19 01 29 08 15 00 25 01 75 01 95 08 81 02 06 00 ff 85 02 09 01 16 01 80 26 ff 7f 75 10 95 02 91 02 c0"
)


@pytest.mark.parametrize("layout", LAYOUTS, ids=["16-bit", "8-bit"])
def test_reports_are_found_with_their_ids_and_sizes(layout):
    pid = PidDescriptor(descriptor(layout))
    assert pid.joystick.id == layout.ids["input"] and len(pid.buttons) == layout.buttons
    assert pid.constant.id == layout.ids["constant"]
    magnitude = pid.constant.fields[MAGNITUDE]
    assert (magnitude.size, magnitude.low, magnitude.high) == (layout.magnitude_bits, *layout.magnitude_range)
    assert pid.load.id == layout.ids["load"] and pid.create.id == layout.ids["create"]


@pytest.mark.parametrize("layout", LAYOUTS, ids=["16-bit", "8-bit"])
@settings(max_examples=60, deadline=None)
@given(data=st.data())
def test_encoded_reports_decode_to_the_same_values_with_hid_tools(layout, data):
    device = PidJoystick(layout)
    pid = PidDescriptor(device.descriptor)
    for report in (pid.constant, pid.set_effect, pid.operation):
        values = {usage: data.draw(st.integers(field.low, field.high)) for usage, field in report.fields.items()}
        _, decoded = device._decode(device.parsed.output_reports, report.encode(values))
        assert decoded == values


@pytest.mark.parametrize("layout", LAYOUTS, ids=["16-bit", "8-bit"])
@given(x=st.floats(0, 1), y=st.floats(0, 1), buttons=st.integers(0, 15))
def test_input_reports_made_by_hid_tools_read_back(layout, x, y, buttons):
    device = PidJoystick(layout)
    pid = PidDescriptor(device.descriptor)
    rx, ry, rbuttons = pid.position(device.input_report(x, y, buttons))
    step = 1 / (layout.axis_range[1] - layout.axis_range[0])
    assert abs(rx - x) <= step / 2 + 1e-12 and abs(ry - y) <= step / 2 + 1e-12 and rbuttons == buttons


def test_a_joystick_without_force_feedback_is_refused():
    with pytest.raises(PidError, match="not a force-feedback joystick"):
        PidDescriptor(PLAIN_JOYSTICK)
    with pytest.raises(PidError, match="unreadable HID report descriptor"):
        PidDescriptor(b"\x05\x01\x09")


def joystick(layout=None, invert=(), **moves):
    device = PidJoystick(layout or Layout())
    handle = FakeHandle(device)
    handle.move(**(moves or {"x": 0.5, "y": 0.5, "buttons": 0}))
    return device, handle, Joystick(handle, device.descriptor, 8.9, 0.0, 0.08, 1e-3, 4e-3, invert)


@pytest.mark.parametrize("layout", LAYOUTS, ids=["16-bit", "8-bit"])
def test_opening_creates_and_starts_one_constant_force_effect_per_axis(layout):
    device, handle, _ = joystick(layout)
    assert device.names() == ["control", "control", "gain"] + ["create", "set_effect", "constant", "operation"] * 2
    assert device.actuators and sorted(e["axes"] for e in device.effects.values()) == [(0, 1), (1, 0)]
    assert all(e["playing"] and e["type"] == 0x26 and e["magnitude"] == 0 for e in device.effects.values())
    durations = {e["duration"] for e in device.effects.values()}
    assert durations == {(1 << 16) - 1}  # Null: play until stopped
    assert handle.nonblocking


@pytest.mark.parametrize("layout", LAYOUTS, ids=["16-bit", "8-bit"])
def test_forces_reach_the_motors_in_proportion_and_clamped(layout):
    device, _, stick = joystick(layout)
    top = layout.magnitude_range[1]
    stick.write(4.45, -2.225)
    assert device.force() == pytest.approx((0.5, -0.25), abs=1 / top)
    stick.write(20.0, -20.0)
    assert device.force() == (1.0, -1.0)


def test_positions_map_onto_the_window_and_inverted_axes_flip():
    _, _, stick = joystick(x=0.25, y=0.75, buttons=1)
    assert stick.read() == pytest.approx((0.02, 1e-3 + 0.25 * 4e-3, 1), abs=1e-6)
    device, _, flipped = joystick(invert=("x", "y"), x=0.25, y=0.75, buttons=0)
    assert flipped.read()[:2] == pytest.approx((0.06, 1e-3 - 0.25 * 4e-3), abs=1e-6)
    flipped.write(1.0, 2.0)
    assert device.force() == pytest.approx((-1.0 / 8.9, -2.0 / 8.9), abs=2e-4)


def test_closing_zeroes_stops_frees_and_disables():
    device, handle, stick = joystick()
    stick.write(3.0, 3.0)
    stick.close()
    assert device.force() == (0.0, 0.0) and device.effects == {} and not device.actuators and handle.closed
    assert device.names()[-8:] == [
        "constant",
        "operation",
        "constant",
        "operation",
        "free",
        "free",
        "control",
        "control",
    ]


def test_emergency_stop_silences_later_writes():
    device, _, stick = joystick()
    stick.write(3.0, 3.0)
    stick.emergency_stop()
    stick.write(5.0, 5.0)
    assert device.force() == (0.0, 0.0)
    assert all(not e["playing"] for e in device.effects.values())


def test_a_vanished_device_ends_the_session_with_a_clear_error():
    _, handle, stick = joystick()
    handle.gone = True
    with pytest.raises(DeviceGone, match="stopped answering"):
        stick.read()
    stick.close()  # must not raise


def test_a_full_effect_memory_is_reported():
    device = PidJoystick()
    device.set_feature = lambda data: setattr(device, "pending", ("full", 0))
    handle = FakeHandle(device)
    with pytest.raises(PidError, match="effect memory is full"):
        Joystick(handle, device.descriptor, 8.9, 0.0, 0.08, 1e-3, 4e-3)


def test_a_whole_session_streams_the_model_and_switches_on_the_trigger():
    """The loop against the virtual device: the stick sweeps pressed into the surface,
    the trigger is pressed once; every force the device received is the model's."""
    first = Track(np.zeros(81), 1e-3)
    second = Track(np.full(81, 1e-3), 1e-3)
    device, handle, stick = joystick(x=0.1, y=0.2, buttons=0)
    for k in range(40):
        handle.schedule(k * 1e-3, x=0.1 + 0.02 * k, buttons=1 if 20 <= k < 23 else 0)
    result = run(
        stick, [first, second], QuasiStatic(), None, Settings(duration=0.04, ramp=0.0, realtime=True, watchdog=1.0)
    )
    streamed = [v[MAGNITUDE | 0] for _, name, v in device.log if name == "constant"][2:]
    pairs = np.array(streamed[: 2 * result.ticks]).reshape(-1, 2) / 10000 * 8.9
    np.testing.assert_allclose(pairs[:, 1], result.trace["F_y"], atol=8.9 / 10000)
    assert result.switches == 1 and (result.trace["h"][-5:] == 1e-3).all() and (result.trace["h"][:5] == 0).all()
    np.testing.assert_allclose(result.trace["F_y"], 1280.0 * (result.trace["h"] - result.trace["y_i"]), rtol=1e-12)
    assert result.trace["contact"].all()
    assert device.force() == (0.0, 0.0) and handle.closed
