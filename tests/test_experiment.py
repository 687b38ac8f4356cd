"""The perception experiment: design, sessions that survive being killed, and an
analysis that recovers known effects and keeps its false-positive rate."""

import csv
import json
import os
import shutil
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from rough.experiment.analysis import fit, wald_p
from rough.experiment.design import COSTA2000, grid_design, load_study, write_study
from rough.experiment.observer import Observer, parse_observer
from rough.experiment.session import read_answers

from conftest import assert_one_line_error, rough

OBSERVER = "rq=12,dimension=-4,spread=0.5,seed=3"


@pytest.fixture(scope="module")
def costa(tmp_path_factory):
    """The paper's design, written once (its 18 surfaces take about a second)."""
    folder = tmp_path_factory.mktemp("studies") / "costa"
    rough("experiment", "design", "--preset", "costa2000", "--seed", "11", folder, check=True)
    return folder


@pytest.fixture
def study(costa, tmp_path):
    copy = tmp_path / "study"
    shutil.copytree(costa, copy)
    return copy


# -- the paper's numbers and the design ---------------------------------------------------------


@pytest.mark.parametrize(
    "wald,printed",
    [
        ("4.47037", "7.8085e-6"),
        ("-2.48803", ".0128"),
        ("-0.76212", ".446"),
        ("4.9217", "8.581e-7"),
        ("-1.027", ".3044"),
        ("-1.815", ".0696"),
        ("-0.051", ".9593"),
        ("-1.734", ".0829"),
        ("-2.504", ".0123"),
        ("-0.966", ".334"),
        ("0.719", ".4721"),
    ],
)
def test_the_papers_wald_statistics_give_its_p_values(wald, printed):
    """Tables 1-2 of the paper: p = 2(1 - Φ(|W|)) from each printed W, within the
    rounding of both printed numbers."""
    w_half = 0.5 * 10.0 ** -len(wald.split(".")[1])
    mantissa, _, exponent = printed.partition("e")
    p_half = 0.5 * 10.0 ** (-len(mantissa.split(".")[1]) + int(exponent or 0))
    highest, lowest = wald_p(abs(float(wald)) - w_half), wald_p(abs(float(wald)) + w_half)
    assert lowest <= float(printed) + p_half and float(printed) - p_half <= highest


def test_the_costa2000_design(costa):
    design = load_study(costa)
    assert len(design.surfaces) == 18 and len(design.subjects) == 14 and len(design.trials) == 14 * 16
    first_set = design.sets[0]
    reference = design.surfaces[first_set["reference"]]
    assert (reference["dimension"], reference["rq"]) == (1.275, 0.2781e-3)
    grid = sorted(
        (design.surfaces[n]["dimension"], round(design.surfaces[n]["rq"] * 1e3, 4)) for n in first_set["neighbours"]
    )
    assert (1.35, 0.3502) in grid and len(grid) == 8 and (1.275, 0.2781) not in grid
    assert {d for d, _ in grid} == {1.2, 1.275, 1.35}
    assert design.surfaces[design.sets[1]["reference"]]["rq"] == 0.75e-3
    for subject in design.subjects:
        trials = design.trials_of(subject)
        assert sorted((t["set"], t["test"]) for t in trials) == sorted(
            (s["id"], n) for s in design.sets for n in s["neighbours"]
        )
    orders = {tuple(t["test"] for t in design.trials_of(s)) for s in design.subjects}
    assert len(orders) == 14
    test_first = np.mean([t["first"] == t["test"] for t in design.trials])
    assert 0.35 < test_first < 0.65
    recorded = json.loads((costa / "study.json").read_text())["surfaces"]
    assert all(isinstance(s["seed"], int) and abs(s["rq_measured"] / s["rq"] - 1) < 0.01 for s in recorded.values())


def test_the_same_seed_makes_the_same_study(tmp_path):
    surfaces, sets = grid_design([(1.3, 0.1e-3)], 0.05, 1.2)
    first = write_study(
        tmp_path / "a", {k: dict(v) for k, v in surfaces.items()}, sets, ["a", "b"], 9, 5e-3, 30.9e-6, 0.1545e-3
    )
    second = write_study(
        tmp_path / "b", {k: dict(v) for k, v in surfaces.items()}, sets, ["a", "b"], 9, 5e-3, 30.9e-6, 0.1545e-3
    )
    assert first.trials == second.trials
    from rough import read

    for name in first.surfaces:
        np.testing.assert_array_equal(read(first.surface_path(name)).heights, read(second.surface_path(name)).heights)


# -- sessions ------------------------------------------------------------------------------------


def answers(folder, subject):
    with open(folder / "answers" / f"{subject}.csv") as stream:
        return list(csv.DictReader(stream))


def test_a_headless_session_answers_every_trial_once(study):
    result = rough("experiment", "run", study, "--subject", "S03", "--observer", OBSERVER, check=True)
    assert "S03: 16 of 16 trials answered, 0 to go" in result.stdout.decode()
    rows = answers(study, "S03")
    assert [int(r["trial"]) for r in rows] == list(range(1, 17))
    assert all(r["device"] == "sim" and float(r["response_time_s"]) == pytest.approx(2.0) for r in rows)
    again = rough("experiment", "run", study, "--subject", "S03", "--observer", OBSERVER, check=True)
    assert "0 to go" in again.stdout.decode() and answers(study, "S03") == rows


@pytest.mark.parametrize("signal_number", [signal.SIGKILL, signal.SIGINT])
def test_a_session_killed_mid_way_resumes_without_losing_or_repeating_a_trial(study, tmp_path, signal_number):
    reference = tmp_path / "reference"
    shutil.copytree(study, reference)
    rough("experiment", "run", reference, "--subject", "S05", "--observer", OBSERVER, check=True)
    command = [
        sys.executable,
        "-m",
        "rough",
        "experiment",
        "run",
        str(study),
        "--subject",
        "S05",
        "--observer",
        OBSERVER,
        "--realtime",
        "--stroke",
        "0.1s",
    ]
    session = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    path = study / "answers" / "S05.csv"
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and (not path.exists() or len(answers(study, "S05")) < 4):
        time.sleep(0.02)
    session.send_signal(signal_number)
    _, stderr = session.communicate(timeout=60)
    before = answers(study, "S05")
    assert 4 <= len(before) < 16
    if signal_number == signal.SIGINT:
        assert session.returncode == 0 and b"paused after" in stderr
    assert not [p for p in (study / "answers").iterdir() if p.name.startswith(".rough-")]
    rough("experiment", "run", study, "--subject", "S05", "--observer", OBSERVER, check=True)
    after = answers(study, "S05")
    assert [int(r["trial"]) for r in after] == list(range(1, 17))
    assert after[: len(before)] == before
    drop = ("response_time_s", "finished")
    assert [{k: v for k, v in r.items() if k not in drop} for r in after] == [
        {k: v for k, v in r.items() if k not in drop} for r in answers(reference, "S05")
    ]


# -- bad folders and files -----------------------------------------------------------------------


def test_bad_study_folders_and_answer_files_exit_2(study, tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    assert_one_line_error(rough("experiment", "analyze", empty), "not a study folder")
    assert_one_line_error(rough("experiment", "analyze", study), "no answers yet")
    assert_one_line_error(
        rough("experiment", "run", study, "--subject", "S99", "--observer", OBSERVER), "not in the study"
    )
    assert_one_line_error(rough("experiment", "run", study, "--subject", "S01"), "--observer")
    assert_one_line_error(
        rough("experiment", "run", study, "--subject", "S01", "--observer", "rq=fast"), "not a number"
    )
    assert_one_line_error(rough("experiment", "design", "--preset", "costa2000", study), "not an empty folder")
    assert_one_line_error(rough("experiment", "design", tmp_path / "new"), "--preset costa2000 or")
    rough("experiment", "run", study, "--subject", "S01", "--observer", OBSERVER, check=True)
    path = study / "answers" / "S01.csv"
    good = path.read_text()
    lines = good.splitlines()
    for broken, message in [
        (lines[0].replace("answer,", "reply,") + "\n" + "\n".join(lines[1:]), "expected the columns"),
        ("\n".join(lines + [lines[1]]), "answered twice"),
        ("\n".join(lines).replace(",first,0,", ",first,1,", 1).replace(",second,0,", ",second,1,", 1), "disagree"),
        ("\n".join([lines[0], lines[1].replace("S01,1,", "S01,99,", 1)]), "not an answer to a planned trial"),
    ]:
        path.write_text(broken)
        assert_one_line_error(rough("experiment", "analyze", study), "S01.csv")
        assert message in rough("experiment", "analyze", study).stderr.decode()
    path.write_text(good)
    (study / "study.json").write_text("{not json")
    assert_one_line_error(rough("experiment", "analyze", study), "not valid JSON")


def test_a_missing_surface_is_named(study):
    victim = next((study / "surfaces").iterdir())
    victim.unlink()
    assert_one_line_error(rough("experiment", "run", study, "--subject", "S01", "--observer", OBSERVER), "is missing")


# -- analysis ------------------------------------------------------------------------------------

CELLS = [
    (i * 0.075, rq * (0.3502 / 0.2781) ** j - rq)
    for rq in (0.2781e-3, 0.75e-3)
    for i in (-1, 0, 1)
    for j in (-1, 0, 1)
    if (i, j) != (0, 0)
]


def simulated_table(observer, subjects, replicates):
    columns = {"rougher": [], "dimension": [], "rq": [], "subject": [], "set": []}
    for s in range(subjects):
        subject = f"S{s:02d}"
        for r in range(replicates):
            for k, (dimension, rq) in enumerate(CELLS):
                columns["rougher"].append(float(observer.judges_test_rougher(subject, 100 * r + k, dimension, rq)))
                columns["dimension"].append(dimension)
                columns["rq"].append(rq * 1e3)
                columns["subject"].append(subject)
                columns["set"].append(1 + k // 8)
    return {k: v if k in ("subject", "set") else np.array(v) for k, v in columns.items()}


def test_simulated_subjects_coefficients_are_recovered():
    """60 simulated studies of 14 subjects who each judge the paper's 16 pairs 4 times,
    with known slopes (6 per mm of Rq, -5 per unit of D) and subject intercepts of SD
    0.5: the estimates centre on the truth (ML's small-sample bias here is ~2.5 %) and
    the standard errors match the scatter."""
    estimates = []
    for seed in range(60):
        result = fit(simulated_table(Observer(rq=6.0, dimension=-5.0, spread=0.5, seed=seed), 14, 4))
        estimates.append(
            [result.coefficients[k][v] for k in ("rq", "fractal_dimension") for v in ("estimate", "stderr")]
        )
    estimates = np.array(estimates)
    for column, truth in ((0, 6.0), (2, -5.0)):
        values, errors = estimates[:, column], estimates[:, column + 1]
        monte_carlo = values.std() / np.sqrt(len(values))
        assert abs(values.mean() - truth) < 0.05 * abs(truth) + 3 * monte_carlo
        assert 0.8 < errors.mean() / values.std() < 1.25


def test_the_wald_test_keeps_its_false_positive_rate_for_a_null_effect():
    """300 studies of the paper's size (14 subjects × 16 pairs) in which D has no effect:
    the Wald test of D rejects at the 5 % level in 2–8.5 % of them (binomial 95 % range)."""
    rejected = [
        fit(simulated_table(Observer(rq=6.0, dimension=0.0, spread=0.5, seed=seed), 14, 1)).coefficients[
            "fractal_dimension"
        ]["p"]
        < 0.05
        for seed in range(300)
    ]
    assert 0.02 <= np.mean(rejected) <= 0.085


def test_separation_is_flagged():
    table = simulated_table(Observer(rq=400.0, dimension=0.0, seed=1), 4, 1)
    assert fit(table).separation


def test_analyze_command(study, tmp_path):
    for subject in ("S01", "S02", "S03", "S04"):
        rough("experiment", "run", study, "--subject", subject, "--observer", OBSERVER, check=True)
    document = json.loads(
        rough("experiment", "analyze", study, "--json", "--plot", tmp_path / "f.png", check=True).stdout
    )
    assert document["n"] == 64
    assert {"fractal_dimension", "rq", "subject_S02", "subject_S03", "subject_S04", "constant"} == set(
        document["coefficients"]
    )
    assert set(document["coefficients"]["rq"]) >= {"estimate", "stderr", "wald", "p"}
    table = rough("experiment", "analyze", study, "--set", "1", check=True).stdout.decode()
    assert "fractal dimension D" in table and "Rq (per mm)" in table and "likelihood ratio" in table
    assert "32 from 4 subjects" in table
    assert (tmp_path / "f.png").read_bytes()[:4] == b"\x89PNG"
    rows = rough("experiment", "analyze", study, "--tsv", check=True).stdout.decode().splitlines()
    estimates = [row.split("\t")[1] for row in rows if row.split("\t")[1].endswith(".estimate")]
    assert len(estimates) == 6 and "coefficients.rq.estimate" in estimates
    assert all(row.split("\t")[0] == str(study) for row in rows)


def test_observer_specs():
    assert parse_observer("rq=12,dimension=-4,spread=0.5,seed=3") == Observer(12.0, -4.0, 0.0, 0.5, 3)
    from rough.errors import InputError

    with pytest.raises(InputError, match="takes"):
        parse_observer("slope=3")
    with pytest.raises(InputError, match="not usable"):
        parse_observer("spread=-1")


def test_answers_are_checked_against_the_trials(study):
    rough("experiment", "run", study, "--subject", "S02", "--observer", OBSERVER, check=True)
    design = load_study(study)
    assert len(read_answers(design, "S02")) == 16
    os.remove(study / "trials.csv")
    from rough.errors import InputError

    with pytest.raises(InputError, match="trials.csv is missing"):
        load_study(study)
    assert COSTA2000["subjects"] == 14


class NoKeys:
    def take(self):
        return None


def test_a_joystick_session_toggles_with_the_trigger_and_answers_with_buttons_2_and_3(tmp_path):
    """The session on a virtual PID joystick: in each trial the subject toggles to the
    other surface once, then presses button 2 (first rougher) or 3 (second rougher)."""
    from virtual_joystick import FakeHandle, PidJoystick

    from rough import read
    from rough.experiment.session import joystick_presenter, run_session
    from rough.render import QuasiStatic, Settings, Track
    from rough.render.hid import Joystick

    surfaces, sets = grid_design([(1.3, 0.1e-3)], 0.05, 1.2)
    design = write_study(tmp_path / "s", surfaces, sets, ["P1"], 4, 5e-3, 30.9e-6, 0.1545e-3)
    device = PidJoystick()
    handle = FakeHandle(device)
    handle.move(0.5, 0.3, 0)
    joystick = Joystick(handle, device.descriptor, 8.9, 0.0, 5e-3, 0.5e-3, 2e-3)
    script = []
    for trial in range(8):
        script += [0, 0, 1, 0, 2 if trial % 2 == 0 else 4, 0]
    for k, buttons in enumerate(script):
        handle.schedule(0.04 * k, buttons=buttons)
    tracks = {name: Track.from_surface(read(design.surface_path(name))) for name in design.surfaces}
    present = joystick_presenter(tracks, joystick, QuasiStatic(), None, Settings(watchdog=1.0), NoKeys())
    progress = run_session(design, "P1", present, "virtual joystick")
    joystick.close()
    rows = read_answers(design, "P1")
    assert progress.answered == 8 and [r["answer"] for r in rows] == ["first", "second"] * 4
    assert all(r["toggles"] == "1" and r["device"] == "virtual joystick" for r in rows)
    assert device.force() == (0.0, 0.0)
