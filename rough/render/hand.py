"""A simulated hand on a simulated joystick: the ``sim`` device.

On a profile (:class:`SimulatedHand`) the hand strokes along x while pressing down with
the force ``press``, through its own ``mass`` and ``damping`` (docs/math.rst §5.5's
illustration: a 0.15 kg hand with 2 N·s/m pushing down with 1 N). On a map
(:class:`MapHand`) it strokes in the plane of the map along a direction. Along its
stroke it moves rigidly, unless ``lateral_stiffness`` (N/m, with ``lateral_damping``)
lets the lateral and friction forces push it off its path. The force the loop writes
is held for one servo period, as a device holds it, and the hand's motion over that
period is integrated exactly (zero-order hold), so the simulation is as stable as the
sampled system it imitates.

A :class:`Stroke` says where the hand is along its stroke: one way at constant speed,
or back and forth over a window, slowing down into each turn and speeding up out of
it as a hand does.
"""

import math

from .contact import zero_order_hold
from .device import Backend, Capabilities

BACKEND = Backend(name="sim", title="a simulated hand", simulated=True)
HAND_MASS = 0.15  # kg
HAND_DAMPING = 2.0  # N·s/m
PRESS = 1.0  # N
TURN = 0.2  # s: the time a hand takes to reverse its stroke


class Stroke:
    """Where a hand stroking at ``speed`` is along its stroke, tick by tick.

    One way (no ``length``): ``s = speed × k × period`` at constant speed. Back and
    forth over ``[0, length]``: the hand starts at 0 at full speed, and at each end
    turns in ``turn`` seconds, its velocity ``speed × cos(π τ / turn)`` through the
    turn (so it slows into the end, stops there and speeds up on the way back: a
    peak acceleration of π speed / turn). The turn begins ``d = speed × turn / π``
    before the end; a turn that would need more than a quarter of the window is made
    shorter.

    Parameters
    ----------
    speed : float
        The stroking speed, m/s.
    period : float
        The servo period, s.
    length : float, optional
        The window to stroke back and forth over, m; default one way.
    turn : float, default 0.2
        Seconds to reverse.

    Examples
    --------
    Back and forth over 10 mm at 20 mm/s: the hand reaches the far end at 0.536 s,
    almost at rest, and comes back:

    >>> from rough.render.hand import Stroke
    >>> stroke = Stroke(0.02, 1e-3, length=0.01)
    >>> [round(stroke.at(k)[0] * 1e3, 3) for k in (0, 250, 536, 1000)]  # mm
    [0.0, 5.0, 10.0, 1.454]
    >>> [round(stroke.at(k)[1] * 1e3, 3) for k in (250, 536, 800)]  # mm/s
    [20.0, 0.106, -20.0]
    """

    def __init__(self, speed, period, length=None, turn=TURN):
        self.speed, self.period, self.length = float(speed), float(period), length
        if length is not None:
            self.turn = min(turn, math.pi * length / (4.0 * abs(self.speed)))
            self.rim = abs(self.speed) * self.turn / math.pi
            self.cruise = (length - 2.0 * self.rim) / abs(self.speed)
            self.first = (length - self.rim) / abs(self.speed)
            self.cycle = 2.0 * (self.turn + self.cruise)

    def at(self, k):
        """``(s, v)`` after ``k`` ticks: the distance along the stroke (m) and the
        velocity along it (m/s)."""
        if self.length is None:
            return self.speed * k * self.period, self.speed
        t, v = k * self.period, abs(self.speed)
        if t < self.first:
            return v * t, v
        tau = (t - self.first) % self.cycle
        turn, rim, far = self.turn, self.rim, self.length - self.rim
        if tau < turn:
            s, velocity = far + rim * math.sin(math.pi * tau / turn), v * math.cos(math.pi * tau / turn)
        elif tau < turn + self.cruise:
            s, velocity = far - v * (tau - turn), -v
        elif tau < 2.0 * turn + self.cruise:
            phase = math.pi * (tau - turn - self.cruise) / turn
            s, velocity = rim - rim * math.sin(phase), -v * math.cos(phase)
        else:
            s, velocity = rim + v * (tau - 2.0 * turn - self.cruise), v
        return min(max(s, 0.0), self.length), velocity


class _Hand:
    """What both simulated hands share: the device interface's bookkeeping (no
    watchdog, nothing to zero, stop or release), the checks of the hand's mass, damping
    and period, and the lateral spring-damper that lets forces push it off its path."""

    label = "sim"

    def __init__(self, stroke, period, mass, damping, lateral_stiffness, lateral_damping):
        if not (mass > 0 and damping >= 0 and period > 0):
            raise ValueError("the hand needs a positive mass and period and a non-negative damping")
        self.stroke, self.period = stroke, float(period)
        self.capabilities = Capabilities(needs_watchdog=False, damping=float(damping), simulated=True)
        self.ticks = 0
        self._lateral = (
            None if lateral_stiffness is None else zero_order_hold(lateral_stiffness, lateral_damping, mass, period)
        )

    def zero(self):
        """Nothing to zero: the next write sets the force."""

    def emergency_stop(self):
        """Nothing to stop."""

    def close(self):
        """Nothing to release."""


class SimulatedHand(_Hand):
    """The device interface (:class:`~rough.render.device.Device`) on a model of a
    hand stroking a profile.

    The hand strokes along x (one way at constant ``speed``, or back and forth as
    ``stroke`` says) while pressing down with ``press``, through its own ``mass`` and
    ``damping``; the force written is held for one period and the motion over it
    integrated exactly. ``read()`` returns ``(x, y, buttons)`` (m, m, always 0),
    ``write(fx, fy)`` applies a force (N) for one period, ``close()`` releases
    nothing.

    Parameters
    ----------
    speed : float
        The stroking speed along x, m/s.
    start_x, start_y : float
        Where the hand starts, metres.
    period : float
        The servo period, s.
    press : float, default 1.0
        The downward force of the hand, N.
    mass : float, default 0.15
        The hand's mass, kg.
    damping : float, default 2.0
        The hand's vertical damping, N·s/m.
    lateral_stiffness : float, optional
        N/m: lets the lateral and friction forces push the hand off its stroke along
        x; default None, a rigid stroke.
    lateral_damping : float, default 20.0
        N·s/m, with ``lateral_stiffness``.
    stroke : Stroke, optional
        The stroke; default one way at ``speed``.

    Attributes
    ----------
    label : str
        ``"sim"``.
    capabilities : Capabilities
        No watchdog (a simulated hand cannot feel a stuck force), simulated, and the
        hand's damping as the device's.
    ticks : int
        Periods written so far.
    y, vy : float
        The hand's height (m) and vertical velocity (m/s).
    velocity : tuple of float
        ``(vx, vy)``, m/s.

    Raises
    ------
    ValueError
        For a mass or period that is not positive, or a negative damping.

    Examples
    --------
    Left to its own press of 1 N, the 0.15 kg hand sinks by about F t²/(2m) = 3.3 µm
    in the first millisecond, while it strokes 20 µm along x:

    >>> from rough.render import SimulatedHand
    >>> hand = SimulatedHand(0.02, start_x=0.0, start_y=0.0, period=1e-3)
    >>> hand.read()
    (0.0, 0.0, 0)
    >>> hand.write(0.0, 0.0)  # no force from the surface
    >>> x, y, buttons = hand.read()
    >>> round(x * 1e6, 6), round(y * 1e6, 2)  # µm
    (20.0, -3.32)
    """

    def __init__(
        self,
        speed,
        start_x,
        start_y,
        period,
        press=PRESS,
        mass=HAND_MASS,
        damping=HAND_DAMPING,
        lateral_stiffness=None,
        lateral_damping=20.0,
        stroke=None,
    ):
        super().__init__(stroke or Stroke(speed, period), period, mass, damping, lateral_stiffness, lateral_damping)
        self.speed, self.press = float(speed), float(press)
        self.start_x = float(start_x)
        self.y, self.vy = float(start_y), 0.0
        self.offset, self.offset_velocity = 0.0, 0.0
        self._vertical = zero_order_hold(0.0, damping, mass, period)

    @property
    def velocity(self):
        return self.stroke.at(self.ticks)[1] + self.offset_velocity, self.vy

    def read(self):
        """``(x, y, buttons)``: metres, metres, no buttons pressed."""
        return self.start_x + self.stroke.at(self.ticks)[0] + self.offset, self.y, 0

    def write(self, fx, fy):
        """Apply ``(fx, fy)`` (N) to the hand for one period."""
        p11, p12, p21, p22, g1, g2 = self._vertical
        push = fy - self.press
        self.y, self.vy = p11 * self.y + p12 * self.vy + g1 * push, p21 * self.y + p22 * self.vy + g2 * push
        if self._lateral is not None:
            self.offset, self.offset_velocity = _held(self._lateral, self.offset, self.offset_velocity, fx)
        self.ticks += 1


class MapHand(_Hand):
    """The device interface (:class:`~rough.render.device.Device`) on a model of a
    hand stroking a map in its plane.

    The hand strokes from ``start`` along the unit vector ``direction`` as
    ``stroke`` says (one way, or back and forth over a chord of the map); rigidly,
    unless ``lateral_stiffness`` lets the force push it off its path in both axes.
    ``read()`` returns ``(x, y, 0)``, the point on the map in metres.

    Parameters
    ----------
    stroke : Stroke
        Where the hand is along its stroke.
    start : tuple of float
        Where the stroke starts, ``(x, y)`` metres.
    direction : tuple of float
        The stroke's unit vector ``(cos θ, sin θ)``.
    period : float
        The servo period, s.
    mass : float, default 0.15
        The hand's mass, kg (with ``lateral_stiffness``).
    damping : float, default 2.0
        The device's damping as the passivity bound sees it, N·s/m.
    lateral_stiffness : float, optional
        N/m, with ``lateral_damping``; default a rigid stroke.
    lateral_damping : float, default 20.0
        N·s/m.

    Examples
    --------
    >>> import math
    >>> from rough.render.hand import MapHand, Stroke
    >>> hand = MapHand(Stroke(0.02, 1e-3), (0.0, 0.0), (math.cos(math.pi / 4), math.sin(math.pi / 4)), 1e-3)
    >>> for tick in range(10):
    ...     hand.write(0.0, 0.0)
    >>> x, y, buttons = hand.read()
    >>> round(x * 1e6, 3), round(y * 1e6, 3)  # µm: 200 µm along the diagonal
    (141.421, 141.421)
    """

    def __init__(
        self,
        stroke,
        start,
        direction,
        period,
        mass=HAND_MASS,
        damping=HAND_DAMPING,
        lateral_stiffness=None,
        lateral_damping=20.0,
    ):
        super().__init__(stroke, period, mass, damping, lateral_stiffness, lateral_damping)
        self.start, self.direction = tuple(map(float, start)), tuple(map(float, direction))
        self.offset = [0.0, 0.0, 0.0, 0.0]  # x, vx, y, vy off the path

    @property
    def velocity(self):
        v = self.stroke.at(self.ticks)[1]
        return v * self.direction[0] + self.offset[1], v * self.direction[1] + self.offset[3]

    def read(self):
        """``(x, y, buttons)``: the point on the map, metres; no buttons pressed."""
        s = self.stroke.at(self.ticks)[0]
        return (
            self.start[0] + s * self.direction[0] + self.offset[0],
            self.start[1] + s * self.direction[1] + self.offset[2],
            0,
        )

    def write(self, fx, fy):
        """Apply ``(fx, fy)`` (N) to the hand for one period."""
        if self._lateral is not None:
            o = self.offset
            o[0], o[1] = _held(self._lateral, o[0], o[1], fx)
            o[2], o[3] = _held(self._lateral, o[2], o[3], fy)
        self.ticks += 1


def _held(step, position, velocity, force):
    """One zero-order-hold step of a spring-damper-mass under ``force``."""
    p11, p12, p21, p22, g1, g2 = step
    return p11 * position + p12 * velocity + g1 * force, p21 * position + p22 * velocity + g2 * force


def open_device(argument, workspace, max_force, surface=None, **hand):
    """The :mod:`~rough.render.device` factory's entry: a :class:`MapHand` when
    ``surface`` is ``"map"`` (``hand`` holds its parameters), else a
    :class:`SimulatedHand`."""
    return MapHand(**hand) if surface == "map" else SimulatedHand(**hand)
