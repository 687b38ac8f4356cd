"""Whole render sessions as the command line runs them: the simulated hand at one or
more speeds, or a physical device until Ctrl-C; and their summary for people and
programs."""

from ..units import format_unit
from .contact import DynamicStylus, GradientField, QuasiStatic
from .device import Workspace, open_device, parse_device
from .force_statistics import forces
from .hand import PRESS
from .loop import check_ticks, planned_ticks, run
from .simulation import simulate
from .stability import VirtualCoupling
from .track import MapTrack


def make_model(name, stiffness, mass, damping, period):
    """``quasi-static`` or ``dynamic`` (the stylus stepped at ``period``)."""
    if name == "dynamic":
        return DynamicStylus(stiffness, mass, damping, period)
    return QuasiStatic(stiffness)


def run_sim(track, speeds, model, friction, settings, **hand):
    """One simulated stroke per speed: ``[(label, Run), ...]`` with labels like ``20mm_s``.
    Refuses the runs before the first starts if their traces together would exceed the
    bound (:data:`~rough.render.loop.TRACE_LIMIT`); Ctrl-C ends the last run begun.
    ``hand`` goes to :func:`~rough.render.simulate` (on a map, ``direction`` too)."""
    length = track.chord(hand.get("direction", 0.0))[2] if isinstance(track, MapTrack) else track.length
    ticks = sum(planned_ticks(settings, settings.duration or length / speed) for speed in speeds)
    check_ticks(ticks, "the run" if len(speeds) == 1 else f"the {len(speeds)} runs")
    runs = []
    for speed in speeds:
        runs.append((f"{speed * 1e3:g}mm_s", simulate(track, speed, model, friction, settings, **hand)))
        if runs[-1][1].ended_by == "interrupt":
            break
    return runs


def workspace(tracks, stick_span=None, invert=()):
    """Where a stick's travel lies on ``tracks``, as a
    :class:`~rough.render.device.Workspace`. On a profile the x travel spans
    ``stick_span[0]`` (default the first track's length) from its start, and the y
    travel ``stick_span[1]`` (default four times the largest height range) centred on
    the highest top. On a map the travel spans ``stick_span`` (default the map's
    extent) from the map's first node along x, centred on the map along y."""
    first = tracks[0]
    if isinstance(first, MapTrack):
        x0, x1, y0, y1 = first.extent
        x_span, y_span = stick_span if stick_span and len(stick_span) == 2 else (x1 - x0, y1 - y0)
        return Workspace(x0, x_span, (y0 + y1) / 2, y_span, tuple(invert))
    top = max(track.top for track in tracks)
    height_range = max(track.top - track.bottom for track in tracks) or 1e-3
    x_span, y_span = stick_span if stick_span and len(stick_span) == 2 else (first.length, 4.0 * height_range)
    return Workspace(first.start, x_span, top, y_span, tuple(invert))


def open_joystick(spec, tracks, max_force, stick_span=None, invert=()):
    """The physical device ``spec`` (``hid[:VID:PID]`` or ``evdev[:PATH]``) set up for
    ``tracks`` (:func:`workspace`): ``(device, its label)``."""
    device = open_device(spec, workspace(tracks, stick_span, invert), max_force)
    return device, device.label


def fitted_model(model, device, load=PRESS):
    """``model`` as ``device`` can render it: on a device with one force axis (a
    wheel) a profile's contact model gives way to its lateral force alone,
    :class:`~rough.render.contact.GradientField` with the normal load ``load`` (N)."""
    if device.capabilities.axes < 2 and not isinstance(model, GradientField):
        return GradientField(load)
    return model


def run_stick(spec, tracks, model_for, friction, settings, stick_span=None, invert=()):
    """A session on the device ``spec`` until the duration passes or Ctrl-C:
    ``(backend name, Run)``. ``model_for(device)`` gives the contact model once the
    device is open (it depends on the device's axes and damping)."""
    check_ticks(planned_ticks(settings) or 0)
    device, _ = open_joystick(spec, tracks, settings.max_force, stick_span, invert)
    try:
        model = model_for(device)
    except BaseException:
        device.close()
        raise
    return parse_device(spec)[0], run(device, tracks, model, friction, settings)


def model_name(model):
    """The ``--model`` name of a contact model: ``quasi-static``, ``dynamic`` or
    ``gradient-field`` (with ``+coupling`` behind a virtual coupling)."""
    if isinstance(model, VirtualCoupling):
        return model_name(model.model) + "+coupling"
    if isinstance(model, GradientField):
        return "gradient-field"
    return "dynamic" if isinstance(model, DynamicStylus) else "quasi-static"


def summary_rows(runs, friction_spec):
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
            "model": model_name(result.model),
            "friction": friction_spec or "none",
            "ended_by": result.ended_by,
            "surface_switches": result.switches,
            **timing,
            **statistics,
        }
        documents.append(document)
        rows += [(f"runs.{index}.{key}", *rest, prefix + key) for key, *rest in _rows(document, result.model)]
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
    rows += _force_rows(d)
    rows += [
        (
            "ended_by",
            d["ended_by"],
            "",
            d["ended_by"] + (f"; trigger switched surfaces {d['surface_switches']}×" if d["surface_switches"] else ""),
        ),
    ]
    return rows


def _force_rows(d):
    if "F_along_rms" in d:
        return [
            ("F_along_rms", d["F_along_rms"], "N", f"{d['F_along_rms']:.4f} N RMS along the motion"),
            ("F_across_rms", d["F_across_rms"], "N", f"{d['F_across_rms']:.4f} N RMS across the motion"),
            ("F_x_rms", d["F_x_rms"], "N", f"{d['F_x_rms']:.4f} N RMS along x"),
            ("F_y_rms", d["F_y_rms"], "N", f"{d['F_y_rms']:.4f} N RMS along y"),
            ("F_max", d["F_max"], "N", f"{d['F_max']:.4f} N largest"),
            ("out_of_contact", d["out_of_contact"], "1", f"{100 * d['out_of_contact']:.2f} % of ticks off the map"),
            ("at_force_limit", d["at_force_limit"], "1", f"{100 * d['at_force_limit']:.2f} % of ticks"),
        ]
    return [
        ("F_y_mean", d["F_y_mean"], "N", f"{d['F_y_mean']:.4f} N normal force, mean"),
        ("F_y_std", d["F_y_std"], "N", f"{d['F_y_std']:.4f} N normal force, standard deviation"),
        ("F_y_max", d["F_y_max"], "N", f"{d['F_y_max']:.4f} N normal force, largest"),
        ("F_x_rms", d["F_x_rms"], "N", f"{d['F_x_rms']:.4f} N RMS"),
        ("out_of_contact", d["out_of_contact"], "1", f"{100 * d['out_of_contact']:.2f} % of ticks"),
        ("at_force_limit", d["at_force_limit"], "1", f"{100 * d['at_force_limit']:.2f} % of ticks"),
    ]


def _describe(model):
    if isinstance(model, VirtualCoupling):
        return (
            f"{_describe(model.model)}, through a virtual coupling Kc "
            f"{format_unit(model.coupling_stiffness, 'stiffness')}, Bc {format_unit(model.coupling_damping, 'damping')}"
        )
    if isinstance(model, GradientField):
        return f"lateral gradient field F = -N·∇h, N {format_unit(model.load, 'force')}"
    if isinstance(model, DynamicStylus):
        return (
            f"dynamic stylus: K {format_unit(model.stiffness, 'stiffness')}, M {format_unit(model.mass, 'mass')} "
            f"({model.mass * 1e-3:.3g} N·s²/mm), C {format_unit(model.damping, 'damping')}"
        )
    return f"quasi-static: K {format_unit(model.stiffness, 'stiffness')}, M and C negligible"
