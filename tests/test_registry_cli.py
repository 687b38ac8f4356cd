"""Every list the command line shows is read from its registry (issue 33): the
choices of options, the devices of --device, the formats convert writes, the
commands of rough --help; and the rules for option names and bare numbers."""

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


def test_hidden_aliases_are_hidden_and_new_names_are_unique():
    names = {}
    for where, param in every_option():
        if getattr(param, "hidden", False):
            assert param.name.startswith("deprecated_"), (where, param.opts)
        for flag in param.opts:
            names.setdefault(flag, set()).add(param.name.removeprefix("deprecated_"))
    assert names["--step"] <= {"step", "angle_step"} and names["--rolloff-wavelength"] == {"rolloff_wavelength"}


@pytest.mark.parametrize(
    "old, new",
    [
        (["synth", "--length", "1mm", "--spacing", "10um"], ["synth", "--length", "1mm", "--step", "10um"]),
        (
            ["synth", "--length", "1mm", "--rolloff", "0.2mm"],
            ["synth", "--length", "1mm", "--rolloff-wavelength", "0.2mm"],
        ),
    ],
)
def test_an_old_option_name_still_works_with_one_warning(old, new):
    common = ["--dimension", "1.3", "--rq", "1um", "--seed", "1", "-f", "tsv"]
    before, after = rough(*old, *common), rough(*new, *common, check=True)
    assert before.returncode == 0 and before.stdout == after.stdout
    assert after.stderr == b""
    (line,) = before.stderr.decode().splitlines()
    assert f"{old[3]} is deprecated (rough 0.12): use {new[3]}; it goes in 0.14" in line


def test_old_and_new_name_together_is_a_usage_error():
    result = rough("synth", "--length", "1mm", "--spacing", "10um", "--step", "10um", "--dimension", "1.3")
    assert result.returncode == 2 and "give --step, not --spacing too" in result.stderr.decode()


def test_resample_asks_for_its_step_before_it_reads_or_makes_anything(tmp_path):
    for args, stdin in ((["resample"], b""), (["resample", str(tmp_path / "absent.x3p")], None)):
        assert_one_line_error(run(*args, input=stdin), "Missing option '--step'")
    result = run("resample", rough_sample("rock-profile.tsv"), rough_sample("rock-map.x3p"), "-o", tmp_path / "out/")
    assert result.returncode == 2 and not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    "args",
    [["render", "--speed", "-1"], ["resample", "--step", "-1"], ["fit-fractal", "--band", "0:1"]],
)
def test_a_refused_bare_number_is_one_line_without_the_bare_number_warning(args):
    result = run(*args, rough_sample("rock-profile.tsv"))
    assert result.returncode == 2 and len(result.stderr.decode().splitlines()) == 1
    assert "bare number" not in result.stderr.decode()


def profile():
    return rough("synth", "--length", "5mm", "--dimension", "1.3", "--rq", "1um", "--seed", "2", check=True).stdout


@pytest.mark.parametrize(
    "bare, named, said",
    [
        (["--cutoff", "0.8"], ["--cutoff", "0.8mm"], "--cutoff 0.8: a bare number is read as 0.8 mm"),
        (["--crop", "0.5:2"], ["--crop", "0.5mm:2mm"], "--crop 0.5: a bare number is read as 0.5 mm"),
    ],
)
def test_a_bare_length_is_read_in_mm_with_a_warning(bare, named, said):
    surface = profile()
    warned = rough("detrend", "-f", "tsv", *bare, input=surface)
    quiet = rough("detrend", "-f", "tsv", *named, input=surface, check=True)
    assert warned.returncode == 0 and warned.stdout == quiet.stdout and quiet.stderr == b""
    (line,) = warned.stderr.decode().splitlines()
    assert said in line and "write the unit (bare numbers are refused from rough 0.14)" in line


def test_a_bare_frequency_is_per_mm_and_a_bare_quantity_in_its_old_unit_with_a_warning():
    surface = profile()
    warned = rough("fit-fractal", "--json", "--band", "0.5:20", input=surface)
    named = rough("fit-fractal", "--json", "--band", "0.5/mm:20/mm", input=surface, check=True)
    assert warned.stdout == named.stdout and "--band 0.5: a bare number is read as 0.5 /mm" in warned.stderr.decode()
    assert len(warned.stderr.decode().splitlines()) == 1  # one warning for the option, not one per end
    speed = rough("render", "--json", "--speed", "40", input=surface)
    assert speed.returncode == 0 and "--speed 40: a bare number is read as 40 mm/s" in speed.stderr.decode()


def test_zero_needs_no_unit():
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
