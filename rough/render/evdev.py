"""A Linux force-feedback device as a render device, through evdev (python-evdev).

Any joystick or wheel whose kernel driver offers constant force (hid-pidff,
hid-universal-pidff, hid-lg4ff, iforce …) appears as an event node,
``/dev/input/eventN``, that takes force-feedback effects. Opening: find the device
(the first event node offering ``FF_CONSTANT``, or the one given), set the device gain
to full (``FF_GAIN``, where offered), switch autocentring off (``FF_AUTOCENTER``, where
offered), upload one constant-force effect per axis with level 0 and infinite replay
length (length 0) and play them. Each tick then drains the pending input events
(non-blocking) and updates an effect in place (``EVIOCSFF`` with its id) only when its
level changed. Closing (normal end, Ctrl-C, an error, the watchdog) sets every level
to 0, stops and erases every effect and closes the node (closing it also makes the
kernel erase any effect this process still holds); a device that has gone away is
reported in one line, not retried.

Directions follow the kernel's own conversion of a direction into x and y
(ff-memless: ``x = level sin θ``, ``y = -level cos θ``, θ the direction in 0x10000ths
of a turn). It agrees with SDL's Linux backend, which adds 180° to SDL's direction
(DirectInput's convention: where the force comes from, 0° away from the user,
clockwise), and so reads the names in linux/input.h (0x0000 down, 0x4000 left, 0x8000
up, 0xC000 right) as the side the force comes from. The x effect has direction 0x4000 (from the left: a
positive level pushes towards increasing ``ABS_X``) and the y effect 0x8000 (from
above: a positive level pushes towards increasing ``ABS_Y``, towards the user on a
joystick). A device with room for one effect only gets one polar effect, its
direction the force's angle and its level the force's magnitude. A driver that hands
the direction to its device unchanged (hid-pidff) leaves the sense to the device's
firmware: ``--invert`` reverses an axis, its position and force alike.

Positions: ``ABS_X`` and ``ABS_Y`` as fractions of their ranges (absinfo minimum to
maximum) placed on the surface by a :class:`~rough.render.device.Workspace`. A wheel
(``ABS_X`` only) has one force axis: its y stays in the middle of its travel and its
y force is dropped. Buttons: bit 0 is the first key code the device offers (its
trigger: ``BTN_TRIGGER``, ``BTN_SOUTH`` …), bits 1 and 2 the next two.
"""

import errno
import math
import os
import struct
import threading

from .. import extras
from .device import Backend, Capabilities, DeviceError, StreamedForce

BACKEND = Backend(
    name="evdev",
    title="a Linux force-feedback device through evdev",
    argument="PATH",
    requires=("evdev",),
)
FULL_LEVEL = 0x7FFF  # the s16 level of the device's full force
FULL_GAIN = 0xFFFF
X_DIRECTION = 0x4000  # the force comes from the left: a positive level pushes towards +ABS_X
Y_DIRECTION = 0x8000  # the force comes from above: a positive level pushes towards +ABS_Y
TURN = 0x10000  # direction units in a full turn
BUTTONS = 3  # key codes reported as the bits of read()'s buttons
LOST = frozenset({errno.ENODEV, errno.ENXIO, errno.EIO, errno.EBADF, errno.ESHUTDOWN})
EFFECT_TYPES = range(0x50, 0x58)  # FF_RUMBLE … FF_RAMP
SHOWN = 8  # devices named in a "none found" message
PERMISSION_HINT = 'add yourself to the input group, or give your user the node with a udev rule (TAG+="uaccess")'


class EvdevError(DeviceError):
    """The device is not a usable force-feedback device, or refused a request."""


class DeviceGone(EvdevError):
    """The device stopped answering (unplugged, or its driver went away)."""


# -- the effects -------------------------------------------------------------------------------


def level(fraction):
    """The s16 effect level of ``fraction`` of the full force (clamped to ±1; NaN is 0).

    Examples
    --------
    >>> from rough.render.evdev import level
    >>> level(0.5), level(-1.0), level(3.0), level(float("nan"))
    (16384, -32767, 32767, 0)
    """
    if not math.isfinite(fraction):
        return 0
    return round(min(1.0, max(-1.0, fraction)) * FULL_LEVEL)


def axis_effects(gx, gy, axes=2):
    """``[(direction, level), ...]``: one constant-force effect per axis for the force
    ``(gx, gy)``, in fractions of the full force along increasing ``ABS_X`` and
    ``ABS_Y`` (only the x effect when ``axes`` is 1).

    Examples
    --------
    >>> from rough.render.evdev import axis_effects
    >>> axis_effects(0.5, -0.25)  # x from the left (0x4000), y from above (0x8000)
    [(16384, 16384), (32768, -8192)]
    >>> axis_effects(0.5, -0.25, axes=1)  # a wheel
    [(16384, 16384)]
    """
    return [(X_DIRECTION, level(gx)), (Y_DIRECTION, level(gy))][:axes]


def polar_effect(gx, gy, direction=X_DIRECTION):
    """``(direction, level)`` of one constant-force effect for the force ``(gx, gy)``
    (fractions of the full force along increasing ``ABS_X`` and ``ABS_Y``): its
    direction the force's angle, its level the force's magnitude (clamped to 1). A zero
    force keeps ``direction``.

    Examples
    --------
    >>> from rough.render.evdev import polar_effect
    >>> polar_effect(0.5, 0.0), polar_effect(0.0, 0.5), polar_effect(0.0, -0.5)
    ((16384, 16384), (32768, 16384), (0, 16384))
    >>> polar_effect(-0.5, 0.0), polar_effect(0.0, 0.0, direction=123)  # from the right (0xC000)
    ((49152, 16384), (123, 0))
    """
    gx, gy = (g if math.isfinite(g) else 0.0 for g in (gx, gy))
    magnitude = level(math.hypot(gx, gy))
    if magnitude == 0:
        return direction, 0
    return round(math.atan2(gx, -gy) / (2 * math.pi) * TURN) % TURN, magnitude


def decode(direction, level):
    """``(gx, gy)``, fractions of the full force along increasing ``ABS_X`` and
    ``ABS_Y``, that an effect of ``direction`` and ``level`` stands for (the kernel's
    ff-memless conversion, without its integer rounding).

    Examples
    --------
    >>> from rough.render.evdev import decode, polar_effect
    >>> [round(g, 4) for g in decode(*polar_effect(-0.3, -0.4))]
    [-0.3, -0.4]
    """
    angle = 2 * math.pi * direction / TURN
    return level / FULL_LEVEL * math.sin(angle), -level / FULL_LEVEL * math.cos(angle)


def constant_effect(direction, level, effect_id=-1):
    """A python-evdev ``ff.Effect``: constant force of ``level`` from ``direction``,
    played for ever (replay length 0) from the moment it is started; ``effect_id`` -1
    asks the kernel for a new effect, an existing id updates that effect in place.

    Examples
    --------
    >>> from rough.render.evdev import constant_effect
    >>> effect = constant_effect(0x4000, -1200, effect_id=3)
    >>> effect.type == 0x52, effect.id, effect.direction, effect.u.ff_constant_effect.level
    (True, 3, 16384, -1200)
    >>> effect.ff_replay.length, effect.ff_replay.delay, effect.ff_trigger.button
    (0, 0, 0)
    """
    ff, ecodes = extras.require("evdev.ff"), extras.require("evdev.ecodes")
    constant = ff.Constant(level, ff.Envelope(0, 0, 0, 0))
    return ff.Effect(
        ecodes.FF_CONSTANT,
        effect_id,
        direction,
        ff.Trigger(0, 0),
        ff.Replay(0, 0),
        ff.EffectType(ff_constant_effect=constant),
    )


# -- the device -------------------------------------------------------------------------------


class EvdevDevice(StreamedForce):
    """The render device interface (:class:`~rough.render.device.Device`) on an open
    evdev node ``device`` (a python-evdev ``InputDevice``, opened for reading and
    writing), with the stick's travel on the surface given by ``workspace`` and
    ``max_force`` (N) standing for the device's full force.

    Attributes
    ----------
    polar : bool
        One polar effect (the device has room for one, or refused a second) rather
        than one effect per axis.
    effects : list of evdev.ff.Effect
        The uploaded effects, with the level each has now.
    """

    velocity = (0.0, 0.0)

    def __init__(self, device, workspace, max_force, label=None):
        self.ecodes = extras.require("evdev.ecodes")
        self.device, self.workspace, self.max_force = device, workspace, float(max_force)
        self.label = label or describe(device)
        self.x_sign, self.y_sign = workspace.signs
        self._lock = threading.Lock()
        self._stopped = self._closed = False
        self.effects, self.polar = [], False
        try:
            self._look()
            self._start()
            self._resync()
        except OSError as error:
            self.close()
            raise self._gone(error) from None
        except BaseException:
            self.close()
            raise

    # -- the device interface ---------------------------------------------------------------

    def read(self):
        """``(x, y, buttons)``: the newest stick position in metres, and the buttons."""
        try:
            event = self.device.read_one()
            while event is not None:
                self._take(event.type, event.code, event.value)
                event = self.device.read_one()
        except OSError as error:
            raise self._gone(error) from None
        return *self.workspace.position(*self._fractions()), self._buttons

    def write(self, fx, fy):
        """Apply the force ``(fx, fy)`` (N; clamped to the device maximum)."""
        gx = _finite(fx) * self.x_sign / self.max_force
        gy = _finite(fy) * self.y_sign / self.max_force
        with self._lock:
            if self._stopped:
                return
            if self.polar:
                targets = [polar_effect(gx, gy, self.effects[0].direction)]
            else:
                targets = axis_effects(gx, gy, self.axes)
            for effect, (direction, value) in zip(self.effects, targets):
                if (effect.direction, effect.u.ff_constant_effect.level) != (direction, value):
                    self._update(effect, direction, value)

    def close(self):
        """Zero the force, stop and erase every effect, close the node; safe to call twice."""
        with self._lock:
            if self._closed:
                return
            self._stopped = self._closed = True
            self._silence()
            for effect in self.effects:
                _quietly(self.device.erase_effect, effect.id)
            self.effects = []
            _quietly(self.device.close)

    # -- setting up ---------------------------------------------------------------------------

    def _look(self):
        e = self.ecodes
        offered = self.device.capabilities(absinfo=False)
        self.offered = set(offered.get(e.EV_FF, ()))
        if e.FF_CONSTANT not in self.offered:
            raise EvdevError(f"{self.label} offers no constant force (FF_CONSTANT){_listing(self.offered)}")
        axes = offered.get(e.EV_ABS, ())
        if e.ABS_X not in axes:
            raise EvdevError(f"{self.label} has no ABS_X axis to read the stick's position from")
        self.axes = 2 if e.ABS_Y in axes else 1
        self.capabilities = Capabilities(axes=self.axes, needs_watchdog=True)
        self.ranges = {}
        for code in (e.ABS_X, e.ABS_Y)[: self.axes]:
            info = self.device.absinfo(code)
            if info.max <= info.min:
                raise EvdevError(f"{self.label} reports an empty range for {('ABS_X', 'ABS_Y')[code - e.ABS_X]}")
            self.ranges[code] = (info.min, info.max)
        self.button_codes = sorted(offered.get(e.EV_KEY, ()))[:BUTTONS]
        self._raw = {code: (low + high) / 2 for code, (low, high) in self.ranges.items()}
        self._buttons = 0

    def _start(self):
        e = self.ecodes
        if e.FF_GAIN in self.offered:
            self._send(e.EV_FF, e.FF_GAIN, FULL_GAIN)
        if e.FF_AUTOCENTER in self.offered:
            self._send(e.EV_FF, e.FF_AUTOCENTER, 0)
        room = getattr(self.device, "ff_effects_count", self.axes) or self.axes
        refusal = None
        if self.axes == 1 or room >= self.axes:
            refusal = self._upload_all([(direction, 0) for direction, _ in axis_effects(0.0, 0.0, self.axes)])
        if self.axes == 2 and (refusal is not None or room < 2):
            self.polar, tried = True, refusal is not None
            refusal = self._upload_all([(X_DIRECTION, 0)])
            if refusal is not None and tried:
                raise EvdevError(
                    f"{self.label} refused constant-force effects, one per axis and one polar ({_reason(refusal)})"
                )
        if refusal is not None:
            raise EvdevError(f"{self.label} refused a constant-force effect ({_reason(refusal)})")
        for effect in self.effects:
            self._send(e.EV_FF, effect.id, 1)

    def _upload_all(self, targets):
        """Upload one new effect per ``(direction, level)``: None, or the OSError of a
        refusal (every effect uploaded so far erased again)."""
        for direction, value in targets:
            effect = constant_effect(direction, value)
            try:
                self.device.upload_effect(effect)
            except OSError as error:
                if error.errno in LOST:
                    raise self._gone(error) from None
                for done in self.effects:
                    _quietly(self.device.erase_effect, done.id)
                self.effects = []
                return error
            self.effects.append(effect)
        return None

    def _resync(self):
        """The stick's and the buttons' state now, from the kernel (at the start, and
        after the kernel dropped events)."""
        try:
            for code in self.ranges:
                self._raw[code] = self.device.absinfo(code).value
            active = set(self.device.active_keys())
        except OSError as error:
            raise self._gone(error) from None
        self._buttons = sum(1 << bit for bit, code in enumerate(self.button_codes) if code in active)

    # -- talking to the device ------------------------------------------------------------------

    def _take(self, kind, code, value):
        e = self.ecodes
        if kind == e.EV_ABS and code in self.ranges:
            self._raw[code] = value
        elif kind == e.EV_KEY and code in self.button_codes:
            bit = 1 << self.button_codes.index(code)
            self._buttons = self._buttons | bit if value else self._buttons & ~bit
        elif kind == e.EV_SYN and code == e.SYN_DROPPED:
            self._resync()

    def _fractions(self):
        e = self.ecodes
        fractions = [0.5, 0.5]
        for index, code in enumerate((e.ABS_X, e.ABS_Y)[: self.axes]):
            low, high = self.ranges[code]
            fractions[index] = (self._raw[code] - low) / (high - low)
        return fractions

    def _update(self, effect, direction, value):
        effect.direction, effect.u.ff_constant_effect.level = direction, value
        try:
            self.device.upload_effect(effect)
        except OSError as error:
            raise self._gone(error) from None

    def _send(self, kind, code, value):
        try:
            self.device.write(kind, code, value)
        except OSError as error:
            raise self._gone(error) from None

    def _silence(self):
        for effect in self.effects:
            _quietly(self._update, effect, effect.direction, 0)
            _quietly(self._send, self.ecodes.EV_FF, effect.id, 0)

    def _gone(self, error):
        return DeviceGone(f"the force-feedback device {self.label} stopped answering ({_reason(error)})")


def _finite(force):
    return force if math.isfinite(force) else 0.0


def _quietly(call, *arguments):
    try:
        call(*arguments)
    except (OSError, ValueError, DeviceError):
        pass


def _reason(error):
    return (getattr(error, "strerror", None) or str(error)).rstrip(".")


def _listing(codes):
    names = [_ff_name(code) for code in sorted(codes) if code in EFFECT_TYPES]
    return f"; it offers {', '.join(names)}" if names else "; it offers no force-feedback effects"


def _ff_name(code):
    names = extras.require("evdev.ecodes").FF.get(code, f"FF_{code:#x}")
    names = [names] if isinstance(names, str) else [n for n in names if not n.endswith(("_MIN", "_MAX", "_EFFECTS"))]
    return names[0]


def describe(device):
    """``"Name (vvvv:pppp) /dev/input/eventN"``: an open device, for reports."""
    return f"{device.name or 'device'} ({device.info.vendor:04x}:{device.info.product:04x}) {device.path}"


# -- finding the device ---------------------------------------------------------------------------


def _open(path):
    """An ``InputDevice`` opened for reading and writing, or the OSError why not (a
    node python-evdev could open read-only only is a ``PermissionError``)."""
    import fcntl  # optional: haptics (Linux only, as evdev is)

    device = extras.require("evdev").InputDevice(path)
    if fcntl.fcntl(device.fd, fcntl.F_GETFL) & os.O_ACCMODE != os.O_RDWR:
        device.close()
        raise PermissionError(errno.EACCES, "no permission to write to it", path)
    return device


def _event_number(path):
    digits = os.path.basename(path)[len("event") :]
    return int(digits) if digits.isdigit() else math.inf


def _sysfs_look(node, sysfs):
    """``(name, force-feedback codes)`` of the event node named ``node`` from sysfs,
    which anyone may read; None where sysfs does not say."""
    device = os.path.join(sysfs, "class", "input", node, "device")
    try:
        with open(os.path.join(device, "name")) as name, open(os.path.join(device, "capabilities", "ff")) as ff:
            label, words = name.read().strip(), ff.read().split()
    except OSError:
        return None
    bits, width = 0, 8 * struct.calcsize("l")  # the kernel prints one unsigned long a word, the highest first
    for word in words:
        bits = bits << width | int(word, 16)
    return label, {code for code in range(bits.bit_length()) if bits >> code & 1}


def _open_look(path):
    """``(name, force-feedback codes, problem)`` of the event node ``path``, opening it."""
    try:
        device = _open(path)
    except OSError as error:
        return None, set(), _reason(error)
    try:
        return device.name, set(device.capabilities(absinfo=False).get(extras.require("evdev.ecodes").EV_FF, ())), None
    except OSError as error:
        return device.name, set(), _reason(error)
    finally:
        device.close()


def find_devices(folder="/dev/input", sysfs="/sys"):
    """Every event node in ``folder`` and what it offers: ``[(path, name, effects,
    problem), ...]`` in the order of their numbers, ``effects`` the names of the
    force-feedback effects offered (``"FF_CONSTANT"`` …). What a node offers is read
    from ``sysfs`` (no permission needed), else from the node itself; ``problem`` is
    None, or why neither said.

    Examples
    --------
    A folder without event nodes (a machine without input devices, or a container):

    >>> from rough.render.evdev import find_devices
    >>> find_devices("/nonexistent")
    []
    """
    try:
        nodes = [node for node in os.listdir(folder) if node.startswith("event")]
    except OSError:
        return []
    found = []
    for node in sorted(nodes, key=_event_number):
        path = os.path.join(folder, node)
        looked = _sysfs_look(node, sysfs)
        name, codes, problem = (*looked, None) if looked is not None else _open_look(path)
        found.append((path, name, tuple(_ff_name(c) for c in sorted(codes) if c in EFFECT_TYPES), problem))
    return found


def find_device(path=None, folder="/dev/input", sysfs="/sys"):
    """Open a force-feedback device for reading and writing.

    Parameters
    ----------
    path : str, optional
        The event node, e.g. ``/dev/input/event5``; default the first node in
        ``folder`` offering constant force (``FF_CONSTANT``).
    folder : str, default "/dev/input"
        Where to look for event nodes when no ``path`` is given.
    sysfs : str, default "/sys"
        Where sysfs is mounted (what each node offers, without opening it).

    Returns
    -------
    evdev.InputDevice
        The open device (non-blocking).

    Raises
    ------
    rough.RoughError
        An ``EvdevError`` (exit status 1, one line): no such node, no permission to
        read and write it (with a hint: the input group or a udev rule), or, when
        searching, no device offering constant force (naming what was seen).

    Examples
    --------
    Opening a device needs one (and permission to open its event node), so no
    example here opens one: with a force-feedback joystick plugged in,
    ``find_device()`` returns the first one offering constant force and
    ``find_device("/dev/input/event5")`` that node. What goes wrong is said in one
    line:

    >>> import rough
    >>> from rough.render.evdev import find_device
    >>> for where in ("/dev/input/no-such-node", None):
    ...     try:
    ...         find_device(where, folder="/nonexistent")
    ...     except rough.RoughError as error:
    ...         print(error)
    /dev/input/no-such-node: no such device node
    no force-feedback device found: no event devices in /nonexistent
    """
    if path is not None:
        return _open_one(path)
    seen = find_devices(folder, sysfs)
    refusal = None
    for candidate, name, effects, problem in seen:
        if problem is None and "FF_CONSTANT" in effects:
            try:
                return _open_one(candidate, name)
            except EvdevError as error:
                refusal = refusal or error
    if refusal is not None:
        raise refusal
    raise EvdevError(f"no force-feedback device found: {_seen(seen, folder)}")


def _open_one(path, name=None):
    where = f"{path} ({name})" if name else path
    try:
        return _open(path)
    except FileNotFoundError:
        raise EvdevError(f"{where}: no such device node") from None
    except PermissionError as error:
        raise EvdevError(f"{where}: {_reason(error)} (rough reads and writes it: {PERMISSION_HINT})") from None
    except OSError as error:
        raise EvdevError(f"{where}: could not be opened ({_reason(error)})") from None


def _seen(seen, folder):
    if not seen:
        return f"no event devices in {folder}"
    notes = []
    for path, name, effects, problem in seen[:SHOWN]:
        what = problem or (f"only {', '.join(effects)}" if effects else "no force feedback")
        notes.append(f"{os.path.basename(path)}{f' {name!r}' if name else ''} ({what})")
    more = f" and {len(seen) - SHOWN} more" if len(seen) > SHOWN else ""
    closed = sum(problem is not None for *_, problem in seen)
    hint = f"; {closed} could not be opened: {PERMISSION_HINT}" if closed else ""
    return f"none of {len(seen)} event devices offers constant force (FF_CONSTANT): {', '.join(notes)}{more}{hint}"


def open_device(argument, workspace, max_force, **options):
    """The :mod:`~rough.render.device` factory's entry: the device ``evdev[:argument]``
    (``argument`` an event node such as ``/dev/input/event5``, or None for the first
    offering constant force) as an :class:`EvdevDevice`."""
    device = find_device(argument)
    try:
        return EvdevDevice(device, workspace, max_force)
    except BaseException:
        _quietly(device.close)
        raise
