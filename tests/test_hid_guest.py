"""The HID driver end to end, through a real kernel: a throwaway QEMU guest (the recipe
in ../shared/reference/virtual-hid) creates a virtual USB force-feedback joystick with
uhid, hid-tools serving its side, and runs ``rough render --device hid`` against it
(tests/vhid_guest.py). The guest is built once into build/vhid (or $ROUGH_VHID); this
needs qemu-system-x86 and root for apt-get, which .ci/run provides. Elsewhere it skips."""

import pytest
from guest import boot, guest_image, guest_python


@pytest.fixture(scope="module")
def outcome(tmp_path_factory):
    image = guest_image()
    return boot(image, guest_python(tmp_path_factory.mktemp("guest-python")), "vhid_guest.py", "vhid guest: started")


def test_rough_finds_the_joystick_and_sets_up_two_constant_force_effects(outcome):
    session = outcome["session"]
    assert session["streaming"], session
    assert session["setup"] == ["control", "control", "gain"] + ["create", "set_effect", "constant", "operation"] * 2
    assert "1209:0001" in session["report"]["device"]


def test_streamed_forces_are_the_models_for_the_stick_motion(outcome):
    session = outcome["session"]
    streamed, physics = session["streamed"], session["physics"]
    assert streamed["ticks"] >= streamed["trace_rows"] > 100
    assert streamed["max_difference"] == 0  # every Set Constant Force report is the traced force, to the bit
    assert streamed["nonzero"] > 50
    assert physics["contact_ticks"] > 50
    assert physics["max_law_error_N"] < 1e-6  # F_y = K (h - y_i)
    assert physics["max_lateral_error_N"] < 1e-6  # F_x = -F_y h'


def test_the_trigger_switches_surfaces(outcome):
    session = outcome["session"]
    assert session["report"]["surface_switches"] == 1
    assert session["physics"]["first_then_second"]


def test_ctrl_c_leaves_the_force_at_zero(outcome):
    session = outcome["session"]
    assert session["returncode"] == 0 and session["stderr"] == ""
    assert session["report"]["ended_by"] == "interrupt"
    assert session["final_force"] == [0.0, 0.0]
    assert session["effects_left"] == 0 and not session["actuators"]


def test_an_unplugged_joystick_ends_the_session_with_one_line(outcome):
    unplug = outcome["unplug"]
    assert unplug["streaming"] and not unplug["hung"]
    assert unplug["returncode"] == 1
    assert len(unplug["stderr"].strip().splitlines()) == 1 and "joystick" in unplug["stderr"]
    assert "Traceback" not in unplug["stderr"]
    assert unplug["exit_after_s"] < 5
