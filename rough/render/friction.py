"""Friction between stylus and surface (docs/math.rst §5.6), off by default.

Each model gives the friction force along the surface tangent from the horizontal
motion of the stylus while it touches; out of contact there is none and the model's
state relaxes. Levels are forces (N), as in the haptic friction displays of Richard and
Cutkosky: they do not scale with the contact force. ``force`` returns the tangential
force on the stylus, positive along +x; the loop splits it into F_x and F_y along
the tangent ``(1, h')/√(1 + h'²)``.

Specs on the command line, ``MODEL:key=value,...`` with units:

    coulomb:level=0.3N,viscous=2N*s/m
    karnopp:static=0.8N,coulomb=0.5N,viscous=1N*s/m,band=2mm/s,stiffness=1N/mm,damping=0.5N*s/m
    dahl:stiffness=1N/mm,coulomb=0.5N
"""

import math

from ..errors import InputError
from ..units import parse_quantity


class CoulombViscous:
    """``F = -(F_C sgn v + b v)``; no stiction (sgn 0 = 0)."""

    def __init__(self, level=0.3, viscous=0.0):
        self.level, self.viscous = level, viscous

    def reset(self):
        """No state."""

    def force(self, contact, x, velocity, period):
        if not contact:
            return 0.0
        sign = (velocity > 0.0) - (velocity < 0.0)
        return -(self.level * sign + self.viscous * velocity)


class Karnopp:
    """Stick-slip after Karnopp (1985), in the form Salcudean and Vlaar used for a
    directly coupled handle: sticking, a spring ``stiffness`` and damper ``damping``
    hold the stylus to the point where it stuck, until their force exceeds the
    ``static`` level; slipping, the force is ``-(coulomb sgn v + viscous v)``, until
    the speed falls inside ``band`` and the stylus sticks again."""

    def __init__(self, static=0.8, coulomb=0.5, viscous=0.0, band=2e-3, stiffness=1000.0, damping=0.5):
        if static < coulomb:
            raise InputError("karnopp friction needs static ≥ coulomb (stick-slip needs static > coulomb)")
        self.static, self.coulomb, self.viscous = static, coulomb, viscous
        self.band, self.stiffness, self.damping = band, stiffness, damping
        self.reset()

    def reset(self):
        self.anchor = None

    def force(self, contact, x, velocity, period):
        if not contact:
            self.anchor = None
            return 0.0
        if self.anchor is None:
            if abs(velocity) > self.band:
                sign = (velocity > 0.0) - (velocity < 0.0)
                return -(self.coulomb * sign + self.viscous * velocity)
            self.anchor = x
        hold = -self.stiffness * (x - self.anchor) - self.damping * velocity
        if abs(hold) <= self.static:
            return hold
        self.anchor = None
        sign = (velocity > 0.0) - (velocity < 0.0) or (hold < 0.0) - (hold > 0.0)
        return -(self.coulomb * sign + self.viscous * velocity)


class Dahl:
    """Dahl's model with α = 1: ``dF/dx = σ₀ (1 - F sgn(dx) / F_C)``, integrated exactly
    over each step (``F → s F_C + (F - s F_C) exp(-σ₀ |Δx| / F_C)``), so it cannot
    overshoot at any stiffness or speed. Pre-sliding is elastic; there is no stiction
    peak. Friction on the stylus is ``-F``."""

    def __init__(self, stiffness=1000.0, coulomb=0.5):
        if not (stiffness > 0 and coulomb > 0):
            raise InputError("dahl friction needs a positive stiffness and coulomb level")
        self.stiffness, self.coulomb = stiffness, coulomb
        self.reset()

    def reset(self):
        self.state, self.last = 0.0, None

    def force(self, contact, x, velocity, period):
        if not contact:
            self.reset()
            return 0.0
        if self.last is not None and x != self.last:
            target = self.coulomb if x > self.last else -self.coulomb
            self.state = target + (self.state - target) * math.exp(-self.stiffness * abs(x - self.last) / self.coulomb)
        self.last = x
        return -self.state


MODELS = {
    "coulomb": (CoulombViscous, {"level": "force", "viscous": "damping"}),
    "karnopp": (
        Karnopp,
        {
            "static": "force",
            "coulomb": "force",
            "viscous": "damping",
            "band": "speed",
            "stiffness": "stiffness",
            "damping": "damping",
        },
    ),
    "dahl": (Dahl, {"stiffness": "stiffness", "coulomb": "force"}),
}


def parse_friction(spec):
    """A friction model from its command-line spec, ``MODEL[:key=value,...]``.

    Parameters
    ----------
    spec : str or None
        ``coulomb`` (keys ``level``, ``viscous``), ``karnopp`` (``static``,
        ``coulomb``, ``viscous``, ``band``, ``stiffness``, ``damping``) or ``dahl``
        (``stiffness``, ``coulomb``); each value a number with a unit (``0.3N``,
        ``2N*s/m``, ``2mm/s``, ``1N/mm``). Keys left out take the model's defaults.
        ``none``, ``off``, an empty string or None mean no friction.

    Returns
    -------
    CoulombViscous, Karnopp, Dahl or None
        The model, with every value in SI units (N, N·s/m, m/s, N/m); None for no
        friction.

    Raises
    ------
    rough.InputError
        For an unknown model or key, a value without a unit or in the wrong unit, a
        negative value, or values the model refuses (Karnopp needs static ≥ coulomb).

    Notes
    -----
    Levels are forces (N) that do not scale with the contact force. The model's
    ``force(contact, x, velocity, period)`` gives the tangential force on the stylus,
    positive along +x; zero out of contact.

    Examples
    --------
    >>> from rough.render import parse_friction
    >>> model = parse_friction("coulomb:level=0.3N,viscous=2N*s/m")
    >>> type(model).__name__, model.level, model.viscous  # N, N·s/m
    ('CoulombViscous', 0.3, 2.0)
    >>> model.force(True, 0.0, 0.01, 1e-3)  # sliding at +10 mm/s: -(0.3 + 2 × 0.01) N
    -0.32
    >>> parse_friction("karnopp:static=0.8N,coulomb=0.5N,band=2mm/s").band  # m/s
    0.002
    >>> parse_friction("none") is None
    True
    >>> import rough
    >>> try:
    ...     parse_friction("coulomb:level=0.3")
    ... except rough.InputError as error:
    ...     print(error)
    '0.3' is not a force (write a number with one of the units N, mN, kN)
    """
    if spec is None or spec.strip().lower() in ("", "none", "off"):
        return None
    name, _, arguments = spec.partition(":")
    if name.strip().lower() not in MODELS:
        raise InputError(f"unknown friction model {name!r} (use {', '.join(MODELS)} or none)")
    model, kinds = MODELS[name.strip().lower()]
    values = {}
    for item in filter(None, (part.strip() for part in arguments.split(","))):
        key, equals, value = item.partition("=")
        if not equals or key.strip() not in kinds:
            raise InputError(f"{name} friction takes {', '.join(f'{k}=' for k in kinds)}; not {item!r}")
        quantity = parse_quantity(value, kinds[key.strip()])
        if quantity < 0:
            raise InputError(f"{name} friction: {key.strip()} must not be negative")
        values[key.strip()] = quantity
    return model(**values)
