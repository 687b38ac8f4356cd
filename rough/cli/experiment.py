"""rough experiment: paired-comparison roughness perception, from design to analysis."""

import logging
import math
import secrets

import click

from .. import experiment as experiments
from .. import extras, io, render
from .. import plot as figures
from ..errors import InputError
from ..units import format_length, parse_length
from .haptics import SPEED, TIME, haptic_options
from .options import LENGTH, LENGTHS, Command, FloatRange, bare_number, plot_option, report_format
from .report import Report, collected_warnings, emit


@click.group(short_help="Paired-comparison roughness experiments: design, run sessions, analyze.")
def experiment():
    """Run a two-alternative forced-choice study of roughness perception, as Costa and
    Cutkosky did: design it (surfaces on a (D, Rq) grid around references, a randomised
    trial list per subject), run each subject's session on the joystick (or headless,
    with the simulated hand and a scripted observer), and analyze the answers by
    logistic regression with Wald tests.

    \b
    Examples:
        rough experiment design --preset costa2000 study
        rough experiment run study --subject S01 --device hid
        rough experiment run study --subject S02 --observer rq=12,dimension=-4,spread=0.5
        rough experiment analyze study --set 1 --plot figure4.png
    """


@experiment.command(cls=Command, short_help="Write a study folder: surfaces with recorded seeds and the trial list.")
@click.argument("study", metavar="STUDY")
@click.option(
    "--preset",
    type=click.Choice(["costa2000"]),
    help="The paper's design (its references, grid, length, resolution, 14 subjects).",
)
@click.option(
    "--reference",
    "references",
    multiple=True,
    metavar="D,RQ",
    help="A reference surface, e.g. 1.275,0.2781mm (repeat for several sets).",
)
@click.option("--dimension-step", type=FloatRange(0, 0.5, min_open=True), help="Neighbours' D offset (default 0.075).")
@click.option(
    "--rq-factor",
    type=FloatRange(1, 10, min_open=True),
    help="Neighbours' Rq ratio (default 0.3502/0.2781 = 1.2593).",
)
@click.option(
    "--subjects", help="A number of subjects (named S01, S02, …) or their names, comma-separated (default 14)."
)
@click.option("--length", type=LENGTH, help="Profile length (default 80 mm).")
@click.option("--step", type=LENGTH, help="Spacing of the surfaces stored and rendered (default 0.1545 mm).")
@click.option("--synthesis-step", type=LENGTH, help="Spacing the surfaces are synthesised at (default 0.0309 mm).")
@click.option(
    "--seed", type=click.IntRange(0), help="Seed of the surfaces and the randomisation (default: drawn and recorded)."
)
@report_format
def design(
    study,
    preset,
    references,
    dimension_step,
    rq_factor,
    subjects,
    length,
    step,
    synthesis_step,
    seed,
    as_json,
    as_tsv,
):
    """Write the study folder STUDY (it must not exist, or be empty): the surfaces,
    synthesised whole-length with recorded seeds, and trials.csv, each subject's pairs
    (every reference against each of its eight (D, Rq) neighbours) in random order with
    a random side. --preset costa2000 is the paper's design.
    """
    defaults = experiments.COSTA2000
    if not references and preset is None:
        raise InputError("give --preset costa2000 or at least one --reference D,RQ")
    chosen = [_reference(text) for text in references] or defaults["references"]
    seed = secrets.randbits(32) if seed is None else seed
    surfaces, sets = experiments.grid_design(
        chosen, dimension_step or defaults["dimension_step"], rq_factor or defaults["rq_factor"]
    )
    length = length or defaults["length"]
    steps = {"--synthesis-step": synthesis_step or defaults["synthesis_spacing"], "--step": step or defaults["spacing"]}
    for flag, spacing in steps.items():
        if round(length / spacing) < 2:
            raise InputError(
                f"--length {format_length(length)} holds fewer than two samples at {flag} {format_length(spacing)}"
            )
    result = experiments.write_study(
        study,
        surfaces,
        sets,
        experiments.subject_ids(subjects or defaults["subjects"]),
        seed,
        length,
        steps["--synthesis-step"],
        steps["--step"],
        preset,
    )
    rows = [
        ("study", str(result.folder), "", str(result.folder)),
        (
            "sets",
            len(result.sets),
            "1",
            "; ".join(
                f"set {s['id']}: reference D = {result.surfaces[s['reference']]['dimension']:g}, "
                f"Rq = {format_length(result.surfaces[s['reference']]['rq'], 4)}, {len(s['neighbours'])} neighbours"
                for s in result.sets
            ),
        ),
        ("surfaces", len(result.surfaces), "1", f"{len(result.surfaces)} profiles in {result.folder / 'surfaces'}"),
        ("subjects", result.subjects, "", f"{len(result.subjects)}: {', '.join(result.subjects)}"),
        (
            "trials",
            len(result.trials),
            "1",
            f"{len(result.trials)} ({len(result.trials) // len(result.subjects)} per subject)",
        ),
        ("seed", seed, "", str(seed)),
    ]
    emit(Report(rows, {key: value for key, value, _, _ in rows}), as_json, as_tsv, study)


def _reference(text):
    parts = text.split(",")
    if len(parts) != 2:
        raise InputError(f"--reference {text!r}: write D,RQ, e.g. 1.275,0.2781mm")
    try:
        dimension = float(parts[0])
    except ValueError:
        raise InputError(f"--reference {text!r}: {parts[0]!r} is not a fractal dimension") from None
    if not 1 < dimension < 2:
        raise InputError(f"--reference {text!r}: a profile's D lies between 1 and 2")
    bare_number(parts[1], "--reference", "mm")
    rq = parse_length(parts[1])
    if not LENGTHS[0] <= rq <= LENGTHS[1]:
        raise InputError(f"--reference {text!r}: Rq must lie between 1 pm and 10000 km")
    return dimension, rq


@experiment.command(short_help="Run (or resume) a subject's session.")
@click.argument("study", metavar="STUDY")
@click.option("--subject", required=True, help="The subject's ID, as in the study (e.g. S01).")
@haptic_options
@click.option(
    "--observer",
    metavar="rq=S1,dimension=S2[,spread=S][,bias=B][,seed=N]",
    help="sim: the scripted observer's logistic slopes per mm of Rq and per unit of D, the SD of its "
    "per-subject intercepts, a bias and a seed.",
)
@click.option(
    "--speed",
    type=SPEED,
    default="60mm/s",
    show_default=True,
    help="sim: the hand's stroke speed (faster than render's 20mm/s: a 1 s stroke must cross a 80 mm surface).",
)
@click.option(
    "--stroke", type=TIME, default="1s", show_default=True, help="sim: how long the hand strokes each surface."
)
@click.option("--realtime", is_flag=True, help="sim: stroke in real time instead of as fast as the machine allows.")
def run(study, subject, haptics, observer, speed, stroke, realtime):
    """Present the unanswered trials of --subject in STUDY, in the study's order, and
    save each answer at once to STUDY/answers/SUBJECT.csv (rewritten atomically after
    every trial): an interrupted session resumes where it stopped. On the joystick the
    trigger toggles between the two surfaces and button 2 (or key 1) answers "the first
    is rougher", button 3 (or key 2) "the second". Ctrl-C pauses the session. With
    --device sim, --observer answers.
    """
    if not experiments.is_name(subject):
        raise InputError(f"--subject {subject!r}: not a name (letters, digits, - and _ only)")
    loaded = experiments.load_study(study)
    loaded.trials_of(subject)
    contact, friction = haptics.contact(), haptics.friction_model()
    if haptics.simulated:
        if observer is None:
            raise InputError("the simulated hand needs a scripted --observer (e.g. --observer rq=12,dimension=-4)")
        haptics.warn_if_unstable(render.HAND_DAMPING)
        present = experiments.simulated_presenter(
            loaded, experiments.parse_observer(observer), speed, contact, friction, haptics.settings(stroke, realtime)
        )
        progress = experiments.run_session(loaded, subject, present, "sim")
    else:
        progress = _joystick_session(loaded, subject, haptics, contact, friction)
    if progress.interrupted:
        click.echo(
            f"{subject}: paused after {progress.answered} of {progress.total} trials; run the same command to resume",
            err=True,
        )
    click.echo(f"{subject}: {progress.answered} of {progress.total} trials answered, {progress.remaining} to go")


def _joystick_session(study, subject, haptics, contact, friction):
    tracks = {name: render.Track.from_surface(io.read(study.surface_path(name))) for name in study.surfaces}
    joystick, _ = render.open_joystick(
        haptics.device, list(tracks.values()), haptics.max_force, haptics.stick_span, haptics.invert
    )
    model = haptics.device_model(contact, render.PRESS, joystick)
    keyboard = experiments.Keyboard()
    try:
        present = experiments.joystick_presenter(tracks, joystick, model, friction, haptics.settings(), keyboard)
        return experiments.run_session(study, subject, present, joystick.label)
    finally:
        keyboard.close()
        joystick.close()


@experiment.command(short_help="Logistic regression of the answers, Wald and likelihood-ratio tests.")
@click.argument("study", metavar="STUDY")
@click.option(
    "--set", "set_id", type=int, help="Analyze one reference set (the paper's Tables 1 and 2 are sets 1 and 2)."
)
@plot_option("Draw the percentage of answers judging each test rougher (the paper's Figures 4-5).")
@report_format
def analyze(study, set_id, plot, as_json, as_tsv):
    """Fit logit P(test judged rougher) = β0 + β_D ΔD + β_Rq ΔRq + Σ γ_s S_s to the
    answers in STUDY (ΔD, ΔRq: test minus reference, Rq in mm; one indicator per subject
    but the first) and print each coefficient with its standard error, Wald statistic
    W = β/SE and p = 2(1 − Φ(abs(W))), as the paper's Tables 1-2 do, with likelihood-ratio
    tests for D and Rq. Warns under (quasi-)separation, where Wald tests mislead.
    """
    extras.require("statsmodels")
    with collected_warnings() as warnings:
        loaded = experiments.load_study(study)
        result = experiments.fit(experiments.answers_table(loaded, set_id), loaded.subjects)
        _warn_separation(result)
    if plot:
        sets = [set_id] if set_id else [s["id"] for s in loaded.sets]
        figures.save(figures.percentage_figure(loaded, sets, title=str(study)), plot)
    emit(Report(_table(loaded, result, set_id), result.as_dict()), as_json, as_tsv, study, warnings)


def _warn_separation(result):
    if result.separation:
        logging.getLogger("rough").warning(
            "(quasi-)separation: some answers are predicted with certainty (e.g. a subject who always chose the same "
            "way), so those Wald statistics are unreliable (Hauck-Donner effect); trust the likelihood-ratio tests"
        )


LABELS = {"fractal_dimension": "fractal dimension D", "rq": "Rq (per mm)", "constant": "constant"}


def _table(study, result, set_id):
    rows = [(None, None, "", f"{'coefficient':>12} {'std. error':>11} {'Wald W':>10} {'p':>11}", "variable")]
    for name, c in result.coefficients.items():
        rows.append(
            (
                f"coefficients.{name}",
                c,
                {"estimate": c["unit"], "stderr": c["unit"], "wald": "1", "p": "1"},
                f"{c['estimate']:12.5g} {c['stderr']:11.5g} {c['wald']:10.5g} {_p(c['p']):>11}",
                LABELS.get(name, name.replace("subject_", "subject ")),
            )
        )
    chosen = [s for s in study.sets if set_id in (None, s["id"])]
    scope = "; ".join(
        f"set {s['id']} (reference D = {study.surfaces[s['reference']]['dimension']:g}, "
        f"Rq = {format_length(study.surfaces[s['reference']]['rq'], 4)})"
        for s in chosen
    )
    ratio = result.likelihood_ratio
    rows += [
        (
            "n",
            result.n,
            "1",
            f"{result.n} from {len(result.subjects)} subjects; {scope}; baseline subject {result.subjects[0]}",
            "answers",
        ),
        (
            "likelihood_ratio",
            ratio,
            "1",
            (
                f"D: χ²(1) = {ratio['fractal_dimension']['statistic']:.4g}, p = "
                f"{_p(ratio['fractal_dimension']['p'])};  "
                f"Rq: χ²(1) = {ratio['rq']['statistic']:.4g}, p = {_p(ratio['rq']['p'])}"
            ),
            "likelihood ratio",
        ),
        (
            "log_likelihood",
            result.log_likelihood,
            "1",
            f"{result.log_likelihood:.4f}" + ("" if result.converged else " (not converged)"),
            "log-likelihood",
        ),
    ]
    return rows


def _p(value):
    if value is None or not math.isfinite(value):
        return "n/a"
    return f"{value:.4f}" if value >= 1e-3 else f"{value:.4g}"
