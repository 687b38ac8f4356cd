"""rough render: feel a profile through a force-feedback joystick, or a simulated hand."""

import click

from .options import CROP, LENGTH, SPACING, TIP, QuantityType, input_options, report_format
from .report import emit

FORCE, STIFFNESS, DAMPING = QuantityType("force", "N"), QuantityType("stiffness", "N/mm"), QuantityType("damping", "N*s/m")
MASS, SPEED, TIME, RATE = QuantityType("mass", "g"), QuantityType("speed", "mm/s"), QuantityType("time", "s"), QuantityType("rate", "Hz")


@click.command(short_help="The haptic contact loop on a USB force-feedback joystick or a simulated hand.")
@input_options(most=2)
@click.option("--device", default="sim", show_default=True, metavar="sim|hid[:VID:PID]",
              help="sim: a simulated hand; hid: the first HID PID force-feedback joystick (or the one with these hex IDs).")
@click.option("--speed", "speeds", type=SPEED, multiple=True, metavar="SPEED",
              help="sim: stroke speed (default 20mm/s; repeat for several runs, e.g. --speed 20mm/s --speed 120mm/s).")
@click.option("--duration", type=TIME, help="Run length (default: sim one pass over the window; hid until Ctrl-C).")
@click.option("--rate", type=RATE, default="1kHz", show_default=True, help="Servo rate.")
@click.option("--model", type=click.Choice(["quasi-static", "dynamic"]), default="quasi-static", show_default=True,
              help="quasi-static: F = K·penetration (M, C negligible); dynamic: the stylus with mass and damping.")
@click.option("--stiffness", type=STIFFNESS, default="1.28N/mm", show_default=True, help="Contact stiffness K.")
@click.option("--mass", type=MASS, default="1.85g", show_default=True,
              help="dynamic: stylus mass M (the slides' 1.85e-6 in N·s²/mm = 1.85 g; they print 1.85e-6 g, MATH §5.3).")
@click.option("--damping", type=DAMPING, default="4.6e-5N*s/mm", show_default=True, help="dynamic: stylus damping C.")
@click.option("--friction", metavar="MODEL[:k=v,...]",
              help="coulomb:level=0.3N,viscous=2N*s/m | karnopp:static=0.8N,coulomb=0.5N,band=2mm/s,stiffness=1N/mm | "
                   "dahl:stiffness=1N/mm,coulomb=0.5N (default none).")
@click.option("--max-force", type=FORCE, default="8.9N", show_default=True, help="Device maximum; the force vector is scaled to it.")
@click.option("--press", type=FORCE, default="1N", show_default=True, help="sim: the hand's downward push.")
@click.option("--hand-mass", type=MASS, default="150g", show_default=True, help="sim: the hand's mass.")
@click.option("--hand-damping", type=DAMPING, default="2N*s/m", show_default=True, help="sim: the hand's damping.")
@click.option("--hand-stiffness", type=STIFFNESS,
              help="sim: lateral stiffness holding the hand to its stroke (default rigid: it strokes at exactly --speed).")
@click.option("--row", type=LENGTH, help="Maps: render the row at this y position (default the middle row).")
@click.option("--crop", "window", type=CROP, help="The profile window X0:X1 to render (lengths; positions include the origin).")
@click.option("--fill", is_flag=True, help="Fill invalid points first (linear interpolation).")
@click.option("--tip", type=TIP,
              help="Render what a round probe of this radius traces instead of the raw profile: a radius, or the "
                   "presets needle (0.05 mm, a hypodermic needle), fingernail (0.5 mm), fingertip (8 mm).")
@click.option("--stick-span", type=SPACING, metavar="X,Y",
              help="hid: lengths the stick's full x and y travel cover (default: the window, and 4× the profile's height range).")
@click.option("--invert", type=click.Choice(["x", "y"]), multiple=True, help="hid: reverse an axis (position and force).")
@click.option("--ramp", type=TIME, help="Ramp the force in over this time at the start (default: hid 0.5 s, sim none).")
@click.option("--realtime", is_flag=True, help="sim: pace the loop in real time (as a joystick is) instead of running flat out.")
@click.option("--velocity-filter", type=RATE, default="100Hz", show_default=True, help="Cut-off of the velocity estimate's low-pass filter.")
@click.option("--watchdog", type=TIME, default="50ms", show_default=True, help="hid: zero the force if the loop stalls this long.")
@click.option("--priority", type=click.IntRange(0, 99), default=50, show_default=True,
              help="Real-time loops: run at SCHED_FIFO priority N where permitted (0: normal scheduling).")
@click.option("--trace", metavar="FILE", help="Write one row per tick (t x y_i h F_x F_y contact; .tsv or .npy); {speed} in the name for several speeds.")
@click.option("--plot", metavar="FILE", help="Draw the force profiles.")
@report_format
def render(surfaces, inputs, device, speeds, duration, rate, model, stiffness, mass, damping, friction, max_force, press,
           hand_mass, hand_damping, hand_stiffness, row, window, fill, tip, stick_span, invert, ramp, realtime,
           velocity_filter, watchdog, priority, trace, plot, as_json, as_tsv):
    """Run the haptic contact loop on the profile INPUT (default: standard input): a
    virtual stylus rides the profile and the contact force (F_y = K·penetration,
    F_x = -F_y·h', resisting the climb) goes to the device, once per servo period,
    paced by a deadline clock. A second INPUT is a second surface: the joystick's
    trigger switches between them. The run ends after --duration or on Ctrl-C; the force
    is zeroed however it ends. Prints the loop's timing (achieved rate, period jitter,
    missed deadlines) and the force statistics.

    \b
    Examples:
        rough synth --length 80mm --dimension 1.275 --rq 0.2781mm | rough resample --spacing 0.1545mm \\
            | rough render --speed 20mm/s --speed 60mm/s --speed 120mm/s --trace forces-{speed}.tsv --plot forces.png
        rough render --model dynamic --friction karnopp:static=0.8N,coulomb=0.5N rock.x3p
        rough render --device hid --stick-span 80mm,10mm rough.x3p smooth.x3p
        rough render --tip fingertip --speed 60mm/s fossil.x3p
    """
    from ..errors import InputError
    from ..render import Settings, Track
    from ..render.friction import parse_friction
    from ..render.session import make_model, run_hid, run_sim, summary_rows

    if device != "sim" and not device.startswith("hid"):
        raise click.BadParameter(f"{device!r}: use sim, hid or hid:VID:PID", param_hint="--device")
    several = len(speeds) > 1
    if trace and several and "{speed}" not in trace:
        raise click.BadParameter("with several speeds, put {speed} in the trace file name", param_hint="--trace")
    tracks = []
    for surface in surfaces:
        if window is not None:
            surface = surface.crop(window[0], window[1] if not surface.is_profile else None)
        if fill:
            from ..fractal.resample import filled

            surface = surface.derive("fill", {}, heights=filled(surface))
        if tip is not None:
            from ..metrology.tip import traced

            surface = traced(surface, tip)
        tracks.append(Track.from_surface(surface, row=row))
    if duration is not None and duration <= 0:
        raise InputError("--duration must be positive")
    settings = Settings(rate=rate, duration=duration, max_force=max_force, velocity_cutoff=velocity_filter,
                        watchdog=watchdog, priority=priority, ramp=ramp if ramp is not None else (0.5 if device != "sim" else 0.0),
                        realtime=realtime or device != "sim")
    contact = make_model(model, stiffness, mass, damping, 1.0 / rate)
    friction_model = parse_friction(friction)
    if device == "sim":
        runs = run_sim(tracks[0], speeds or (0.02,), contact, friction_model, settings,
                       press=press, hand_mass=hand_mass, hand_damping=hand_damping, lateral_stiffness=hand_stiffness)
    else:
        runs = [run_hid(device, tracks, contact, friction_model, settings, stick_span, invert)]
    _outputs(runs, trace, plot)
    rows, document = summary_rows(runs, model, contact, friction)
    emit(rows, document, as_json, as_tsv)


def _outputs(runs, trace, plot):
    from ..render import write_trace

    if trace:
        for label, result in runs:
            write_trace(result, trace.replace("{speed}", label))
    if plot:
        from .. import plots

        plots.save(plots.force_figure(runs), plot)
