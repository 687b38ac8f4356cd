"""Haptic rendering: feel a surface profile through a force-feedback joystick.

A virtual stylus rides the profile, or a point moves over the map (:mod:`.track`); a
contact model (:mod:`.contact`) and optionally a friction model (:mod:`.friction`)
give the force on the hand; the servo loop (:mod:`.loop`) reads a device, computes and
writes that force once per period. Devices (:mod:`.device`, one interface and one
factory): the simulated hand (``sim``, :mod:`.hand`, for headless runs and tests), a
HID PID joystick through hidraw (``hid``, :mod:`.hid`) and any Linux force-feedback
device through evdev (``evdev``, :mod:`.evdev`). SI units throughout: m, s, N, kg.

>>> import rough
>>> from rough.render import Track, forces, simulate
>>> track = Track.from_surface(rough.read(rough.sample("rock-profile.tsv")))
>>> result = simulate(track, speed=0.06)  # 60 mm/s, the simulated hand
>>> f"F_y {forces(result)['F_y_mean']:.3f} ± {forces(result)['F_y_std']:.3f} N"
'F_y 0.997 ± 0.347 N'
"""

import math

import numpy as np

from .contact import MAX_FORCE, STIFFNESS, DynamicStylus, GradientField, QuasiStatic, clamp
from .device import open_device
from .friction import parse_friction
from .hand import HAND_DAMPING, HAND_MASS, PRESS, TURN, MapHand, SimulatedHand, Stroke
from .loop import Run, Settings, run
from .track import MAP_TRACE_FIELDS, TRACE_FIELDS, MapTrack, Track

__all__ = [
    "MAX_FORCE",
    "STIFFNESS",
    "TRACE_FIELDS",
    "MAP_TRACE_FIELDS",
    "DynamicStylus",
    "GradientField",
    "MapHand",
    "MapTrack",
    "QuasiStatic",
    "Run",
    "Settings",
    "SimulatedHand",
    "Stroke",
    "Track",
    "clamp",
    "along_and_across",
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
    direction=0.0,
    turn=TURN,
):
    """Stroke a track with the simulated hand, and record what the loop did.

    On a profile the hand starts at the start of the track, on the surface under its
    own press (the contact model's spring compressed by ``press``), and strokes along
    x at ``speed`` while pressing down. On a map it strokes in the map's plane along
    ``direction``, over the longest chord through the map's centre, and feels the
    gradient field ``-N ∇h`` with the load N = ``press``. A run longer than one pass
    strokes back and forth, turning at the ends (:class:`~rough.render.hand.Stroke`).

    Parameters
    ----------
    track : Track or MapTrack
        The profile or map to stroke.
    speed : float
        The stroking speed, m/s.
    model : QuasiStatic, DynamicStylus or GradientField, optional
        The contact model; default ``QuasiStatic()`` (K = 1.28 N/mm) on a profile,
        ``GradientField(press)`` on a map.
    friction : object, optional
        A friction model from :func:`parse_friction`; default none.
    settings : Settings, optional
        Loop settings; default ``Settings(realtime=False)`` (unpaced: as fast as the
        machine allows). The duration defaults to one pass over the track,
        ``track.length / speed`` (on a map, the chord's length / speed).
    press : float, default 1.0
        The hand's downward force, N (on a map, the normal load).
    hand_mass : float, default 0.15
        The hand's mass, kg.
    hand_damping : float, default 2.0
        The hand's damping, N·s/m.
    lateral_stiffness : float, optional
        N/m: lets the lateral and friction forces push the hand off its path; default
        a rigid stroke.
    direction : float, default 0.0
        Maps: the stroke's direction, radians from +x.
    turn : float, default 0.2
        Seconds the hand takes to reverse at each end, in a run longer than one pass.

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
    Off the track (past its end, or pushed off it by the forces) there is no
    surface: the trace's ``h`` is NaN there and the force is zero. The force is
    clamped to ``settings.max_force``.

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
    settings = settings or Settings(realtime=False)
    if isinstance(track, MapTrack):
        start, unit, length = track.chord(direction)
    else:
        length = track.length
    one_pass = length / abs(speed)
    if settings.duration is None:
        settings = Settings(**{**settings.__dict__, "duration": one_pass})
    stroke = Stroke(speed, settings.period, length if settings.duration > one_pass else None, turn)
    options = dict(period=settings.period, mass=hand_mass, damping=hand_damping, lateral_stiffness=lateral_stiffness)
    if isinstance(track, MapTrack):
        model = model or GradientField(press)
        hand = open_device("sim", surface="map", stroke=stroke, start=start, direction=unit, **options)
    else:
        model = model or QuasiStatic()
        start_y = track.at(track.start)[0] - press / getattr(model, "static_stiffness", model.stiffness)
        hand = open_device(
            "sim", speed=speed, start_x=track.start, start_y=start_y, press=press, stroke=stroke, **options
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
        On a profile: ``F_y_mean``, ``F_y_std``, ``F_y_max`` (the normal force:
        mean, standard deviation, peak) and ``F_x_rms`` (the lateral force), N. On a
        map: ``F_along_rms`` and ``F_across_rms`` (the force along and across the
        motion, :func:`along_and_across`), ``F_x_rms``, ``F_y_rms`` (along the
        stick's axes) and ``F_max`` (the largest magnitude), N. Both:
        ``out_of_contact`` and ``at_force_limit``, the fractions of ticks out of
        contact (on a map: off it) and at the force limit. The forces in a trace are
        always finite: the loop writes a force that is not finite (NaN heights, a
        diverging model) as zero.

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
    shared = {
        "out_of_contact": float(1.0 - trace["contact"].mean()),
        "at_force_limit": float(np.mean(np.hypot(fx, fy) >= limit * (1 - 1e-9))),
    }
    if "y_i" not in trace.dtype.names:
        along, across = along_and_across(trace)
        return {
            "F_along_rms": _rms(along),
            "F_across_rms": _rms(across),
            "F_x_rms": _rms(fx),
            "F_y_rms": _rms(fy),
            "F_max": float(np.hypot(fx, fy).max()),
            **shared,
        }
    return {
        "F_y_mean": float(fy.mean()),
        "F_y_std": float(fy.std()),
        "F_y_max": float(fy.max()),
        "F_x_rms": _rms(fx),
        **shared,
    }


def _rms(values):
    return float(math.sqrt(np.mean(values * values)))


def along_and_across(trace):
    """The force of a map run split along and across the motion.

    Parameters
    ----------
    trace : numpy.ndarray
        A map run's trace (fields ``MAP_TRACE_FIELDS``).

    Returns
    -------
    along, across : numpy.ndarray
        N per tick: the force's component along the direction of motion (from this
        tick's point to the next; positive pushes the hand on), and at right angles
        to it (positive to the left of the motion). A tick without motion takes the
        last direction before it (the first direction for the ticks before any
        motion); a run that never moves has NaN throughout.

    Examples
    --------
    A stroke along +y over a ramp rising along x: no force along the stroke, and across
    it the push down the slope (towards -x, to the left of the motion), N × slope:

    >>> import numpy as np
    >>> from rough.render import MapTrack, along_and_across, simulate
    >>> x = np.arange(41) * 0.1e-3
    >>> ramp = MapTrack(np.tile(0.2 * x, (41, 1)), (0.1e-3, 0.1e-3))  # slope 0.2
    >>> along, across = along_and_across(simulate(ramp, 0.02, direction=np.pi / 2).trace)
    >>> round(float(np.abs(along).max()), 12), round(float(across.mean()), 12)  # N
    (0.0, 0.2)
    """
    x, y = trace["x"], trace["y"]
    dx, dy = np.diff(x, append=x[-1:]), np.diff(y, append=y[-1:])
    length = np.hypot(dx, dy)
    moving = length > 0
    last = np.maximum.accumulate(np.where(moving, np.arange(x.size), -1))
    if not moving.any():
        return np.full(x.size, np.nan), np.full(x.size, np.nan)
    last[last < 0] = np.argmax(moving)
    ux, uy = dx[last] / length[last], dy[last] / length[last]
    fx, fy = trace["F_x"], trace["F_y"]
    return fx * ux + fy * uy, fy * ux - fx * uy


def write_trace(result, path):
    """Save the trace of a run, one row per tick.

    Parameters
    ----------
    result : Run
        A run from :func:`simulate` or :func:`run`.
    path : str or os.PathLike
        The file to write: NPY (a structured array with the fields of
        ``TRACE_FIELDS``, or ``MAP_TRACE_FIELDS`` for a map) when it ends in
        ``.npy``, else TSV with the header line ``t x y_i h F_x F_y contact`` (for a
        map ``t x y h F_x F_y contact``). Written atomically.

    Notes
    -----
    Columns: time (s), stylus position x (m), hand height ``y_i`` (m), surface height
    ``h`` under the stylus (m; NaN where there is no surface, off the profile),
    forces ``F_x`` and ``F_y`` (N), and contact (0/1). For a map, x and y are the
    point on the map (the stick's axes) and ``F_x``, ``F_y`` the force in the
    stick's plane.

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
        fields = trace.dtype.names
        stream.write(("\t".join(fields) + "\n").encode())
        columns = np.column_stack([trace[name].astype(np.float64) for name in fields])
        np.savetxt(stream, columns, fmt=["%.9g"] * 6 + ["%d"], delimiter="\t")
