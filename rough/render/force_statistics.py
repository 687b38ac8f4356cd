"""The force statistics of a run (:func:`forces`), and a map run's force split along
and across the motion."""

import math

import numpy as np


def forces(result, max_force=None):
    """Force statistics of a run.

    Parameters
    ----------
    result : Run
        A run from :func:`~rough.render.simulate` or :func:`~rough.render.run`.
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
