"""The passivity bound, its warning and the virtual coupling (docs/math.rst §5.7).

The energy tests run the real servo loop (:func:`rough.render.run`) on the real
simulated hand, whose motion under the force held for one period is integrated
exactly (zero-order hold), as a device's is: the sampled dynamics that the bound is
about. Two thin wrappers record what the loop does not trace: the hand's velocity
at each tick (read from the hand when the loop reads it) and the contact model's
stored energy after each step.
"""

import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rough.render import DynamicStylus, QuasiStatic, Settings, SimulatedHand, Track, forces, run, simulate
from rough.render.stability import VirtualCoupling, passivity_bound, stability_warning

DEVICE_DAMPING = 0.45  # N·s/m: the CLI's --device-damping default
DEFAULT_STIFFNESS = 1280.0  # N/m: the paper's 1.28 N/mm
FLAT = Track(np.zeros(11), 1e-3)  # 10 mm of flat surface at height 0


# -- the bound and the warning ------------------------------------------------------------


@pytest.mark.parametrize(
    "rate, damping, virtual_damping, bound",
    [
        (1000.0, 0.45, 0.0, 900.0),  # the CLI's default device at 1 kHz: 0.9 N/mm
        (500.0, 0.45, 0.0, 450.0),  # over USB at 500 Hz
        (4000.0, 0.45, 0.0, 3600.0),
        (1000.0, 2.0, 0.0, 4000.0),  # the simulated hand's damping
        (1000.0, 0.45, 0.2, 500.0),  # a virtual damper takes |B| of b
        (1000.0, 0.45, -0.2, 500.0),
        (1000.0, 0.45, 0.45, 0.0),
        (1000.0, 0.45, 1.0, 0.0),
        (1000.0, 0.0, 0.0, 0.0),
    ],
)
def test_passivity_bound_is_two_b_minus_the_virtual_damping_over_t(rate, damping, virtual_damping, bound):
    assert passivity_bound(rate, damping, virtual_damping) == pytest.approx(bound, rel=1e-12, abs=1e-12)


@pytest.mark.parametrize(
    "rate, damping", [(0.0, 0.45), (-1.0, 0.45), (math.inf, 0.45), (1000.0, -0.1), (1000.0, math.nan)]
)
def test_passivity_bound_refuses_a_meaningless_rate_or_damping(rate, damping):
    with pytest.raises(ValueError):
        passivity_bound(rate, damping)


def test_the_default_stiffness_warns_at_1_khz_in_one_line_naming_the_bound_and_its_source():
    message = stability_warning(DEFAULT_STIFFNESS, 1000.0, DEVICE_DAMPING)
    assert message == (
        "--stiffness 1.28 N/mm exceeds the passivity bound 0.9 N/mm at 1000 Hz for a device damping of "
        "0.45 N·s/m (K ≤ 2b/T, Colgate & Schenkel 1997): expect buzzing or chatter; lower it to 0.9 N/mm, "
        "raise --rate to 1423 Hz, or add --coupling 0.9N/mm,0N*s/m"
    )
    assert "\n" not in message


def test_the_default_stiffness_warns_at_500_hz_and_is_silent_at_4_khz_or_on_the_simulated_hand():
    assert "the passivity bound 0.45 N/mm at 500 Hz" in stability_warning(DEFAULT_STIFFNESS, 500.0, DEVICE_DAMPING)
    assert stability_warning(DEFAULT_STIFFNESS, 4000.0, DEVICE_DAMPING) is None  # bound 3.6 N/mm
    assert stability_warning(DEFAULT_STIFFNESS, 1000.0, 2.0) is None  # the simulated hand's 2 N·s/m: 4 N/mm


def test_a_stiffness_at_the_bound_is_passive_and_just_above_it_is_not():
    assert stability_warning(900.0, 1000.0, 0.45) is None
    message = stability_warning(900.4, 1000.0, 0.45)
    assert message.startswith("--stiffness 0.9004 N/mm exceeds the passivity bound 0.9 N/mm")  # digits enough to differ


def test_a_coupling_under_the_bound_silences_the_warning_and_one_over_it_warns_about_itself():
    assert stability_warning(DEFAULT_STIFFNESS, 1000.0, DEVICE_DAMPING, coupling=(900.0, 0.0)) is None
    assert stability_warning(DEFAULT_STIFFNESS, 1000.0, DEVICE_DAMPING, coupling=(700.0, 0.05)) is None
    assert stability_warning(1e6, 1000.0, DEVICE_DAMPING, coupling=(700.0, 0.05)) is None  # any wall behind it
    message = stability_warning(DEFAULT_STIFFNESS, 1000.0, DEVICE_DAMPING, coupling=(800.0, 0.1))
    assert message.startswith("--coupling 0.8 N/mm, 0.1 N·s/m exceeds the passivity bound at 1000 Hz")
    assert "Kc T/2 + Bc = 0.5 N·s/m > b" in message and "\n" not in message
    assert "lower its stiffness to 0.7 N/mm or raise --rate to 1143 Hz" in message
    # a coupling over the bound warns even when the wall itself is under it
    assert stability_warning(100.0, 1000.0, DEVICE_DAMPING, coupling=(2000.0, 0.0)) is not None
    assert "lower its damping below 0.45" in stability_warning(100.0, 1000.0, DEVICE_DAMPING, coupling=(10.0, 0.5))


def test_an_undamped_device_warns_without_suggesting_a_rate_or_a_coupling():
    message = stability_warning(100.0, 1000.0, 0.0)
    assert "no sampled spring is passive" in message and "--coupling" not in message


def _suggestions(message):
    stiffness = re.search(r"lower it to ([0-9.e+-]+) N/mm", message)
    rate = re.search(r"raise --rate to (\d+) Hz", message)
    coupling = re.search(r"--coupling ([0-9.e+-]+)N/mm,0N\*s/m", message)
    return float(stiffness[1]) * 1e3, float(rate[1]), (float(coupling[1]) * 1e3, 0.0)


@given(
    stiffness=st.floats(1.0, 1e6),
    rate=st.floats(100.0, 1e5),
    damping=st.floats(1e-3, 10.0),
)
def test_the_warning_fires_exactly_above_the_bound_and_its_suggestions_are_passive(stiffness, rate, damping):
    message = stability_warning(stiffness, rate, damping)
    bound = passivity_bound(rate, damping)
    assert (message is None) == (stiffness <= bound * (1 + 1e-9))
    if message is not None:
        assert "\n" not in message
        lower, faster, coupling = _suggestions(message)
        assert stability_warning(lower, rate, damping) is None
        assert lower >= 0.99 * bound  # rounded down to 3 digits, not further
        assert stability_warning(stiffness, faster, damping) is None
        assert stability_warning(stiffness, rate, damping, coupling=coupling) is None


# -- the coupled contact ------------------------------------------------------------------


def test_the_coupling_keeps_the_wrapped_stiffness_and_its_own_and_refuses_other_models():
    coupled = VirtualCoupling(QuasiStatic(5000.0), 400.0, 0.1, period=2e-3)
    assert coupled.stiffness == 5000.0  # simulate() places the hand with press / model.stiffness
    assert (coupled.coupling_stiffness, coupled.coupling_damping, coupled.period) == (400.0, 0.1, 2e-3)
    assert coupled.static_stiffness == pytest.approx(5000.0 * 400.0 / 5400.0)
    with pytest.raises(TypeError):
        VirtualCoupling(DynamicStylus(), 400.0, 0.0, 1e-3)
    for stiffness, damping, period in ((0.0, 0.0, 1e-3), (400.0, -0.1, 1e-3), (400.0, 0.0, 0.0), (math.inf, 0, 1e-3)):
        with pytest.raises(ValueError):
            VirtualCoupling(QuasiStatic(), stiffness, damping, period)


def test_at_rest_the_coupled_wall_is_the_two_springs_in_series_with_the_lateral_term():
    coupled = VirtualCoupling(QuasiStatic(12800.0), 900.0, 0.3, period=1e-3)
    for _ in range(3):  # at rest: the damper carries nothing
        fx, fy, contact = coupled.step(0.0, 2e-4, -0.2, 0.0, -8e-4, 0.0, 0.0, 0.0)
    assert contact and fy == pytest.approx(coupled.static_stiffness * 1e-3, rel=1e-12)
    assert fx == pytest.approx(0.2 * fy, rel=1e-12)  # F_x = -F_y h': pulled down the falling slope
    assert coupled.proxy == pytest.approx(2e-4 - fy / 12800.0, rel=1e-12)
    assert coupled.step(0.0, 2e-4, -0.2, 0.0, 3e-4, 0.0, 0.0, 0.0) == (0.0, 0.0, False)


def test_the_coupling_recovers_from_a_glitched_position():
    coupled = VirtualCoupling(QuasiStatic(5000.0), 400.0, 0.1, period=1e-3)
    assert coupled.step(0.0, 0.0, 0.0, 0.0, math.nan, 0.0, 0.0, 0.0) == (0.0, 0.0, False)
    fx, fy, contact = coupled.step(0.0, 0.0, 0.0, 0.0, -1e-3, 0.0, 0.0, 0.0)
    assert contact and fy == pytest.approx(coupled.static_stiffness * 1e-3)


positions = st.lists(st.floats(-2e-3, 2e-3), min_size=1, max_size=60)


@given(
    wall=st.floats(10.0, 1e6),
    share=st.floats(0.01, 1.0),
    damper_share=st.floats(0.0, 0.9),
    damping=st.floats(0.05, 5.0),
    rate=st.floats(100.0, 2e4),
    ys=positions,
    vy=st.floats(-0.5, 0.5),
    h=st.floats(-1e-3, 1e-3),
)
def test_the_coupled_force_never_pulls_nor_exceeds_the_wall_on_the_hand(
    wall, share, damper_share, damping, rate, ys, vy, h
):
    """For any motion of the hand, coupled under the bound: 0 <= F_y <= K (h - y)⁺."""
    period = 1.0 / rate
    bc = damper_share * damping  # Kc T/2 + Bc <= b
    kc = share * passivity_bound(rate, damping, bc)
    coupled = VirtualCoupling(QuasiStatic(wall), kc, bc, period)
    for y in ys:
        fx, fy, contact = coupled.step(0.0, h, 0.3, 0.0, y, 0.0, vy, 0.0)
        assert 0.0 <= fy <= wall * max(h - y, 0.0) * (1 + 1e-9) + 1e-15
        assert contact == (fy > 0.0)
        assert fx == -fy * 0.3


# -- energy: the sampled wall against the coupled one ------------------------------------


class Recorder:
    """The device interface around a simulated hand, keeping the hand's exact height
    and velocity at each tick (read when the loop reads the hand)."""

    def __init__(self, hand):
        self.hand, self.label, self.capabilities = hand, hand.label, hand.capabilities
        self.states = {}

    @property
    def velocity(self):
        return self.hand.velocity

    def read(self):
        self.states[self.hand.ticks] = (self.hand.y, self.hand.vy)
        return self.hand.read()

    def write(self, fx, fy):
        self.hand.write(fx, fy)

    def zero(self):
        self.hand.zero()

    def emergency_stop(self):
        self.hand.emergency_stop()

    def close(self):
        self.hand.close()


class Probe:
    """A contact model that records the energy stored in the one it wraps after each
    step: the coupling's own account, or the bare wall's ½ K ((h - y)⁺)²."""

    def __init__(self, model):
        self.model, self.stiffness, self.energies = model, model.stiffness, []

    def reset(self, y=None):
        self.model.reset(y)

    def step(self, x, h, slope, curvature, y, vx, vy, ax):
        result = self.model.step(x, h, slope, curvature, y, vx, vy, ax)
        stored = getattr(self.model, "energy", None)
        self.energies.append(0.5 * self.model.stiffness * max(h - y, 0.0) ** 2 if stored is None else stored)
        return result


def drop(model, rate=500.0, damping=0.5, mass=0.15, press=0.2, height=1e-4, duration=1.0):
    """Let the simulated hand, pressing down with ``press``, fall from ``height`` onto the
    flat wall through the servo loop; the energy at each tick, J:
    ``½ m v² + press y + the contact's stored energy``, and the run."""
    hand = SimulatedHand(0.0, 0.0, height, period=1.0 / rate, press=press, mass=mass, damping=damping)
    device, probe = Recorder(hand), Probe(model)
    settings = Settings(rate=rate, duration=duration, realtime=False, max_force=1e9)  # no clamp: §5.7
    result = run(device, [FLAT], probe, settings=settings)
    y, v = np.array([device.states[k] for k in range(result.ticks)]).T
    assert np.array_equal(y, result.trace["y_i"])
    return 0.5 * mass * v**2 + press * y + np.array(probe.energies), result


def largest_gain(model, rate, damping, mass, press, height):
    """The largest energy gain of one tick in a 0.3 s drop, as a share of the energy's
    scale (its largest magnitude, plus the press over 2 mm, plus 1 nJ)."""
    energy, _ = drop(model, rate=rate, damping=damping, mass=mass, press=press, height=height, duration=0.3)
    return np.diff(energy).max() / (np.abs(energy).max() + press * 2e-3 + 1e-9)


RATE, HAND_DAMPING = 500.0, 0.5  # Hz, N·s/m: bound 2b/T = 500 N/m
STIFF = 10 * passivity_bound(RATE, HAND_DAMPING)  # 5 N/mm, ten times the bound
TOLERANCE = 1e-12  # J: rounding, against energies of 2e-5 J and more


def test_a_stiff_sampled_wall_at_500_hz_pumps_energy_into_the_hand():
    energy, result = drop(QuasiStatic(STIFF))
    assert energy[0] == pytest.approx(0.2 * 1e-4)  # 20 µJ: the press over the 0.1 mm drop
    assert energy.max() > 20 * energy[0]  # about 1.1 mJ within the second
    heights = result.trace["y_i"]
    first = np.argmax(result.trace["contact"])
    assert heights[first:].max() > 10 * heights[0]  # bounces higher than it fell from


def test_through_a_coupling_under_the_bound_the_same_wall_never_gains_energy():
    coupled = VirtualCoupling(QuasiStatic(STIFF), 0.9 * passivity_bound(RATE, HAND_DAMPING), 0.0, 1.0 / RATE)
    energy, result = drop(coupled)
    assert np.diff(energy).max() <= TOLERANCE  # never grows, tick by tick
    assert energy.max() <= energy[0] + TOLERANCE
    first = np.argmax(result.trace["contact"])
    assert result.trace["y_i"][first:].max() < result.trace["y_i"][0]  # never climbs back to where it fell from
    assert result.trace["contact"][-100:].all()  # settled on the surface


def test_the_bare_wall_under_the_bound_never_gains_energy_either():
    energy, _ = drop(QuasiStatic(0.9 * passivity_bound(RATE, HAND_DAMPING)))
    assert np.diff(energy).max() <= TOLERANCE


def test_a_coupling_over_the_bound_does_not_keep_the_wall_passive():
    coupled = VirtualCoupling(QuasiStatic(STIFF), 3 * passivity_bound(RATE, HAND_DAMPING), 0.0, 1.0 / RATE)
    energy, _ = drop(coupled)
    assert energy.max() > 2 * energy[0]


@settings(max_examples=40, deadline=None)
@given(
    wall=st.floats(1.0, 100.0),
    share=st.floats(0.05, 1.0),
    damper_share=st.floats(0.0, 0.9),
    damping=st.floats(0.1, 5.0),
    rate=st.floats(200.0, 5000.0),
    mass=st.floats(0.02, 1.0),
    press=st.floats(0.0, 2.0),
    height=st.floats(0.0, 2e-3),
)
def test_random_drops_through_a_coupling_under_the_bound_never_gain_energy(
    wall, share, damper_share, damping, rate, mass, press, height
):
    """The storage ½ m v² + press y + ½ Kc e² + ½ K ((h - p)⁺)² + (Bc/2T) Δe² never
    grows, for walls 1 to 100 times the bound."""
    bc = damper_share * damping
    kc = share * passivity_bound(rate, damping, bc)
    coupled = VirtualCoupling(QuasiStatic(wall * passivity_bound(rate, damping)), kc, bc, 1.0 / rate)
    assert largest_gain(coupled, rate, damping, mass, press, height) <= 1e-10


def test_simulate_settles_the_hand_on_the_coupled_wall_at_its_press():
    flat = Track(np.zeros(1001), 0.1e-3)
    coupled = VirtualCoupling(QuasiStatic(12800.0), 3000.0, 0.0, period=1e-3)  # under 4 N/mm (b = 2 N·s/m)
    result = simulate(flat, speed=0.02, model=coupled)
    assert forces(result)["out_of_contact"] == 0.0
    assert result.trace["F_y"][-1000:].mean() == pytest.approx(1.0, rel=1e-3)  # N: the press
    assert -result.trace["y_i"][-1] == pytest.approx(1.0 / coupled.static_stiffness, rel=1e-3)


@settings(max_examples=20, deadline=None)
@given(
    over=st.floats(1.5, 4.0),
    damping=st.floats(0.1, 5.0),
    rate=st.floats(200.0, 5000.0),
    mass=st.floats(0.02, 1.0),
    press=st.floats(0.1, 2.0),
    height=st.floats(0.0, 2e-3),
)
def test_the_same_check_flags_random_couplings_over_the_bound(over, damping, rate, mass, press, height):
    """The tolerance above is tight enough to see a coupling 1.5 to 4 times over the bound."""
    bound = passivity_bound(rate, damping)
    coupled = VirtualCoupling(QuasiStatic(50 * bound), over * bound, 0.0, 1.0 / rate)
    assert largest_gain(coupled, rate, damping, mass, press, height) > 1e-10
