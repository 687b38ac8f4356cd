"""Every render backend keeps the contract of rough.render.device: its declared facts,
its factory's signature, and (when it opens without hardware) the Device protocol
through a short run of the servo loop. Parametrised over device.backends() at
collection time, so an installed plugin (entry-point group rough.devices) is tested
by name with no edit here. Then the HID backend's guard against a joystick that a
kernel force-feedback driver holds (against a fake sysfs tree), and the stability
warning as the command line gives it."""

import inspect
import logging
import math
import os
import sys
import types

import numpy as np
import pytest

import rough
import rough.extras
from rough import RoughError
from rough.render import QuasiStatic, Settings, Track, forces, run, simulate
from rough.render import device as registry
from rough.render.device import Backend, Capabilities, Device, Workspace
from rough.render.hand import BACKEND as HAND
from rough.render.hid import find_joystick, kernel_force_feedback
from rough.render.pid import PidError

from conftest import assert_one_line_error
from conftest import rough as run_rough

BACKENDS = registry.backends()
TRACK = Track(np.zeros(101), 0.1e-3)  # 10 mm, flat
SPACE = Workspace(0.0, TRACK.length, 0.0, 1e-3)
MAX_FORCE = 2.0  # N
FACTORY = ("argument", "workspace", "max_force")


@pytest.mark.parametrize("name", list(BACKENDS))
def test_a_backend_declares_its_facts(name):
    backend = BACKENDS[name]
    assert isinstance(backend, Backend) and backend.name == name
    assert name and ":" not in name and name == name.strip()
    assert isinstance(backend.title, str) and backend.title
    assert backend.argument is None or (isinstance(backend.argument, str) and backend.argument.strip())
    assert isinstance(backend.requires, tuple) and all(isinstance(module, str) for module in backend.requires)
    assert isinstance(backend.simulated, bool)
    assert backend.form in registry.forms() and f"{name}: {backend.title}" in registry.descriptions()


@pytest.mark.parametrize("name", list(BACKENDS))
def test_its_factory_takes_the_registry_arguments(name):
    parameters = list(inspect.signature(registry.modules()[name].open_device).parameters.values())
    assert tuple(parameter.name for parameter in parameters[:3]) == FACTORY
    assert all(parameter.kind is inspect.Parameter.POSITIONAL_OR_KEYWORD for parameter in parameters[:3])
    assert parameters[-1].kind is inspect.Parameter.VAR_KEYWORD


@pytest.mark.parametrize("name", list(BACKENDS))
def test_it_opens_and_keeps_the_device_protocol_or_says_why_in_one_line(name):
    if BACKENDS[name].simulated:
        options = dict(speed=0.02, start_x=0.0, start_y=-1.0 / QuasiStatic().stiffness, period=1e-3)
        opened = registry.open_device(name, SPACE, MAX_FORCE, **options)
    else:
        try:
            opened = registry.open_device(name, SPACE, MAX_FORCE)
        except RoughError as error:  # no such hardware here, or its extra is not installed
            assert str(error) and "\n" not in str(error)
            return
    assert isinstance(opened, Device) and isinstance(opened.label, str)
    capabilities = opened.capabilities
    assert isinstance(capabilities, Capabilities) and capabilities.axes in (1, 2)
    assert capabilities.rate is None or capabilities.rate > 0
    assert capabilities.damping >= 0
    vx, vy = opened.velocity
    x, y, buttons = opened.read()
    assert all(math.isfinite(value) for value in (vx, vy, x, y)) and isinstance(buttons, int)
    if not capabilities.simulated:  # a real device: opened and closed, no force written
        opened.close()
        opened.close()
        return
    result = run(opened, [TRACK], QuasiStatic(), None, Settings(realtime=False, duration=0.05))
    assert result.ticks == 50 and result.ended_by == "duration"
    assert np.isfinite(result.trace["F_y"]).all() and np.isfinite(result.trace["F_x"]).all()
    opened.close()  # a second close is safe


def test_the_simulated_hand_renders_a_short_run():
    result = simulate(TRACK, speed=0.1)  # 0.1 s over the flat track
    assert result.ticks == 100 and result.settings.duration == pytest.approx(0.1)
    assert round(forces(result)["F_y_mean"], 9) == 1.0 and registry.is_simulated(HAND.name)


def test_an_unknown_device_names_every_backend():
    with pytest.raises(registry.DeviceError) as caught:
        registry.parse_device("no-such-device")
    for name, backend in BACKENDS.items():
        assert name in str(caught.value)
        assert backend.argument is None or f"{name}:{backend.argument}" in str(caught.value)


@pytest.fixture
def plugins(monkeypatch):
    """Install entry points ``{name: module}`` for the registry, afresh."""

    def install(points, modules=()):
        for module in modules:
            monkeypatch.setitem(sys.modules, module.__name__, module)
        monkeypatch.setattr(registry, "entry_points", lambda group: dict(points))
        registry.modules.cache_clear()

    yield install
    registry.modules.cache_clear()


def toy_module(module_name, name):
    toy = types.ModuleType(module_name)
    toy.BACKEND = Backend(name=name, title="a toy")
    toy.open_device = lambda argument, workspace, max_force, **options: None
    return toy


def test_a_plugin_joins_after_the_built_in_backends_which_win_over_it(plugins):
    plugins({"sim": "toy_sim", "toy": "toy_device"}, [toy_module("toy_sim", "sim"), toy_module("toy_device", "toy")])
    known = registry.backends()
    assert list(known)[-1] == "toy" and known["sim"].title == BACKENDS["sim"].title
    assert registry.forms().endswith(" or toy")


def test_a_broken_plugin_is_left_out_with_one_warning_line(plugins, caplog):
    plugins({"gone": "no_such_rough_device_module", "bare": "bare_device"}, [types.ModuleType("bare_device")])
    with caplog.at_level(logging.WARNING, logger="rough"):
        known = registry.backends()
    assert "gone" not in known and "bare" not in known
    warnings = [record.getMessage() for record in caplog.records]
    assert len(warnings) == 2 and all("\n" not in warning for warning in warnings)
    assert "'gone' (no_such_rough_device_module) is left out" in warnings[0]


def fake_sysfs(root, ff_bits, driver="hid-generic"):
    """/sys/class/hidraw/hidraw3 → a HID device with one input device (event7) whose
    force-feedback capability bits are ``ff_bits``."""
    device = root / "devices" / "pci0000:00" / "usb1" / "0003:1209:0001.0004"
    (device / "input" / "input7" / "capabilities").mkdir(parents=True)
    (device / "input" / "input7" / "event7").mkdir()
    (device / "input" / "input7" / "capabilities" / "ff").write_text(ff_bits + "\n")
    (root / "bus" / "hid" / "drivers" / driver).mkdir(parents=True)
    os.symlink(root / "bus" / "hid" / "drivers" / driver, device / "driver")
    (root / "class" / "hidraw" / "hidraw3").mkdir(parents=True)
    os.symlink(device, root / "class" / "hidraw" / "hidraw3" / "device")
    return root


def test_a_kernel_driver_offering_force_feedback_is_seen(tmp_path):
    sysfs = fake_sysfs(tmp_path, "107030000 0", driver="usbhid")
    assert kernel_force_feedback(b"/dev/hidraw3", str(sysfs)) == ("usbhid", "/dev/input/event7")


def test_an_input_device_without_force_feedback_is_not_a_hold(tmp_path):
    sysfs = fake_sysfs(tmp_path, "0")
    assert kernel_force_feedback(b"/dev/hidraw3", str(sysfs)) is None
    assert kernel_force_feedback(b"/dev/hidraw9", str(sysfs)) is None


class FakeHidraw:
    """hidapi's hidraw module with one joystick listed; opening it would be a failure
    of the guard."""

    opened = []

    @staticmethod
    def enumerate():
        return [{"path": b"/dev/hidraw3", "vendor_id": 0x1209, "product_id": 0x0001, "product_string": "FF stick"}]

    class device:
        def open_path(self, path):
            FakeHidraw.opened.append(path)
            raise OSError("must not be opened")


def test_the_hid_backend_refuses_a_joystick_the_kernel_drives_and_names_the_evdev_node(tmp_path, monkeypatch):
    sysfs = fake_sysfs(tmp_path, "107030000 0", driver="usbhid")
    monkeypatch.setattr(rough.extras, "require", lambda module: FakeHidraw)
    FakeHidraw.opened.clear()
    with pytest.raises(PidError) as refused:
        find_joystick("hid:1209:0001", sysfs=str(sysfs))
    message = str(refused.value)
    assert "usbhid" in message and "--device evdev:/dev/input/event7" in message and "\n" not in message
    assert FakeHidraw.opened == []


def test_the_hid_backend_opens_a_joystick_the_kernel_leaves_alone(tmp_path, monkeypatch):
    sysfs = fake_sysfs(tmp_path, "0")
    monkeypatch.setattr(rough.extras, "require", lambda module: FakeHidraw)
    FakeHidraw.opened.clear()
    with pytest.raises(PidError, match="could be opened"):
        find_joystick("hid", sysfs=str(sysfs))
    assert FakeHidraw.opened == [b"/dev/hidraw3"]


@pytest.mark.parametrize(
    "options, warns",
    [
        (["--hand-damping", "0.45N*s/m"], True),  # bound 0.9 N/mm at 1 kHz, under the default 1.28 N/mm
        (["--hand-damping", "0.45N*s/m", "--rate", "4kHz"], False),  # bound 3.6 N/mm
        (["--hand-damping", "0.45N*s/m", "--rate", "500Hz"], True),  # bound 0.45 N/mm
        ([], False),  # the simulated hand's 2 N·s/m: bound 4 N/mm
        (["--hand-damping", "0.45N*s/m", "--coupling", "0.9N/mm,0N*s/m"], False),
        (["--hand-damping", "0.45N*s/m", "--coupling", "2N/mm,0N*s/m"], True),
    ],
)
def test_the_stability_warning_fires_above_the_bound_and_is_silent_below(options, warns):
    result = run_rough("render", "--duration", "20ms", *options, rough.sample("rock-profile.tsv"))
    assert result.returncode == 0, result.stderr
    lines = result.stderr.decode().strip().splitlines()
    assert (len(lines) == 1 and "passivity bound" in lines[0]) if warns else lines == []


@pytest.mark.parametrize("option", [["--model", "dynamic"], ["--coupling", "0.5N/mm,0N*s/m"]])
def test_maps_refuse_the_profile_models(tmp_path, option):
    rough.Surface(np.zeros((5, 5)), (1e-4, 1e-4)).write(tmp_path / "flat.x3p")
    assert_one_line_error(run_rough("render", *option, tmp_path / "flat.x3p"), "profiles")
