"""Haptic rendering: feel a surface profile through a force-feedback joystick.

A virtual stylus rides the profile (:mod:`.track`); a contact model
(:mod:`.contact`) and optionally a friction model (:mod:`.friction`) give the force
on the hand; the servo loop (:mod:`.loop`) reads a device, computes and writes that
force once per period. Devices: :class:`.hand.SimulatedHand` (``sim``, for headless
runs and tests) and :class:`.hid.Joystick` (``hid``, a USB force-feedback joystick
speaking HID PID through hidapi). SI units throughout: m, s, N, kg.

    >>> import rough
    >>> from rough.render import Track, forces, simulate
    >>> track = Track.from_surface(rough.read("rock.x3p"))
    >>> result = simulate(track, speed=0.06)       # 60 mm/s, the simulated hand
    >>> forces(result)["F_y_std"]                  # N
"""

import math

import numpy as np

from .contact import MAX_FORCE, STIFFNESS, DynamicStylus, QuasiStatic, clamp
from .friction import parse_friction
from .hand import HAND_DAMPING, HAND_MASS, PRESS, SimulatedHand
from .loop import TRACE_FIELDS, Run, Settings, run
from .track import Track

__all__ = [
    "MAX_FORCE",
    "STIFFNESS",
    "TRACE_FIELDS",
    "DynamicStylus",
    "QuasiStatic",
    "Run",
    "Settings",
    "SimulatedHand",
    "Track",
    "clamp",
    "forces",
    "parse_friction",
    "run",
    "simulate",
    "write_trace",
]


def simulate(
    track,
    speed,
    model=None,
    friction=None,
    settings=None,
    press=PRESS,
    hand_mass=HAND_MASS,
    hand_damping=HAND_DAMPING,
    lateral_stiffness=None,
):
    """Stroke ``track`` once at ``speed`` (m/s) with the simulated hand, starting at
    rest on the surface under its own press; returns the loop's :class:`Run`. The
    duration defaults to one pass over the track; the run is unpaced unless
    ``settings.realtime``."""
    model = model or QuasiStatic()
    settings = settings or Settings(realtime=False)
    if settings.duration is None:
        settings = Settings(**{**settings.__dict__, "duration": track.length / speed})
    start = track.at(track.start)[0] - press / model.stiffness
    hand = SimulatedHand(
        speed,
        track.start,
        start,
        settings.period,
        press=press,
        mass=hand_mass,
        damping=hand_damping,
        lateral_stiffness=lateral_stiffness,
    )
    result = run(hand, [track], model, friction, settings)
    result.speed = speed
    return result


def forces(result, max_force=None):
    """Force statistics of a run (N, and fractions of ticks): F_y mean, spread and
    peak, F_x RMS, time out of contact, ticks at the force limit."""
    trace = result.trace
    fy, fx = trace["F_y"], trace["F_x"]
    limit = result.settings.max_force if max_force is None else max_force
    return {
        "F_y_mean": float(fy.mean()),
        "F_y_std": float(fy.std()),
        "F_y_max": float(fy.max()),
        "F_x_rms": float(math.sqrt(np.mean(fx * fx))),
        "out_of_contact": float(1.0 - trace["contact"].mean()),
        "at_force_limit": float(np.mean(np.hypot(fx, fy) >= limit * (1 - 1e-9))),
    }


def write_trace(result, path):
    """One row per tick: ``t x y_i h F_x F_y contact`` (s, m, m, m, N, N, 0/1), as TSV
    with that header line, or as NPY (a structured array with those fields) when
    ``path`` ends in .npy. Written atomically; h is NaN where there is no surface."""
    from ..io.atomic import atomic_output

    trace = result.trace
    with atomic_output(path) as stream:
        if str(path).lower().endswith(".npy"):
            np.save(stream, trace)
            return
        stream.write(("\t".join(TRACE_FIELDS) + "\n").encode())
        columns = np.column_stack([trace[name].astype(np.float64) for name in TRACE_FIELDS])
        np.savetxt(stream, columns, fmt=["%.9g"] * 6 + ["%d"], delimiter="\t")
