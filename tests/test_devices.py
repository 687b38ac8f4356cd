"""The HID backend's guard against a joystick that a kernel force-feedback driver holds
(against a fake sysfs tree), and the stability warning as the command line gives it."""

import os

import numpy as np
import pytest

import rough
import rough.extras
from rough.render.hid import find_joystick, kernel_force_feedback
from rough.render.pid import PidError

from conftest import assert_one_line_error
from conftest import rough as run_rough


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
