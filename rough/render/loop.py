"""The servo loop: read the device, compute the force, write it, once per period.

Each tick reads the hand's position (and buttons), estimates its velocity and
acceleration (backward differences through a first-order low-pass, ``velocity_cutoff``),
looks up the surface under it, asks the contact model and the friction model for the
force, clamps the force vector to ``max_force`` by scaling both components, ramps it in
over ``ramp`` seconds at the start, and writes it. The trigger (button 1) switches
between two surfaces on each press.

Real time: ticks are paced by a deadline clock (sleep until 0.2 ms before the
deadline, then spin), with the garbage collector paused and, where the system allows
it, the loop's thread at real-time priority (SCHED_FIFO ``priority``), so that other
processes cannot preempt it for milliseconds. A tick that starts a whole
period or more late counts its deadlines as missed and the schedule skips them rather
than bursting. A simulated device runs as fast as the machine allows unless
``realtime`` is set. Safety: whatever ends the loop (its duration, Ctrl-C, an
exception, a device error), the device is closed, which zeroes the force; a watchdog
thread zeroes it too if the loop stalls for ``watchdog`` seconds (default 10 ms: long
enough to ride through an operating-system hiccup, short enough that a hand never
feels a stuck force). A non-finite force (a glitched position) is written as zero.
"""

import array
import dataclasses
import gc
import math
import os
import sys
import threading
import time

import numpy as np

from ..errors import InputError, RoughError
from .contact import MAX_FORCE, clamp
from .track import TRACE_FIELDS

SPIN = 2e-4  # s before each deadline spent spinning instead of sleeping
TICK_BYTES = 8 * (len(TRACE_FIELDS) + 2)  # a trace row, and a real-time tick's start and deadline
TRACE_LIMIT = 512 * 2**20  # bytes a run's trace may take: 7.4 million ticks, 2 hours at 1 kHz
MAX_TICKS = TRACE_LIMIT // TICK_BYTES


def check_ticks(ticks, what="the run"):
    """Refuse ``ticks`` (in all) past :data:`MAX_TICKS`, before anything starts."""
    if not ticks <= MAX_TICKS:
        raise InputError(
            f"{what} would take {ticks:.4g} ticks (run time × rate), {ticks * TICK_BYTES / 2**20:.4g} MiB of trace: "
            f"over the bound of {TRACE_LIMIT // 2**20} MiB ({MAX_TICKS} ticks, {MAX_TICKS / 3.6e6:.3g} hours at 1 kHz)"
        )


def planned_ticks(settings, duration=None):
    """The ticks a run of ``duration`` (default ``settings.duration``) takes; None without one."""
    duration = settings.duration if duration is None else duration
    if duration is None:
        return None
    ticks = duration * settings.rate
    return max(1, round(ticks)) if ticks <= MAX_TICKS else ticks


class LoopStalled(RoughError):
    """The watchdog found the loop stalled and zeroed the force."""


@dataclasses.dataclass
class Settings:
    """What the loop needs besides the device, surfaces and models (SI units).

    Attributes
    ----------
    rate : float, default 1000.0
        Ticks per second, Hz.
    duration : float or None, default None
        How long to run, s; None runs until stopped (Ctrl-C, or ``until``).
    ramp : float, default 0.0
        Seconds over which the force ramps in at the start.
    max_force : float, default 8.9
        The force limit, N (the Impulse Engine 2000's): the force vector is scaled
        down to it every tick.
    realtime : bool, default True
        Pace the ticks by a deadline clock; False runs a simulated device as fast as
        the machine allows.
    velocity_cutoff : float, default 100.0
        The cut-off of the first-order low-pass on the velocity and acceleration
        estimates, Hz.
    watchdog : float, default 0.01
        Seconds of stalled loop after which the watchdog zeroes a joystick's force.
    priority : int, default 50
        The SCHED_FIFO priority asked for in real time (0: normal priority).
    period : float
        ``1 / rate``, s.

    Examples
    --------
    >>> from rough.render import Settings
    >>> settings = Settings(rate=2000.0, realtime=False)
    >>> settings.period, settings.max_force  # s, N
    (0.0005, 8.9)
    """

    rate: float = 1000.0
    duration: float = None
    ramp: float = 0.0
    max_force: float = MAX_FORCE
    realtime: bool = True
    velocity_cutoff: float = 100.0
    watchdog: float = 0.01
    priority: int = 50

    @property
    def period(self):
        """``1 / rate``, s."""
        return 1.0 / self.rate


@dataclasses.dataclass
class Run:
    """What a run did: the trace, the timing, and how it ended.

    Attributes
    ----------
    trace : numpy.ndarray
        A structured array, one row per tick, with the fields of ``TRACE_FIELDS``:
        ``t`` (s), ``x`` (stylus position, m), ``y_i`` (hand height, m), ``h`` (the
        surface under the stylus, m; NaN where there is no surface), ``F_x``,
        ``F_y`` (the force written, N) and ``contact`` (bool). On a map the fields
        are ``MAP_TRACE_FIELDS``: ``y`` (the point's y on the map, m) replaces
        ``y_i``, and ``F_x``, ``F_y`` lie in the map's plane.
    ticks : int
        Ticks run.
    wall_time : float
        Seconds the loop took.
    settings : Settings
        The settings it ran with.
    starts, deadlines : numpy.ndarray or None
        Real-time runs: each tick's start time and deadline (``time.perf_counter``
        seconds); None when unpaced.
    missed : int
        Deadlines missed (ticks that started a whole period or more late).
    switches : int
        How many times the trigger switched between two surfaces.
    ended_by : str
        ``"duration"``, ``"answer"`` (``until`` returned an answer),
        ``"interrupt"`` (Ctrl-C) or ``"trace limit"`` (a run without a duration
        reached :data:`MAX_TICKS`).
    speed : float or None
        The stroking speed of a simulated run, m/s.
    device : str
        ``"sim"``, or the joystick's label.
    scheduling : str
        ``"unpaced"``, ``"normal priority"`` or ``"SCHED_FIFO N"``.
    answer : object
        What ``until`` returned to end the run, or None.
    model : object
        The contact model (or gradient field) the run was rendered with.

    Notes
    -----
    ``timing()`` gives the achieved rate (Hz), the period jitter p50/p99/max (s), the
    missed deadlines and the largest lateness (s) of a real-time run; for an unpaced
    run only the ticks, simulated and wall time and their ratio.

    Examples
    --------
    >>> import numpy as np
    >>> from rough.render import Track, simulate
    >>> result = simulate(Track(np.zeros(101), 0.1e-3), speed=0.02)  # 10 mm at 20 mm/s
    >>> result.ticks, result.trace.shape, result.device, result.scheduling
    (500, (500,), 'sim', 'unpaced')
    >>> timing = result.timing()
    >>> round(timing["simulated_time"], 9), timing["realtime_factor"] > 1  # s
    (0.5, True)
    """

    trace: np.ndarray
    ticks: int
    wall_time: float
    settings: Settings
    starts: np.ndarray = None
    deadlines: np.ndarray = None
    missed: int = 0
    switches: int = 0
    ended_by: str = "duration"
    speed: float = None
    device: str = "sim"
    scheduling: str = "unpaced"
    answer: object = None
    model: object = None

    def timing(self):
        """Achieved rate (Hz), period jitter p50/p99/max (s), missed deadlines and the
        largest lateness (s); for an unpaced run only the speed against real time."""
        simulated = self.ticks * self.settings.period
        timing = {
            "ticks": self.ticks,
            "simulated_time": simulated,
            "wall_time": self.wall_time,
            "realtime_factor": simulated / self.wall_time if self.wall_time > 0 else math.inf,
            "scheduling": self.scheduling,
        }
        if self.starts is not None and self.starts.size > 2:
            periods = np.diff(self.starts)
            jitter = np.abs(periods - self.settings.period)
            timing.update(
                rate=(self.starts.size - 1) / (self.starts[-1] - self.starts[0]),
                jitter_p50=float(np.percentile(jitter, 50)),
                jitter_p99=float(np.percentile(jitter, 99)),
                jitter_max=float(jitter.max()),
                missed_deadlines=self.missed,
                max_lateness=float((self.starts - self.deadlines).max()),
            )
        return timing


class _Watchdog(threading.Thread):
    """Zeroes the device's force if the loop's tick count stops advancing for
    ``timeout`` seconds (looking eight times per timeout)."""

    def __init__(self, device, timeout):
        super().__init__(name="rough-render-watchdog", daemon=True)
        self.device, self.timeout = device, timeout
        self.tick, self.tripped = 0, False
        self._last, self._changed = -1, 0.0
        self._done = threading.Event()

    def run(self):
        while not self._done.wait(self.timeout / 8):
            if self.look(time.monotonic()):
                return

    def look(self, now):
        """One look at the loop at the time ``now`` (seconds): True, with the device
        stopped, when its tick has not advanced for more than the timeout."""
        if self.tick != self._last:
            self._last, self._changed = self.tick, now
        elif now - self._changed > self.timeout:
            self.tripped = True
            self.device.emergency_stop()
        return self.tripped

    def stop(self):
        self._done.set()


def run(device, tracks, model, friction=None, settings=None, until=None):
    """Run the servo loop: read the device, compute the force, write it, every period.

    Parameters
    ----------
    device : Device
        A :class:`~rough.render.device.Device`: a simulated hand or a joystick.
    tracks : list of Track or list of MapTrack
        One or two tracks; the trigger (button 1) switches between two.
    model : QuasiStatic, DynamicStylus or GradientField
        The contact model (on a map, the gradient field); it starts afresh.
    friction : object, optional
        A friction model from :func:`~rough.render.parse_friction` (it starts afresh); default none.
    settings : Settings, optional
        Default ``Settings()`` (real time, 1 kHz, until stopped).
    until : callable, optional
        Called with the buttons every tick; when it returns something true the loop
        ends and keeps it as ``Run.answer``.

    Returns
    -------
    Run
        The trace and timing. However the loop ends (its duration, ``until``,
        Ctrl-C, an exception), the device is closed, which zeroes the force.

    Raises
    ------
    rough.InputError
        Before anything starts, when ``settings.duration × settings.rate`` exceeds
        :data:`MAX_TICKS` (a trace over :data:`TRACE_LIMIT` bytes). A run without a
        duration ends at that many ticks.
    rough.RoughError
        ``LoopStalled`` when the watchdog found the loop stalled and zeroed the
        force (devices that need a watchdog, in real time).

    Notes
    -----
    Each tick estimates the velocity and acceleration (backward differences through
    a first-order low-pass), looks up the surface under the stylus, asks the contact
    and friction models for the force, clamps the force vector to
    ``settings.max_force``, ramps it in over ``settings.ramp`` and writes it. A
    force that is not finite (NaN heights, a diverging model) is written as zero.

    Examples
    --------
    The simulated hand on a flat track, for 0.1 s, and then until a callback answers:

    >>> import numpy as np
    >>> from rough.render import QuasiStatic, Settings, SimulatedHand, Track, run
    >>> track = Track(np.zeros(101), 0.1e-3)
    >>> hand = SimulatedHand(0.02, start_x=0.0, start_y=0.0, period=1e-3)
    >>> result = run(hand, [track], QuasiStatic(), settings=Settings(duration=0.1, realtime=False))
    >>> result.ticks, result.ended_by
    (100, 'duration')
    >>> calls = []
    >>> def ten_ticks(buttons):
    ...     calls.append(buttons)
    ...     return "enough" if len(calls) > 10 else None
    >>> hand = SimulatedHand(0.02, start_x=0.0, start_y=0.0, period=1e-3)
    >>> result = run(hand, [track], QuasiStatic(), settings=Settings(realtime=False), until=ten_ticks)
    >>> result.ticks, result.ended_by, result.answer
    (10, 'answer', 'enough')
    """
    settings = settings or Settings()
    try:
        check_ticks(planned_ticks(settings) or 0)
    except InputError:
        device.close()
        raise
    model.reset()
    if friction is not None:
        friction.reset()
    watchdog = None
    if settings.realtime and device.capabilities.needs_watchdog:
        watchdog = _Watchdog(device, settings.watchdog)
    collector = gc.isenabled()
    gc.disable()
    previous, scheduling = _raise_priority(settings.priority) if settings.realtime else (None, "unpaced")
    switching = sys.getswitchinterval()
    if watchdog is not None:  # a loop stuck in Python code must hand the watchdog the interpreter soon
        sys.setswitchinterval(min(switching, settings.watchdog / 8))
    loop = _Loop(device, tracks, model, friction, settings, watchdog, until)
    try:
        loop.spin()
    except KeyboardInterrupt:
        loop.ended_by = "interrupt"
    finally:
        sys.setswitchinterval(switching)
        if previous is not None:
            os.sched_setscheduler(0, *previous)
        if watchdog is not None:
            watchdog.stop()
        if collector:
            gc.enable()
        device.close()
    loop.scheduling = scheduling
    if watchdog is not None and watchdog.tripped:
        raise LoopStalled(f"the servo loop stalled for more than {settings.watchdog * 1e3:g} ms; the force was zeroed")
    return loop.result()


def _raise_priority(priority):
    """Put the calling thread at SCHED_FIFO ``priority``; returns the policy to restore
    (or None) and what the loop got."""
    if not priority or not hasattr(os, "sched_setscheduler"):
        return None, "normal priority"
    previous = (os.sched_getscheduler(0), os.sched_getparam(0))
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    except OSError:
        return None, "normal priority (real-time priority not permitted)"
    return previous, f"SCHED_FIFO {priority}"


class _Loop:
    def __init__(self, device, tracks, model, friction, settings, watchdog, until):
        self.device, self.tracks, self.model, self.friction = device, list(tracks), model, friction
        self.fields = self.tracks[0].fields
        self.feelings = [track.feel(model, friction, settings.period) for track in self.tracks]
        self.until, self.answer = until, None
        self.settings, self.watchdog = settings, watchdog
        self.rows, self.starts, self.deadlines = array.array("d"), array.array("d"), array.array("d")
        self.ticks, self.missed, self.switches = 0, 0, 0
        self.ended_by = "duration"
        self.wall_time = 0.0
        self.scheduling = "unpaced"

    def spin(self):
        s = self.settings
        period, realtime, limit = s.period, s.realtime, s.max_force
        total = planned_ticks(s) or MAX_TICKS
        ramp_ticks = s.ramp * s.rate
        alpha = 1.0 - math.exp(-2.0 * math.pi * s.velocity_cutoff * period)
        read, write = self.device.read, self.device.write
        record = self.rows.extend
        watchdog, until = self.watchdog, self.until
        track = 0
        feel = self.feelings[track]
        x_last, y_last, buttons = read()
        vx, vy = self.device.velocity
        x_last, y_last, ax, pressed = x_last - vx * period, y_last - vy * period, 0.0, buttons & 1
        clock, sleep = time.perf_counter, time.sleep
        begin = clock()
        deadline = begin
        k = 0
        try:
            while k < total:
                if realtime:
                    now = clock()
                    if now - deadline >= period:
                        skipped = int((now - deadline) / period)
                        self.missed += skipped
                        deadline += skipped * period
                    elif deadline - now > SPIN:
                        sleep(deadline - now - SPIN)
                    while clock() < deadline:
                        pass
                    self.starts.append(clock())
                    self.deadlines.append(deadline)
                    deadline += period
                    if watchdog is not None:
                        if watchdog.tripped:
                            break
                        watchdog.tick = k
                        if k == 1:
                            watchdog.start()
                x, y, buttons = read()
                if until is not None:
                    self.answer = until(buttons)
                    if self.answer:
                        self.ended_by = "answer"
                        break
                fresh = vx + alpha * ((x - x_last) / period - vx)
                ax += alpha * ((fresh - vx) / period - ax)
                vx = fresh
                vy += alpha * ((y - y_last) / period - vy)
                x_last, y_last = x, y
                if buttons & 1 and not pressed and len(self.tracks) > 1:
                    track = 1 - track
                    feel = self.feelings[track]
                    self.model.reset()
                    self.switches += 1
                pressed = buttons & 1
                h, fx, fy, contact = feel(x, y, vx, vy, ax)
                fx, fy = clamp(fx, fy, limit)
                if k < ramp_ticks:
                    fx, fy = fx * k / ramp_ticks, fy * k / ramp_ticks
                write(fx, fy)
                record((k * period, x, y, h, fx, fy, contact))
                k += 1
            if k == total and s.duration is None:
                self.ended_by = "trace limit"
        finally:
            self.ticks = k
            self.wall_time = clock() - begin

    def result(self):
        fields = self.fields
        columns = np.frombuffer(self.rows, dtype=np.float64).reshape(-1, len(fields))
        trace = np.empty(len(columns), dtype=[(name, np.float64) for name in fields[:-1]] + [("contact", np.bool_)])
        for index, name in enumerate(fields):
            trace[name] = columns[:, index]
        trace["h"][~np.isfinite(trace["h"])] = np.nan
        starts = np.frombuffer(self.starts, dtype=np.float64) if self.starts else None
        deadlines = np.frombuffer(self.deadlines, dtype=np.float64) if self.deadlines else None
        if starts is not None:
            trace["t"] = starts[: trace.size] - starts[0]
        return Run(
            trace,
            self.ticks,
            self.wall_time,
            self.settings,
            starts,
            deadlines,
            self.missed,
            self.switches,
            self.ended_by,
            device=self.device.label,
            scheduling=self.scheduling,
            answer=self.answer,
            model=self.model,
        )
