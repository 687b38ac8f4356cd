"""The everyday of issue 35: global options after the command, outputs checked before
any work, a note when standard input is a terminal, repeated warnings summarised,
``--crop`` on every command that reads a surface, and readable force plots."""

import dataclasses
import json
import os
import pathlib
import pty
import shutil
import subprocess
import sys

import click
import numpy as np
import pytest

import rough
from rough.cli import main
from rough.cli.batch import warning_template

ROOT = pathlib.Path(__file__).resolve().parents[1]
MAP = ROOT / "sample_profiles" / "rock-map.x3p"
PROFILE = ROOT / "sample_profiles" / "rock-profile.tsv"
SPACING_WARNING = "overrides the file's own"


def run(capsys, *args):
    """``rough ARGS`` in this process: (status, stdout, stderr)."""
    status = main.run([str(arg) for arg in args])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


# 1. global options anywhere


@pytest.mark.parametrize("where", ["before", "after"])
def test_quiet_silences_warnings_before_or_after_the_command(capsys, where):
    options = ["info", "--spacing", "1um", MAP]
    args = ["-q", *options] if where == "before" else [*options[:1], "-q", *options[1:]]
    status, out, err = run(capsys, *args)
    assert status == 0 and "Sq" in out
    assert err == ""
    status, out, err = run(capsys, *options)  # and without it the warning is back
    assert SPACING_WARNING in err


def test_debug_after_the_command_shows_the_traceback(capsys):
    status, _, err = run(capsys, "info", "--debug", "/nonexistent/scan.x3p")
    assert status == 2 and "Traceback" in err


def test_verbose_after_the_command_adds_to_the_group_s(capsys):
    status, _, err = run(capsys, "-v", "info", "-v", MAP)
    assert status == 0 and main._said["verbose"] == 2


def _commands():
    """Every built-in command (and subcommand), loaded as the group loads it."""
    group = main.cli
    with click.Context(group) as ctx:
        for name in main.COMMANDS:
            command = group.get_command(ctx, name)
            yield name, command
            for sub, subcommand in getattr(command, "commands", {}).items():
                yield f"{name} {sub}", subcommand


@pytest.mark.parametrize(("name", "command"), list(_commands()), ids=[name for name, _ in _commands()])
def test_every_command_lists_the_global_options_once(name, command):
    with click.Context(command, info_name=name) as ctx:
        text = command.get_help(ctx)
    for option in ("-q, --quiet", "-v, --verbose", "--debug"):
        assert text.count(option) == 1, (name, option)


def test_a_command_s_help_loads_no_numpy():
    code = "import sys; from rough.cli import main; main.run(['info', '--help']); print('numpy' in sys.modules)"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, env=_env(), check=True)
    assert "-q, --quiet" in result.stdout.decode()
    assert result.stdout.decode().split()[-1] == "False"


def _env():
    return {**os.environ, "PYTHONPATH": str(ROOT)}


# 2. outputs checked before any work


@pytest.fixture
def no_work(monkeypatch):
    """Reading or synthesising fails loudly: a refusal must come before either."""

    def worked(*args, **kwargs):
        raise AssertionError("the work started")

    for name in ("read", "open_surface"):
        monkeypatch.setattr(rough.io, name, worked)
    for name in ("synthesize_map", "synthesize_profile"):
        monkeypatch.setattr(rough.fractal, name, worked)


def _targets(folder):
    missing = folder / "missing" / "out"
    return [
        (["features", "--plot", f"{missing}.png", PROFILE], "--plot", "does not exist"),
        (["features", "--plot", folder / "x.xyz", PROFILE], "--plot", "as .xyz"),
        (["features", "--list", folder, PROFILE], "--list", "is a folder"),
        (["features", "--list", folder / "list.png", PROFILE], "--list", "as .png"),
        (["features", "--segments", f"{missing}.tsv", MAP], "--segments", "does not exist"),
        (["fit-fractal", "--psd", folder / "psd.png", PROFILE], "--psd", "as .png"),
        (["fit-fractal", "--plot", folder, PROFILE], "--plot", "is a folder"),
        (["render", "--trace", folder / "trace.png", PROFILE], "--trace", "as .png"),
        (["render", "--plot", f"{missing}.png", PROFILE], "--plot", "does not exist"),
        (["rose", "--plot", f"{missing}.png", MAP], "--plot", "does not exist"),
        (["map", "--window", "16px", "-o", f"{missing}.tif", MAP], "--output", "does not exist"),
        (["map", "--window", "16px", "-o", folder / "out.unknown", MAP], "--output", "a surface as .unknown"),
        (["show", "--plot", f"{missing}.png", MAP], "--plot", "does not exist"),
        (["show", "--plot", folder, MAP], "--plot", "is a folder"),
        (["convert", MAP, "-o", f"{missing}.x3p"], "--output", "does not exist"),
        (["detrend", MAP, "-o", f"{missing}.x3p"], "--output", "does not exist"),
        (["resample", "--step", "0.1mm", MAP, "-o", f"{missing}.x3p"], "--output", "does not exist"),
        (["synth", "--size", "64x64", "--dimension", "2.3", "--rq", "1um", "-o", folder], "--output", "is a folder"),
        (["synth", "--size", "64x64", "--dimension", "2.3", "--rq", "1um", "-o", f"{missing}.x3p"], "--output", ""),
        (["experiment", "analyze", folder, "--plot", folder / "p.xyz"], "--plot", "as .xyz"),
    ]


@pytest.mark.parametrize("case", range(len(_targets(pathlib.Path("/")))))
def test_an_unwritable_output_is_refused_before_any_work(capsys, no_work, tmp_path, case):
    args, flag, problem = _targets(tmp_path)[case]
    status, out, err = run(capsys, *args)
    assert status == 2, err
    assert len(err.strip().splitlines()) == 1 and flag in err and problem in err, err
    assert "the work started" not in err and "Traceback" not in err
    assert os.listdir(tmp_path) == []


def test_an_output_in_a_read_only_folder_is_refused_before_any_work(capsys, no_work, tmp_path):
    folder = tmp_path / "locked"
    folder.mkdir(mode=0o500)
    if os.access(folder, os.W_OK):
        pytest.skip("running as a user who may write anywhere")
    status, _, err = run(capsys, "features", "--plot", folder / "p.png", PROFILE)
    assert status == 2 and "permission denied" in err


@pytest.mark.parametrize(
    ("args", "refusal"),
    [
        (["show", MAP], "refusing to draw a figure on a terminal"),
        (["features", "--plot", "-", PROFILE], "refusing to draw a figure on a terminal"),
        (["synth", "--size", "64x64", "--dimension", "2.3", "--rq", "1um"], "refusing to write binary X3P"),
    ],
)
def test_a_figure_or_binary_surface_for_a_terminal_is_refused_first(capsys, monkeypatch, no_work, args, refusal):
    monkeypatch.setattr(sys.stdout, "isatty", lambda: True)
    status, _, err = run(capsys, *args)
    assert status == 2 and refusal in err and "the work started" not in err, err


def test_devices_and_templates_pass_the_check(capsys, tmp_path):
    status, _, err = run(capsys, "convert", PROFILE, "-f", "tsv", "-o", os.devnull)
    assert status == 0, err
    status, _, err = run(capsys, "features", "--list", tmp_path / "{stem}.tsv", PROFILE, PROFILE)
    assert status == 0 and (tmp_path / "rock-profile.tsv").is_file(), err


# 3. a note when waiting on a terminal


def _on_a_terminal(*args, typed=b""):
    """``rough ARGS`` with standard input a pseudo-terminal on which ``typed`` and one
    Ctrl-D are typed once the command has said its first line (at once, with -q):
    (status, stdout, stderr)."""
    controller, terminal = pty.openpty()
    with subprocess.Popen(
        [sys.executable, "-m", "rough", *args],
        stdin=terminal,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=_env(),
    ) as process:
        os.close(terminal)
        first = b"" if "-q" in args else process.stderr.readline()
        os.write(controller, typed + b"\x04")
        out, rest = process.communicate(timeout=60)
    os.close(controller)
    return process.returncode, out.decode(), (first + rest).decode()


def test_reading_a_terminal_says_so_in_one_line():
    status, _, err = _on_a_terminal("info")
    lines = err.splitlines()
    assert lines[0] == (
        "rough info: reading a surface from standard input (end with Ctrl-D; give a FILE to read a file)"
    )
    assert status == 2 and "empty" in lines[1]


def test_one_ctrl_d_ends_what_is_typed():
    status, out, err = _on_a_terminal("info", "--json", "--spacing", "1um", typed=b"1e-6\n3e-6\n2e-6\n")
    assert status == 0, err
    assert json.loads(out)["shape"] == [3]


def test_quiet_or_a_pipe_gives_no_note():
    assert "reading a surface" not in _on_a_terminal("info", "-q")[2]
    result = subprocess.run(
        [sys.executable, "-m", "rough", "info"], input=MAP.read_bytes(), capture_output=True, env=_env()
    )
    assert result.returncode == 0 and result.stderr == b""


# 4. repeated warnings summarised


def test_a_warning_repeated_by_many_files_is_printed_once_and_counted(capsys, tmp_path):
    names = []
    for number in range(12):
        names.append(tmp_path / f"scan-{number}.x3p")
        shutil.copy(MAP, names[-1])
    status, out, err = run(capsys, "info", "--spacing", "1um", *names)
    assert status == 0
    lines = err.splitlines()
    assert len(lines) == 2, err
    assert lines[0].startswith(f"rough info: {names[0]}: warning: the spacing given")
    assert lines[1].startswith(
        f"rough info: the same warning for 11 more files ({names[1]}, {names[2]}, {names[3]}, …): the spacing given"
    )
    status, out, err = run(capsys, "info", "--json", "--spacing", "1um", *names)
    documents = [json.loads(line) for line in out.splitlines()]
    assert len(documents) == 12
    assert all(any(SPACING_WARNING in w for w in document["warnings"]) for document in documents)


def test_a_summary_shows_only_the_numbers_its_files_share(capsys, tmp_path):
    """The numbers of the first file's warning are not passed off as the others': a
    number that differs between the files is shown as …"""
    surface = rough.read(MAP)
    names = [tmp_path / f"scan-{step}um.x3p" for step in (50, 20, 30)]
    for name, step in zip(names, (50e-6, 20e-6, 30e-6)):
        dataclasses.replace(surface, spacing=(step, step)).write(name)
    status, out, err = run(capsys, "info", "--spacing", "1um", *names)
    assert status == 0
    summary = err.splitlines()[-1]
    assert summary.startswith(f"rough info: the same warning for 2 more files ({names[1]}, {names[2]}): ")
    assert "1 µm" in summary and "50 µm" not in summary and "…" in summary


def test_one_file_s_warnings_are_never_summarised(capsys):
    status, _, err = run(capsys, "info", "--spacing", "1um", MAP)
    assert SPACING_WARNING in err and "the same warning" not in err


def test_the_same_warning_is_the_text_without_the_name_and_the_numbers():
    first = warning_template("a.x3p: 12 of 4096 points (0.29 %) are NaN", "a.x3p")
    assert first == warning_template("b/c.x3p: 3 of 1e+06 points (3e-04 %) are NaN", "b/c.x3p")
    assert first != warning_template("a.x3p: 12 of 4096 points are out of range", "a.x3p")


# 5. --crop on every command that reads a surface


def test_every_command_that_reads_a_surface_takes_crop():
    readers = [
        name
        for name, command in _commands()
        if any(param.name == "input" for param in command.params) and any(p.name == "spacing" for p in command.params)
    ]
    assert {"info", "convert", "resample", "render", "features", "show"} <= set(readers)
    for name, command in _commands():
        if name in readers:
            assert [p for p in command.params if "--crop" in p.opts], name


@pytest.mark.parametrize("memory", [None, "1KB"])
def test_info_crops_in_memory_and_in_tiles(capsys, tmp_path, memory):
    tif = tmp_path / "map.tif"
    assert run(capsys, "convert", MAP, "-o", tif)[0] == 0
    extra = [] if memory is None else ["--memory", memory]
    status, out, err = run(capsys, "info", "--json", "--crop", "1mm:2mm,0:1mm", *extra, tif)
    document = json.loads(out)
    assert status == 0, err
    assert document["shape"] == [21, 21] and document["origin"] == pytest.approx([1e-3, 0])
    assert document.get("tiled", False) == (memory is not None)


def test_convert_and_resample_crop(capsys, tmp_path):
    whole = rough.read(MAP)
    status, _, err = run(capsys, "convert", "--crop", "1mm:2mm", MAP, "-o", tmp_path / "part.x3p")
    assert status == 0, err
    part = rough.read(tmp_path / "part.x3p")
    assert part.points == (21, whole.points[1])
    np.testing.assert_array_equal(part.heights, whole.heights[:, 20:41])
    status, _, err = run(capsys, "resample", "--crop", "1mm:2mm", "--step", "0.1mm", MAP, "-o", tmp_path / "r.x3p")
    assert status == 0, err
    assert rough.read(tmp_path / "r.x3p").origin[0] == pytest.approx(1e-3)


def test_render_crops_as_reading_does(capsys, tmp_path):
    trace = tmp_path / "trace.npy"
    status, _, err = run(capsys, "render", "--crop", "10mm:20mm", "--trace", trace, PROFILE)
    assert status == 0, err
    x = np.load(trace)["x"]
    spacing = rough.read(PROFILE).spacing[0]
    assert 10e-3 - spacing <= x[np.isfinite(x)].min() and x.max() <= 20e-3 + spacing


def test_a_y_range_on_a_profile_is_refused_by_every_command(capsys):
    for command in ("info", "render"):
        status, _, err = run(capsys, command, "--crop", "1mm:2mm,0:1mm", PROFILE)
        assert status == 2 and "a profile has no y range" in err, err


# 6. readable force plots


@pytest.fixture(scope="module")
def profile_runs():
    track = rough.render.Track.from_surface(rough.read(PROFILE))
    return [(label, rough.render.simulate(track, speed=speed)) for label, speed in (("20 mm/s", 0.02),)]


def test_the_legends_leave_the_end_of_the_trace_clear(profile_runs):
    figure = rough.plot.force_figure(profile_runs)
    figure.canvas.draw()
    for axis in figure.axes:
        legend = axis.get_legend()
        if legend is None:
            continue
        box = legend.get_window_extent()
        for line in axis.get_lines():
            x, y = line.get_xdata(), line.get_ydata()
            last = x >= x.min() + 0.9 * (x.max() - x.min())
            points = axis.transData.transform(np.column_stack([x[last], y[last]]))
            inside = (
                (points[:, 0] >= box.x0)
                & (points[:, 0] <= box.x1)
                & (points[:, 1] >= box.y0)
                & (points[:, 1] <= box.y1)
            )
            assert not inside.any(), (axis.get_ylabel(), line.get_label())
    assert sum(axis.get_legend() is not None for axis in figure.axes) == 2


def test_map_forces_are_drawn_as_a_field_over_x_and_y():
    surface = rough.fractal.fill_invalid(rough.read(MAP))
    track = rough.render.MapTrack.from_surface(surface)
    result = rough.render.simulate(track, speed=0.02)
    figure = rough.plot.force_figure([("20 mm/s", result)])
    plots = [axis for axis in figure.axes if axis.get_ylabel().startswith("y (")]
    assert len(plots) == 3
    assert plots[-1].get_xlabel() in ("x (mm)", "x (µm)")
    for axis in plots:
        coloured = [c for c in axis.collections if c.get_array() is not None]
        assert coloured and np.isfinite(coloured[0].get_array()).any()
        assert not axis.get_lines()  # no dense trace drawn as lines
    bars = [axis.get_ylabel() for axis in figure.axes if axis not in plots]
    assert "force along the motion (N)" in bars and "force across the motion (N)" in bars
