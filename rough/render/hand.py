"""A simulated hand on a simulated joystick: the ``sim`` device.

The hand strokes along x at a constant ``speed`` while pressing down with the force
``press``, through its own ``mass`` and ``damping`` (MATH.md §5.5's illustration: a
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
    """The device interface (``read``, ``write``, ``close``) on a model of a hand."""

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
