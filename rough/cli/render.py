"""rough render: feel a profile through a force-feedback joystick, or a simulated hand."""

import click

from .haptics import DAMPING, FORCE, MASS, SPEED, STIFFNESS, TIME, haptic_options
from .options import CROP, POSITION, TIP, input_options, plot_option, report_format
from .report import Report, on_stdout, shown


@click.command(short_help="The haptic contact loop on a USB force-feedback joystick or a simulated hand.")
@input_options(together=2)
@haptic_options
@click.option(
    "--speed",
    "speeds",
    type=SPEED,
    multiple=True,
    metavar="SPEED",
    help="sim: stroke speed (default 20mm/s, slow enough to feel each feature; experiment run strokes at "
    "60mm/s; repeat for several runs, e.g. --speed 20mm/s --speed 120mm/s). A bare number is in mm/s.",
)
@click.option("--duration", type=TIME, help="Run length (default: sim one pass over the window; hid until Ctrl-C).")
@click.option("--press", type=FORCE, default="1N", show_default=True, help="sim: the hand's downward push.")
@click.option("--hand-mass", type=MASS, default="150g", show_default=True, help="sim: the hand's mass.")
@click.option("--hand-damping", type=DAMPING, default="2N*s/m", show_default=True, help="sim: the hand's damping.")
@click.option(
    "--hand-stiffness",
    type=STIFFNESS,
    help="sim: lateral stiffness holding the hand to its stroke (default rigid: it strokes at exactly --speed).",
)
@click.option(
    "--realtime", is_flag=True, help="sim: pace the loop in real time (as a joystick is) instead of running flat out."
)
@click.option("--row", type=POSITION, help="Maps: render the row at this y position (default the middle row).")
@click.option(
    "--crop", "window", type=CROP, help="The profile window X0:X1 to render (lengths; positions include the origin)."
)
@click.option("--fill", is_flag=True, help="Fill invalid points first (linear interpolation).")
@click.option(
    "--tip",
    type=TIP,
    help="Render what a round probe of this radius traces instead of the raw profile: a radius, or the "
    "presets needle (0.05 mm, a hypodermic needle), fingernail (0.5 mm), fingertip (8 mm).",
)
@click.option(
    "--trace",
    metavar="FILE",
    help="Write one row per tick (t x y_i h F_x F_y contact; .tsv or .npy); {speed} in the name for several speeds.",
)
@plot_option("Draw the force profiles.")
@report_format
def render(
    surfaces,
    inputs,
    haptics,
    speeds,
    duration,
    press,
    hand_mass,
    hand_damping,
    hand_stiffness,
    realtime,
    row,
    window,
    fill,
    tip,
    trace,
    plot,
):
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
    from ..render import Track
    from ..render.session import run_hid, run_sim, summary_rows

    report = not on_stdout(trace=trace, plot=plot)
    if trace == "-" and len(speeds) > 1:
        raise click.BadParameter("with several speeds, the traces need file names with {speed}", param_hint="--trace")
    if trace and len(speeds) > 1 and "{speed}" not in trace:
        raise click.BadParameter("with several speeds, put {speed} in the trace file name", param_hint="--trace")
    tracks = []
    for surface in surfaces:
        if window is not None:
            surface = surface.crop(window[0], window[1] if not surface.is_profile else None)
        if fill:
            from ..fractal.resample import fill_invalid

            surface = fill_invalid(surface)
        if tip is not None:
            from ..metrology.tip import traced

            surface = traced(surface, tip)
        tracks.append(Track.from_surface(surface, row=row))
    settings = haptics.settings(duration, realtime)
    contact, friction = haptics.contact(), haptics.friction_model()
    if haptics.simulated:
        runs = run_sim(
            tracks[0],
            speeds or (0.02,),
            contact,
            friction,
            settings,
            press=press,
            hand_mass=hand_mass,
            hand_damping=hand_damping,
            lateral_stiffness=hand_stiffness,
        )
    else:
        runs = [run_hid(haptics.device, tracks, contact, friction, settings, haptics.stick_span, haptics.invert)]
    _outputs(runs, trace, plot, shown(inputs[0]))
    return Report(*summary_rows(runs, haptics.model, contact, haptics.friction)) if report else None


def _outputs(runs, trace, plot, title):
    from ..render import write_trace

    if trace:
        for label, result in runs:
            write_trace(result, trace.replace("{speed}", label))
    if plot:
        from .. import plots

        plots.save(plots.force_figure(runs, title=title), plot)
