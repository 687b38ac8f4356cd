"""Whole render sessions as the command line runs them: the simulated hand at one or
more speeds, or a joystick until Ctrl-C; and their summary for people and programs."""

from ..units import format_unit
from . import forces, simulate
from .contact import DynamicStylus, QuasiStatic
from .loop import check_ticks, planned_ticks, run


def make_model(name, stiffness, mass, damping, period):
    """``quasi-static`` or ``dynamic`` (the stylus stepped at ``period``)."""
    if name == "dynamic":
        return DynamicStylus(stiffness, mass, damping, period)
    return QuasiStatic(stiffness)


def run_sim(track, speeds, model, friction, settings, **hand):
    """One simulated stroke per speed: ``[(label, Run), ...]`` with labels like ``20mm_s``.
    Refuses the runs before the first starts if their traces together would exceed the
    bound (:data:`~rough.render.loop.TRACE_LIMIT`); Ctrl-C ends the last run begun."""
    ticks = sum(planned_ticks(settings, settings.duration or track.length / speed) for speed in speeds)
    check_ticks(ticks, "the run" if len(speeds) == 1 else f"the {len(speeds)} runs")
    runs = []
    for speed in speeds:
        runs.append((f"{speed * 1e3:g}mm_s", simulate(track, speed, model, friction, settings, **hand)))
        if runs[-1][1].ended_by == "interrupt":
            break
    return runs


def open_joystick(spec, tracks, max_force, stick_span=None, invert=()):
    """The joystick ``spec`` (``hid`` or ``hid:VID:PID``) set up for ``tracks``: the
    stick's x travel spans ``stick_span[0]`` (default the first track's length) and its
    y travel ``stick_span[1]`` (default four times the largest height range) below the
    highest top. Returns ``(Joystick, label)``."""
    from .hid import Joystick, find_joystick

    handle, descriptor, label = find_joystick(spec)
    first = tracks[0]
    top = max(track.top for track in tracks)
    height_range = max(track.top - track.bottom for track in tracks) or 1e-3
    x_span, y_span = stick_span if stick_span and len(stick_span) == 2 else (first.length, 4.0 * height_range)
    try:
        return Joystick(handle, descriptor, max_force, first.start, x_span, top, y_span, invert), label
    except BaseException:
        handle.close()
        raise


def run_hid(spec, tracks, model, friction, settings, stick_span=None, invert=()):
    """A session on the joystick ``spec`` until the duration passes or Ctrl-C: ``("hid", Run)``."""
    check_ticks(planned_ticks(settings) or 0)
    joystick, label = open_joystick(spec, tracks, settings.max_force, stick_span, invert)
    result = run(joystick, tracks, model, friction, settings)
    result.device = label
    return "hid", result


def summary_rows(runs, model_name, model, friction_spec):
    """Report rows ``(key, value, unit, text, label)`` and the JSON document of ``runs``:
    ``{"runs": [one dict per run]}``, the rows keyed ``runs.I.KEY`` and labelled
    ``KEY`` (``SPEED.KEY`` for several runs)."""
    rows, documents = [], []
    for index, (label, result) in enumerate(runs):
        timing, statistics = result.timing(), forces(result)
        prefix = f"{label}." if len(runs) > 1 else ""
        document = {
            "device": result.device,
            "speed": result.speed,
            "model": model_name,
            "friction": friction_spec or "none",
            "ended_by": result.ended_by,
            "surface_switches": result.switches,
            **timing,
            **statistics,
        }
        documents.append(document)
        rows += [(f"runs.{index}.{key}", *rest, prefix + key) for key, *rest in _rows(document, model)]
    return rows, {"runs": documents}


def _rows(d, model):
    rows = [
        (
            "device",
            d["device"],
            "",
            d["device"] + ("" if d["speed"] is None else f", stroking at {format_unit(d['speed'], 'speed')}"),
        ),
        (
            "model",
            d["model"],
            "",
            _describe(model) + (f"; friction {d['friction']}" if d["friction"] != "none" else ""),
        ),
        (
            "ticks",
            d["ticks"],
            "1",
            f"{d['ticks']} ticks, {d['simulated_time']:.3f} s of loop time in {d['wall_time']:.3f} s "
            f"({d['realtime_factor']:.0f}× real time)"
            if "rate" not in d
            else f"{d['ticks']} ticks in {d['wall_time']:.3f} s",
        ),
    ]
    if "rate" in d:
        rows += [
            ("rate", d["rate"], "Hz", f"{d['rate']:.1f} Hz achieved ({d['scheduling']})"),
            ("jitter_p50", d["jitter_p50"], "s", f"{d['jitter_p50'] * 1e6:.1f} µs period jitter, median"),
            ("jitter_p99", d["jitter_p99"], "s", f"{d['jitter_p99'] * 1e6:.1f} µs period jitter, 99th percentile"),
            ("jitter_max", d["jitter_max"], "s", f"{d['jitter_max'] * 1e6:.1f} µs period jitter, largest"),
            (
                "missed_deadlines",
                d["missed_deadlines"],
                "1",
                f"{d['missed_deadlines']} missed deadlines (latest tick {d['max_lateness'] * 1e3:.3f} ms late)",
            ),
        ]
    rows += [
        ("F_y_mean", d["F_y_mean"], "N", f"{d['F_y_mean']:.4f} N normal force, mean"),
        ("F_y_std", d["F_y_std"], "N", f"{d['F_y_std']:.4f} N normal force, standard deviation"),
        ("F_y_max", d["F_y_max"], "N", f"{d['F_y_max']:.4f} N normal force, largest"),
        ("F_x_rms", d["F_x_rms"], "N", f"{d['F_x_rms']:.4f} N RMS"),
        ("out_of_contact", d["out_of_contact"], "1", f"{100 * d['out_of_contact']:.2f} % of ticks"),
        ("at_force_limit", d["at_force_limit"], "1", f"{100 * d['at_force_limit']:.2f} % of ticks"),
        (
            "ended_by",
            d["ended_by"],
            "",
            d["ended_by"] + (f"; trigger switched surfaces {d['surface_switches']}×" if d["surface_switches"] else ""),
        ),
    ]
    return rows


def _describe(model):
    if isinstance(model, DynamicStylus):
        return (
            f"dynamic stylus: K {format_unit(model.stiffness, 'stiffness')}, M {format_unit(model.mass, 'mass')} "
            f"({model.mass * 1e-3:.3g} N·s²/mm), C {format_unit(model.damping, 'damping')}"
        )
    return f"quasi-static: K {format_unit(model.stiffness, 'stiffness')}, M and C negligible"
