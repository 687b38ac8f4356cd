"""A USB force-feedback joystick as a render device, through hidapi's hidraw backend.

Opening: find the joystick (the first hidraw device whose report descriptor offers the
PID reports, or the one with a given vendor and product ID), parse its descriptor
(:mod:`.pid`), reset it, enable its actuators, set full device gain, and create two
constant-force effects, one per axis (Create New Effect, then PID Block Load for the
effect's block index; Set Effect with infinite duration; Set Constant Force 0; Effect
Operation start). Each tick then reads the newest input report (non-blocking) and
writes one Set Constant Force report per axis. Closing (normal end, Ctrl-C, an error,
the watchdog) writes zero magnitudes, stops and frees the effects, stops all effects
and disables the actuators; a device that has gone away is reported, not retried.

Positions: a :class:`~rough.render.device.Workspace` maps the stick's travel onto the
surface; for a profile its x range spans the window and its y range four times the
height range centred on the top, so a centred stick rests above the surface.

A joystick that a kernel force-feedback driver holds (hid-pidff, hid-universal-pidff
…: its input device offers force feedback) is refused: the kernel keeps its own table
of the device's effects, so rough's reset, its effects and its "stop all" on closing
would clobber whatever a game or SDL uploaded through evdev, and the kernel's later
updates would land on blocks rough freed. Such a joystick is driven through the
kernel, with ``--device evdev`` (:mod:`rough.render.evdev`).
"""

import dataclasses
import os
import threading
import time

from .. import extras
from .device import Backend, Capabilities, StreamedForce, Workspace
from .pid import (
    CONSTANT_FORCE,
    DEVICE_GAIN,
    DIRECTION_ENABLE,
    DISABLE_ACTUATORS,
    DURATION,
    EFFECT_BLOCK_INDEX,
    ENABLE_ACTUATORS,
    GAIN,
    LOAD_FULL,
    LOAD_SUCCESS,
    LOOP_COUNT,
    MAGNITUDE,
    OP_START,
    OP_STOP,
    RESET,
    SAMPLE_PERIOD,
    START_DELAY,
    STOP_ALL,
    TRIGGER_BUTTON,
    TRIGGER_REPEAT,
    PidDescriptor,
    PidError,
    X,
    Y,
)

BACKEND = Backend(
    name="hid",
    title="a HID PID joystick through hidraw",
    argument="VID:PID",
    requires=("hidraw", "hidtools"),
)
PID_PAGE_ITEM = (b"\x05\x0f", b"\x06\x0f\x00")  # Usage Page (PID), short and long forms


class DeviceGone(PidError):
    """The joystick stopped answering (unplugged, or its driver went away)."""


class Joystick(StreamedForce):
    """The render device interface (:class:`~rough.render.device.Device`) on a HID PID
    joystick opened through ``handle`` (a hidapi device object). The stick's travel
    lies on the surface as the :class:`~rough.render.device.Workspace` of
    ``x_start``, ``x_span``, ``y_centre``, ``y_span`` and ``invert`` says."""

    capabilities = Capabilities(axes=2, needs_watchdog=True)
    velocity = (0.0, 0.0)

    def __init__(self, handle, descriptor, max_force, x_start, x_span, y_centre, y_span, invert=(), label="joystick"):
        self.handle, self.pid = handle, PidDescriptor(descriptor)
        self.max_force = float(max_force)
        self.x_start, self.x_span, self.y_centre, self.y_span = x_start, x_span, y_centre, y_span
        self.workspace, self.label = Workspace(x_start, x_span, y_centre, y_span, tuple(invert)), label
        self.x_sign, self.y_sign = self.workspace.signs
        self._lock = threading.Lock()
        self._stopped = False
        self._closed = False
        self._state = (0.5, 0.5, 0)
        self.blocks = []
        handle.set_nonblocking(1)
        self._open_effects()
        self._read_until_position()

    # -- the device interface ---------------------------------------------------------------

    def read(self):
        """``(x, y, buttons)``: the newest stick position in metres, and the buttons."""
        while True:
            report = self._io(self.handle.read, self.pid.joystick.size + 1)
            if not report:
                break
            position = self.pid.position(bytes(report))
            if position is not None:
                self._state = position
        u, v, buttons = self._state
        return *self.workspace.position(u, v), buttons

    def write(self, fx, fy):
        """Stream the force ``(fx, fy)`` (N; clamped to the device maximum)."""
        field = self.pid.constant.fields[MAGNITUDE]
        with self._lock:
            if self._stopped:
                return
            for block, force in zip(self.blocks, (fx * self.x_sign, fy * self.y_sign)):
                self._send(
                    self.pid.constant, {EFFECT_BLOCK_INDEX: block, MAGNITUDE: field.scale(force / self.max_force)}
                )

    def close(self):
        """Zero the force, stop and free the effects, disable the actuators, close the handle."""
        if self._closed:
            return
        with self._lock:
            self._stopped = True
            self._silence()
            for block in self.blocks if self.pid.free else ():
                self._quietly(self.pid.free, {EFFECT_BLOCK_INDEX: block})
            self._quietly(self.pid.control, {self._control_usage: self._control.choose(STOP_ALL)})
            self._quietly(self.pid.control, {self._control_usage: self._control.choose(DISABLE_ACTUATORS)})
            self._closed = True
            self.handle.close()

    # -- setting up ---------------------------------------------------------------------------

    @property
    def _control_usage(self):
        return next(iter(self.pid.control.fields))

    @property
    def _control(self):
        return self.pid.control.fields[self._control_usage]

    def _open_effects(self):
        for action in (RESET, ENABLE_ACTUATORS):
            if action in self._control.choices:
                self._send(self.pid.control, {self._control_usage: self._control.choose(action)})
        if self.pid.gain is not None:
            self._send(self.pid.gain, {DEVICE_GAIN: self.pid.gain.fields[DEVICE_GAIN].high})
        for axis in (X, Y):
            block = self._create_effect()
            self.blocks.append(block)
            self._send(self.pid.set_effect, self._effect_parameters(block, axis))
            self._send(self.pid.constant, {EFFECT_BLOCK_INDEX: block, MAGNITUDE: 0})
            operation = self.pid.operation
            self._send(
                operation,
                {EFFECT_BLOCK_INDEX: block, _array_usage(operation): _array(operation).choose(OP_START), LOOP_COUNT: 1},
            )

    def _create_effect(self):
        create = self.pid.create
        self._io(
            self.handle.send_feature_report, create.wire({_array_usage(create): _array(create).choose(CONSTANT_FORCE)})
        )
        load = self.pid.load
        answer = bytes(self._io(self.handle.get_feature_report, load.id, load.size + (0 if load.id else 1)))
        if not load.id:
            answer = answer[1:]
        status_field = _array(load)
        status = status_field.choices[status_field.get(answer) - status_field.low] if len(answer) >= load.size else None
        if status != LOAD_SUCCESS:
            reason = "its effect memory is full" if status == LOAD_FULL else "it did not confirm the effect"
            raise PidError(f"the joystick could not create a constant-force effect: {reason}")
        return load.fields[EFFECT_BLOCK_INDEX].get(answer)

    def _effect_parameters(self, block, axis):
        report = self.pid.set_effect
        values = {
            EFFECT_BLOCK_INDEX: block,
            _array_usage(report): _array(report).choose(CONSTANT_FORCE),
            X: int(axis == X),
            Y: int(axis == Y),
            DIRECTION_ENABLE: 0,
        }
        for usage in (DURATION, TRIGGER_BUTTON):  # Null: play until stopped; no trigger button
            if usage in report.fields:
                values[usage] = report.fields[usage].null
        for usage in (TRIGGER_REPEAT, SAMPLE_PERIOD, START_DELAY):
            if usage in report.fields:
                values[usage] = max(0, report.fields[usage].low)
        if GAIN in report.fields:
            values[GAIN] = report.fields[GAIN].high
        return values

    def _read_until_position(self):
        deadline = time.monotonic() + 1.0
        while time.monotonic() < deadline:
            report = self._io(self.handle.read, self.pid.joystick.size + 1, 50)
            if report and self.pid.position(bytes(report)) is not None:
                self._state = self.pid.position(bytes(report))
                return

    # -- talking to the device ------------------------------------------------------------------

    def _silence(self):
        for block in self.blocks:
            self._quietly(self.pid.constant, {EFFECT_BLOCK_INDEX: block, MAGNITUDE: 0})
            operation = self.pid.operation
            self._quietly(
                operation,
                {EFFECT_BLOCK_INDEX: block, _array_usage(operation): _array(operation).choose(OP_STOP), LOOP_COUNT: 0},
            )

    def _send(self, report, values):
        written = self._io(self.handle.write, report.wire(values))
        if written is not None and written < 0:
            raise DeviceGone(f"the joystick refused a report: {self.handle.error() or 'write failed'}")

    def _quietly(self, report, values):
        try:
            self._send(report, values)
        except (PidError, OSError, ValueError):
            pass

    def _io(self, call, *arguments):
        try:
            return call(*arguments)
        except (OSError, ValueError) as error:
            raise DeviceGone(f"the joystick stopped answering ({error})") from None


def _array_usage(report):
    return next(usage for usage, field in report.fields.items() if field.choices)


def _array(report):
    return report.fields[_array_usage(report)]


def kernel_force_feedback(hidraw_path, sysfs="/sys"):
    """The kernel's hold on a hidraw device's force feedback: ``(driver, event node)``
    when an input device of the same HID device offers force feedback (a kernel
    driver such as hid-pidff drives its effects), else None.

    Parameters
    ----------
    hidraw_path : bytes or str
        The hidraw node, e.g. ``b"/dev/hidraw3"``.
    sysfs : str, default "/sys"
        Where sysfs is mounted.

    Examples
    --------
    >>> from rough.render.hid import kernel_force_feedback
    >>> kernel_force_feedback(b"/dev/hidraw-none", sysfs="/nonexistent") is None
    True
    """
    name = os.path.basename(os.fsdecode(hidraw_path))
    device = os.path.realpath(os.path.join(sysfs, "class", "hidraw", name, "device"))
    inputs = os.path.join(device, "input")
    for entry in sorted(os.listdir(inputs)) if os.path.isdir(inputs) else ():
        try:
            with open(os.path.join(inputs, entry, "capabilities", "ff")) as bits:
                offered = int(bits.read().replace(" ", "") or "0", 16)
        except (OSError, ValueError):
            continue
        if offered:
            driver = os.path.basename(os.path.realpath(os.path.join(device, "driver")))
            events = [e for e in sorted(os.listdir(os.path.join(inputs, entry))) if e.startswith("event")]
            return driver, "/dev/input/" + events[0] if events else None
    return None


def find_joystick(spec="hid", sysfs="/sys"):
    """Open a force-feedback joystick through hidapi's hidraw backend.

    The first hidraw device whose report descriptor offers the HID PID (force
    feedback) reports, or the one with the given vendor and product ID.

    Parameters
    ----------
    spec : str, default "hid"
        ``hid`` for the first PID joystick, or ``hid:VID:PID`` with hexadecimal IDs
        (e.g. ``hid:1209:0001``).

    Returns
    -------
    handle : hidraw.device
        The open device.
    descriptor : bytes
        Its HID report descriptor.
    label : str
        The product name and IDs, e.g. ``"Impulse Engine (1209:0001)"``.

    Raises
    ------
    rough.RoughError
        A ``PidError`` (exit status 1) for a malformed ``spec``, when no HID device
        speaks HID PID, when a candidate could not be opened (with the hidraw
        permissions as a hint), or when a kernel force-feedback driver holds the
        joystick (:func:`kernel_force_feedback`; the message names the evdev node to
        use instead).

    See Also
    --------
    rough.render.run : Run the servo loop on a device.

    Examples
    --------
    Opening a joystick needs the hardware (and permission to open its hidraw
    node), so no example here opens one: with a force-feedback joystick plugged in,
    ``find_joystick("hid")`` returns ``(handle, descriptor, label)`` and
    ``find_joystick("hid:1209:0001")`` picks the device with those IDs; without one
    it raises a ``PidError`` saying that no force-feedback joystick was found. A
    malformed spec is refused before any device is looked at:

    >>> import rough
    >>> from rough.render.hid import find_joystick
    >>> try:
    ...     find_joystick("hid:zz")
    ... except rough.RoughError as error:
    ...     print(error)
    --device 'hid:zz': write hid or hid:VID:PID with hexadecimal IDs, e.g. hid:1209:0001
    """
    hidraw = extras.require("hidraw")

    wanted = None
    if spec != "hid":
        try:
            _, vendor, product = spec.split(":")
            wanted = (int(vendor, 16), int(product, 16))
        except ValueError:
            raise PidError(
                f"--device {spec!r}: write hid or hid:VID:PID with hexadecimal IDs, e.g. hid:1209:0001"
            ) from None
    candidates = [d for d in hidraw.enumerate() if wanted is None or (d["vendor_id"], d["product_id"]) == wanted]
    refused, held = [], []
    for info in candidates:
        kernel = kernel_force_feedback(info["path"], sysfs)
        if kernel is not None:
            held.append(kernel)
            continue
        handle = hidraw.device()
        try:
            handle.open_path(info["path"])
            descriptor = bytes(handle.get_report_descriptor())
        except (OSError, ValueError) as error:
            refused.append(f"{info['path'].decode(errors='replace')} ({error})")
            continue
        if any(item in descriptor for item in PID_PAGE_ITEM):
            label = f"{info.get('product_string') or 'joystick'} ({info['vendor_id']:04x}:{info['product_id']:04x})"
            return handle, descriptor, label
        handle.close()
    if held:
        driver, node = held[0]
        raise PidError(
            f"the kernel's force-feedback driver ({driver}) holds the joystick, and rough writing to it over hidraw "
            f"would clobber the kernel's effects: use --device evdev{':' + node if node else ''} instead"
        )
    if refused:
        raise PidError(
            f"no force-feedback joystick could be opened: {'; '.join(refused)} (check the hidraw permissions)"
        )
    what = (
        "no HID device"
        if not candidates
        else f"{len(candidates)} HID device(s) but none speaks HID PID (force feedback)"
    )
    target = "" if wanted is None else f" with ID {wanted[0]:04x}:{wanted[1]:04x}"
    raise PidError(f"no force-feedback joystick found: {what}{target}")


def open_device(argument, workspace, max_force, **options):
    """The :mod:`~rough.render.device` factory's entry: the joystick ``hid[:argument]``."""
    handle, descriptor, label = find_joystick("hid" if argument is None else f"hid:{argument}")
    try:
        return Joystick(handle, descriptor, max_force, *dataclasses.astuple(workspace), label=label)
    except BaseException:
        handle.close()
        raise
