"""Haptic rendering: feel a surface profile through a force-feedback joystick.

A virtual stylus rides the profile (:mod:`.track`); a contact model
(:mod:`.contact`) and optionally a friction model (:mod:`.friction`) give the force
on the hand; the servo loop (:mod:`.loop`) reads a device, computes and writes that
force once per period. Devices: :class:`.hand.SimulatedHand` (``sim``, for headless
runs and tests) and :class:`.hid.Joystick` (``hid``, a USB force-feedback joystick
speaking HID PID through hidapi). SI units throughout: m, s, N, kg.

>>> import rough
>>> from rough.render import Track, forces, simulate
>>> track = Track.from_surface(rough.read(rough.sample("rock-profile.tsv")))
>>> result = simulate(track, speed=0.06)  # 60 mm/s, the simulated hand
>>> f"F_y {forces(result)['F_y_mean']:.3f} ± {forces(result)['F_y_std']:.3f} N"
'F_y 0.997 ± 0.347 N'
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
    """Stroke a track once with the simulated hand, and record what the loop did.

    The hand starts at rest at the start of the track, on the surface under its own
    press (the contact model's spring compressed by ``press``), and strokes along x
    at ``speed`` while pressing down.

    Parameters
    ----------
    track : Track
        The profile to stroke.
    speed : float
        The stroking speed along x, m/s.
    model : QuasiStatic or DynamicStylus, optional
        The contact model; default ``QuasiStatic()`` (K = 1.28 N/mm).
    friction : object, optional
        A friction model from :func:`parse_friction`; default none.
    settings : Settings, optional
        Loop settings; default ``Settings(realtime=False)`` (unpaced: as fast as the
        machine allows). The duration defaults to one pass over the track,
        ``track.length / speed``.
    press : float, default 1.0
        The hand's downward force, N.
    hand_mass : float, default 0.15
        The hand's mass, kg.
    hand_damping : float, default 2.0
        The hand's damping, N·s/m.
    lateral_stiffness : float, optional
        N/m: lets the lateral and friction forces push the hand off its path; default
        a rigid stroke along x.

    Returns
    -------
    Run
        The trace and timing of the run, with ``speed`` set.

    Raises
    ------
    rough.InputError
        Before it starts, for a run whose trace would exceed
        :data:`~rough.render.loop.TRACE_LIMIT` (512 MiB: duration × rate past
        :data:`~rough.render.loop.MAX_TICKS`).

    See Also
    --------
    forces : Force statistics of the run.
    write_trace : Save the trace.

    Notes
    -----
    Off the track (past its end) there is no surface: the trace's ``h`` is NaN
    there and the force is zero. The force is clamped to ``settings.max_force``.

    Examples
    --------
    On a flat track the hand settles at its press, 1 N, and feels no lateral force:

    >>> import numpy as np
    >>> from rough.render import Track, forces, simulate
    >>> flat = Track(np.zeros(1001), 0.1e-3)  # 100 mm
    >>> result = simulate(flat, speed=0.02)  # 20 mm/s: 5 s, 5000 ticks at 1 kHz
    >>> result.ticks, result.ended_by
    (5000, 'duration')
    >>> statistics = forces(result)
    >>> round(statistics["F_y_mean"], 9), round(statistics["F_x_rms"], 9)  # N
    (1.0, 0.0)
    """
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
    """Force statistics of a run.

    Parameters
    ----------
    result : Run
        A run from :func:`simulate` or :func:`run`.
    max_force : float, optional
        The force limit, N, for ``at_force_limit``; default the run's
        ``settings.max_force``.

    Returns
    -------
    dict of str to float
        ``F_y_mean``, ``F_y_std``, ``F_y_max`` (the normal force: mean, standard
        deviation, peak) and ``F_x_rms`` (the lateral force), N; ``out_of_contact``
        and ``at_force_limit``, the fractions of ticks out of contact and at the
        force limit. The forces in a trace are always finite: the loop writes a
        force that is not finite (NaN heights, a diverging model) as zero.

    Examples
    --------
    >>> import rough
    >>> from rough.render import Track, forces, simulate
    >>> track = Track.from_surface(rough.read(rough.sample("rock-profile.tsv")))
    >>> statistics = forces(simulate(track, speed=0.06))
    >>> sorted(statistics)
    ['F_x_rms', 'F_y_max', 'F_y_mean', 'F_y_std', 'at_force_limit', 'out_of_contact']
    >>> print(f"F_y {statistics['F_y_mean']:.3f} N, peak {statistics['F_y_max']:.3f} N")
    F_y 0.997 N, peak 1.841 N
    >>> f"F_x {statistics['F_x_rms']:.3f} N RMS"
    'F_x 0.453 N RMS'
    >>> statistics["out_of_contact"]
    0.0
    """
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
    """Save the trace of a run, one row per tick.

    Parameters
    ----------
    result : Run
        A run from :func:`simulate` or :func:`run`.
    path : str or os.PathLike
        The file to write: NPY (a structured array with the fields of
        ``TRACE_FIELDS``) when it ends in ``.npy``, else TSV with the header line
        ``t x y_i h F_x F_y contact``. Written atomically.

    Notes
    -----
    Columns: time (s), stylus position x (m), hand height ``y_i`` (m), surface height
    ``h`` under the stylus (m; NaN where there is no surface, off the profile),
    forces ``F_x`` and ``F_y`` (N), and contact (0/1).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> import numpy as np
    >>> from rough.render import Track, simulate, write_trace
    >>> result = simulate(Track(np.zeros(101), 0.1e-3), speed=0.02)  # 10 mm at 20 mm/s
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     write_trace(result, pathlib.Path(folder) / "trace.tsv")
    ...     lines = (pathlib.Path(folder) / "trace.tsv").read_text().splitlines()
    ...     write_trace(result, pathlib.Path(folder) / "trace.npy")
    ...     trace = np.load(pathlib.Path(folder) / "trace.npy")
    >>> lines[0].split(), len(lines)  # a header and 500 ticks
    (['t', 'x', 'y_i', 'h', 'F_x', 'F_y', 'contact'], 501)
    >>> trace.dtype.names == tuple(lines[0].split()), trace.shape
    (True, (500,))
    """
    from ..io.atomic import atomic_output

    trace = result.trace
    with atomic_output(path) as stream:
        if str(path).lower().endswith(".npy"):
            np.save(stream, trace)
            return
        stream.write(("\t".join(TRACE_FIELDS) + "\n").encode())
        columns = np.column_stack([trace[name].astype(np.float64) for name in TRACE_FIELDS])
        np.savetxt(stream, columns, fmt=["%.9g"] * 6 + ["%d"], delimiter="\t")
