"""Contact between the stylus and the profile (docs/math.rst §5.2), in SI units.

Forces are those on the stylus and so on the hand: F_y up positive, F_x along +x.
Both models return ``(F_x, F_y, contact)`` from the stylus position ``x``, the surface
under it ``(h, h', h'')`` and the hand's state (``y`` its height, ``vx``, ``vy`` its
velocity, ``ax`` its horizontal acceleration).

* :class:`QuasiStatic` (default; the paper's experiment, M and C negligible):
  ``F_y = K (h - y)`` while ``y <= h``, else 0, and ``F_x = -F_y h'``: the lateral force
  resists climbing (the sources print the opposite sign, the force on the surface).
* :class:`DynamicStylus`: a stylus of mass M hangs from the hand on the spring K and
  damper C. In contact its tip follows the surface and the constraint force is
  ``F = M ÿ_s - K (y - y_s) - C (ẏ - ẏ_s)`` with ``ÿ_s = h'' ẋ² + h' ẍ``, where h'' is
  the mean curvature over the path of the last tick (the change of slope over the
  distance moved), so that a corner narrower than one tick's travel still loads the
  stylus instead of slipping between two samples of h''; contact is
  lost when that force would pull (F < 0), and regained, plastically, when the tip
  reaches the surface again. In free flight the stylus ODE is integrated exactly
  (matrix exponential, zero-order hold) in sub-steps, so it is stable for any M, K
  and C at any loop rate. The hand feels the coupling force ``K (y_s - y) + C (ẏ_s - ẏ)``.
"""

import math

STIFFNESS = 1280.0  # N/m: the paper's 1.28 N/mm
STYLUS_MASS = 1.85e-3  # kg: the slides' "1.85e-6" read in N·s²/mm (docs/math.rst §5.3)
STYLUS_DAMPING = 0.046  # N·s/m: the slides' 4.6e-5 N/(mm/s)
MAX_FORCE = 8.9  # N: the Impulse Engine 2000


class QuasiStatic:
    """The penalty wall along the profile with Minsky's lateral-gradient term.

    The paper's experiment, with the stylus's mass and damping negligible:
    ``F_y = K (h - y)`` while the hand is at or below the surface (``y <= h``), else 0,
    and ``F_x = -F_y h'``: the lateral force resists climbing. ``step(x, h, slope,
    curvature, y, vx, vy, ax)`` returns ``(F_x, F_y, contact)`` (N, N, bool), the force
    on the stylus and so on the hand; ``reset()`` does nothing (no state).

    Parameters
    ----------
    stiffness : float, default 1280.0
        The contact stiffness K, N/m (the paper's 1.28 N/mm).

    Attributes
    ----------
    stiffness : float
        K, N/m.

    Raises
    ------
    ValueError
        For a stiffness that is not positive.

    Examples
    --------
    One micrometre into a surface that rises with slope 0.1:

    >>> from rough.render import QuasiStatic
    >>> model = QuasiStatic()
    >>> fx, fy, contact = model.step(0.0, 1e-6, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0)
    >>> print(f"F_x {fx * 1e3:.3f} mN, F_y {fy * 1e3:.3f} mN, contact {contact}")
    F_x -0.128 mN, F_y 1.280 mN, contact True
    >>> model.step(0.0, 0.0, 0.1, 0.0, 1e-6, 0.0, 0.0, 0.0)  # above the surface
    (0.0, 0.0, False)
    """

    def __init__(self, stiffness=STIFFNESS):
        if not stiffness > 0:
            raise ValueError("the contact stiffness must be positive")
        self.stiffness = float(stiffness)

    def reset(self, y=None):
        """No state to reset."""

    def step(self, x, h, slope, curvature, y, vx, vy, ax):
        penetration = h - y
        if penetration < 0.0:
            return 0.0, 0.0, False
        fy = self.stiffness * penetration
        return -fy * slope, fy, True


class DynamicStylus:
    """The stylus with mass and damping, hanging from the hand on a spring and damper.

    In contact the stylus's tip follows the surface and the constraint force is
    ``F = M ÿ_s - K (y - y_s) - C (ẏ - ẏ_s)`` with ``ÿ_s = h'' ẋ² + h' ẍ``; contact is
    lost when that force would pull (F < 0), and regained, plastically, when the tip
    reaches the surface again. In free flight the stylus is integrated exactly
    (zero-order hold) in sub-steps, stable for any M, K and C at any loop rate. The
    hand feels the coupling force ``K (y_s - y) + C (ẏ_s - ẏ)``. ``step(x, h, slope,
    curvature, y, vx, vy, ax)`` returns ``(F_x, F_y, contact)`` (N, N, bool);
    ``reset(y=None)`` puts the stylus at rest at height ``y``, free, or with no ``y``
    on the surface.

    Parameters
    ----------
    stiffness : float, default 1280.0
        The spring K between hand and stylus, N/m (1.28 N/mm).
    mass : float, default 1.85e-3
        The stylus mass M, kg (the slides' "1.85e-6" read in N·s²/mm).
    damping : float, default 0.046
        The damper C, N·s/m (the slides' 4.6e-5 N/(mm/s)).
    period : float, default 1e-3
        The servo period it is stepped at, s.
    substeps : int, default 10
        Sub-steps per period in free flight.

    Attributes
    ----------
    stiffness, mass, damping : float
        K (N/m), M (kg) and C (N·s/m).
    substeps : int
        Sub-steps per period.
    substep : float
        ``period / substeps``, s.
    position, velocity : float
        The stylus's height (m) and vertical velocity (m/s).
    touching : bool
        Whether the stylus is on the surface.

    Raises
    ------
    ValueError
        For a stiffness, mass, period or substeps that is not positive, or a
        negative damping.

    Notes
    -----
    h'' is the mean curvature over the path of the last tick (the change of slope
    over the distance moved), so that a corner narrower than one tick's travel still
    loads the stylus instead of slipping between two samples of h''.

    Examples
    --------
    Resting on a flat surface with the hand 1 mm below the tip, the spring pushes
    up with K × 1 mm:

    >>> from rough.render import DynamicStylus
    >>> model = DynamicStylus()
    >>> model.touching
    True
    >>> fx, fy, contact = model.step(0.0, 0.0, 0.0, 0.0, -1e-3, 0.0, 0.0, 0.0)
    >>> round(fy, 9), contact  # N
    (1.28, True)

    Stroking a flat track with the simulated hand, it settles at the hand's press:

    >>> import numpy as np
    >>> from rough.render import Track, forces, simulate
    >>> result = simulate(Track(np.zeros(101), 0.1e-3), speed=0.02, model=DynamicStylus())
    >>> round(forces(result)["F_y_mean"], 6)  # N
    1.0
    """

    def __init__(self, stiffness=STIFFNESS, mass=STYLUS_MASS, damping=STYLUS_DAMPING, period=1e-3, substeps=10):
        if not (stiffness > 0 and mass > 0 and damping >= 0 and period > 0 and substeps >= 1):
            raise ValueError("the stylus needs positive stiffness, mass and period and a non-negative damping")
        self.stiffness, self.mass, self.damping = float(stiffness), float(mass), float(damping)
        self.substeps = int(substeps)
        self.substep = period / substeps
        self._flight = zero_order_hold(stiffness, damping, mass, self.substep)
        self.reset()

    def reset(self, y=None):
        """Put the stylus at rest at height ``y``, free; with no ``y``, on the surface."""
        self.position, self.velocity, self.touching = (0.0 if y is None else y), 0.0, y is None
        self._path = None

    def step(self, x, h, slope, curvature, y, vx, vy, ax):
        k, c = self.stiffness, self.damping
        if self._path is not None and abs(x - self._path[0]) > 1e-9:
            curvature = (slope - self._path[1]) / (x - self._path[0])
        self._path = (x, slope)
        if not self.touching and self.position <= h:
            self.touching = True
            self.position, self.velocity = h, slope * vx
        if self.touching:
            tip, tip_velocity = h, slope * vx
            load = self.mass * (curvature * vx * vx + slope * ax) - k * (y - tip) - c * (vy - tip_velocity)
            self.position, self.velocity = tip, tip_velocity
            if load >= 0.0:
                return -load * slope, k * (tip - y) + c * (tip_velocity - vy), True
            self.touching = False
        fy = k * (self.position - y) + c * (self.velocity - vy)
        self._fly(h, slope * vx, k * y + c * vy)
        return 0.0, fy, False

    def _fly(self, h, surface_rate, drive):
        p11, p12, p21, p22, g1, g2 = self._flight
        position, velocity = self.position, self.velocity
        for j in range(1, self.substeps + 1):
            position, velocity = (
                p11 * position + p12 * velocity + g1 * drive,
                p21 * position + p22 * velocity + g2 * drive,
            )
            ground = h + surface_rate * j * self.substep
            if position <= ground:
                self.touching = True
                position, velocity = ground, surface_rate
                break
        self.position, self.velocity = position, velocity


class GradientField:
    """Minsky's lateral-gradient texture, for a point moving over a map.

    The hand, pressing with the normal load ``N``, feels ``F = -N ∇h`` in the plane
    of the map: the 2-D form of the profile models' lateral term ``F_x = -F_y h'``
    with ``F_y = N``. Along the motion it resists the climb; across the motion it
    pushes down the slope. No state: ``reset()`` does nothing.

    Parameters
    ----------
    load : float, default 1.0
        The normal load N, newtons.

    Raises
    ------
    ValueError
        For a load that is negative or not finite.

    Examples
    --------
    >>> from rough.render.contact import GradientField
    >>> GradientField(2.0).load  # N
    2.0
    """

    def __init__(self, load=1.0):
        if not 0 <= load < math.inf:
            raise ValueError("the normal load must be finite and not negative")
        self.load = float(load)

    def reset(self, y=None):
        """No state to reset."""


def zero_order_hold(stiffness, damping, mass, period):
    """The exact step of ``m ẍ = F - k x - b ẋ`` over ``period`` with F held constant:
    ``(Φ11, Φ12, Φ21, Φ22, Γ1, Γ2)`` such that ``x' = Φ11 x + Φ12 v + Γ1 F`` and
    ``v' = Φ21 x + Φ22 v + Γ2 F``: the exponential of the augmented matrix
    ``[[0, 1, 0], [-k/m, -b/m, 1/m], [0, 0, 0]] × period``.

    Examples
    --------
    A free mass (k = b = 0) under a held force moves by F T²/(2m):

    >>> from rough.render.contact import zero_order_hold
    >>> p11, p12, p21, p22, g1, g2 = zero_order_hold(0.0, 0.0, 2.0, 0.1)
    >>> (p11, p12, p21, p22), round(g1, 15), round(g2, 15)
    ((1.0, 0.1, 0.0, 1.0), 0.0025, 0.05)
    """
    # in the balanced state (x, v/ω, F/(m ω²)), ω² = k/m (or 1/T² for a free mass), the
    # entries are at most ωT and bT/m: no more squarings than the motion needs
    omega = math.sqrt(stiffness / mass) if stiffness > 0 else 1.0 / period
    turn = omega * period
    spring = stiffness / mass * period / omega
    step = _exponential([[0.0, turn, 0.0], [-spring, -damping / mass * period, turn], [0.0] * 3])
    to_state = (1.0, omega, mass * omega * omega)  # x, v, F from the balanced state
    p12 = step[0][1] / to_state[1]
    # Φ21 = -(k/m) Φ12 and Γ2 = Φ12/m hold exactly (Φ12' = Φ22, Φ22' = -(k/m) Φ12 - (b/m) Φ22,
    # and Γ2 = ∫Φ22/m): taken from Φ12, they keep its accuracy where the squarings lose
    # that of a small entry (Γ2 of a stiff, heavily damped hold, 1e-11 of its column)
    spring_step = 0.0 - stiffness / mass * p12  # +0.0 for a free mass
    return (step[0][0], p12, spring_step, step[1][1], step[0][2] / to_state[2], p12 / mass)


def _exponential(matrix):
    """The exponential of a small square matrix (lists of floats): a Taylor series of
    the matrix scaled to a norm of at most 1/2 (its remainder after 20 terms is below
    1e-24), then squared back. Pure Python: scipy's expm wakes the BLAS threads, which
    then spin on another core for about 0.1 s, doubling the CPU time of a short
    simulated run."""
    size = len(matrix)
    norm = max(sum(abs(v) for v in row) for row in matrix)
    squarings = max(0, math.ceil(math.log2(norm / 0.5))) if norm > 0.5 else 0
    scaled = [[v / 2.0**squarings for v in row] for row in matrix]
    result = [[float(i == j) for j in range(size)] for i in range(size)]
    term = [row[:] for row in result]
    for k in range(1, 21):
        term = [[v / k for v in row] for row in _product(term, scaled)]
        result = [[r + t for r, t in zip(rows, terms)] for rows, terms in zip(result, term)]
    for _ in range(squarings):
        result = _product(result, result)
    return result


def _product(a, b):
    columns = list(zip(*b))
    return [[math.fsum(x * y for x, y in zip(row, column)) for column in columns] for row in a]


def clamp(fx, fy, limit):
    """Scale ``(fx, fy)`` down to magnitude ``limit`` (N) if it is larger, keeping its
    direction; a force that is not finite becomes zero."""
    magnitude = math.hypot(fx, fy)
    if magnitude <= limit:
        return fx, fy
    if not magnitude < math.inf:  # NaN or infinite: a glitch, never a force to send
        return 0.0, 0.0
    scale = limit / magnitude
    return fx * scale, fy * scale
