"""Regressions of the everyday defects found trying rough as a new user would: each
test is one reported defect, run as the user ran it."""

import os
import subprocess
import sys
import zipfile

import pytest

from rough import read, sample

PROFILE = str(sample("rock-profile.tsv"))
MAP = str(sample("rock-map.x3p"))


def rough(*args, env=None, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "rough", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
        env={**os.environ, **(env or {})},
        cwd=cwd,
    )


def refused(result, *words):
    """One line on standard error, status 2, no traceback, naming ``words``."""
    lines = result.stderr.splitlines()
    assert result.returncode == 2, result.stderr
    assert len(lines) == 1 and "Traceback" not in result.stderr and "internal error" not in result.stderr, lines
    for word in words:
        assert word in lines[0], lines[0]


def test_source_date_epoch_zero_writes_a_zip_dated_1980(tmp_path):
    out = tmp_path / "a.x3p"
    result = rough(
        "synth",
        "--length",
        "1mm",
        "--dimension",
        "1.3",
        "--rq",
        "1um",
        "--seed",
        "1",
        "-o",
        out,
        env={"SOURCE_DATE_EPOCH": "0"},
    )
    assert result.returncode == 0, result.stderr
    assert read(out).history[-1]["time"] == "1970-01-01T00:00:00Z"
    assert {info.date_time for info in zipfile.ZipFile(out).infolist()} == {(1980, 1, 1, 0, 0, 0)}


@pytest.mark.parametrize("epoch", ["foo", "-5", "1.5", "99999999999999999999"])
def test_a_source_date_epoch_that_is_not_a_time_is_refused(tmp_path, epoch):
    out = tmp_path / "a.x3p"
    result = rough(
        "synth", "--length", "1mm", "--dimension", "1.3", "--rq", "1um", "-o", out, env={"SOURCE_DATE_EPOCH": epoch}
    )
    refused(result, "SOURCE_DATE_EPOCH")
    assert not out.exists()


@pytest.mark.parametrize(
    "args, words",
    [
        (("render", "--stiffness", "0", PROFILE), ["--stiffness", "positive"]),
        (("render", "--hand-mass", "0", PROFILE), ["--hand-mass", "positive"]),
        (("render", "--rate", "0", PROFILE), ["--rate", "positive"]),
        (("render", "--max-force", "0", PROFILE), ["--max-force"]),
        (
            ("synth", "--length", "1mm", "--dimension", "1.3", "--rq", "1um", "--step", "0"),
            ["--step", "positive"],
        ),
        (("synth", "--length", "1mm", "--dimension", "1.3", "--rq", "1um", "--step", "-1um"), ["--step"]),
        (("synth", "--length", "0.01um", "--dimension", "1.3", "--rq", "1um"), ["fewer than two samples"]),
        (("resample", "--step", "0", PROFILE), ["--step"]),
        (("features", "--jrc-spacing", "0", PROFILE), ["--jrc-spacing", "positive"]),
        (("fit-fractal", "--resolution", "0", PROFILE), ["--resolution", "positive"]),
        (("detrend", "--cutoff", "-1mm", PROFILE), ["--cutoff", "positive"]),
        (("fit-fractal", "--band", "5/mm:0.05/mm", PROFILE), ["FMIN must be below FMAX"]),
        (("fit-fractal", "--band", "0:5/mm", PROFILE), ["positive"]),
        (("features", "--crop", "1mm:0.5mm", PROFILE), ["ends before it starts"]),
        (("features", "--crop", ":0.01um", PROFILE), [":10nm", "fewer than two samples", "63.252 mm"]),
        (("convert", MAP, "-o", "x.sur"), ["x.sur", "rough reads Digital Surf SUR (.sur) but does not write it"]),
        (("convert", MAP, "-o", "x.foo"), ["cannot tell the format"]),
        (("info", "--json", "--tsv", MAP), ["--json or --tsv"]),
    ],
)
def test_values_without_physical_sense_are_refused_in_one_line(tmp_path, args, words):
    refused(rough(*args, cwd=tmp_path), *words)
    assert not list(tmp_path.iterdir())


def test_bare_rough_prints_the_overview_and_succeeds():
    result = rough()
    assert result.returncode == 0 and not result.stderr
    assert result.stdout.startswith("Usage: rough") and "show" in result.stdout and "-h, --help" in result.stdout


def test_side_files_on_dash_go_to_standard_output(tmp_path):
    plot = subprocess.run(
        [sys.executable, "-m", "rough", "features", "--plot", "-", PROFILE],
        capture_output=True,
        cwd=tmp_path,
        check=True,
    )
    assert plot.stdout[:4] == b"\x89PNG"
    psd = rough("fit-fractal", "--psd", "-", PROFILE, cwd=tmp_path)
    assert psd.stdout.splitlines()[1] == "frequency_per_m\tdensity_m3\tcount"
    listed = rough("features", "--list", "-", PROFILE, cwd=tmp_path)
    assert listed.stdout.splitlines()[1].startswith("kind\tposition")
    assert not list(tmp_path.iterdir())  # no file named "-"


def test_overriding_a_files_spacing_warns_once_with_both_values():
    result = rough("fit-fractal", "--spacing", "1um", PROFILE)
    warnings = [line for line in result.stderr.splitlines() if "spacing given" in line]
    assert warnings == ["rough fit-fractal: warning: the spacing given, 1 µm, overrides the file's own, 30.9 µm"]


def test_completion_completes_paths_commands_and_presets():
    def complete(words, index):
        env = {"_ROUGH_COMPLETE": "bash_complete", "COMP_WORDS": words, "COMP_CWORD": str(index)}
        return rough(env=env).stdout.split()

    assert complete("rough info ", 2) == ["file,"]
    assert complete("rough convert x -o ", 4) == ["file,"]
    assert complete("rough fe", 1) == ["plain,features"]
    assert complete("rough detrend --tip fin", 3) == ["plain,fingernail", "plain,fingertip"]
    assert "plain,fingertip" in complete("rough render --tip ", 3)


def test_info_prints_heights_with_the_digits_their_range_needs(shared_data):
    result = rough("info", "--json", shared_data / "SurfaceTopography" / "hfm-1.hfm")
    text = rough("info", shared_data / "SurfaceTopography" / "hfm-1.hfm").stdout
    z = {line.split()[0]: line.split(None, 1)[1] for line in text.splitlines() if line.startswith("z_")}
    assert z["z_min"] != z["z_max"], z
    import json

    document = json.loads(result.stdout)
    assert document["z_max"] - document["z_min"] < 1e-4 * document["z_max"]  # the narrow range of the report


def test_help_states_defaults_that_differ_between_commands():
    def help(*command):
        return " ".join(rough(*command, "--help").stdout.split())

    assert "detrend's default is 2" in help("fit-fractal") and "detrend's default is 2" in help("rose")
    assert "60mm/s" in help("render") and "20mm/s" in help("experiment", "run")
    assert "default m, not mm" in help("info")
