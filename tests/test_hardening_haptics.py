"""Issue 14, haptics and experiment: nonsense options and absurd runs are refused in one
line before anything starts, study files are checked against the design, nothing is
written outside the study folder, and Ctrl-C anywhere in a session pauses it."""

import contextlib
import json
import pathlib

import numpy as np
import pytest

import rough.cli.main as cli_main
import rough.experiment.session as session
import rough.io.atomic as atomic
import rough.render.loop as loop
import rough.render.session as render_session
from rough.errors import InputError
from rough.experiment.design import grid_design, load_study, write_study
from rough.render import QuasiStatic, Settings, SimulatedHand, Track, run, simulate

from conftest import assert_one_line_error, rough

OBSERVER = "rq=12,dimension=-4,seed=3"


@pytest.fixture(scope="module")
def profile():
    return rough("synth", "--length", "5mm", "--dimension", "1.3", "--rq", "0.1mm", "--seed", "2", check=True).stdout


# -- render: options that make no physical sense, runs that would never end ----------------------


@pytest.mark.parametrize(
    "options,message",
    [
        (["--rate", "0"], "--rate"),
        (["--rate", "-1kHz"], "must not be negative"),
        (["--speed", "0"], "--speed"),
        (["--stiffness", "0"], "--stiffness"),
        (["--hand-mass", "0"], "--hand-mass"),
        (["--model", "dynamic", "--mass", "0"], "--mass"),
        (["--max-force", "0"], "--max-force"),
        (["--duration", "0s"], "--duration"),
        (["--velocity-filter", "0"], "--velocity-filter"),
        (["--rate", "1e7Hz"], "a rate must lie between 0.001 Hz and 100000 Hz"),
        (["--duration", "1e7s"], "a time must lie between 1e-06 s and 1e+06 s"),
        (["--duration", "1e300s"], "a time must lie between 1e-06 s and 1e+06 s"),
    ],
)
def test_render_refuses_nonsense_values_in_one_line(profile, options, message):
    assert_one_line_error(rough("render", *options, input=profile), message)


@pytest.mark.parametrize(
    "options",
    [
        ["--duration", "1e5s"],
        ["--speed", "1e-4mm/s"],
        ["--rate", "100kHz", "--duration", "3600s"],
        ["--speed", "1mm/s", "--speed", "2mm/s", "--duration", "5000s"],
    ],
)
def test_render_refuses_runs_whose_trace_would_exceed_the_bound_at_once(profile, options):
    result = rough("render", *options, input=profile)
    assert_one_line_error(result, "512 MiB", "ticks")


def test_a_kilometre_spacing_is_refused_at_once(tmp_path):
    np.save(tmp_path / "column.npy", np.array([0.0, 1e-6, 0.0, 2e-6]))
    assert_one_line_error(rough("render", "--spacing", "1km", tmp_path / "column.npy"), "512 MiB")


def test_the_library_refuses_absurd_runs_and_closes_the_device():
    track = Track(np.zeros(101), 0.1e-3)
    with pytest.raises(InputError, match="512 MiB"):
        simulate(track, speed=1e-9)
    closed = []
    hand = SimulatedHand(0.02, 0.0, 0.0, 1e-3)
    hand.close = lambda: closed.append(True)
    with pytest.raises(InputError, match="ticks"):
        run(hand, [track], QuasiStatic(), settings=Settings(duration=1e7, realtime=False))
    assert closed == [True] and hand.ticks == 0


def test_a_run_without_a_duration_ends_at_the_trace_bound(monkeypatch):
    monkeypatch.setattr(loop, "MAX_TICKS", 50)
    hand = SimulatedHand(0.02, 0.0, 0.0, 1e-3)
    result = run(hand, [Track(np.zeros(101), 0.1e-3)], QuasiStatic(), settings=Settings(realtime=False))
    assert (result.ticks, result.ended_by, result.trace.size) == (50, "trace limit", 50)


def test_ctrl_c_ends_a_run_of_several_speeds(monkeypatch):
    calls = []

    class Interrupted:
        ended_by = "interrupt"

    monkeypatch.setattr(render_session, "simulate", lambda *args, **kwargs: calls.append(args) or Interrupted())
    track = Track(np.zeros(101), 0.1e-3)
    runs = render_session.run_sim(track, [0.01, 0.02, 0.03], QuasiStatic(), None, Settings(realtime=False))
    assert len(runs) == len(calls) == 1


# -- study folders checked against the design ----------------------------------------------------


@pytest.fixture
def study(tmp_path):
    """A one-set study of two subjects; S01 has answered all 8 trials."""
    surfaces, sets = grid_design([(1.275, 0.2781e-3)], 0.075, 1.2593)
    study = write_study(tmp_path / "study", surfaces, sets, ["S01", "S02"], 5, 4e-3, 30.9e-6, 0.1545e-3)
    script = iter(["first", "second"] * 4)
    session.run_session(study, "S01", lambda trial: (next(script), 1.0, 1), "script")
    return study.folder


def analyze(folder):
    return rough("experiment", "analyze", folder)


def run_subject(folder, subject="S02"):
    return rough("experiment", "run", folder, "--subject", subject, "--observer", OBSERVER)


def outside(folder):
    """Every file under the test's folder that is not in the study."""
    return {p for p in folder.parent.rglob("*") if folder not in p.parents and p != folder}


def edit_answers(folder, line, column, value):
    path = folder / "answers" / "S01.csv"
    rows = [row.split(",") for row in path.read_text().splitlines()]
    rows[line - 1][rows[0].index(column)] = value
    path.write_text("\n".join(",".join(row) for row in rows) + "\n")


def test_a_subject_that_is_a_path_is_refused_and_nothing_is_written_outside(study):
    before = outside(study)
    assert_one_line_error(run_subject(study, "../../../../tmp/x"), "--subject", "not a name")
    document = json.loads((study / "study.json").read_text())
    document["subjects"].append("../../../../tmp/x")
    (study / "study.json").write_text(json.dumps(document))
    assert_one_line_error(run_subject(study, "../../../../tmp/x"), "--subject", "not a name")
    assert_one_line_error(run_subject(study, "S02"), "study.json", "not a name")
    assert outside(study) == before


def test_a_subject_path_in_the_trial_list_is_refused_with_its_line(study):
    path = study / "trials.csv"
    lines = path.read_text().splitlines()
    lines[3] = lines[3].replace("S01,", "../x,", 1)
    path.write_text("\n".join(lines) + "\n")
    assert_one_line_error(run_subject(study), "trials.csv, line 4")


def test_the_answers_folder_may_not_lead_outside_the_study(study, tmp_path):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (study / "answers" / "S01.csv").rename(elsewhere / "S01.csv")
    (study / "answers").rmdir()
    (study / "answers").symlink_to(elsewhere)
    assert_one_line_error(run_subject(study), "answers", "not a folder")
    assert sorted(p.name for p in elsewhere.iterdir()) == ["S01.csv"]


@pytest.mark.parametrize("command", ["run", "analyze"])
def test_answers_cut_mid_row_are_refused_by_run_and_analyze(study, command):
    path = study / "answers" / "S01.csv"
    text = path.read_text()
    path.write_text(text[: text.rindex(",script,")])
    result = run_subject(study, "S01") if command == "run" else analyze(study)
    assert_one_line_error(result, "S01.csv, line 9", "cut")


def test_a_trial_list_cut_mid_row_is_refused(study):
    path = study / "trials.csv"
    text = path.read_text()
    path.write_text(text[: len(text) - 12])
    assert_one_line_error(analyze(study), "trials.csv, line", "cut")


@pytest.mark.parametrize(
    "column,value,message",
    [
        ("test_dimension", "abc", "test_dimension 'abc'"),
        ("test_rq_m", "nan", "test_rq_m 'nan'"),
        ("reference_rq_m", "inf", "reference_rq_m 'inf'"),
        ("reference_dimension", "1.3", "not the design's 1.275"),
        ("test_dimension", "1.9", "test_dimension '1.9'"),
        ("response_time_s", "-1", "response_time_s"),
        ("toggles", "x", "whole numbers"),
        ("finished", "yesterday", "finished"),
    ],
)
def test_every_answer_column_is_checked_against_the_design(study, column, value, message):
    edit_answers(study, 3, column, value)
    assert_one_line_error(analyze(study), "S01.csv, line 3", message)
    assert_one_line_error(run_subject(study, "S01"), "S01.csv, line 3", message)


def test_non_finite_or_impossible_design_values_are_refused(study):
    path = study / "study.json"
    good = path.read_text()
    document = json.loads(good)
    document["surfaces"]["R1"]["rq"] = float("nan")
    path.write_text(json.dumps(document))
    assert_one_line_error(analyze(study), "study.json", "NaN")
    document["surfaces"]["R1"]["rq"] = 0.2781e-3
    document["surfaces"]["R1"]["file"] = "../../R1.x3p"
    path.write_text(json.dumps(document))
    assert_one_line_error(analyze(study), "study.json", "not a path inside the study folder")


@pytest.mark.parametrize("command", ["run", "analyze"])
def test_an_answers_file_that_is_a_folder_is_refused(study, command):
    path = study / "answers" / "S01.csv"
    path.unlink()
    path.mkdir()
    result = run_subject(study, "S01") if command == "run" else analyze(study)
    assert_one_line_error(result, "S01.csv", "not a regular file")


# -- Ctrl-C anywhere in a session pauses it, the answers intact ----------------------------------


@pytest.fixture
def fresh(tmp_path):
    surfaces, sets = grid_design([(1.275, 0.2781e-3)], 0.075, 1.2593)
    return write_study(tmp_path / "study", surfaces, sets, ["S01"], 5, 4e-3, 30.9e-6, 0.1545e-3)


def answer_first(trial):
    return "first", 1.0, 1


def interrupt_save(monkeypatch, number):
    """Ctrl-C lands as the answers are saved for the ``number``-th time."""
    save, calls = session._save, []

    def interrupted(*args):
        calls.append(1)
        if len(calls) == number:
            raise KeyboardInterrupt
        save(*args)

    monkeypatch.setattr(session, "_save", interrupted)
    return save


def test_ctrl_c_before_a_save_pauses_with_the_answers_intact(fresh, monkeypatch):
    save = interrupt_save(monkeypatch, 3)
    progress = session.run_session(fresh, "S01", answer_first, "script")
    assert (progress.answered, progress.interrupted) == (2, True)
    assert len(session.read_answers(fresh, "S01")) == 2
    monkeypatch.setattr(session, "_save", save)
    assert session.run_session(fresh, "S01", answer_first, "script").answered == 8


def test_ctrl_c_after_the_rename_counts_the_answer_saved(fresh, monkeypatch):
    real = atomic.atomic_output

    @contextlib.contextmanager
    def then_interrupted(path):
        with real(path) as stream:
            yield stream
        if len(pathlib.Path(path).read_text().splitlines()) == 4:
            raise KeyboardInterrupt

    monkeypatch.setattr(session, "atomic_output", then_interrupted)
    progress = session.run_session(fresh, "S01", answer_first, "script")
    assert (progress.answered, progress.remaining, progress.interrupted) == (3, 5, True)
    assert [int(row["trial"]) for row in session.read_answers(fresh, "S01")] == [1, 2, 3]


def test_ctrl_c_while_the_answers_are_read_pauses(fresh, monkeypatch):
    session.run_session(fresh, "S01", lambda trial: None, "script")
    monkeypatch.setattr(session, "read_answers", lambda *args: (_ for _ in ()).throw(KeyboardInterrupt))
    progress = session.run_session(fresh, "S01", answer_first, "script")
    assert progress.interrupted and progress.answered == 0


def test_the_command_pauses_with_status_0_when_ctrl_c_lands_in_a_save(fresh, monkeypatch, capsys):
    interrupt_save(monkeypatch, 2)
    status = cli_main.run(["experiment", "run", str(fresh.folder), "--subject", "S01", "--observer", OBSERVER])
    captured = capsys.readouterr()
    assert status == 0, captured.err
    assert "paused after 1 of 8 trials" in captured.err
    assert len(load_study(fresh.folder).trials_of("S01")) == 8
    assert len(session.read_answers(fresh, "S01")) == 1


def test_a_trace_on_standard_output_takes_the_reports_place(tmp_path):
    np.save(tmp_path / "column.npy", np.linspace(0, 1e-4, 200))
    result = rough("render", "--spacing", "0.1mm", "--trace", "-", tmp_path / "column.npy", check=True)
    lines = result.stdout.decode().splitlines()
    assert lines[0].split() == ["t", "x", "y_i", "h", "F_x", "F_y", "contact"], lines[:2]
    assert all(len(line.split("\t")) == 7 for line in lines[1:])
    two = rough("render", "--spacing", "0.1mm", "--trace", "-", "--speed", "1mm/s", "--speed", "2mm/s",
                tmp_path / "column.npy")  # fmt: skip
    assert_one_line_error(two, "{speed}")
