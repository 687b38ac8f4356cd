"""The evdev force-feedback backend without a kernel: the effect encoding checked
against python-evdev's ``ff.Effect`` structures and the kernel's own conversion of a
direction into x and y (ff-memless), and the open/stream/close sequence and its faults
against an in-process stand-in for ``evdev.InputDevice``. tests/test_evdev_guest.py
runs the backend through a real kernel, against a uinput device."""

import collections
import ctypes
import errno
import math
import os
import threading
import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

evdev = pytest.importorskip("evdev", reason="python-evdev (the haptics extra) is not installed")
from evdev import ecodes, ff  # noqa: E402
from evdev.device import AbsInfo, DeviceInfo  # noqa: E402

import rough  # noqa: E402
from rough.render import QuasiStatic, Settings, Track, run  # noqa: E402
from rough.render import evdev as backend  # noqa: E402
from rough.render.device import Device, DeviceError, Workspace  # noqa: E402
from rough.render.evdev import (  # noqa: E402
    FULL_LEVEL,
    X_DIRECTION,
    Y_DIRECTION,
    DeviceGone,
    EvdevDevice,
    EvdevError,
    axis_effects,
    constant_effect,
    decode,
    level,
    polar_effect,
)
from rough.render.loop import LoopStalled  # noqa: E402

MAX_FORCE = 8.9
NO_SYSFS = "/nonexistent-sysfs"  # the finding tests look at their nodes, not at this machine's devices
SPACE = Workspace(0.0, 0.01, 0.0, 0.004)
JOYSTICK_KEYS = (ecodes.BTN_THUMB2, ecodes.BTN_TRIGGER, ecodes.BTN_THUMB, ecodes.BTN_TOP)


def kernel_xy(direction, value):
    """ff-memless's ml_combine_effects: the x and y of a constant force (before its s8
    scaling; whole degrees, as the kernel has them), the reference the encoding must
    agree with."""
    degrees = direction * 360 // 0xFFFF
    return value * math.sin(math.radians(degrees)), -value * math.cos(math.radians(degrees))


class FakeInputDevice:
    """What rough uses of ``evdev.InputDevice``, with an effect memory like the kernel's
    ff-core: every upload is checked as the bytes the ioctl would carry."""

    def __init__(self, axes=2, room=16, ff_codes=None, keys=JOYSTICK_KEYS, refuse=()):
        self.path, self.name = "/dev/input/event7", "Fake FF joystick"
        self.info = DeviceInfo(0x03, 0x1209, 0x0001, 0x0100)
        self.ff_effects_count = room
        self.ff_codes = (
            [ecodes.FF_CONSTANT, ecodes.FF_GAIN, ecodes.FF_AUTOCENTER] if ff_codes is None else list(ff_codes)
        )
        self.abs = {ecodes.ABS_X: AbsInfo(0, -32767, 32767, 0, 0, 0), ecodes.ABS_Y: AbsInfo(0, -32767, 32767, 0, 0, 0)}
        if axes == 1:
            del self.abs[ecodes.ABS_Y]
        self.keys, self.pressed = list(keys), set()
        self.refuse = list(refuse)  # errno for the n-th new effect, or None to accept it
        self.memory, self.playing = {}, set()
        self.gain = self.autocentre = None
        self.log, self.events = [], collections.deque()
        self.closed, self.lost = False, None

    # what the backend calls
    def capabilities(self, verbose=False, absinfo=True):
        found = {ecodes.EV_ABS: list(self.abs), ecodes.EV_FF: self.ff_codes}
        if self.keys:
            found[ecodes.EV_KEY] = self.keys
        return found

    def absinfo(self, code):
        self._check()
        return self.abs[code]

    def active_keys(self):
        self._check()
        return sorted(self.pressed)

    def read_one(self):
        self._check()
        return self.events.popleft() if self.events else None

    def write(self, kind, code, value):
        self._check()
        assert kind == ecodes.EV_FF
        self.log.append(("write", code, value))
        if code == ecodes.FF_GAIN:
            self.gain = value
        elif code == ecodes.FF_AUTOCENTER:
            self.autocentre = value
        elif value:
            assert code in self.memory
            self.playing.add(code)
        else:
            self.playing.discard(code)

    def upload_effect(self, effect):
        self._check()
        sent = ff.Effect.from_buffer_copy(memoryview(effect).tobytes())  # what EVIOCSFF carries
        assert sent.type == ecodes.FF_CONSTANT and sent.ff_replay.length == 0 and sent.ff_replay.delay == 0
        assert sent.ff_trigger.button == 0 and bytes(sent.u.ff_constant_effect.ff_envelope) == bytes(8)
        if sent.id == -1:
            refusal = self.refuse.pop(0) if self.refuse else None
            if refusal is not None:
                raise OSError(refusal, "refused")
            if len(self.memory) >= self.ff_effects_count:
                raise OSError(errno.ENOSPC, "No space left on device")
            sent.id = min(set(range(self.ff_effects_count)) - set(self.memory))
        else:
            assert sent.id in self.memory, "an update of an effect that was never uploaded"
        self.memory[sent.id] = (sent.direction, sent.u.ff_constant_effect.level)
        self.log.append(("upload", sent.id, sent.direction, sent.u.ff_constant_effect.level))
        effect.id = sent.id
        return sent.id

    def erase_effect(self, effect_id):
        self._check()
        self.log.append(("erase", effect_id))
        del self.memory[effect_id]
        self.playing.discard(effect_id)

    def close(self):
        self.closed = True

    # the device's side
    def _check(self):
        if self.closed:
            raise OSError(errno.EBADF, "Bad file descriptor")
        if self.lost:
            raise OSError(self.lost, "No such device")

    def move(self, x=None, y=None, **buttons):
        for code, value in ((ecodes.ABS_X, x), (ecodes.ABS_Y, y)):
            if value is not None:
                self.events.append(evdev.InputEvent(0, 0, ecodes.EV_ABS, code, value))
                self.abs[code] = self.abs[code]._replace(value=value)
        for name, down in buttons.items():
            code = ecodes.ecodes[name]
            self.events.append(evdev.InputEvent(0, 0, ecodes.EV_KEY, code, int(down)))
            (self.pressed.add if down else self.pressed.discard)(code)
        self.events.append(evdev.InputEvent(0, 0, ecodes.EV_SYN, ecodes.SYN_REPORT, 0))

    def force(self):
        """The force the kernel would play: the sum of the playing effects, fractions of full."""
        x = y = 0.0
        for effect_id in self.playing:
            gx, gy = kernel_xy(*self.memory[effect_id])
            x, y = x + gx / FULL_LEVEL, y + gy / FULL_LEVEL
        return x, y

    def uploads(self):
        return [entry[1:] for entry in self.log if entry[0] == "upload"]


def opened(fake=None, workspace=SPACE):
    fake = fake or FakeInputDevice()
    return fake, EvdevDevice(fake, workspace, MAX_FORCE)


# -- the encoding ---------------------------------------------------------------------------------


def test_an_effect_is_python_evdevs_ff_effect_as_the_kernel_takes_it():
    effect = constant_effect(X_DIRECTION, -1234, effect_id=5)
    assert isinstance(effect, ff.Effect) and ctypes.sizeof(effect) == 48  # struct ff_effect on 64-bit Linux
    sent = ff.Effect.from_buffer_copy(memoryview(effect).tobytes())
    assert (sent.type, sent.id, sent.direction) == (ecodes.FF_CONSTANT, 5, 0x4000)
    assert sent.u.ff_constant_effect.level == -1234
    assert (sent.ff_replay.length, sent.ff_replay.delay) == (0, 0)  # length 0: played until stopped
    assert (sent.ff_trigger.button, sent.ff_trigger.interval) == (0, 0)
    assert constant_effect(Y_DIRECTION, 0).id == -1  # a new effect: the kernel picks its id


@pytest.mark.parametrize(
    ("gx", "gy", "expected"),
    [
        (0.5, 0.0, [(0x4000, 16384), (0x8000, 0)]),
        (-0.5, 0.0, [(0x4000, -16384), (0x8000, 0)]),
        (0.0, 0.25, [(0x4000, 0), (0x8000, 8192)]),
        (0.0, -0.25, [(0x4000, 0), (0x8000, -8192)]),
        (2.0, -7.0, [(0x4000, FULL_LEVEL), (0x8000, -FULL_LEVEL)]),  # clamped to full
        (math.nan, math.inf, [(0x4000, 0), (0x8000, 0)]),  # never a glitch to the device
    ],
)
def test_one_effect_per_axis_carries_the_signed_force(gx, gy, expected):
    assert axis_effects(gx, gy) == expected
    assert axis_effects(gx, gy, axes=1) == expected[:1]


@pytest.mark.parametrize(("gx", "gy"), [(1, 0), (-1, 0), (0, 1), (0, -1), (0.6, -0.8)])
def test_a_positive_level_pushes_along_the_increasing_axis_as_the_kernel_converts_it(gx, gy):
    x = sum(kernel_xy(*effect)[0] for effect in axis_effects(gx, gy))
    y = sum(kernel_xy(*effect)[1] for effect in axis_effects(gx, gy))
    assert x == pytest.approx(gx * FULL_LEVEL, abs=1.0) and y == pytest.approx(gy * FULL_LEVEL, abs=1.0)


@pytest.mark.parametrize(
    ("gx", "gy", "direction", "side"),
    [
        (0.0, -1.0, 0x0000, "down"),  # pushes up (away from the user): comes from below
        (1.0, 0.0, 0x4000, "left"),  # pushes towards +x: comes from the left
        (0.0, 1.0, 0x8000, "up"),  # pushes towards the user: comes from above
        (-1.0, 0.0, 0xC000, "right"),
        (0.5, 0.5, 0x6000, "up-left"),
    ],
)
def test_a_polar_effect_comes_from_the_side_linux_input_h_names(gx, gy, direction, side):
    found, magnitude = polar_effect(gx, gy)
    assert found == direction, side
    assert magnitude == level(math.hypot(gx, gy))
    x, y = kernel_xy(found, magnitude)
    assert (x, y) == (pytest.approx(gx * FULL_LEVEL, abs=3), pytest.approx(gy * FULL_LEVEL, abs=3))


def test_a_polar_effect_clamps_the_magnitude_and_keeps_its_direction_at_zero():
    assert polar_effect(3.0, 4.0)[1] == FULL_LEVEL
    assert polar_effect(0.0, 0.0, direction=0x1234) == (0x1234, 0)
    assert polar_effect(math.nan, 0.0, direction=7) == (7, 0)


@settings(max_examples=300, deadline=None)
@given(st.floats(-MAX_FORCE, MAX_FORCE))
def test_the_level_round_trips_within_one_lsb(force):
    assert abs(level(force / MAX_FORCE) * MAX_FORCE / FULL_LEVEL - force) <= MAX_FORCE / FULL_LEVEL / 2 + 1e-12


@settings(max_examples=300, deadline=None)
@given(st.floats(-1, 1), st.floats(-1, 1))
def test_a_polar_effect_round_trips_within_its_resolution(gx, gy):
    scale = min(1.0, 1.0 / max(math.hypot(gx, gy), 1e-300))
    gx, gy = gx * scale, gy * scale
    x, y = decode(*polar_effect(gx, gy))
    tolerance = 1 / FULL_LEVEL + math.hypot(gx, gy) * math.pi / 0x10000 + 1e-12
    assert math.hypot(x - gx, y - gy) <= tolerance


# -- opening ------------------------------------------------------------------------------------------


def test_opening_sets_full_gain_no_autocentre_and_plays_one_effect_per_axis():
    fake, device = opened()
    assert isinstance(device, Device)
    assert device.label == "Fake FF joystick (1209:0001) /dev/input/event7"
    assert device.capabilities.axes == 2 and device.capabilities.needs_watchdog and not device.polar
    assert device.velocity == (0.0, 0.0)
    assert fake.log == [
        ("write", ecodes.FF_GAIN, 0xFFFF),
        ("write", ecodes.FF_AUTOCENTER, 0),
        ("upload", 0, 0x4000, 0),
        ("upload", 1, 0x8000, 0),
        ("write", 0, 1),
        ("write", 1, 1),
    ]
    assert fake.playing == {0, 1} and fake.force() == (0.0, 0.0)


def test_gain_and_autocentre_are_left_alone_where_the_device_has_neither():
    fake, _ = opened(FakeInputDevice(ff_codes=[ecodes.FF_CONSTANT]))
    assert fake.gain is None and fake.autocentre is None and len(fake.memory) == 2


def test_a_device_with_room_for_one_effect_gets_one_polar_effect():
    fake, device = opened(FakeInputDevice(room=1))
    assert device.polar and fake.uploads() == [(0, 0x4000, 0)] and fake.playing == {0}
    device.write(0.0, -MAX_FORCE / 2)
    assert fake.uploads()[-1] == (0, 0x0000, 16384)  # pushing up (-y) comes from below
    device.write(MAX_FORCE * 0.3, MAX_FORCE * 0.4)
    assert fake.force() == (pytest.approx(0.3, abs=1e-3), pytest.approx(0.4, abs=1e-3))


def test_a_refused_second_effect_falls_back_to_one_polar_effect():
    fake, device = opened(FakeInputDevice(refuse=[None, errno.ENOSPC]))
    assert device.polar
    assert [entry[0] for entry in fake.log] == ["write", "write", "upload", "erase", "upload", "write"]
    assert list(fake.memory) == [0] and fake.playing == {0}


def test_refused_effects_either_way_are_one_clear_error_with_nothing_left_behind():
    fake = FakeInputDevice(refuse=[None, errno.ENOSPC, errno.EINVAL])
    with pytest.raises(EvdevError, match="refused constant-force effects, one per axis and one polar") as caught:
        EvdevDevice(fake, SPACE, MAX_FORCE)
    assert "\n" not in str(caught.value) and isinstance(caught.value, rough.RoughError)
    assert fake.memory == {} and fake.closed


def test_a_wheel_refusing_its_effect_is_a_clear_error():
    fake = FakeInputDevice(axes=1, refuse=[errno.EINVAL])
    with pytest.raises(EvdevError, match="refused a constant-force effect"):
        EvdevDevice(fake, SPACE, MAX_FORCE)
    assert fake.closed


def test_a_device_without_constant_force_is_refused_naming_what_it_offers():
    fake = FakeInputDevice(ff_codes=[ecodes.FF_RUMBLE, ecodes.FF_PERIODIC, ecodes.FF_GAIN])
    with pytest.raises(EvdevError, match=r"offers no constant force \(FF_CONSTANT\); it offers FF_RUMBLE, FF_PERIODIC"):
        EvdevDevice(fake, SPACE, MAX_FORCE)
    assert fake.closed and fake.log == []


@pytest.mark.parametrize("where", ["upload", "play"])
def test_a_fault_in_the_middle_of_opening_erases_what_was_uploaded(where):
    fake = FakeInputDevice()
    original = getattr(fake, "write" if where == "play" else "upload_effect")

    def failing(*arguments):
        if where == "upload" and len(fake.memory) == 1 or where == "play" and arguments[1] == 1:
            raise OSError(errno.EIO, "Input/output error")
        return original(*arguments)

    setattr(fake, "write" if where == "play" else "upload_effect", failing)
    with pytest.raises(DeviceGone, match="stopped answering"):
        EvdevDevice(fake, SPACE, MAX_FORCE)
    assert fake.memory == {} and fake.playing == set() and fake.closed


def test_an_interrupt_while_opening_leaves_nothing_behind():
    fake = FakeInputDevice()
    original = fake.upload_effect

    def interrupted(effect):
        new = effect.id == -1
        original(effect)
        if new and len(fake.memory) == 2:
            raise KeyboardInterrupt  # after the ioctl, before python-evdev wrote the id back

    fake.upload_effect = interrupted
    with pytest.raises(KeyboardInterrupt):
        EvdevDevice(fake, SPACE, MAX_FORCE)
    assert fake.closed and fake.memory == {1: (0x8000, 0)}  # its id never came back: closing the node frees it


# -- streaming -----------------------------------------------------------------------------------------


def test_forces_are_written_as_levels_and_only_when_they_change():
    fake, device = opened()
    before = len(fake.log)
    device.write(MAX_FORCE / 2, -MAX_FORCE / 4)
    device.write(MAX_FORCE / 2, -MAX_FORCE / 4)  # unchanged: no ioctl
    device.write(MAX_FORCE / 2, 0.0)  # only y changed
    assert fake.log[before:] == [("upload", 0, 0x4000, 16384), ("upload", 1, 0x8000, -8192), ("upload", 1, 0x8000, 0)]
    assert fake.force() == (pytest.approx(0.5, abs=1e-4), pytest.approx(0.0, abs=1e-12))


def test_the_workspace_reverses_an_inverted_axis_force_and_position():
    fake, device = opened(workspace=Workspace(0.0, 0.01, 0.0, 0.004, invert=("x",)))
    device.write(MAX_FORCE / 2, MAX_FORCE / 2)
    assert fake.memory == {0: (0x4000, -16384), 1: (0x8000, 16384)}
    fake.move(x=32767, y=-32767)
    assert device.read()[:2] == (pytest.approx(0.0), pytest.approx(-0.002))


def test_reading_drains_every_pending_event_and_keeps_the_newest():
    fake, device = opened()
    assert device.read() == (pytest.approx(0.005), pytest.approx(0.0), 0)  # centred at the start
    fake.move(x=-32767, y=32767)
    fake.move(x=32767, BTN_TRIGGER=1)
    fake.move(BTN_THUMB2=1)
    x, y, buttons = device.read()
    assert (x, y) == (pytest.approx(0.01), pytest.approx(0.002)) and not fake.events
    assert buttons == 0b101  # trigger and the third button (in key-code order: TRIGGER, THUMB, THUMB2)
    fake.move(BTN_TRIGGER=0, BTN_TOP=1)  # the fourth button is not reported
    assert device.read()[2] == 0b100


def test_after_dropped_events_the_state_is_read_back_from_the_kernel():
    fake, device = opened()
    fake.abs[ecodes.ABS_X] = fake.abs[ecodes.ABS_X]._replace(value=32767)
    fake.pressed.add(ecodes.BTN_THUMB)
    fake.events.append(evdev.InputEvent(0, 0, ecodes.EV_SYN, ecodes.SYN_DROPPED, 0))
    assert device.read() == (pytest.approx(0.01), pytest.approx(0.0), 0b010)


def test_a_wheel_has_one_force_axis_and_rests_in_the_middle_of_y():
    fake, device = opened(FakeInputDevice(axes=1, keys=(ecodes.BTN_SOUTH, ecodes.BTN_EAST)))
    assert device.capabilities.axes == 1 and fake.uploads() == [(0, 0x4000, 0)]
    device.write(-MAX_FORCE, MAX_FORCE)  # the y force has nowhere to go
    assert fake.memory == {0: (0x4000, -FULL_LEVEL)}
    fake.move(x=0, BTN_SOUTH=1)
    assert device.read() == (pytest.approx(0.005), pytest.approx(0.0), 1)


def test_a_starting_position_is_read_from_the_kernel():
    fake = FakeInputDevice()
    fake.abs[ecodes.ABS_X] = fake.abs[ecodes.ABS_X]._replace(value=-32767)
    fake.pressed.add(ecodes.BTN_TRIGGER)
    _, device = opened(fake)
    assert device.read() == (pytest.approx(0.0), pytest.approx(0.0), 1)


# -- stopping ------------------------------------------------------------------------------------------


def test_closing_zeroes_stops_and_erases_every_effect_once():
    fake, device = opened()
    device.write(MAX_FORCE, MAX_FORCE)
    device.close()
    assert fake.memory == {} and fake.playing == set() and fake.closed
    tail = fake.log[-6:]
    assert tail[:4] == [("upload", 0, 0x4000, 0), ("write", 0, 0), ("upload", 1, 0x8000, 0), ("write", 1, 0)]
    assert sorted(tail[4:]) == [("erase", 0), ("erase", 1)]
    entries = len(fake.log)
    device.close()
    device.write(1.0, 1.0)
    assert len(fake.log) == entries


def test_an_emergency_stop_zeroes_the_force_and_ignores_later_writes():
    fake, device = opened()
    device.write(MAX_FORCE, 0.0)
    device.emergency_stop()
    assert fake.playing == set() and all(value == 0 for _, value in fake.memory.values())
    device.write(MAX_FORCE, MAX_FORCE)
    device.zero()
    assert all(value == 0 for _, value in fake.memory.values()) and fake.playing == set()
    device.close()
    assert fake.memory == {}


def test_an_emergency_stop_from_another_thread_waits_for_the_write_in_progress():
    fake, device = opened()
    inside, release = threading.Event(), threading.Event()
    original = fake.upload_effect

    def slow(effect):
        inside.set()
        release.wait(5)
        return original(effect)

    fake.upload_effect = slow
    writer = threading.Thread(target=device.write, args=(MAX_FORCE, MAX_FORCE))
    writer.start()
    inside.wait(5)
    stopper = threading.Thread(target=device.emergency_stop)
    stopper.start()
    time.sleep(0.05)
    assert stopper.is_alive()  # the lock: the stop comes after the write, not in the middle of it
    release.set()
    writer.join(5)
    stopper.join(5)
    assert fake.playing == set() and all(value == 0 for _, value in fake.memory.values())


@pytest.mark.parametrize("where", ["write", "read"])
def test_a_lost_device_is_one_line_and_closing_it_afterwards_is_quiet(where):
    fake, device = opened()
    fake.lost = errno.ENODEV
    with pytest.raises(DeviceGone) as caught:
        device.write(MAX_FORCE, 0.0) if where == "write" else device.read()
    message = str(caught.value)
    assert "\n" not in message and "device" in message and "No such device" in message
    assert isinstance(caught.value, DeviceError) and caught.value.exit_code == 1
    device.close()
    assert fake.closed


# -- the servo loop on the device ----------------------------------------------------------------------


def sine_track():
    x = np.arange(101) * 0.1e-3
    return Track(0.2e-3 * np.sin(2 * np.pi * x / 4e-3), 0.1e-3)


def test_the_loop_streams_its_traced_forces_as_levels_and_leaves_nothing_behind():
    fake = FakeInputDevice()
    fake.abs[ecodes.ABS_Y] = fake.abs[ecodes.ABS_Y]._replace(value=-16000)  # pressed into the surface
    device = EvdevDevice(fake, Workspace(0.0, 0.01, 0.2e-3, 4e-3), MAX_FORCE)
    original, ticks = fake.read_one, []

    def sweeping():  # the stick moves a little between one tick's read and the next
        event = original()
        if event is None:
            ticks.append(None)
            fake.move(x=min(32767, -32767 + 300 * len(ticks)))
        return event

    fake.read_one = sweeping
    result = run(device, [sine_track()], QuasiStatic(), settings=Settings(duration=0.2, realtime=False))
    levels = {0: [0], 1: [0]}
    for effect_id, _, value in fake.uploads()[2:]:
        levels[effect_id].append(value)
    for effect_id, field in ((0, "F_x"), (1, "F_y")):
        expected = [0] + [int(v) for v in np.round(result.trace[field] / MAX_FORCE * FULL_LEVEL)]
        changes = [v for i, v in enumerate(expected) if i == 0 or v != expected[i - 1]]
        assert levels[effect_id][: len(changes)] == changes
        assert levels[effect_id][len(changes) :] == [0]  # the zero of closing
    assert np.count_nonzero(result.trace["F_y"]) > 50
    assert fake.memory == {} and fake.closed


def test_a_stalled_loop_has_its_force_zeroed_by_the_watchdog():
    fake = FakeInputDevice()
    fake.abs[ecodes.ABS_Y] = fake.abs[ecodes.ABS_Y]._replace(value=-16000)  # pressed in: a force from the start
    device = EvdevDevice(fake, Workspace(0.0, 0.01, 0.2e-3, 4e-3), MAX_FORCE)
    original, calls, stalled = fake.read_one, [], []

    def stalling():
        calls.append(None)
        if len(calls) == 5:  # the loop hangs in a read, with the force on
            stalled.append([value for _, value in fake.memory.values()])
            deadline = time.monotonic() + 5
            while fake.playing and time.monotonic() < deadline:
                time.sleep(0.01)
            stalled.append((set(fake.playing), [value for _, value in fake.memory.values()]))
        return original()

    fake.read_one = stalling
    with pytest.raises(LoopStalled):
        run(device, [sine_track()], QuasiStatic(), settings=Settings(rate=200, duration=5.0, watchdog=0.1, priority=0))
    before, (playing, levels) = stalled
    assert any(before) and playing == set() and levels == [0, 0]  # zeroed by the watchdog while the loop hung
    assert fake.memory == {} and fake.closed


# -- finding the device --------------------------------------------------------------------------------


@pytest.fixture
def nodes(tmp_path, monkeypatch):
    """A folder of event nodes whose opening is played by fakes."""
    table = {}

    def fake_open(path):
        what = table[path]
        if isinstance(what, OSError):
            raise what
        return what

    monkeypatch.setattr(backend, "_open", fake_open)

    def add(number, what):
        path = str(tmp_path / f"event{number}")
        (tmp_path / f"event{number}").touch()
        table[path] = what
        return path

    return tmp_path, add


def keyboard():
    fake = FakeInputDevice(ff_codes=[])
    fake.name = "AT keyboard"
    return fake


def test_the_first_device_offering_constant_force_is_found_in_number_order(nodes):
    folder, add = nodes
    add(10, FakeInputDevice())
    add(2, keyboard())
    rumble = FakeInputDevice(ff_codes=[ecodes.FF_RUMBLE])
    rumble.name = "Pad"
    add(3, rumble)
    add(9, FakeInputDevice())
    assert [os.path.basename(path) for path, *_ in backend.find_devices(str(folder), NO_SYSFS)] == [
        "event2",
        "event3",
        "event9",
        "event10",
    ]
    assert backend.find_devices(str(folder), NO_SYSFS)[1][1:] == ("Pad", ("FF_RUMBLE",), None)
    chosen = backend.find_device(folder=str(folder), sysfs=NO_SYSFS)
    assert chosen is backend._open(str(folder / "event9"))


def test_no_device_with_constant_force_is_one_line_naming_what_was_seen(nodes):
    folder, add = nodes
    add(0, keyboard())
    rumble = FakeInputDevice(ff_codes=[ecodes.FF_RUMBLE])
    rumble.name = "Pad"
    add(1, rumble)
    add(2, PermissionError(errno.EACCES, "Permission denied"))
    with pytest.raises(EvdevError) as caught:
        backend.find_device(folder=str(folder), sysfs=NO_SYSFS)
    message = str(caught.value)
    assert message.startswith("no force-feedback device found: none of 3 event devices offers constant force")
    assert "event0 'AT keyboard' (no force feedback)" in message and "event1 'Pad' (only FF_RUMBLE)" in message
    assert "event2 (Permission denied)" in message and "the input group" in message and "\n" not in message


def test_a_named_node_that_cannot_be_opened_says_why(nodes, monkeypatch):
    folder, add = nodes
    denied = add(4, PermissionError(errno.EACCES, "no permission to write to it"))
    with pytest.raises(EvdevError, match="event4: no permission to write to it .*input group.*udev rule"):
        backend.find_device(denied)
    missing = add(5, FileNotFoundError(errno.ENOENT, "No such file or directory"))
    with pytest.raises(EvdevError, match="event5: no such device node"):
        backend.find_device(missing)


def test_the_factory_opens_the_named_node_and_closes_it_on_a_refusal(nodes):
    folder, add = nodes
    path = add(6, FakeInputDevice())
    device = rough.render.device.open_device(f"evdev:{path}", SPACE, MAX_FORCE)
    assert isinstance(device, EvdevDevice) and device.label.endswith("/dev/input/event7")
    device.close()
    keys_only = add(7, keyboard())
    with pytest.raises(EvdevError, match="offers no constant force"):
        rough.render.device.open_device(f"evdev:{keys_only}", SPACE, MAX_FORCE)
    assert backend._open(keys_only).closed


def test_a_node_python_evdev_opens_read_only_is_a_permission_error(tmp_path, monkeypatch):
    class ReadOnly:
        def __init__(self, path):
            self.fd = os.open(tmp_path / "node", os.O_RDONLY | os.O_CREAT)
            self.closed = False

        def close(self):
            os.close(self.fd)
            self.closed = True

    monkeypatch.setattr(evdev, "InputDevice", ReadOnly)
    with pytest.raises(PermissionError, match="no permission to write"):
        backend._open(str(tmp_path / "node"))


def fake_sysfs(root, node, name, ff_words):
    device = root / "class" / "input" / node / "device"
    (device / "capabilities").mkdir(parents=True)
    (device / "name").write_text(name + "\n")
    (device / "capabilities" / "ff").write_text(ff_words + "\n")


def test_what_each_node_offers_is_read_from_sysfs_without_opening_it(nodes, tmp_path):
    folder, add = nodes
    sysfs = tmp_path / "sys"
    fake_sysfs(sysfs, "event0", "AT keyboard", "0")
    fake_sysfs(sysfs, "event1", "Pad", "10000 0")  # FF_RUMBLE: bit 0x50, in the second 64-bit word
    fake_sysfs(sysfs, "event2", "Wheel", "300040000 0")  # FF_CONSTANT, FF_GAIN, FF_AUTOCENTER
    for number in range(3):
        add(number, PermissionError(errno.EACCES, "Permission denied"))
    seen = backend.find_devices(str(folder), str(sysfs))
    assert [entry[1:] for entry in seen] == [
        ("AT keyboard", (), None),
        ("Pad", ("FF_RUMBLE",), None),
        ("Wheel", ("FF_CONSTANT",), None),
    ]
    with pytest.raises(EvdevError, match=r"event2 \(Wheel\): Permission denied \(.*input group"):
        backend.find_device(folder=str(folder), sysfs=str(sysfs))
    wheel = FakeInputDevice(axes=1)
    add(2, wheel)
    assert backend.find_device(folder=str(folder), sysfs=str(sysfs)) is wheel
