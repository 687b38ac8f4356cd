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

Positions: the stick's x range maps onto the profile window (``x_span`` metres, from
the window start), its y range onto ``y_span`` metres centred on ``y_centre``, so a
centred stick rests above the surface. ``invert`` flips an axis (position and force).
"""

import threading

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

PID_PAGE_ITEM = (b"\x05\x0f", b"\x06\x0f\x00")  # Usage Page (PID), short and long forms


class DeviceGone(PidError):
    """The joystick stopped answering (unplugged, or its driver went away)."""


class Joystick:
    """The render device interface (``read``, ``write``, ``close``,
    ``emergency_stop``) on a HID PID joystick opened through ``handle`` (a hidapi
    device object)."""

    needs_watchdog = True

    def __init__(self, handle, descriptor, max_force, x_start, x_span, y_centre, y_span, invert=()):
        self.handle, self.pid = handle, PidDescriptor(descriptor)
        self.max_force = float(max_force)
        self.x_start, self.x_span, self.y_centre, self.y_span = x_start, x_span, y_centre, y_span
        self.x_sign, self.y_sign = (-1 if "x" in invert else 1), (-1 if "y" in invert else 1)
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
        fx, fy, buttons = self._state
        if self.x_sign < 0:
            fx = 1.0 - fx
        if self.y_sign < 0:
            fy = 1.0 - fy
        return self.x_start + fx * self.x_span, self.y_centre + (fy - 0.5) * self.y_span, buttons

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

    def emergency_stop(self):
        """Zero the force and stop the effects now (from any thread); later writes are ignored."""
        with self._lock:
            self._stopped = True
            self._silence()

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
        import time

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


def find_joystick(spec="hid"):
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
        speaks HID PID, or when a candidate could not be opened (with the hidraw
        permissions as a hint).

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
    from ..extras import require

    hidraw = require("hidraw")

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
    refused = []
    for info in candidates:
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
