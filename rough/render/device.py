"""The render device interface, and the one place that opens a device by its name.

A device is anything the servo loop can read a position from and write a force to:
:class:`~rough.render.hand.SimulatedHand` (``sim``), a HID PID joystick through
hidraw (``hid``, :mod:`rough.render.hid`) and a Linux force-feedback device through
evdev (``evdev``, :mod:`rough.render.evdev`). Each backend is one module with an
``open_device(argument, workspace, max_force, **options)`` function and a line in
:data:`BACKENDS`; nothing else in rough names a backend.

A physical device reports its stick in its own units; the :class:`Workspace` says
where the stick's travel lies on the surface (metres) and which axes are reversed.
"""

import dataclasses
import importlib
from typing import Protocol, runtime_checkable

from ..errors import RoughError

# name -> (module, what it is, the form of the argument after "name:")
BACKENDS = {
    "sim": ("rough.render.hand", "a simulated hand", None),
    "hid": ("rough.render.hid", "a HID PID joystick through hidraw", "VID:PID"),
    "evdev": ("rough.render.evdev", "a Linux force-feedback device through evdev", "PATH"),
}
DEVICE_DAMPING = 0.45  # N·s/m, assumed: it puts the bound 2b/T at 0.9 N/mm at 1 kHz (docs/math.rst §5.7)


class DeviceError(RoughError):
    """A device could not be opened or stopped answering (exit status 1)."""


@dataclasses.dataclass(frozen=True)
class Capabilities:
    """What a device can do.

    Attributes
    ----------
    axes : int
        Force axes in the stick's plane: 2 for a joystick, 1 for a wheel.
    rate : float or None
        The highest force update rate it takes, Hz; None when unknown or unbounded.
    needs_watchdog : bool
        Whether a stalled loop must have its force zeroed by a watchdog thread (every
        device a hand holds).
    damping : float
        The device's own viscous damping b, N·s/m, for the passivity bound
        (:func:`rough.render.stability.passivity_bound`).
    simulated : bool
        A simulated device: the loop may run it unpaced.
    """

    axes: int = 2
    rate: float = None
    needs_watchdog: bool = True
    damping: float = DEVICE_DAMPING
    simulated: bool = False


@runtime_checkable
class Device(Protocol):
    """The interface every render device implements (SI units).

    Attributes
    ----------
    label : str
        What the device is, for reports, e.g. ``"sim"`` or
        ``"Virtual FF joystick (1209:0001)"``.
    capabilities : Capabilities
        Axes, rate, watchdog and damping.
    velocity : tuple of float
        ``(vx, vy)`` at the moment it was opened, m/s: the loop's velocity estimate
        starts there.
    """

    label: str
    capabilities: Capabilities
    velocity: tuple

    def read(self):
        """``(x, y, buttons)``: the newest position in metres and a bit mask of buttons
        (bit 0 the trigger)."""

    def write(self, fx, fy):
        """Apply the force ``(fx, fy)`` (N) until the next write."""

    def zero(self):
        """Write zero force and keep the device ready for more."""

    def emergency_stop(self):
        """Zero the force now, from any thread; later writes are ignored."""

    def close(self):
        """Zero the force and release the device; safe to call twice."""


@dataclasses.dataclass(frozen=True)
class Workspace:
    """Where a stick's travel lies on the surface.

    The stick at ``(u, v)`` (each 0 … 1 across its travel) is at
    ``x = x_start + u x_span`` and ``y = y_centre + (v - 1/2) y_span`` metres; an axis
    named in ``invert`` is reversed, its position and its force.

    Examples
    --------
    >>> from rough.render.device import Workspace
    >>> space = Workspace(0.0, 0.08, 0.0, 0.01, invert=("y",))
    >>> space.position(0.5, 0.0)  # m: the middle of x, the top of y (reversed)
    (0.04, 0.005)
    >>> space.signs
    (1, -1)
    """

    x_start: float
    x_span: float
    y_centre: float
    y_span: float
    invert: tuple = ()

    @property
    def signs(self):
        """``(±1, ±1)``: -1 for a reversed axis."""
        return (-1 if "x" in self.invert else 1), (-1 if "y" in self.invert else 1)

    def position(self, u, v):
        """Metres from the stick's fractions of its travel."""
        if "x" in self.invert:
            u = 1.0 - u
        if "y" in self.invert:
            v = 1.0 - v
        return self.x_start + u * self.x_span, self.y_centre + (v - 0.5) * self.y_span


class StreamedForce:
    """``zero`` and ``emergency_stop`` for a joystick that streams its force under
    ``self._lock``, ignores writes once ``self._stopped`` is set, and stops its effects
    with ``self._silence()``: the HID and evdev backends."""

    def zero(self):
        """Stream zero force, the effects left playing."""
        self.write(0.0, 0.0)

    def emergency_stop(self):
        """Zero the force and stop the effects now (from any thread); later writes are ignored."""
        with self._lock:
            self._stopped = True
            self._silence()


class HeldOpen:
    """A device whose ``close`` only zeroes the force, so that one device serves many
    runs (the experiment's trials); close the device itself at the end."""

    def __init__(self, device):
        self.device = device
        self.label, self.capabilities = device.label, device.capabilities

    @property
    def velocity(self):
        return self.device.velocity

    def read(self):
        return self.device.read()

    def write(self, fx, fy):
        self.device.write(fx, fy)

    def zero(self):
        self.device.zero()

    def emergency_stop(self):
        self.device.emergency_stop()

    def close(self):
        self.device.zero()


def parse_device(spec):
    """``(backend, argument)`` from a device name such as ``sim``, ``hid:1209:0001`` or
    ``evdev:/dev/input/event5`` (argument None when absent).

    Raises
    ------
    rough.RoughError
        A ``DeviceError`` for a name that is not a backend.

    Examples
    --------
    >>> from rough.render.device import parse_device
    >>> parse_device("hid:1209:0001"), parse_device("evdev")
    (('hid', '1209:0001'), ('evdev', None))
    """
    name, _, argument = spec.partition(":")
    if name not in BACKENDS or (argument and BACKENDS[name][2] is None):
        forms = ", ".join(f"{n} or {n}:{a}" if a else n for n, (_, _, a) in BACKENDS.items())
        raise DeviceError(f"--device {spec!r}: use {forms}")
    return name, argument or None


def is_simulated(spec):
    """Whether the device name ``spec`` is a simulated one."""
    return parse_device(spec)[0] == "sim"


def open_device(spec, workspace=None, max_force=None, **options):
    """Open the device named ``spec``.

    Parameters
    ----------
    spec : str
        ``sim``, ``hid[:VID:PID]`` or ``evdev[:PATH]`` (see :data:`BACKENDS`).
    workspace : Workspace, optional
        Where the stick's travel lies on the surface (physical devices).
    max_force : float, optional
        The force that the device's full output stands for, N (physical devices).
    **options
        Passed to the backend: the simulated hand's stroke, press, mass and damping.

    Returns
    -------
    Device

    Raises
    ------
    rough.RoughError
        For an unknown name, or a device that cannot be found or opened (one line,
        exit status 1).

    Examples
    --------
    >>> from rough.render.device import Device, open_device
    >>> hand = open_device("sim", speed=0.02, start_x=0.0, start_y=0.0, period=1e-3)
    >>> isinstance(hand, Device), hand.label, hand.capabilities.simulated
    (True, 'sim', True)
    """
    name, argument = parse_device(spec)
    backend = importlib.import_module(BACKENDS[name][0])
    return backend.open_device(argument, workspace, max_force, **options)
