"""Runs inside the throwaway QEMU guest (../shared/reference/virtual-hid): makes a
virtual USB force-feedback joystick through /dev/uinput (python-evdev), serves its
force-feedback side in a thread of this process, and runs ``rough render --device
evdev:/dev/input/eventN`` against it as a user would (a separate process: uinput
needs the uploading client and the server to be different processes). Prints one
line ``RESULT {json}`` with what happened; tests/test_evdev_guest.py judges it.

Scenario "session": the stick sweeps across the window pressed into the surface, the
trigger is pressed once, then rough gets SIGINT. Scenario "polar": a joystick with
room for one effect, which rough finds among the guest's event devices by itself.
Scenario "refused": a joystick that refuses the second effect.
Scenario "unplug": the joystick is destroyed while rough streams forces.
"""

import errno
import json
import math
import pathlib
import select
import signal
import threading
import time

import numpy as np
from evdev import AbsInfo, UInput, ecodes
from guest_tools import ending, scratch_folder, start_render

from rough import Surface

HERE = pathlib.Path(__file__).resolve().parent
SPACING = 0.1e-3
MAX_FORCE = 8.9
FULL_LEVEL = 0x7FFF
RAW = 32767  # the stick's axes run from -RAW to RAW


class VirtualJoystick:
    """A uinput joystick (X, Y, three buttons) with constant force, gain and
    autocentre, whose force-feedback requests a thread of this process answers and
    records: ``log`` holds ``(seconds, what, ...)`` in order of arrival."""

    def __init__(self, max_effects=16, refuse=()):
        events = {
            ecodes.EV_ABS: [(code, AbsInfo(0, -RAW, RAW, 0, 0, 0)) for code in (ecodes.ABS_X, ecodes.ABS_Y)],
            ecodes.EV_KEY: [ecodes.BTN_TRIGGER, ecodes.BTN_THUMB, ecodes.BTN_THUMB2],
            ecodes.EV_FF: [ecodes.FF_CONSTANT, ecodes.FF_GAIN, ecodes.FF_AUTOCENTER],
        }
        self.ui = UInput(
            events,
            name="rough test FF joystick",
            vendor=0x1209,
            product=0x0002,
            bustype=ecodes.BUS_USB,
            max_effects=max_effects,
        )
        self.path = self.ui.device.path
        self.refuse = list(refuse)  # answers for the uploads of new effects: 0 or -errno
        self.effects, self.playing, self.log = {}, set(), []
        self.gain = self.autocentre = None
        self.started = time.monotonic()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._thread.start()

    def _serve(self):
        while not self._stop.is_set():
            if not select.select([self.ui.fd], [], [], 0.01)[0]:
                continue
            event = self.ui.read_one()
            while event is not None:
                self._answer(event)
                event = self.ui.read_one()

    def _answer(self, event):
        now = time.monotonic() - self.started
        if event.type == ecodes.EV_UINPUT and event.code == ecodes.UI_FF_UPLOAD:
            upload = self.ui.begin_upload(event.value)
            effect = upload.effect
            new = effect.id not in self.effects
            upload.retval = self.refuse.pop(0) if new and self.refuse else 0
            details = (effect.id, effect.type, effect.direction, effect.u.ff_constant_effect.level)
            self.log.append((now, "upload" if upload.retval == 0 else "refused", *details, effect.ff_replay.length))
            if upload.retval == 0:
                self.effects[effect.id] = details[2:]
            self.ui.end_upload(upload)
        elif event.type == ecodes.EV_UINPUT and event.code == ecodes.UI_FF_ERASE:
            erase = self.ui.begin_erase(event.value)
            erase.retval = 0
            self.log.append((now, "erase", erase.effect_id))
            self.effects.pop(erase.effect_id, None)
            self.playing.discard(erase.effect_id)
            self.ui.end_erase(erase)
        elif event.type == ecodes.EV_FF and event.code == ecodes.FF_GAIN:
            self.gain = event.value
            self.log.append((now, "gain", event.value))
        elif event.type == ecodes.EV_FF and event.code == ecodes.FF_AUTOCENTER:
            self.autocentre = event.value
            self.log.append((now, "autocentre", event.value))
        elif event.type == ecodes.EV_FF:
            (self.playing.add if event.value else self.playing.discard)(event.code)
            self.log.append((now, "play" if event.value else "stop", event.code))

    def streaming(self, effects, timeout):
        """Wait until ``effects`` effects play; True when they do."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if len(self.playing) >= effects:
                return True
            time.sleep(0.05)
        return False

    def move(self, u=None, v=None, trigger=None):
        """The stick to ``(u, v)``, fractions of its travel; the trigger down or up."""
        for code, fraction in ((ecodes.ABS_X, u), (ecodes.ABS_Y, v)):
            if fraction is not None:
                self.ui.write(ecodes.EV_ABS, code, round(-RAW + 2 * RAW * fraction))
        if trigger is not None:
            self.ui.write(ecodes.EV_KEY, ecodes.BTN_TRIGGER, int(trigger))
        self.ui.syn()

    def unplug(self):
        self._stop.set()
        self._thread.join(5)
        self.ui.close()

    def names(self):
        return [entry[1] for entry in self.log]


def profiles(folder):
    x = np.arange(101) * SPACING
    first = 0.2e-3 * np.sin(2 * np.pi * x / 4e-3)
    Surface(first, (SPACING,), metadata={"title": "A"}).write(folder / "a.x3p")
    Surface(first + 0.5e-3, (SPACING,), metadata={"title": "B"}).write(folder / "b.x3p")


def start_rough(folder, node, *extra):
    return start_render(folder, "evdev" if node is None else f"evdev:{node}", *extra)


def stroke(folder, device, effects, steps, node):
    """rough on ``device`` (found by its event ``node``, or None: rough looks for it)
    while the stick sweeps ``steps`` steps pressed into the surface, the trigger pressed
    once half way, then SIGINT."""
    device.move(0.1, 0.3, 0)
    started = time.monotonic()
    rough = start_rough(folder, node, "--trace", str(folder / "trace.npy"))
    streaming = device.streaming(effects, 180)
    setup_s = time.monotonic() - started
    for step in range(steps):
        device.move(0.1 + 0.8 * step / steps, 0.3, steps // 2 <= step < steps // 2 + 3)
        time.sleep(0.02)
    time.sleep(0.2)
    rough.send_signal(signal.SIGINT)
    interrupted = time.monotonic()
    out, err = rough.communicate(timeout=120)
    exit_s = time.monotonic() - interrupted
    time.sleep(0.3)
    trace = np.load(folder / "trace.npy") if (folder / "trace.npy").exists() else None
    return {
        "streaming": streaming,
        "startup_s": setup_s,
        "exit_after_interrupt_s": exit_s,
        "returncode": rough.returncode,
        "stderr": err,
        "report": json.loads(out)["runs"][0] if out.strip() else None,
        "setup": device.names()[: 2 + 2 * effects],
        "initial": [entry[2:] for entry in device.log if entry[1] == "upload"][:effects],
        "gain": device.gain,
        "autocentre": device.autocentre,
        "effects_left": len(device.effects),
        "playing_left": sorted(device.playing),
        "final_levels": [level for _, level in device.effects.values()],
        "closing": _closing(device),
        "trace_rows": 0 if trace is None else int(trace.size),
    }, trace


def _closing(device):
    """What the device got after the last non-zero level: ``[[what, id], ...]``."""
    last = max((i for i, entry in enumerate(device.log) if entry[1] == "upload" and entry[5]), default=-1)
    return [[entry[1], entry[2], *([entry[5]] if entry[1] == "upload" else [])] for entry in device.log[last + 1 :]]


def _updates(device):
    """Each effect's levels after its first upload: ``{id: [(direction, level), ...]}``."""
    seen, updates = set(), {}
    for entry in device.log:
        if entry[1] != "upload":
            continue
        effect_id, _, direction, level, _ = entry[2:]
        if effect_id in seen:
            updates.setdefault(effect_id, []).append((direction, level))
        seen.add(effect_id)
    return updates


def _changes(levels):
    """The levels a stream sends: each one that differs from the one before, from 0."""
    return [int(v) for i, v in enumerate(levels) if v != (levels[i - 1] if i else 0)]


def session(folder):
    device = VirtualJoystick()
    result, trace = stroke(folder, device, 2, 60, device.path)
    ids = sorted(entry[0] for entry in result["initial"])
    updates = _updates(device)
    paired = {"pairs": 0, "max_difference": None, "unmatched": 0, "extra": {}, "nonzero": 0}
    if trace is not None and len(ids) == 2:
        differences = []
        for effect_id, field in zip(ids, ("F_x", "F_y")):
            expected = _changes(np.round(trace[field] / MAX_FORCE * FULL_LEVEL).astype(int).tolist())
            sent = [level for _, level in updates.get(effect_id, [])]
            count = min(len(expected), len(sent))
            differences += [abs(a - b) for a, b in zip(expected[:count], sent[:count])]
            paired["pairs"] += count
            paired["unmatched"] += len(expected) - count
            paired["extra"][field] = sent[count:]  # the interrupted tick's write (untraced), and closing's zero
            paired["nonzero"] += sum(1 for level in sent if level)
        paired["max_difference"] = max(differences) if differences else None
        result["positions"] = {
            "x_min": float(trace["x"].min()),
            "x_max": float(trace["x"].max()),
            "y_i": sorted({round(float(y), 9) for y in trace["y_i"]}),
        }
    result["streamed"] = paired
    device.unplug()
    return result


def polar(folder):
    from rough.render.evdev import X_DIRECTION, find_devices, polar_effect

    device = VirtualJoystick(max_effects=1)
    result, trace = stroke(folder, device, 1, 30, None)
    result["seen"] = find_devices()  # what rough chose among, read from sysfs
    updates = [pair for pairs in _updates(device).values() for pair in pairs]
    expected, errors = [], []
    if trace is not None:
        forces = np.column_stack([trace["F_x"], trace["F_y"]]) / MAX_FORCE
        last = (X_DIRECTION, 0)
        for force in forces:
            target = polar_effect(*force, direction=last[0])
            if target != last:
                expected.append((target, force * FULL_LEVEL))
                last = target
        for (target, force), sent in zip(expected, updates):
            angle = 2 * math.pi * sent[0] / 0x10000
            decoded = (sent[1] * math.sin(angle), -sent[1] * math.cos(angle))  # ff-memless, in floating point
            errors.append(float(np.hypot(*(force - decoded))))
    count = min(len(expected), len(updates))
    result["streamed"] = {
        "updates": len(updates),
        "expected": len(expected),
        "pairs": count,
        "mismatched": sum(target != tuple(sent) for (target, _), sent in zip(expected, updates)),
        "max_error_lsb": max(errors) if errors else None,
        "nonzero": sum(1 for _, level in updates if level),
        "directions": len({direction for direction, _ in updates}),
        "extra": [list(pair) for pair in updates[count:]],
    }
    device.unplug()
    return result


def refused(folder):
    device = VirtualJoystick(refuse=[0, -errno.ENOSPC])
    device.move(0.5, 0.5, 0)
    started = time.monotonic()
    rough = start_rough(folder, device.path)
    streaming = device.streaming(1, 180)
    startup = time.monotonic() - started
    time.sleep(0.5)
    rough.send_signal(signal.SIGINT)
    out, err = rough.communicate(timeout=120)
    time.sleep(0.3)
    result = {
        "streaming": streaming,
        "startup_s": startup,
        "returncode": rough.returncode,
        "stderr": err,
        "sequence": [entry[1:] for entry in device.log if entry[1] in ("upload", "refused", "erase", "play")][:5],
        "effects_left": len(device.effects),
    }
    device.unplug()
    return result


def unplug(folder):
    device = VirtualJoystick()
    device.move(0.5, 0.3, 0)
    rough = start_rough(folder, device.path)
    streaming = device.streaming(2, 180)
    time.sleep(0.5)
    device.unplug()
    return {"streaming": streaming, **ending(rough, time.monotonic())}


def main():
    print("evdev guest: started", flush=True)
    folder = scratch_folder()
    profiles(folder)
    result = {}
    for name, scenario in (("session", session), ("polar", polar), ("refused", refused), ("unplug", unplug)):
        begun = time.monotonic()
        try:
            result[name] = scenario(folder)
        except Exception as error:  # one scenario's failure must not hide the others' results
            result[name] = {"error": f"{type(error).__name__}: {error}"}
        result[name]["scenario_s"] = time.monotonic() - begun
        print(f"scenario {name} done in {result[name]['scenario_s']:.1f} s", flush=True)
    print("RESULT " + json.dumps(result, default=float), flush=True)


if __name__ == "__main__":
    main()
