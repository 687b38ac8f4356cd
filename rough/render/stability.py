"""Stability of the sampled contact: the passivity bound, its warning, and the virtual
coupling (docs/math.rst §5.7), in SI units.

A virtual spring K (and damper B) computed from the sampled position and held for one
period T drives a device whose own viscous damping is b. Colgate & Schenkel (1997)
showed that this sampled-data system is passive, for any hand that holds it, if and
only if ``b > K T / 2 + |B|``: the largest passive stiffness is
``K_max = 2 (b - |B|) / T`` (:func:`passivity_bound`). A stiffer wall puts energy
into the hand on every contact; the hand feels it as buzzing or chatter
(:func:`stability_warning`).

A :class:`VirtualCoupling` keeps a stiff wall passive: the hand is joined by a spring
Kc and damper Bc that satisfy the bound to a massless proxy, and only the proxy
touches the wall. Its force on the hand is passive at any wall stiffness whenever
``Kc T / 2 + Bc <= b``.
"""

import math

from .contact import QuasiStatic

SOURCE = "Colgate & Schenkel 1997"
TOLERANCE = 1e-9  # relative: a stiffness at the bound, up to rounding, is passive


def _check(rate, damping):
    if not 0 < rate < math.inf:
        raise ValueError("the servo rate must be positive and finite")
    if not 0 <= damping < math.inf:
        raise ValueError("the device damping must be finite and not negative")


def passivity_bound(rate, damping, virtual_damping=0.0):
    """The largest virtual stiffness a sampled device renders passively.

    Colgate & Schenkel (1997): a virtual wall ``F = -K y - B ẏ``, computed from the
    position sampled every ``T = 1 / rate`` (the velocity by backward difference) and
    held for one period, on a device of mass m and viscous damping b, is passive if
    and only if ``b > K T / 2 + |B|``, whatever m. So
    ``K_max = 2 (b - |B|) / T``, and 0 when ``b <= |B|``.

    Parameters
    ----------
    rate : float
        The servo rate 1/T, Hz.
    damping : float
        The device's own viscous damping b, N·s/m.
    virtual_damping : float, default 0.0
        The virtual damping B rendered with the spring, N·s/m (its sign does not
        matter).

    Returns
    -------
    float
        K_max, N/m.

    Raises
    ------
    ValueError
        For a rate that is not positive and finite, a negative or infinite damping,
        or a virtual damping that is not finite.

    Examples
    --------
    A device with 0.45 N·s/m of damping: 0.9 N/mm at 1 kHz, half that at 500 Hz.

    >>> from rough.render.stability import passivity_bound
    >>> passivity_bound(1000.0, 0.45), passivity_bound(500.0, 0.45)  # N/m
    (900.0, 450.0)
    >>> passivity_bound(1000.0, 0.45, virtual_damping=0.2)  # the damper takes its share
    500.0
    >>> passivity_bound(1000.0, 0.45, virtual_damping=0.5)  # no spring is passive
    0.0
    """
    _check(rate, damping)
    if not abs(virtual_damping) < math.inf:
        raise ValueError("the virtual damping must be finite")
    return max(0.0, 2.0 * (damping - abs(virtual_damping)) * rate)


def stability_warning(stiffness, rate, damping, coupling=None):
    """One line of warning when the rendered contact is not passive, else None.

    Without a coupling, warns when the contact stiffness exceeds
    :func:`passivity_bound` ``(rate, damping)``; with a coupling ``(Kc, Bc)``, the wall
    is felt only through it, so the coupling itself is checked instead:
    ``Kc T / 2 + |Bc| <= b``. A stiffness at the bound (to rounding) is passive.

    Parameters
    ----------
    stiffness : float
        The contact stiffness K, N/m (``--stiffness``).
    rate : float
        The servo rate, Hz (``--rate``).
    damping : float
        The device's damping b, N·s/m.
    coupling : tuple of float, optional
        ``(Kc, Bc)``: the virtual coupling's stiffness (N/m) and damping (N·s/m)
        (``--coupling``); default none.

    Returns
    -------
    str or None
        The warning, one line with no newline, naming the bound, its source and
        the ways out (a stiffness, a rate and a coupling that satisfy it); None when
        the contact is passive.

    Raises
    ------
    ValueError
        As :func:`passivity_bound`.

    Examples
    --------
    The default 1.28 N/mm at 1 kHz on a device of 0.45 N·s/m, and then at 4 kHz:

    >>> from rough.render.stability import stability_warning
    >>> print(stability_warning(1280.0, 1000.0, 0.45))  # doctest: +NORMALIZE_WHITESPACE
    --stiffness 1.28 N/mm exceeds the passivity bound 0.9 N/mm at 1000 Hz for a device
    damping of 0.45 N·s/m (K ≤ 2b/T, Colgate & Schenkel 1997): expect buzzing or
    chatter; lower it to 0.9 N/mm, raise --rate to 1423 Hz, or add --coupling
    0.9N/mm,0N*s/m
    >>> stability_warning(1280.0, 4000.0, 0.45) is None
    True

    Behind a coupling that satisfies the bound it is silent; behind one that does
    not, it warns about the coupling:

    >>> stability_warning(1280.0, 1000.0, 0.45, coupling=(900.0, 0.0)) is None
    True
    >>> print(stability_warning(1280.0, 1000.0, 0.45, coupling=(800.0, 0.1)))  # doctest: +NORMALIZE_WHITESPACE
    --coupling 0.8 N/mm, 0.1 N·s/m exceeds the passivity bound at 1000 Hz for a device
    damping of 0.45 N·s/m (Kc T/2 + Bc = 0.5 N·s/m > b, Colgate & Schenkel 1997): the
    coupling itself will buzz or chatter; lower its stiffness to 0.7 N/mm or raise
    --rate to 1143 Hz
    """
    _check(rate, damping)
    where = f"at {rate:g} Hz for a device damping of {damping:.3g} N·s/m"
    if coupling is None:
        bound = passivity_bound(rate, damping)
        if stiffness <= bound * (1 + TOLERANCE):
            return None
        digits = 3 if f"{stiffness * 1e-3:.3g}" != f"{bound * 1e-3:.3g}" else 6  # enough to tell them apart
        given, limit = f"{stiffness * 1e-3:.{digits}g}", f"{bound * 1e-3:.{digits}g}"
        head = f"--stiffness {given} N/mm exceeds the passivity bound {limit} N/mm {where} (K ≤ 2b/T, {SOURCE}): "
        if damping <= 0.0:
            return head + "no sampled spring is passive on an undamped device; give its damping"
        suggestion = _floor3(bound * 1e-3)
        rate_needed = math.ceil(stiffness / (2.0 * damping) * (1 - TOLERANCE))
        return head + (
            f"expect buzzing or chatter; lower it to {suggestion:g} N/mm, raise --rate to {rate_needed:d} Hz, "
            f"or add --coupling {suggestion:g}N/mm,0N*s/m"
        )
    kc, bc = coupling
    margin = kc / (2.0 * rate) + abs(bc)
    if margin <= damping * (1 + TOLERANCE):
        return None
    head = (
        f"--coupling {kc * 1e-3:.3g} N/mm, {bc:.3g} N·s/m exceeds the passivity bound {where} "
        f"(Kc T/2 + Bc = {margin:.3g} N·s/m > b, {SOURCE}): the coupling itself will buzz or chatter; "
    )
    if abs(bc) >= damping:
        return head + f"lower its damping below {damping:.3g} N·s/m"
    rate_needed = math.ceil(kc / (2.0 * (damping - abs(bc))) * (1 - TOLERANCE))
    return head + (
        f"lower its stiffness to {_floor3(passivity_bound(rate, damping, bc) * 1e-3):g} N/mm "
        f"or raise --rate to {rate_needed:d} Hz"
    )


def _floor3(value):
    """``value`` rounded down to 3 significant digits (0 for 0), so that a suggested
    stiffness stays under the bound it was printed from."""
    if value <= 0.0:
        return 0.0
    scale = 10.0 ** (math.floor(math.log10(value)) - 2)
    return math.floor(value / scale * (1 + TOLERANCE)) * scale


class VirtualCoupling:
    """A stiff penalty wall felt through a virtual coupling, passive by construction.

    A massless proxy at height p stands between the hand (height y) and the wall of a
    :class:`~rough.render.contact.QuasiStatic` model (stiffness K): the wall pushes
    the proxy with ``K (h - p)⁺`` and the proxy is joined to the hand by the spring Kc
    and damper Bc. Each tick the proxy's force balance is solved implicitly, with its
    velocity and the hand's by backward difference over the period T (the hand's
    from the positions this model is given, not the loop's filtered estimate):

    ``K (h - p)⁺ + Kc (y - p) + Bc [(y - y_prev) - (p - p_prev)] / T = 0``,

    one root, found in closed form (free if it lies above the surface). The hand
    feels the coupling's pull on it, which balances the wall: ``F_y = K (h - p)⁺ >= 0``,
    with ``F_x = -F_y h'``. The proxy never sinks below the hand, so ``F_y`` never
    exceeds ``K (h - y)⁺``; statically the hand feels K and Kc in series,
    ``K Kc / (K + Kc)``. With ``Kc T / 2 + Bc <= b`` (the device's damping b) the
    sampled system is passive at any K (docs/math.rst §5.7): the storage
    ``½ m v² + ½ Kc (y - p)² + ½ K ((h - p)⁺)² + (Bc / 2T) Δ(y - p)²`` (plus the
    potential of any steady push on the hand) never grows.

    Parameters
    ----------
    model : QuasiStatic
        The wall; its stiffness K may exceed the passivity bound.
    stiffness : float
        The coupling's stiffness Kc, N/m.
    damping : float
        The coupling's damping Bc, N·s/m.
    period : float
        The servo period T, s.

    Attributes
    ----------
    model : QuasiStatic
        The wrapped wall.
    stiffness : float
        The wall's K, N/m (the wrapped model's).
    coupling_stiffness, coupling_damping : float
        Kc (N/m) and Bc (N·s/m).
    period : float
        T, s.
    static_stiffness : float
        ``K Kc / (K + Kc)``, N/m: what the hand feels at rest against the wall.
    proxy : float or None
        The proxy's height after the last step, m; None after a reset.
    energy : float
        The virtual part of the storage after the last step, J:
        ``½ Kc (y - p)² + ½ K ((h - p)⁺)² + (Bc / 2T) Δ(y - p)²`` (the last term is
        the damper's share of the storage function, 0 when Bc = 0).

    Raises
    ------
    TypeError
        For a model that is not a :class:`~rough.render.contact.QuasiStatic`.
    ValueError
        For a coupling stiffness or period that is not positive and finite, or a
        coupling damping that is negative or infinite.

    Notes
    -----
    ``reset(y=None)`` forgets the proxy: on the next step it starts at rest against
    the hand (where it would sit in static equilibrium with the hand's previous
    position, ``y - vy T``); ``y`` is accepted for the contact models' interface and
    not used. The bound is not checked here (the device's damping is not known):
    see :func:`stability_warning`.

    Examples
    --------
    A 12.8 N/mm wall behind a 0.9 N/mm coupling: 1 mm into the wall at rest, the
    hand feels the two springs in series, about 0.84 N/mm:

    >>> from rough.render import QuasiStatic
    >>> from rough.render.stability import VirtualCoupling
    >>> coupled = VirtualCoupling(QuasiStatic(12800.0), 900.0, 0.0, period=1e-3)
    >>> coupled.stiffness, round(coupled.static_stiffness, 3)  # N/m
    (12800.0, 840.876)
    >>> fx, fy, contact = coupled.step(0.0, 0.0, 0.1, 0.0, -1e-3, 0.0, 0.0, 0.0)
    >>> round(fy, 6), round(fx, 6), contact  # N
    (0.840876, -0.084088, True)
    >>> round(coupled.proxy * 1e6, 3)  # µm: the proxy sits F/K into the wall
    -65.693
    >>> coupled.step(0.0, 0.0, 0.1, 0.0, 1e-3, 0.0, 0.0, 0.0)  # the hand 1 mm above it
    (0.0, 0.0, False)

    A simulated hand pressing down with 0.2 N falls from 0.1 mm onto a 5 N/mm wall
    served at 500 Hz. Its damping, 0.5 N·s/m, bounds the passive stiffness at
    0.5 N/mm: on the bare wall it bounces ever higher, through a 0.45 N/mm coupling
    it never climbs back to where it fell from:

    >>> import numpy as np
    >>> from rough.render import Settings, SimulatedHand, Track, run
    >>> def highest_bounce(model):  # mm, after the first contact
    ...     hand = SimulatedHand(0.0, 0.0, 1e-4, period=2e-3, press=0.2, damping=0.5)
    ...     settings = Settings(rate=500.0, duration=1.0, realtime=False)
    ...     trace = run(hand, [Track(np.zeros(11), 1e-3)], model, settings=settings).trace
    ...     return round(float(trace["y_i"][trace["contact"].argmax():].max()) * 1e3, 3)
    >>> highest_bounce(QuasiStatic(5000.0)), highest_bounce(VirtualCoupling(QuasiStatic(5000.0), 450.0, 0.0, 2e-3))
    (4.605, 0.073)
    """

    def __init__(self, model, stiffness, damping, period):
        if not isinstance(model, QuasiStatic):
            raise TypeError(f"the virtual coupling wraps the quasi-static wall, not {type(model).__name__}")
        if not (0 < stiffness < math.inf and 0 < period < math.inf):
            raise ValueError("the coupling needs a positive, finite stiffness and period")
        if not 0 <= damping < math.inf:
            raise ValueError("the coupling's damping must be finite and not negative")
        self.model = model
        self.stiffness = model.stiffness
        self.coupling_stiffness, self.coupling_damping = float(stiffness), float(damping)
        self.period = float(period)
        self.static_stiffness = self.stiffness * self.coupling_stiffness / (self.stiffness + self.coupling_stiffness)
        self.reset()

    def reset(self, y=None):
        """Forget the proxy: on the next step it starts at rest against the hand."""
        self.model.reset()
        self.proxy, self.energy = None, 0.0
        self._stretch = None  # y - p at the last tick

    def step(self, x, h, slope, curvature, y, vx, vy, ax):
        k, kc, c = self.stiffness, self.coupling_stiffness, self.coupling_damping / self.period
        stretch = self._stretch
        if stretch is None:  # the last tick: the hand at y - vy T, the proxy at rest against it
            stretch = -k * max(h - (y - vy * self.period), 0.0) / (k + kc)
        # e = y - p; free: (Kc + c) e = c e_prev; on the wall: K (h - p) + (Kc + c) e = c e_prev
        free = y - c * stretch / (kc + c)  # the proxy's height if it does not touch
        depth = (kc + c) * (h - free) / (k + kc + c) if free < h else 0.0  # h - p, and F = K (h - p)
        proxy = h - depth if depth > 0.0 else free
        e = y - proxy
        if not math.isfinite(e):  # a glitched position (NaN): no force, and start afresh
            self.reset()
            return 0.0, 0.0, False
        self.energy = 0.5 * kc * e * e + 0.5 * k * depth * depth + 0.5 * c * (e - stretch) ** 2
        self.proxy, self._stretch = proxy, e
        if depth <= 0.0:
            return 0.0, 0.0, False
        fy = k * depth
        return -fy * slope, fy, True
