"""The render device interface, and the registry of backends that opens a device by
its name.

A device is anything the servo loop can read a position from and write a force to:
:class:`~rough.render.hand.SimulatedHand` (``sim``), a HID PID joystick through
hidraw (``hid``, :mod:`rough.render.hid`) and a Linux force-feedback device through
evdev (``evdev``, :mod:`rough.render.evdev`). Each backend is one module that declares
its facts once, ``BACKEND = Backend(...)``, and opens a device with
``open_device(argument, workspace, max_force, **options)``. The built-in modules are
:data:`BUILT_IN`; a plugin package adds one through the entry-point group
``rough.devices`` (:mod:`rough.plugins`). Every list of backends (help texts, error
messages, tests) comes from :func:`backends`.

A physical device reports its stick in its own units; the :class:`Workspace` says
where the stick's travel lies on the surface (metres) and which axes are reversed.
"""

import dataclasses
import functools
import importlib
import logging
from typing import Protocol, runtime_checkable

from ..errors import RoughError
from ..plugins import entry_points

#: The modules of the built-in backends, in the order messages name them.
BUILT_IN = ("rough.render.hand", "rough.render.hid", "rough.render.evdev")
GROUP = "rough.devices"
DEVICE_DAMPING = 0.45  # N·s/m, assumed: it puts the bound 2b/T at 0.9 N/mm at 1 kHz (docs/math.rst §5.7)
log = logging.getLogger("rough")


@dataclasses.dataclass(frozen=True)
class Backend:
    """What a render backend is, declared once in its module as ``BACKEND``.

    Attributes
    ----------
    name : str
        Its name in ``--device NAME[:ARGUMENT]``.
    title : str
        What it opens, for help texts, e.g. ``"a simulated hand"``.
    argument : str or None
        The form of what may follow ``NAME:``, e.g. ``"VID:PID"``; None when it takes
        nothing.
    requires : tuple of str
        The optional modules it needs (:func:`rough.extras.require` names the extra
        that installs each).
    simulated : bool
        The simulated hand: it strokes by itself, so ``render`` runs it at each
        ``--speed`` (:func:`rough.render.simulate`) rather than until Ctrl-C.

    Examples
    --------
    >>> from rough.render.device import Backend
    >>> Backend("hid", "a HID PID joystick", argument="VID:PID").form
    'hid[:VID:PID]'
    """

    name: str
    title: str
    argument: str = None
    requires: tuple = ()
    simulated: bool = False

    @property
    def form(self):
        """``NAME[:ARGUMENT]``, as help texts write it."""
        return f"{self.name}[:{self.argument}]" if self.argument else self.name


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


@functools.cache
def modules():
    """``{name: module}`` of every backend: the built-in ones (:data:`BUILT_IN`), then
    the plugins of the entry-point group ``rough.devices`` whose names are not taken.
    A plugin that fails to load, or lacks ``BACKEND`` or ``open_device``, is left out
    with a one-line warning."""
    found = {}
    for path in BUILT_IN:
        module = importlib.import_module(path)
        found[module.BACKEND.name] = module
    for name, value in entry_points(GROUP).items():
        if name not in found:
            module = _plugin(name, value)
            if module is not None:
                found[name] = module
    return found


def _plugin(name, value):
    try:
        module = importlib.import_module(value)
        if not (isinstance(module.BACKEND, Backend) and callable(module.open_device)):
            raise TypeError("BACKEND must be a rough.render.device.Backend and open_device a function")
    except Exception as error:  # a broken plugin must not stop rough
        log.warning(f"the device plugin {name!r} ({value}) is left out: {type(error).__name__}: {error}")
        return None
    return module


def backends():
    """``{name: Backend}`` of every backend, built-in first (see :func:`modules`).

    Examples
    --------
    >>> from rough.render.device import backends
    >>> list(backends())[:3]
    ['sim', 'hid', 'evdev']
    """
    return {name: module.BACKEND for name, module in modules().items()}


def forms():
    """The device names ``--device`` takes, for help texts.

    Examples
    --------
    >>> from rough.render.device import forms
    >>> forms()  # with no plugin installed
    'sim, hid[:VID:PID] or evdev[:PATH]'
    """
    *others, last = [backend.form for backend in backends().values()]
    return f"{', '.join(others)} or {last}" if others else last


def descriptions():
    """What each backend opens, for help texts: ``"sim: a simulated hand; hid: …"``."""
    return "; ".join(f"{name}: {backend.title}" for name, backend in backends().items())


def parse_device(spec):
    """``(backend, argument)`` from a device name such as ``sim``, ``hid:1209:0001`` or
    ``evdev:/dev/input/event5`` (argument None when absent).

    Raises
    ------
    rough.RoughError
        A ``DeviceError`` for a name that is not a backend, naming them all.

    Examples
    --------
    >>> from rough.render.device import parse_device
    >>> parse_device("hid:1209:0001"), parse_device("evdev")
    (('hid', '1209:0001'), ('evdev', None))
    """
    name, _, argument = spec.partition(":")
    known = backends()
    if name not in known or (argument and known[name].argument is None):
        choices = ", ".join(f"{n} or {n}:{backend.argument}" if backend.argument else n for n, backend in known.items())
        raise DeviceError(f"--device {spec!r}: use {choices}")
    return name, argument or None


def is_simulated(spec):
    """Whether the device name ``spec`` is the simulated hand (:attr:`Backend.simulated`)."""
    return backends()[parse_device(spec)[0]].simulated


def open_device(spec, workspace=None, max_force=None, **options):
    """Open the device named ``spec``.

    Parameters
    ----------
    spec : str
        ``NAME[:ARGUMENT]``, one of :func:`forms`: ``sim``, ``hid[:VID:PID]`` or
        ``evdev[:PATH]``, or a plugin's.
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
    return modules()[name].open_device(argument, workspace, max_force, **options)
