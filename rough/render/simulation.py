"""Stroke a track with the simulated hand (:func:`simulate`): the headless run of the
servo loop behind ``rough render --device sim`` and the experiment's simulated
sessions."""

from .contact import GradientField, QuasiStatic
from .hand import HAND_DAMPING, HAND_MASS, PRESS, TURN, MapHand, SimulatedHand, Stroke
from .loop import Settings, run
from .track import MapTrack


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
        A friction model from :func:`~rough.render.parse_friction`; default none.
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
        hand = MapHand(stroke=stroke, start=start, direction=unit, **options)
    else:
        model = model or QuasiStatic()
        start_y = track.at(track.start)[0] - press / getattr(model, "static_stiffness", model.stiffness)
        hand = SimulatedHand(speed=speed, start_x=track.start, start_y=start_y, press=press, stroke=stroke, **options)
    result = run(hand, [track], model, friction, settings)
    result.speed = speed
    return result
