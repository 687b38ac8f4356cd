"""Every list the command line shows is read from its registry (issue 33): the
choices of options, the devices of --device, the formats convert writes, the
commands of rough --help; and the rules for option names and bare numbers."""

import json

import click
import numpy
import pytest

from rough import metrology, render
from rough import sample as rough_sample
from rough.cli import options
from rough.cli.convert import convert
from rough.cli.haptics import DeviceOption
from rough.cli.main import COMMANDS, cli
from rough.io import registry

from conftest import assert_one_line_error
from conftest import rough as run


def rough(*args, **kwargs):
    """``rough ARGS`` at a fixed time, so that two runs write the same history."""
    return run(*args, env={"SOURCE_DATE_EPOCH": "1700000000"}, **kwargs)


def every_option():
    """(command path, option) for every option of every built-in command."""
    found = []
    for name in COMMANDS:
        command = cli.get_command(None, name)
        subcommands = getattr(command, "commands", {"": command})
        for sub, each in subcommands.items():
            found += [(f"{name} {sub}".strip(), param) for param in each.params]
    return found


REGISTERED = [(where, param) for where, param in every_option() if isinstance(param.type, options.RegistryChoice)]


@pytest.mark.parametrize("where, param", REGISTERED, ids=[f"{w} {p.opts[-1]}" for w, p in REGISTERED])
def test_a_registry_choice_reads_its_registry(where, param):
    choices = param.type.choices
    assert choices and all(isinstance(choice, str) for choice in choices)
    assert not isinstance(param.default, str) or param.default in choices


def test_the_tip_presets_are_the_librarys():
    assert options.TIP_PRESETS == tuple(metrology.PRESETS)


def test_device_help_names_every_backend():
    param = next(param for _, param in every_option() if isinstance(param, DeviceOption))
    for name, backend in render.backends().items():
        assert backend.form in param.metavar and f"{name}: {backend.title}" in param.help


def test_convert_help_names_every_writable_format():
    for name in registry.writable():
        assert registry.formats()[name].title in convert.epilog


def test_no_option_is_hidden_and_each_new_name_has_one_meaning():
    """rough 0.14 removed the hidden aliases that 0.12 kept for the renamed options."""
    names = {}
    for where, param in every_option():
        assert not getattr(param, "hidden", False), (where, param.opts)
        for flag in param.opts:
            names.setdefault(flag, set()).add(param.name)
    assert names["--step"] == {"step"} and names["--rolloff-wavelength"] == {"rolloff_wavelength"}
    assert names["--angle-step"] == {"angle_step"} and names["--spacing"] == {"spacing"}


def command_of(where):
    """The click command ``where`` ("synth", "experiment design") names."""
    command = cli
    for name in where.split():
        command = command.get_command(None, name)
    return command


@pytest.mark.parametrize("where, old", list(options.RENAMED), ids=" ".join)
def test_an_old_option_name_is_refused_in_one_line_that_names_the_new_one(where, old, tmp_path):
    new, release = options.RENAMED[where, old]
    command = command_of(where)
    assert isinstance(command, options.Command)
    flags = {flag for param in command.params for flag in param.opts}
    assert old not in flags and new in flags
    out = tmp_path / "out.x3p"
    result = rough(*where.split(), old, "1mm", "-o" if where != "show" else "--plot", out, input=b"")
    assert_one_line_error(result, f"{old} was renamed {new} in rough {release}")
    assert not out.exists()


def test_an_unknown_option_is_still_clicks_usage_error():
    assert_one_line_error(rough("synth", "--spacing-typo", "1mm"), "No such option '--spacing-typo'")
    assert_one_line_error(rough("detrend", "--input-spacing", "1mm", input=b""), "No such option")


def test_resample_takes_the_input_spacing_as_spacing_like_every_command(tmp_path):
    heights = tmp_path / "column.npy"
    numpy.save(heights, numpy.sin(numpy.arange(400) / 7.0) * 1e-6)
    result = rough("resample", "--spacing", "1um", "--step", "2um", "-f", "tsv", heights, check=True)
    coarse = json.loads(rough("info", "--json", input=result.stdout, check=True).stdout)
    assert coarse["spacing"] == pytest.approx([2e-6]) and coarse["shape"] == [200]
    assert_one_line_error(rough("resample", "--step", "2um", heights), "--spacing")


def test_resample_asks_for_its_step_before_it_reads_or_makes_anything(tmp_path):
    for args, stdin in ((["resample"], b""), (["resample", str(tmp_path / "absent.x3p")], None)):
        assert_one_line_error(run(*args, input=stdin), "Missing option '--step'")
    # the new spacing as 0.12 spelled it is now the input's: still no --step
    old = ["resample", "--spacing", "0.1545mm", rough_sample("rock-profile.tsv"), rough_sample("rock-map.x3p")]
    result = run(*old, "-o", tmp_path / "out/")
    assert result.returncode == 2 and "Missing option '--step'" in result.stderr.decode()
    assert not (tmp_path / "out").exists()


def profile():
    return rough("synth", "--length", "5mm", "--dimension", "1.3", "--rq", "1um", "--seed", "2", check=True).stdout


@pytest.mark.parametrize(
    "bare, named, said",
    [
        (["detrend", "--cutoff", "0.8"], ["detrend", "--cutoff", "0.8mm"], "--cutoff 0.8: give a unit, e.g. 0.8mm"),
        (["detrend", "--crop", "0.5:2"], ["detrend", "--crop", "0.5mm:2mm"], "--crop 0.5: give a unit, e.g. 0.5mm"),
        (["detrend", "--crop", "0:2"], ["detrend", "--crop", "0:2mm"], "--crop 2: give a unit, e.g. 2mm"),
        (["detrend", "--spacing", "1um,2"], ["detrend", "--spacing", "1um"], "--spacing 2: give a unit, e.g. 2mm"),
        (["info", "--regrid", "0.01"], ["info", "--regrid", "0.01mm"], "--regrid 0.01: give a unit, e.g. 0.01mm"),
        (["fit-fractal", "--band", "0.5:20/mm"], ["fit-fractal", "--band", "0.5/mm:20/mm"], "--band 0.5: give a unit"),
        (["render", "--speed", "40"], ["render", "--speed", "40mm/s"], "--speed 40: give a unit, e.g. 40mm/s"),
        (["render", "--coupling", "1,0"], ["render", "--coupling", "1N/mm,0"], "--coupling 1: give a unit, e.g. 1N/mm"),
    ],
)
def test_a_bare_number_is_refused_in_one_line_that_shows_the_unit(bare, named, said):
    surface = profile()
    refused = rough(*bare, "--json" if bare[0] in ("fit-fractal", "render", "info") else "-ftsv", input=surface)
    assert_one_line_error(refused, said)
    assert refused.stdout == b""
    unit = {"--band": "per mm", "--speed": "mm/s", "--coupling": "N/mm"}.get(bare[1], "mm")
    assert f"(bare numbers were read as {unit} until rough 0.13)" in refused.stderr.decode()
    rough(*named, "--json" if named[0] in ("fit-fractal", "render", "info") else "-ftsv", input=surface, check=True)


def test_a_bare_reference_rq_is_refused_before_the_study_is_written(tmp_path):
    study = tmp_path / "study"
    refused = rough("experiment", "design", "--reference", "1.275,0.2781", "--subjects", "1", study)
    assert_one_line_error(refused, "--reference 0.2781: give a unit, e.g. 0.2781mm (bare numbers were read as mm")
    assert not study.exists()
    rough("experiment", "design", "--reference", "1.275,0.2781mm", "--subjects", "1", "--seed", "1", study, check=True)


def test_zero_needs_no_unit():
    for text in ("0", "0.0", "-0", " 0e5 "):
        options.bare_number(text, "--height", "mm")  # not refused
    with pytest.raises(click.UsageError, match="^--height 1e-3: give a unit, e.g. 1e-3mm"):
        options.bare_number("1e-3", "--height", "mm")
    result = rough("detrend", "-f", "tsv", "--crop", "0:2mm", input=profile(), check=True)
    assert result.stderr == b""


def test_a_bare_number_is_refused_by_the_library():
    from rough.errors import InputError
    from rough.units import parse_frequency, parse_length, parse_quantity

    for parse, args in ((parse_length, ()), (parse_frequency, ()), (parse_quantity, ("force",))):
        with pytest.raises(InputError, match="names no unit|is not a force"):
            parse("0.8", *args)
        assert parse("0", *args) == 0.0


def test_a_bad_unit_is_still_one_line():
    assert_one_line_error(rough("detrend", "--cutoff", "0.8parsec", input=profile()), "unknown length unit")
