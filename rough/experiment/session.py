"""Running a subject's session: the remaining trials, one at a time, each answer saved
before the next trial starts.

The answers file ``answers/<subject>.csv`` is rewritten whole through a temporary file
and a rename after every trial, so it always holds every answered trial and nothing
half-written: a session killed at any moment resumes at the first unanswered trial,
losing nothing and repeating nothing.

On a joystick the subject feels the first surface of the pair; the trigger (button 1)
toggles to the other; button 2 answers "the first is rougher", button 3 "the second";
keys 1 and 2 on the keyboard do the same. With the simulated hand, a scripted
:class:`~.observer.Observer` answers after the hand has stroked both surfaces.
"""

import contextlib
import csv
import dataclasses
import datetime
import io
import math
import sys
import threading
import time

from ..errors import InputError
from ..io import read
from ..io.atomic import atomic_output
from ..progress import progress
from ..render.device import HeldOpen
from ..render.loop import run
from ..render.simulation import simulate
from ..render.track import Track
from .design import TRIAL_FIELDS, read_rows

ANSWER_FIELDS = TRIAL_FIELDS + (
    "answer",
    "test_rougher",
    "reference_dimension",
    "reference_rq_m",
    "test_dimension",
    "test_rq_m",
    "response_time_s",
    "toggles",
    "device",
    "finished",
)
ANSWER_BUTTONS = {2: "first", 4: "second"}  # button 2, button 3 (bit masks)
ANSWER_KEYS = {"1": "first", "2": "second"}
TIME_FORMAT = "%Y-%m-%dT%H:%M:%SZ"


@dataclasses.dataclass
class Progress:
    """What a call to :func:`run_session` did."""

    answered: int
    remaining: int
    total: int
    interrupted: bool = False


def read_answers(study, subject):
    """The answered trials of ``subject`` (rows as dicts), every column checked against
    the trial list and the design."""
    path = study.answers_path(subject)
    if not path.exists() and not path.is_symlink():
        return []
    planned = {t["trial"]: t for t in study.trials_of(subject)}
    rows, seen = [], set()
    for line, row in read_rows(path, ANSWER_FIELDS, "answers file"):
        where = f"{path}, line {line}"
        try:
            number, rougher, toggles = int(row["trial"]), int(row["test_rougher"]), int(row["toggles"])
        except ValueError:
            raise InputError(f"{where}: trial, test_rougher and toggles must be whole numbers") from None
        trial = planned.get(number)
        if trial is None or number in seen or rougher not in (0, 1) or row["answer"] not in ("first", "second"):
            raise InputError(f"{where}: not an answer to a planned trial (or answered twice)")
        if any(str(trial[key]) != row[key] for key in TRIAL_FIELDS):
            raise InputError(f"{where}: does not match trial {number} of trials.csv")
        if (row["answer"] == ("first" if trial["first"] == trial["test"] else "second")) != bool(rougher):
            raise InputError(f"{where}: answer and test_rougher disagree")
        for column, value in _design_values(study, trial).items():
            if _float(row[column]) != value:
                raise InputError(f"{where}: {column} {row[column]!r} is not the design's {value!r}")
        seconds = _float(row["response_time_s"])
        if not (seconds >= 0 and toggles >= 0):
            raise InputError(f"{where}: response_time_s and toggles must be finite and not negative")
        try:
            datetime.datetime.strptime(row["finished"], TIME_FORMAT)
        except ValueError:
            raise InputError(f"{where}: finished {row['finished']!r} is not a time like 2024-05-01T12:00:00Z") from None
        seen.add(number)
        rows.append(row)
    return rows


def _design_values(study, trial):
    test, reference = study.surfaces[trial["test"]], study.surfaces[trial["reference"]]
    return {
        "reference_dimension": reference["dimension"],
        "reference_rq_m": reference["rq"],
        "test_dimension": test["dimension"],
        "test_rq_m": test["rq"],
    }


def _float(text):
    """A finite number, or NaN (which equals nothing and passes no comparison)."""
    try:
        value = float(text)
    except ValueError:
        return math.nan
    return value if math.isfinite(value) else math.nan


def run_session(study, subject, present, device_name):
    """Present every unanswered trial of a subject, saving each answer at once.

    Parameters
    ----------
    study : Study
        The study, from :func:`~rough.experiment.design.load_study`.
    subject : str
        One of ``study.subjects``.
    present : callable
        ``present(trial)`` → ``(answer, response_time_s, toggles)``, with ``answer``
        ``"first"`` or ``"second"`` (the surface judged rougher), or None when the
        subject stopped; ``trial`` is a dict with the fields of ``TRIAL_FIELDS``.
    device_name : str
        Recorded with each answer.

    Returns
    -------
    Progress
        ``answered``, ``remaining`` and ``total`` trials, and ``interrupted`` (True
        when ``present`` returned None or Ctrl-C paused the session).

    Raises
    ------
    rough.InputError
        For a subject not in the study, or an answers file that is unreadable or
        does not match the trial list.

    Notes
    -----
    ``answers/<subject>.csv`` is rewritten whole through a temporary file and a
    rename after every trial, so it always holds every answered trial and nothing
    half-written; running the session again resumes at the first unanswered trial
    without repeating one.

    Examples
    --------
    A scripted subject who answers three trials and stops, then comes back:

    >>> import pathlib, tempfile
    >>> from rough.experiment.design import grid_design, write_study
    >>> surfaces, sets = grid_design([(1.275, 0.2781e-3)], 0.075, 1.2593)
    >>> folder = tempfile.TemporaryDirectory()
    >>> study = write_study(pathlib.Path(folder.name) / "study", surfaces, sets, ["S01"], 5, 4e-3, 30.9e-6, 0.1545e-3)
    >>> from rough.experiment.session import run_session
    >>> script = iter(["first", "second", "first"])
    >>> def three_then_stop(trial):
    ...     answer = next(script, None)
    ...     return None if answer is None else (answer, 1.5, 2)
    >>> run_session(study, "S01", three_then_stop, "script")
    Progress(answered=3, remaining=5, total=8, interrupted=True)
    >>> run_session(study, "S01", lambda trial: ("first", 1.0, 1), "script")
    Progress(answered=8, remaining=0, total=8, interrupted=False)
    >>> len(study.answers_path("S01").read_text().splitlines())  # a header and 8 answers
    9
    >>> folder.cleanup()
    """
    trials = study.trials_of(subject)
    _answers_file(study, subject)
    saved = 0
    try:
        answers = read_answers(study, subject)
        saved = len(answers)
        done = {int(row["trial"]) for row in answers}
        with _trials_bar(subject, len(trials) - saved, device_name) as bar:
            for trial in trials:
                if trial["trial"] in done:
                    continue
                outcome = present(trial)
                if outcome is None:
                    break
                answers.append(_answer_row(study, trial, *outcome, device_name))
                _save(study, subject, answers)
                saved = len(answers)
                bar.update()
            else:
                return Progress(saved, len(trials) - saved, len(trials))
    except KeyboardInterrupt:
        try:
            saved = len(read_answers(study, subject))
        except (KeyboardInterrupt, InputError):
            pass
    return Progress(saved, len(trials) - saved, len(trials), interrupted=True)


def _trials_bar(subject, count, device_name):
    """A progress bar over the simulated hand's trials (none on a joystick, whose
    subject needs the terminal quiet)."""
    if device_name != "sim":
        return contextlib.nullcontext(_NoBar())
    return progress(total=count, description=f"{subject}: trials", unit="trial")


class _NoBar:
    def update(self, n=1):
        pass


def _answer_row(study, trial, answer, seconds, toggles, device_name):
    return {
        **{key: trial[key] for key in TRIAL_FIELDS},
        "answer": answer,
        "test_rougher": int(trial[answer] == trial["test"]),
        **_design_values(study, trial),
        "response_time_s": f"{seconds:.3f}",
        "toggles": toggles,
        "device": device_name,
        "finished": datetime.datetime.now(datetime.timezone.utc).strftime(TIME_FORMAT),
    }


def _answers_file(study, subject):
    """``answers/<subject>.csv``, made sure to lie inside the study folder: the answers
    folder is a real folder, and the file a regular file or absent (not a link)."""
    path = study.answers_path(subject)
    if path.parent.is_symlink() or (path.parent.exists() and not path.parent.is_dir()):
        raise InputError(f"{path.parent}: not a folder (answers are written only inside the study folder)")
    if path.is_symlink() or (path.exists() and not path.is_file()):
        raise InputError(f"{path}: not a regular file (answers are written only inside the study folder)")
    return path


def _save(study, subject, rows):
    path = _answers_file(study, subject)
    path.parent.mkdir(exist_ok=True)
    text = io.StringIO()
    writer = csv.DictWriter(text, ANSWER_FIELDS, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    with atomic_output(path) as stream:
        stream.write(text.getvalue().encode())


def simulated_presenter(study, observer, speed, model, friction, settings, **hand):
    """A ``present(trial)`` for :func:`run_session` that uses the simulated hand.

    Each trial strokes the simulated hand once over each surface of the pair, then
    asks the observer's judgement from the design's nominal D and Rq.

    Parameters
    ----------
    study : Study
        The study whose surfaces are presented (each read once, on first use).
    observer : Observer
        The scripted observer, from :func:`~rough.experiment.observer.parse_observer`.
    speed : float
        The stroking speed, m/s.
    model : QuasiStatic or DynamicStylus
        The contact model.
    friction : object or None
        A friction model from :func:`rough.render.parse_friction`, or None.
    settings : Settings
        Loop settings, as for :func:`rough.render.simulate`.
    **hand
        ``press``, ``hand_mass``, ``hand_damping``, ``lateral_stiffness``, passed to
        :func:`rough.render.simulate`.

    Returns
    -------
    callable
        ``present(trial)`` → ``(answer, response_time_s, toggles)``: the side judged
        rougher, the strokes' simulated time (s) and 1 toggle; None when a stroke was
        interrupted.

    Raises
    ------
    rough.InputError
        (from ``present``) For a surface file that cannot be read or rendered.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from rough.experiment.design import grid_design, write_study
    >>> surfaces, sets = grid_design([(1.275, 0.2781e-3)], 0.075, 1.2593)
    >>> folder = tempfile.TemporaryDirectory()
    >>> study = write_study(pathlib.Path(folder.name) / "study", surfaces, sets, ["S01"], 5, 4e-3, 30.9e-6, 0.1545e-3)
    >>> from rough.experiment.observer import parse_observer
    >>> from rough.experiment.session import run_session, simulated_presenter
    >>> from rough.render import QuasiStatic, Settings
    >>> observer = parse_observer("rq=12,dimension=-4,seed=7")
    >>> present = simulated_presenter(study, observer, 0.02, QuasiStatic(), None, Settings(realtime=False))
    >>> answer, seconds, toggles = present(study.trials[0])
    >>> answer in ("first", "second"), f"{seconds:.3f} s", toggles  # two 3.86 mm strokes at 20 mm/s
    (True, '0.386 s', 1)
    >>> run_session(study, "S01", present, "sim")
    Progress(answered=8, remaining=0, total=8, interrupted=False)
    >>> folder.cleanup()
    """
    tracks = {}

    def present(trial):
        seconds = 0.0
        for side in ("first", "second"):
            name = trial[side]
            if name not in tracks:
                tracks[name] = Track.from_surface(read(study.surface_path(name)))
            stroke = simulate(tracks[name], speed, model, friction, settings, **hand)
            if stroke.ended_by == "interrupt":
                return None
            seconds += stroke.timing()["simulated_time"]
        test, reference = study.surfaces[trial["test"]], study.surfaces[trial["reference"]]
        rougher = observer.judges_test_rougher(
            trial["subject"], trial["trial"], test["dimension"] - reference["dimension"], test["rq"] - reference["rq"]
        )
        test_side = "first" if trial["first"] == trial["test"] else "second"
        return (test_side if rougher else ("second" if test_side == "first" else "first")), seconds, 1

    return present


class Keyboard:
    """Keys 1 and 2 from standard input, read by a background thread (single key
    presses on a terminal, lines otherwise)."""

    def __init__(self):
        self.key = None
        self._restore = None
        if sys.stdin is None:
            return
        if sys.stdin.isatty():
            import termios  # optional: POSIX terminals only
            import tty  # optional: POSIX terminals only

            descriptor = sys.stdin.fileno()
            saved = termios.tcgetattr(descriptor)
            tty.setcbreak(descriptor)
            self._restore = lambda: termios.tcsetattr(descriptor, termios.TCSADRAIN, saved)
        threading.Thread(target=self._listen, daemon=True, name="rough-keyboard").start()

    def _listen(self):
        while True:
            character = sys.stdin.read(1)
            if not character:
                return
            if character in ANSWER_KEYS:
                self.key = ANSWER_KEYS[character]

    def take(self):
        key, self.key = self.key, None
        return key

    def close(self):
        if self._restore is not None:
            self._restore()


def joystick_presenter(tracks, joystick, model, friction, settings, keyboard):
    """Present a trial on the joystick until the subject answers; ``tracks`` maps every
    surface name of the study to its :class:`~rough.render.Track`, read before the first
    trial so that trials follow each other without a pause."""
    held = HeldOpen(joystick)

    def answered(buttons):
        for mask, answer in ANSWER_BUTTONS.items():
            if buttons & mask:
                return answer
        return keyboard.take()

    def present(trial):
        pair = [tracks[trial["first"]], tracks[trial["second"]]]
        keyboard.take()
        started = time.monotonic()
        result = run(held, pair, model, friction, dataclasses.replace(settings, duration=None), until=answered)
        if result.ended_by != "answer":
            return None
        _wait_for_release(held)
        return result.answer, time.monotonic() - started, result.switches

    return present


def _wait_for_release(device, timeout=5.0):
    """Wait (force zero) until the answer button is let go, so it does not answer the next trial too."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and device.read()[2] & (2 | 4):
        device.zero()
        time.sleep(0.005)
