"""Issue 31: every numeric option of every command, fed the extremes (1e308, -1e308,
1e-320, 0, NaN, ±inf, and an integer of 31 digits), either works or is refused in one
line with status 2: never status 1, an internal error, a traceback, or an output with
infinite heights. The options are found by walking the command tree, so a new option
is covered as soon as it exists.

An option that takes a length, a frequency or a physical quantity is fed each extreme
twice: with its unit (``1e308mm``), which must work or be refused for its size, and
bare (``1e308``), which rough 0.14 refuses in one line that shows the unit (a bare
zero needs none).

To keep this quick, one worker process per command runs its cases in-process through
:func:`rough.cli.main.run`, each with descriptors 1 and 2 sent to files."""

import json
import os
import pathlib
import re
import subprocess
import sys

import click
import pytest

from rough.cli import haptics, options, synth
from rough.cli.main import cli

from conftest import assert_one_line_error, rough

EXTREMES = ["1e308", "-1e308", "1e-320", "0", "nan", "inf", "-inf", "1e-9", "1e9"]
HUGE_INTEGER = "1" + "0" * 30
# each composite type's values, the extreme put in each of its places (V); V[UNIT] is a
# place that takes a unit, filled both with it and bare
PLACES = {
    options.SpacingType: ["V[mm]", "V[mm],1um", "1um,V[mm]"],
    options.RegridType: ["V[mm]", "V[mm]:linear"],
    options.CropType: ["V[mm]:", ":V[mm]", "0:V[mm]", "V[mm]:1e308mm"],
    options.FrequencyRangeType: ["V[/mm]:", ":V[/mm]", "V[/mm]:1e308/mm"],
    options.RatioPairType: ["V:90", "10:V"],
    haptics.CouplingType: ["V[N/mm],0", "1N/mm,V[N*s/m]"],
    synth.AnisotropyType: [
        "V,1um,2.4,3um,30",
        "2.2,V[mm],2.4,3um,30",
        "2.2,1um,V,3um,30",
        "2.2,1um,2.4,V[mm],30",
        "2.2,1um,2.4,3um,V",
    ],
    synth.SizeType: ["Vx64", "64xV"],
}
PLACE = re.compile(r"V(?:\[([^]]*)\])?")
BARE = "give a unit, e.g."  # what a refused bare number says
NOT_NUMBERS = (click.types.StringParamType, click.Choice, click.Path, click.types.BoolParamType)
SKIPPED = {"show"}  # its own tests (tests/test_show.py)


def commands(group=cli, path=()):
    context = click.Context(group)
    for name in group.list_commands(context):
        command = group.get_command(context, name)
        if isinstance(command, click.Group):
            yield from commands(command, (*path, name))
        elif name not in SKIPPED:
            yield (*path, name), command


def numeric_options(command):
    for parameter in command.params:
        if isinstance(parameter, click.Option) and not parameter.is_flag and not parameter.count:
            if not isinstance(parameter.type, NOT_NUMBERS):
                yield parameter


def unit_of(kind):
    """The unit a single value of this type takes (None for a plain number)."""
    if isinstance(kind, options.LengthType):
        return "mm"
    return kind.default_unit if isinstance(kind, options.QuantityType) else None


def values_for(parameter):
    """``(value, bare)``: each extreme in each place, and ``bare`` when it is a
    non-zero number given without the unit its place takes."""
    unit = unit_of(parameter.type)
    single = [f"V[{unit}]" if unit else "V"]
    places = next((PLACES[kind] for kind in type(parameter.type).__mro__ if kind in PLACES), single)
    extremes = EXTREMES + ([HUGE_INTEGER] if isinstance(parameter.type, click.types.IntParamType) else [])
    values = []
    for place in places:
        for value in extremes:
            if "[" in place:  # with its unit, and bare
                values.append((PLACE.sub(lambda match, value=value: value + match.group(1), place), False))
                values.append((PLACE.sub(value, place), value not in ("0", "nan", "inf", "-inf")))
            else:
                values.append((PLACE.sub(value, place), False))
    return values


COMMANDS = dict(commands())


def test_every_numeric_type_is_one_that_refuses_nan():
    """click's FloatRange and FLOAT accept NaN (it passes every comparison): options use
    rough's FloatRange, or a type of rough.cli.options."""
    raw = [
        f"{' '.join(path)} {parameter.opts[-1]}"
        for path, command in COMMANDS.items()
        for parameter in numeric_options(command)
        if type(parameter.type) in (click.FloatRange, click.types.FloatParamType)
    ]
    assert raw == []


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("ranges")
    made = {name: folder / name for name in ("map.x3p", "profile.x3p", "study", "answered")}
    synthesis = ["--dimension", "2.3", "--rq", "1um", "--seed", "1", "--step", "2um"]
    rough("synth", "--size", "64x48", *synthesis, "-o", made["map.x3p"], check=True)
    rough("synth", "--points", "400", *synthesis[2:], "--dimension", "1.3", "-o", made["profile.x3p"], check=True)
    for study in ("study", "answered"):
        design = ["--reference", "1.275,0.2781mm", "--reference", "1.5,0.2mm", "--subjects", "2", "--seed", "1"]
        rough("experiment", "design", *design, made[study], check=True)
    for subject in ("S01", "S02"):
        rough("experiment", "run", made["answered"], "--subject", subject, "--observer", OBSERVER, check=True)
    return {name.removesuffix(".x3p"): str(path) for name, path in made.items()}


OBSERVER = "rq=12,dimension=-4"
# the arguments each command needs besides the option under test; {map}, {profile},
# {study} (a fresh copy), {out} and {folder} (new) are filled in by the worker
BASES = {
    ("convert",): ["{map}", "-o", "{out}"],
    ("detrend",): ["{map}", "-o", "{out}"],
    ("features",): ["{map}", "--json"],
    ("fit-fractal",): ["{map}", "--json"],
    ("info",): ["{map}", "--json"],
    ("resample",): ["{map}", "--step", "4um", "-o", "{out}"],
    ("rose",): ["{map}", "--json"],
    ("map",): ["{map}", "--window", "16px", "--parameters", "Sq,hurst", "--json"],
    ("render",): ["{map}", "--duration", "20ms", "--json"],
    ("report",): ["{profile}", "-o", "-"],
    ("synth",): ["--size", "32x32", "--step", "2um", "--dimension", "2.3", "--rq", "1um", "-o", "{out}"],
    ("experiment", "design"): ["{folder}", "--reference", "1.275,0.2781mm", "--subjects", "1", "--seed", "1"],
    ("experiment", "run"): ["{study}", "--subject", "S01", "--observer", OBSERVER, "--stroke", "0.2s"],
    ("experiment", "analyze"): ["{answered}"],
}
# the same on a profile (render's stylus, synth's profile options, features' profile parameters)
PROFILE_BASES = {
    ("render",): ["{profile}", "--duration", "20ms", "--json"],
    ("features",): ["{profile}", "--json"],
    ("detrend",): ["{profile}", "-o", "{out}"],
    ("synth",): ["--points", "256", "--dimension", "1.3", "--rq", "1um", "-o", "{out}"],
}
SYNTH_PROFILE = ["--dimension", "1.3", "--rq", "1um", "-o", "{out}"]
OWN_BASES = {  # options that change which arguments make a valid call
    ("synth", "--length"): SYNTH_PROFILE,
    ("synth", "--points"): SYNTH_PROFILE,
    ("synth", "--fragments"): ["--points", "256", *SYNTH_PROFILE],
    ("synth", "--size"): ["--step", "2um", "--dimension", "2.3", "--rq", "1um", "-o", "{out}"],
    ("synth", "--amplitude"): ["--size", "32x32", "--step", "2um", "--dimension", "2.3", "-o", "{out}"],
    ("synth", "--anisotropy"): ["--size", "32x32", "--step", "2um", "-o", "{out}"],
}


def without(base, flag):
    """``base`` without ``flag`` and its value."""
    if flag not in base:
        return base
    at = base.index(flag)
    return base[:at] + base[at + 2 :]


def cases(path, command):
    for parameter in numeric_options(command):
        flag = parameter.opts[-1]
        own = OWN_BASES.get((path[-1], flag))
        bases = [own] if own else [BASES[path], *([PROFILE_BASES[path]] if path in PROFILE_BASES else [])]
        for base in bases:
            for value, bare in values_for(parameter):
                yield [*path, *without(base, flag), flag, value], bare


WORKER = r"""
import json, os, shutil, sys, tempfile
import numpy as np
import rough
from rough.cli.main import run

places, cases, report = json.loads(sys.argv[1]), json.loads(sys.argv[2]), sys.argv[3]
with open(report, "w") as results:
    for number, case in enumerate(cases):
        work = tempfile.mkdtemp()
        named = dict(places, out=os.path.join(work, "out.x3p"), folder=os.path.join(work, "new"))
        named["study"] = shutil.copytree(places["study"], os.path.join(work, "study"))
        args = [part.format(**named) if part.startswith("{") else part for part in case]
        with open(os.path.join(work, "1"), "w+b") as out, open(os.path.join(work, "2"), "w+b") as err:
            saved = os.dup(1), os.dup(2)
            os.dup2(out.fileno(), 1), os.dup2(err.fileno(), 2)
            try:
                status = run(args)
                sys.stdout.flush(), sys.stderr.flush()
            finally:
                os.dup2(saved[0], 1), os.dup2(saved[1], 2)
            out.seek(0), err.seek(0)
            stdout, stderr = out.read(), err.read().decode(errors="replace")
        heights = None
        if status == 0 and os.path.exists(named["out"]):
            try:
                z = rough.read(named["out"]).heights
                heights = {"inf": int(np.isinf(z).sum()), "finite": int(np.isfinite(z).sum())}
            except rough.RoughError as error:
                heights = {"inf": 0, "finite": 0, "unreadable": str(error)}
        if status == 0 and "--json" in args:
            try:
                json.loads(stdout)
            except ValueError as error:
                stderr += f" [not JSON: {error}]"
        results.write(json.dumps({"case": case, "status": status, "stderr": stderr, "heights": heights}) + "\n")
        shutil.rmtree(work)
"""


@pytest.mark.parametrize("path", [p for p, c in COMMANDS.items() if any(numeric_options(c))], ids=" ".join)
def test_every_numeric_option_works_or_is_refused_in_one_line(path, inputs, tmp_path):
    todo, bare = zip(*cases(path, COMMANDS[path]))
    places = inputs
    report = tmp_path / "report.jsonl"
    subprocess.run(
        [sys.executable, "-c", WORKER, json.dumps(places), json.dumps(todo), str(report)], check=True, timeout=1800
    )
    results = [json.loads(line) for line in pathlib.Path(report).read_text().splitlines()]
    assert len(results) == len(todo)
    wrong = []
    for result, refused in zip(results, bare):
        lines = result["stderr"].splitlines()
        errors = [line for line in lines if "warning:" not in line]
        problems = []
        if result["status"] not in (0, 2):
            problems.append(f"status {result['status']}")
        if result["status"] == 2 and len(errors) != 1:
            problems.append(f"{len(errors)} error lines")
        if refused and (result["status"] != 2 or BARE not in result["stderr"]):
            problems.append("a bare number not refused as one")
        if not refused and BARE in result["stderr"]:
            problems.append("refused as a bare number")
        if any(word in result["stderr"] for word in ("internal error", "Traceback", "not JSON")):
            problems.append("internal error")
        heights = result["heights"]
        if heights is not None and (heights["inf"] or not heights["finite"]):
            problems.append(f"output heights {heights}")
        if problems:
            wrong.append(f"{' '.join(result['case'])}: {', '.join(problems)}: {result['stderr'].strip()[:300]}")
    if os.environ.get("ROUGH_RANGES_REPORT"):
        with open(os.environ["ROUGH_RANGES_REPORT"], "a") as dump:
            dump.write("".join(line + "\n" for line in wrong))
    assert not wrong, "\n".join(wrong)


def test_the_spacing_options_take_what_a_surface_takes():
    from rough.surface import SPACING_RANGE

    assert options.SPACINGS == SPACING_RANGE


@pytest.mark.parametrize(
    "args, said",
    [
        (["detrend", "--tip", "1e308m", "{map}"], "'1e308m': a tip radius must lie between 1 pm and 10000 km"),
        (["synth", "--length", "1e308m", "--dimension", "1.3", "--rq", "1um"], "'1e308m': a length must lie between"),
        (["synth", "--size", "8x8", "--step", "1e-320m", "--dimension", "2.3", "--rq", "1um"], "'1e-320m': a length"),
        (["rose", "--resolution", "1e-320m", "{map}"], "'1e-320m': a length must lie between 1 pm and 10000 km"),
        (["render", "--rate", "1e-320Hz", "{map}"], "'1e-320Hz': a rate must lie between 0.001 Hz and 100000 Hz"),
        (["render", "--mass", "1e-320g", "{map}"], "'1e-320g': a mass must lie between"),
        (["experiment", "run", "--rate", "1e-320Hz", "--subject", "S01", "{study}"], "'1e-320Hz': a rate must lie"),
        (["rose", "--level", "nan", "{map}"], "'nan' is not a finite number"),
        (["synth", "--size", "8x8", "--dimension", "2.3", "--rq", "1e308m"], "'1e308m': a length must lie between"),
    ],
)
def test_the_values_reported_in_issue_31_are_refused_in_one_line(inputs, args, said, tmp_path):
    output = ["-o", tmp_path / "out.x3p"] if args[0] in ("synth", "detrend") else []
    assert_one_line_error(rough(*(arg.format(**inputs) for arg in args), *output), said)
    assert list(tmp_path.iterdir()) == []
