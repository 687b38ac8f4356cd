"""The evdev backend end to end, through a real kernel: a throwaway QEMU guest (the
recipe in ../shared/reference/virtual-hid) creates a virtual USB force-feedback
joystick with uinput, python-evdev serving its side, and runs ``rough render --device
evdev:/dev/input/eventN`` against it (tests/evdev_guest.py). The guest is built once
into build/vhid (or $ROUGH_VHID); this needs qemu-system-x86 and root for apt-get,
which .ci/run provides. Elsewhere it skips."""

import pytest
from guest import boot, guest_image, guest_python

pytest.importorskip("evdev", reason="python-evdev (the haptics extra) is not installed")

X_DIRECTION, Y_DIRECTION, FF_CONSTANT = 0x4000, 0x8000, 0x52


@pytest.fixture(scope="module")
def outcome(tmp_path_factory):
    image = guest_image()
    result = boot(
        image, guest_python(tmp_path_factory.mktemp("guest-python")), "evdev_guest.py", "evdev guest: started"
    )
    for name, scenario in result.items():
        assert "error" not in scenario, f"scenario {name}: {scenario['error']}"
    return result


def errors(stderr):
    """The lines of stderr that are not warnings (a stiffness over the passivity bound at
    the guest's low rate is warned about, rightly)."""
    return [line for line in stderr.splitlines() if ": warning: " not in line]


def test_rough_finds_the_device_and_sets_up_one_effect_per_axis(outcome):
    session = outcome["session"]
    assert session["streaming"], session
    assert session["setup"] == ["gain", "autocentre", "upload", "upload", "play", "play"]
    assert session["gain"] == 0xFFFF and session["autocentre"] == 0
    initial = [entry[1:] for entry in session["initial"]]  # type, direction, level, replay length (0: for ever)
    assert initial == [[FF_CONSTANT, X_DIRECTION, 0, 0], [FF_CONSTANT, Y_DIRECTION, 0, 0]]
    assert "(1209:0002) /dev/input/event" in session["report"]["device"]


def test_every_level_update_is_the_traced_force_to_the_lsb(outcome):
    streamed = outcome["session"]["streamed"]
    assert streamed["pairs"] > 50 and streamed["nonzero"] > 50
    assert streamed["max_difference"] == 0 and streamed["unmatched"] == 0
    for field, extra in streamed["extra"].items():  # at most the interrupted tick's untraced write, then zero
        assert 1 <= len(extra) <= 2 and extra[-1] == 0, (field, extra)


def test_the_stick_position_is_read_through_evdev(outcome):
    positions = outcome["session"]["positions"]
    assert positions["x_min"] == pytest.approx(1e-3, abs=1e-6)  # 10 % of a 10 mm span
    assert positions["x_max"] == pytest.approx(8.867e-3, abs=2e-5)
    assert positions["y_i"] == [pytest.approx(-0.1e-3, abs=1e-6)]  # the top (0.7 mm) less 20 % of 4 mm


def test_the_trigger_switches_surfaces(outcome):
    assert outcome["session"]["report"]["surface_switches"] == 1


def test_ctrl_c_zeroes_stops_and_erases_every_effect(outcome):
    session = outcome["session"]
    assert session["returncode"] == 0 and errors(session["stderr"]) == []
    assert session["report"]["ended_by"] == "interrupt" and session["exit_after_interrupt_s"] < 10
    assert session["effects_left"] == 0 and session["playing_left"] == []
    closing = session["closing"]
    assert {entry[0] for entry in closing} == {"upload", "stop", "erase"}
    assert all(entry[2] == 0 for entry in closing if entry[0] == "upload")
    assert sorted(entry[1] for entry in closing if entry[0] == "erase") == [entry[0] for entry in session["initial"]]


def test_a_device_with_room_for_one_effect_gets_one_polar_effect(outcome):
    polar = outcome["polar"]
    assert "(1209:0002) /dev/input/event" in polar["report"]["device"]  # found by rough among the guest's devices
    ours = [entry for entry in polar["seen"] if entry[0] in polar["report"]["device"]]
    assert [entry[1:] for entry in ours] == [["rough test FF joystick", ["FF_CONSTANT"], None]]
    assert polar["setup"] == ["gain", "autocentre", "upload", "play"]
    assert [entry[1:] for entry in polar["initial"]] == [[FF_CONSTANT, X_DIRECTION, 0, 0]]
    streamed = polar["streamed"]
    assert streamed["pairs"] == streamed["expected"] > 10 and streamed["mismatched"] == 0
    assert streamed["max_error_lsb"] < 2  # level rounding, and the direction's 2π/65536 steps
    assert streamed["directions"] > 3 and streamed["extra"][-1][1] == 0
    assert polar["returncode"] == 0 and polar["report"]["ended_by"] == "interrupt" and polar["effects_left"] == 0


def test_a_refused_second_effect_falls_back_to_one_polar_effect(outcome):
    refused = outcome["refused"]
    assert refused["streaming"] and [entry[0] for entry in refused["sequence"]] == [
        "upload",
        "refused",
        "erase",
        "upload",
        "play",
    ]
    assert refused["returncode"] == 0 and errors(refused["stderr"]) == [] and refused["effects_left"] == 0


def test_an_unplugged_device_ends_the_session_with_one_line(outcome):
    unplug = outcome["unplug"]
    assert unplug["streaming"] and not unplug["hung"]
    assert unplug["returncode"] == 1
    lines = errors(unplug["stderr"])
    assert len(lines) == 1 and "device" in lines[0] and "stopped answering" in lines[0], unplug["stderr"]
    assert "Traceback" not in unplug["stderr"]
    assert unplug["exit_after_s"] < 5
