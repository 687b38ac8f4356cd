"""A simulated hand on a simulated joystick: the ``sim`` device.

The hand strokes along x at a constant ``speed`` while pressing down with the force
``press``, through its own ``mass`` and ``damping`` (docs/math.rst §5.5's illustration: a
0.15 kg hand with 2 N·s/m pushing down with 1 N). Along x it follows its stroke
rigidly, unless ``lateral_stiffness`` (N/m, with ``lateral_damping``) lets the
lateral and friction forces push it off its path. The force the loop writes is held
for one servo period, as a device holds it, and the hand's motion over that period
is integrated exactly (zero-order hold), so the simulation is as stable as the
sampled system it imitates.
"""

from .contact import zero_order_hold

HAND_MASS = 0.15  # kg
HAND_DAMPING = 2.0  # N·s/m
PRESS = 1.0  # N


class SimulatedHand:
    """The device interface (``read``, ``write``, ``close``) on a model of a hand.

    The hand strokes along x at a constant ``speed`` while pressing down with
    ``press``, through its own ``mass`` and ``damping``; the force written is held
    for one period and the motion over it integrated exactly. ``read()`` returns
    ``(x, y, buttons)`` (m, m, always 0), ``write(fx, fy)`` applies a force (N) for
    one period, ``close()`` releases nothing.

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

    Attributes
    ----------
    name : str
        ``"sim"``.
    needs_watchdog : bool
        False: a simulated hand cannot feel a stuck force.
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

    name = "sim"
    needs_watchdog = False

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
    ):
        if not (mass > 0 and damping >= 0 and period > 0):
            raise ValueError("the hand needs a positive mass and period and a non-negative damping")
        self.speed, self.press, self.period = float(speed), float(press), float(period)
        self.start_x = float(start_x)
        self.ticks = 0
        self.y, self.vy = float(start_y), 0.0
        self.offset, self.offset_velocity = 0.0, 0.0
        self._vertical = zero_order_hold(0.0, damping, mass, period)
        self._lateral = (
            None if lateral_stiffness is None else zero_order_hold(lateral_stiffness, lateral_damping, mass, period)
        )

    @property
    def velocity(self):
        return self.speed + self.offset_velocity, self.vy

    def read(self):
        """``(x, y, buttons)``: metres, metres, no buttons pressed."""
        return self.start_x + self.speed * self.ticks * self.period + self.offset, self.y, 0

    def write(self, fx, fy):
        """Apply ``(fx, fy)`` (N) to the hand for one period."""
        p11, p12, p21, p22, g1, g2 = self._vertical
        push = fy - self.press
        self.y, self.vy = p11 * self.y + p12 * self.vy + g1 * push, p21 * self.y + p22 * self.vy + g2 * push
        if self._lateral is not None:
            p11, p12, p21, p22, g1, g2 = self._lateral
            e, v = self.offset, self.offset_velocity
            self.offset, self.offset_velocity = p11 * e + p12 * v + g1 * fx, p21 * e + p22 * v + g2 * fx
        self.ticks += 1

    def close(self):
        """Nothing to release."""
