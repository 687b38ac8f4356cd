"""rough render: feel a profile or a map through a force-feedback joystick, or a simulated hand."""

import functools
import math

import click

from .. import fractal, metrology
from .. import plot as figures
from .. import render as haptic
from .haptics import DAMPING, FORCE, MASS, SPEED, STIFFNESS, TIME, haptic_options
from .options import POSITION, TIP, TRACE, FloatRange, crop_option, input_options, plot_option, report_format, side_file
from .report import Report, on_stdout, shown


@click.command(short_help="The haptic contact loop on a force-feedback joystick or a simulated hand.")
@input_options(together=2)
@haptic_options
@click.option(
    "--speed",
    "speeds",
    type=SPEED,
    multiple=True,
    metavar="SPEED",
    help="sim: stroke speed (default 20mm/s, slow enough to feel each feature; experiment run strokes at "
    "60mm/s; repeat for several runs, e.g. --speed 20mm/s --speed 120mm/s).",
)
@click.option(
    "--duration", type=TIME, help="Run length (default: sim one pass over the window; joysticks until Ctrl-C)."
)
@click.option(
    "--press",
    type=FORCE,
    default="1N",
    show_default=True,
    help="sim: the hand's downward push; maps: the normal load N of the lateral force -N·∇h (every device).",
)
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
@click.option(
    "--direction",
    type=FloatRange(-360, 360),
    default=0.0,
    show_default=True,
    metavar="DEGREES",
    help="sim on maps: stroke along this direction (degrees from +x), through the map's centre.",
)
@click.option(
    "--turn",
    type=TIME,
    default="0.2s",
    show_default=True,
    help="sim: the time the hand takes to reverse, when --duration is longer than one pass (back-and-forth strokes).",
)
@click.option("--row", type=POSITION, help="Maps: render only the row at this y position, as a profile.")
@crop_option
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
    callback=side_file(TRACE),
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
    direction,
    turn,
    row,
    fill,
    tip,
    trace,
    plot,
):
    """Run the haptic contact loop on the profile or map INPUT (default: standard
    input), once per servo period, paced by a deadline clock. On a profile a virtual
    stylus rides it: the stick's x moves along the profile, its y presses into it, and
    the contact force (F_y = K·penetration, F_x = -F_y·h', resisting the climb) goes to
    the device. On a map the stick's x and y move a point over the map, which pushes
    the hand down the local slope with F = -N·∇h (Minsky's lateral-gradient texture, N
    the --press), so a 2-axis joystick feels the whole map, its lay and anisotropy.
    A second INPUT is a second surface: the trigger switches between them. The run
    ends after --duration or on Ctrl-C; the force is zeroed however it ends. Prints
    the loop's timing (achieved rate, period jitter, missed deadlines) and the force
    statistics; warns when --stiffness exceeds the device's passivity bound.

    \b
    Examples:
        rough synth --length 80mm --dimension 1.275 --rq 0.2781mm | rough resample --step 0.1545mm -o rock.x3p
        rough render --speed 20mm/s --speed 60mm/s --speed 120mm/s --trace forces-{speed}.tsv --plot forces.png rock.x3p
        rough render --model dynamic --friction karnopp:static=0.8N,coulomb=0.5N rock.x3p
        rough render --device hid --stick-span 80mm,10mm rough.x3p smooth.x3p
        rough render --device evdev:/dev/input/event5 --stick-span 20mm,20mm bedding-plane.x3p
        rough render --duration 60s --direction 90 --trace across.tsv lay.x3p
        rough render --tip fingertip --speed 60mm/s fossil.x3p
    """
    report = not on_stdout(trace=trace, plot=plot)
    if trace == "-" and len(speeds) > 1:
        raise click.BadParameter("with several speeds, the traces need file names with {speed}", param_hint="--trace")
    if trace and len(speeds) > 1 and "{speed}" not in trace:
        raise click.BadParameter("with several speeds, put {speed} in the trace file name", param_hint="--trace")
    tracks = [_track(surface, fill, tip, row) for surface in surfaces]
    if len({type(track) for track in tracks}) > 1:
        raise click.BadParameter("the two surfaces must both be profiles or both maps (or give --row)")
    settings = haptics.settings(duration, realtime)
    on_map = isinstance(tracks[0], haptic.MapTrack)
    contact = haptics.field(press) if on_map else haptics.contact()
    friction = haptics.friction_model()
    if haptics.simulated:
        if not on_map:
            haptics.warn_if_unstable(hand_damping)
        hand = dict(hand_mass=hand_mass, hand_damping=hand_damping, lateral_stiffness=hand_stiffness, turn=turn)
        if on_map:
            hand["direction"] = math.radians(direction)
        else:
            hand["press"] = press
        runs = haptic.run_sim(tracks[0], speeds or (0.02,), contact, friction, settings, **hand)
    else:
        runs = [
            haptic.run_stick(
                haptics.device,
                tracks,
                functools.partial(haptics.device_model, contact, press),
                friction,
                settings,
                haptics.stick_span,
                haptics.invert,
            )
        ]
    _outputs(runs, trace, plot, shown(inputs[0]))
    return Report(*haptic.summary_rows(runs, haptics.friction)) if report else None


def _track(surface, fill, tip, row):
    """The Track (a profile, or a map's row) or MapTrack that ``surface`` (cropped as it
    was read, ``--crop``) is rendered as."""
    if fill:
        surface = fractal.fill_invalid(surface)
    if tip is not None:
        surface = metrology.traced(surface, tip)
    if surface.is_profile or row is not None:
        return haptic.Track.from_surface(surface, row=row)
    return haptic.MapTrack.from_surface(surface)


def _outputs(runs, trace, plot, title):
    if trace:
        for label, result in runs:
            haptic.write_trace(result, trace.replace("{speed}", label))
    if plot:
        figures.save(figures.force_figure(runs, title=title), plot)
