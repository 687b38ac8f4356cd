"""Runs inside the throwaway QEMU guest (../shared/reference/virtual-hid): makes a
virtual USB force-feedback joystick through /dev/uhid, with hid-tools as the device
side, and runs ``rough render --device hid`` against it as a user would. Prints one
line ``RESULT {json}`` with what happened; tests/test_hid_guest.py judges it.

Scenario "session": the stick sweeps across the window pressed into the surface, the
trigger is pressed once, then rough gets SIGINT. Scenario "unplug": the device is
destroyed while rough streams forces.
"""

import json
import pathlib
import signal
import sys
import threading
import time

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import numpy as np
from guest_tools import ending, scratch_folder, start_render
from hidtools.uhid import UHIDDevice
from virtual_joystick import PidJoystick

from rough import Surface

VID, PID = 0x1209, 0x0001
SPACING = 0.1e-3
MAX_FORCE = 8.9


class VirtualJoystick(UHIDDevice):
    def __init__(self):
        super().__init__()
        self.model = PidJoystick()
        self.name = "rough test FF joystick"
        self.info = (0x03, VID, PID)
        self.phys = "rough-test/0"
        self.rdesc = self.model.descriptor
        self.streaming = threading.Event()

    def output_report(self, data, size, rtype):
        self.model.output(bytes(data[:size]))
        if sum(e["playing"] for e in self.model.effects.values()) == 2:
            self.streaming.set()

    def set_report(self, req, rnum, rtype, data):
        self.model.set_feature(bytes(data))
        return 0

    def get_report(self, req, rnum, rtype):
        return 0, list(self.model.get_feature(rnum))

    def move(self, x=None, y=None, buttons=None):
        self.call_input_event(self.model.input_report(x, y, buttons))


def serve(stop):
    while not stop.is_set():
        UHIDDevice.dispatch(0.01)


def profiles(folder):
    x = np.arange(101) * SPACING
    first = 0.2e-3 * np.sin(2 * np.pi * x / 4e-3)
    second = first + 0.5e-3
    Surface(first, (SPACING,), metadata={"title": "A"}).write(folder / "a.x3p")
    Surface(second, (SPACING,), metadata={"title": "B"}).write(folder / "b.x3p")
    return first, second


def start_rough(folder, *extra):
    return start_render(folder, f"hid:{VID:04x}:{PID:04x}", *extra)


def plug_in(x):
    """A new virtual joystick, served by a thread until the returned event is set."""
    device = VirtualJoystick()
    device.create_kernel_device()
    stop = threading.Event()
    threading.Thread(target=serve, args=(stop,), daemon=True).start()
    time.sleep(0.5)
    device.move(x, 0.3, 0)
    return device, stop


def session(folder, first, second):
    device, stop = plug_in(0.1)
    started = time.monotonic()
    rough = start_rough(folder, "--trace", str(folder / "trace.tsv"))
    streaming = device.streaming.wait(120)
    setup = device.model.names()
    sweep_start = time.monotonic()
    for step in range(60):
        device.move(0.1 + 0.8 * step / 60, 0.3, 1 if 30 <= step < 33 else 0)
        time.sleep(0.02)
    time.sleep(0.2)
    rough.send_signal(signal.SIGINT)
    out, err = rough.communicate(timeout=60)
    time.sleep(0.3)
    forces = [(t, v[0xF0022], v[0xF0070]) for t, name, v in device.model.log if name == "constant"]
    trace = np.genfromtxt(folder / "trace.tsv", names=True, delimiter="\t")
    stop.set()
    device.destroy()
    return {
        "streaming": streaming,
        "startup_s": sweep_start - started,
        "setup": setup,
        "returncode": rough.returncode,
        "stderr": err,
        "report": json.loads(out)["runs"][0] if out.strip() else None,
        "final_force": device.model.force(),
        "effects_left": len(device.model.effects),
        "actuators": device.model.actuators,
        "after_close": [name for _, name, _ in device.model.log][-6:],
        "streamed": _streamed(forces, trace),
        "physics": _physics(trace, first, second),
    }


def _streamed(forces, trace):
    """Pair the Set Constant Force reports (x block then y block, each tick) with the
    trace's forces: the largest difference in logical units."""
    ticks = [
        (forces[i][2], forces[i + 1][2])
        for i in range(2, len(forces) - 1, 2)
        if forces[i][1] == 1 and forces[i + 1][1] == 2
    ]
    count = min(len(ticks), trace.size)
    expected = np.column_stack(
        [np.round(trace["F_x"][:count] / MAX_FORCE * 10000), np.round(trace["F_y"][:count] / MAX_FORCE * 10000)]
    )
    sent = np.array(ticks[:count], dtype=float)
    return {
        "ticks": len(ticks),
        "trace_rows": int(trace.size),
        "max_difference": float(np.abs(sent - expected).max()) if count else None,
        "nonzero": int(np.count_nonzero(sent[:, 1])) if count else 0,
    }


def _physics(trace, first, second):
    """Does every traced force follow the model, on the surface the trigger chose?"""
    x = np.arange(first.size) * SPACING
    touching = trace["contact"] > 0
    on_first = np.isclose(trace["h"], np.interp(trace["x"], x, first), atol=1e-9)
    on_second = np.isclose(trace["h"], np.interp(trace["x"], x, second), atol=1e-9)
    stiffness = 1280.0
    law = np.abs(trace["F_y"][touching] - np.clip(stiffness * (trace["h"] - trace["y_i"]), 0, None)[touching])
    slope = np.where(
        on_second,
        np.interp(trace["x"], x, np.gradient(second, SPACING)),
        np.interp(trace["x"], x, np.gradient(first, SPACING)),
    )
    lateral = np.abs(trace["F_x"] + trace["F_y"] * slope)[touching]
    switch = int(np.argmax(on_second)) if on_second.any() else None
    return {
        "contact_ticks": int(touching.sum()),
        "max_law_error_N": float(law.max()) if law.size else None,
        "max_lateral_error_N": float(lateral.max()) if lateral.size else None,
        "first_then_second": bool(switch is not None and on_first[:switch].all() and on_second[switch:].all()),
        "switch_at_s": None if switch is None else float(trace["t"][switch]),
    }


def unplug(folder):
    device, stop = plug_in(0.5)
    rough = start_rough(folder)
    streaming = device.streaming.wait(120)
    time.sleep(0.3)
    stop.set()
    time.sleep(0.05)
    device.destroy()
    return {"streaming": streaming, **ending(rough, time.monotonic())}


def main():
    print("vhid guest: started", flush=True)
    folder = scratch_folder()
    first, second = profiles(folder)
    result = {"session": session(folder, first, second), "unplug": unplug(folder)}
    print("RESULT " + json.dumps(result, default=float), flush=True)


if __name__ == "__main__":
    main()
