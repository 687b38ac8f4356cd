"""Paired-comparison designs: reference surfaces, their neighbours on a (D, Rq) grid,
and the trial list, written to a study folder.

A study folder holds ``study.json`` (the design: every surface's D, Rq and seed, the
subjects, the randomisation seed), ``surfaces/*.x3p`` (the profiles, synthesised with
their recorded seeds), ``trials.csv`` (subject, trial, set, reference, test, first,
second: the order and sides, randomised per subject) and, once sessions run,
``answers/<subject>.csv``. The analysis uses the nominal D and Rq of the design;
``study.json`` also records each surface's Rq as stored (``rq_measured``, after
resampling), which differs slightly (docs/math.rst §6.3).

The ``costa2000`` preset is the paper's design: references D = 1.275, Rq = 0.2781 mm
and D = 1.425, Rq = 0.75 mm, each compared with the eight neighbours of a 3 × 3 grid of
D ± 0.075 and Rq × (1.2593)^±1, 80 mm profiles synthesised at 0.0309 mm (the
encoder's resolution) and stored at 0.1545 mm, 14 subjects. The paper states only one
neighbour's Rq (0.3502 mm, Rq × 1.2593 for the first set); the other levels follow the
same ratio, an assumption (docs/math.rst §6.1).
"""

import csv
import dataclasses
import io
import json
import math
import os
import pathlib
import re
import shutil
import tempfile

import numpy as np

from ..errors import InputError
from ..fractal import resample, synthesize_profile

FORMAT = "rough-study 1"
TRIAL_FIELDS = ("subject", "trial", "set", "reference", "test", "first", "second")
COSTA2000 = {
    "references": [(1.275, 0.2781e-3), (1.425, 0.75e-3)],
    "dimension_step": 0.075,
    "rq_factor": 0.3502 / 0.2781,
    "subjects": 14,
    "length": 80e-3,
    "synthesis_spacing": 30.9e-6,
    "spacing": 0.1545e-3,
}


@dataclasses.dataclass
class Study:
    """A study folder's design, as :func:`load_study` reads it.

    Attributes
    ----------
    folder : pathlib.Path
        Where the study lives.
    surfaces : dict
        Surface id → ``{"file", "dimension", "rq", "seed", "rq_measured"}``: the
        profile's file (relative to ``folder``), its nominal D and Rq (m), its
        synthesis seed and its Rq as stored, after resampling (m).
    sets : list of dict
        ``{"id", "reference", "neighbours"}`` per reference set.
    subjects : list of str
        The subject ids.
    trials : list of dict
        Every trial, with the fields of ``TRIAL_FIELDS``: subject, trial (number),
        set, reference, test, first, second.
    seed : int
        The randomisation seed of the design.
    preset : str or None
        The preset the design came from (``costa2000``), if any.

    Notes
    -----
    Methods: ``surface_path(surface_id)`` (the path of a surface's file),
    ``trials_of(subject)`` (the subject's trials in order; an InputError for an
    unknown subject) and ``answers_path(subject)`` (``answers/<subject>.csv``).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from rough.experiment.design import grid_design, write_study
    >>> surfaces, sets = grid_design([(1.275, 0.2781e-3)], 0.075, 1.2593)
    >>> folder = tempfile.TemporaryDirectory()
    >>> study = write_study(
    ...     pathlib.Path(folder.name) / "study", surfaces, sets, ["S01", "S02"], seed=5,
    ...     length=4e-3, synthesis_spacing=30.9e-6, spacing=0.1545e-3,
    ... )
    >>> study.subjects, len(study.trials), len(study.trials_of("S01"))
    (['S01', 'S02'], 16, 8)
    >>> study.surface_path("R1").name, study.answers_path("S02").name
    ('R1.x3p', 'S02.csv')
    >>> folder.cleanup()
    """

    folder: pathlib.Path
    surfaces: dict  # id -> {"file", "dimension", "rq", "seed"}
    sets: list  # [{"id", "reference", "neighbours"}]
    subjects: list
    trials: list  # dicts with TRIAL_FIELDS
    seed: int
    preset: str = None

    def surface_path(self, surface_id):
        return self.folder / self.surfaces[surface_id]["file"]

    def trials_of(self, subject):
        if subject not in self.subjects:
            raise InputError(f"{self.folder}: subject {subject!r} is not in the study ({', '.join(self.subjects)})")
        return [t for t in self.trials if t["subject"] == subject]

    def answers_path(self, subject):
        if not is_name(subject):
            raise InputError(f"{self.folder}: subject {subject!r} is not a name (letters, digits, - and _)")
        return self.folder / "answers" / f"{subject}.csv"


def grid_design(references, dimension_step, rq_factor):
    """The surfaces and reference sets of a grid design around each reference.

    Each reference is compared with the eight neighbours of its 3 × 3 grid
    ``D + {-1, 0, 1}·dimension_step``, ``Rq × rq_factor^{-1, 0, 1}``.

    Parameters
    ----------
    references : list of tuple of float
        ``[(D, Rq), ...]``: each reference's fractal dimension and RMS height (m).
    dimension_step : float
        The step in D between grid levels.
    rq_factor : float
        The ratio of Rq between grid levels.

    Returns
    -------
    surfaces : dict
        Surface id → ``{"dimension", "rq"}`` (Rq in m): the references ``R1``, ``R2``,
        … and their neighbours, named like ``R1-D1.35-Rq0.3502mm``.
    sets : list of dict
        ``{"id", "reference", "neighbours"}`` per reference, ids from 1.

    Examples
    --------
    The paper's first set (``COSTA2000``):

    >>> from rough.experiment.design import grid_design
    >>> surfaces, sets = grid_design([(1.275, 0.2781e-3)], dimension_step=0.075, rq_factor=0.3502 / 0.2781)
    >>> len(surfaces), sets[0]["id"], sets[0]["reference"], len(sets[0]["neighbours"])
    (9, 1, 'R1', 8)
    >>> test = sets[0]["neighbours"][-1]  # one step up in D and in Rq
    >>> test, surfaces[test]["dimension"], f"{surfaces[test]['rq'] * 1e3:.4f} mm"
    ('R1-D1.35-Rq0.3502mm', 1.35, '0.3502 mm')
    """
    surfaces, sets = {}, []
    for number, (dimension, rq) in enumerate(references, start=1):
        reference = f"R{number}"
        surfaces[reference] = {"dimension": dimension, "rq": rq}
        neighbours = []
        for i in (-1, 0, 1):
            for j in (-1, 0, 1):
                if i == j == 0:
                    continue
                test = {"dimension": round(dimension + i * dimension_step, 10), "rq": rq * rq_factor**j}
                name = f"R{number}-D{test['dimension']:.4g}-Rq{test['rq'] * 1e3:.4g}mm"
                surfaces[name] = test
                neighbours.append(name)
        sets.append({"id": number, "reference": reference, "neighbours": neighbours})
    return surfaces, sets


def trial_list(sets, subjects, seed):
    """Every subject compares each reference with each of its neighbours once, in a
    random order with a random side for the test, seeded by (seed, subject index)."""
    pairs = [(s["id"], s["reference"], test) for s in sets for test in s["neighbours"]]
    trials = []
    for index, subject in enumerate(subjects):
        generator = np.random.default_rng([seed, index])
        order = generator.permutation(len(pairs))
        test_first = generator.integers(0, 2, size=len(pairs)).astype(bool)
        for number, (k, first) in enumerate(zip(order, test_first), start=1):
            set_id, reference, test = pairs[k]
            trials.append(
                {
                    "subject": subject,
                    "trial": number,
                    "set": set_id,
                    "reference": reference,
                    "test": test,
                    "first": test if first else reference,
                    "second": reference if first else test,
                }
            )
    return trials


def subject_ids(subjects):
    """``14`` → S01 … S14; ``alice,bob`` → those names."""
    if isinstance(subjects, int) or str(subjects).isdigit():
        count = int(subjects)
        if not 1 <= count <= 999:
            raise InputError("give between 1 and 999 subjects")
        return [f"S{k:0{max(2, len(str(count)))}d}" for k in range(1, count + 1)]
    names = [name.strip() for name in str(subjects).split(",") if name.strip()]
    if len(set(names)) != len(names) or not all(is_name(n) for n in names):
        raise InputError("subject names must be distinct and use letters, digits, - and _ only")
    return names


def write_study(folder, surfaces, sets, subjects, seed, length, synthesis_spacing, spacing, preset=None):
    """Synthesise every surface and write the study folder, atomically.

    Each surface is a whole-length spectral synthesis with its own seed (drawn from
    ``seed``), scaled to its Rq, then band-limited resampling to ``spacing``. The
    folder is staged beside its final place and renamed when complete: it appears
    complete or not at all.

    Parameters
    ----------
    folder : str or os.PathLike
        The study folder: new, or an existing empty folder; its parent must exist.
    surfaces : dict
        Surface id → ``{"dimension", "rq"}`` (Rq in m), as from :func:`grid_design`.
        Updated in place with each surface's ``file``, ``seed`` and ``rq_measured``
        (its Rq as stored, m).
    sets : list of dict
        ``{"id", "reference", "neighbours"}``, as from :func:`grid_design`.
    subjects : list of str
        Subject ids (letters, digits, ``-`` and ``_``).
    seed : int
        Seeds the surfaces and the randomisation of each subject's trial order and
        sides.
    length : float
        The profiles' length, m.
    synthesis_spacing : float
        The spacing the profiles are synthesised at, m (the paper's encoder
        resolution is 30.9 µm).
    spacing : float
        The spacing they are stored at, m (the paper's 0.1545 mm).
    preset : str, optional
        The name of the preset the design came from, recorded in ``study.json``.

    Returns
    -------
    Study
        The study as :func:`load_study` reads it back.

    Raises
    ------
    rough.InputError
        For an existing non-empty folder (or a file), or a parent folder that does
        not exist. Nothing is left behind on any failure.

    Notes
    -----
    The folder holds ``study.json`` (the design), ``surfaces/*.x3p``, ``trials.csv``
    (every subject compares each reference with each of its neighbours once, in a
    random order with a random side for the test) and an empty ``answers/``.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> import rough
    >>> from rough.experiment.design import grid_design, write_study
    >>> surfaces, sets = grid_design([(1.275, 0.2781e-3)], 0.075, 1.2593)
    >>> folder = tempfile.TemporaryDirectory()
    >>> place = pathlib.Path(folder.name) / "study"
    >>> study = write_study(
    ...     place, surfaces, sets, ["S01", "S02"], seed=5, length=4e-3, synthesis_spacing=30.9e-6, spacing=0.1545e-3
    ... )
    >>> sorted(path.name for path in place.iterdir())
    ['answers', 'study.json', 'surfaces', 'trials.csv']
    >>> len(list((place / "surfaces").glob("*.x3p"))), len(study.trials)  # 9 surfaces; 8 trials per subject
    (9, 16)
    >>> f"{study.surfaces['R1']['rq_measured'] * 1e3:.4f} mm"  # the nominal 0.2781 mm, after resampling
    '0.2729 mm'
    >>> try:
    ...     write_study(place, surfaces, sets, ["S01"], 5, 4e-3, 30.9e-6, 0.1545e-3)
    ... except rough.InputError as error:
    ...     print(str(error).endswith("exists and is not an empty folder; choose a new study folder"))
    True
    >>> folder.cleanup()
    """
    folder = pathlib.Path(folder)
    if folder.exists() and (not folder.is_dir() or any(folder.iterdir())):
        raise InputError(f"{folder}: exists and is not an empty folder; choose a new study folder")
    parent = folder.resolve().parent
    if not parent.is_dir():
        raise InputError(f"{folder}: the folder {parent} does not exist")
    points = round(length / synthesis_spacing)
    seeds = np.random.SeedSequence(seed).generate_state(len(surfaces))
    staging = pathlib.Path(tempfile.mkdtemp(prefix=".rough-study-", dir=parent))
    try:
        (staging / "surfaces").mkdir()
        (staging / "answers").mkdir()
        for (name, surface), surface_seed in zip(sorted(surfaces.items()), seeds):
            profile = synthesize_profile(
                points, synthesis_spacing, surface["dimension"], rq=surface["rq"], seed=int(surface_seed)
            )
            if not math.isclose(spacing, synthesis_spacing):
                profile = resample(profile, spacing)
            profile.metadata["title"] = (
                f"study surface {name}: D = {surface['dimension']:g}, Rq = {surface['rq'] * 1e3:.4g} mm"
            )
            profile.write(staging / "surfaces" / f"{name}.x3p")
            heights = profile.heights - profile.heights.mean()
            surface.update(
                file=f"surfaces/{name}.x3p", seed=int(surface_seed), rq_measured=float(np.sqrt(np.mean(heights**2)))
            )
        document = {
            "format": FORMAT,
            "preset": preset,
            "seed": seed,
            "length": length,
            "synthesis_spacing": synthesis_spacing,
            "spacing": spacing,
            "subjects": subjects,
            "sets": sets,
            "surfaces": surfaces,
        }
        (staging / "study.json").write_text(json.dumps(document, indent=2) + "\n")
        _write_trials(staging / "trials.csv", trial_list(sets, subjects, seed))
        if folder.exists():
            folder.rmdir()
        os.replace(staging, folder)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    return load_study(folder)


def load_study(folder):
    """Read and check a study folder.

    Parameters
    ----------
    folder : str or os.PathLike
        A folder made by :func:`write_study`.

    Returns
    -------
    Study
        The design, its surfaces and its trial list.

    Raises
    ------
    rough.InputError
        Naming the folder or file, for a folder without ``study.json``, a
        ``study.json`` that is not valid JSON, not a ``rough-study 1`` file or an
        incomplete design, a missing surface file, or a missing or malformed
        ``trials.csv``.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> import rough
    >>> from rough.experiment.design import grid_design, load_study, write_study
    >>> surfaces, sets = grid_design([(1.275, 0.2781e-3)], 0.075, 1.2593)
    >>> folder = tempfile.TemporaryDirectory()
    >>> place = pathlib.Path(folder.name) / "study"
    >>> _ = write_study(place, surfaces, sets, ["S01"], 5, 4e-3, 30.9e-6, 0.1545e-3)
    >>> study = load_study(place)
    >>> study.subjects, study.seed, study.sets[0]["reference"]
    (['S01'], 5, 'R1')
    >>> try:
    ...     load_study(place / "surfaces")
    ... except rough.InputError as error:
    ...     print(str(error).split(": ", 1)[1])
    not a study folder (no study.json; make one with rough experiment design)
    >>> folder.cleanup()
    """
    folder = pathlib.Path(folder)
    path = folder / "study.json"
    if not path.is_file():
        raise InputError(f"{folder}: not a study folder (no study.json; make one with rough experiment design)")
    try:
        document = json.loads(path.read_text(), parse_constant=_refuse_constant)
    except (UnicodeError, json.JSONDecodeError) as error:
        raise InputError(f"{path}: not valid JSON ({error})") from None
    except ValueError as error:
        raise InputError(f"{path}: {error}") from None
    if not isinstance(document, dict) or document.get("format") != FORMAT:
        raise InputError(f"{path}: not a {FORMAT} file")
    try:
        surfaces, sets, subjects, seed = _check_design(document)
    except (KeyError, TypeError, ValueError, AttributeError) as error:
        raise InputError(f"{path}: incomplete or malformed design ({error})") from None
    for name, surface in surfaces.items():
        if not (folder / surface["file"]).is_file():
            raise InputError(f"{folder}: surface {name} is missing ({surface['file']})")
    trials = _read_trials(folder / "trials.csv", surfaces, sets, subjects)
    return Study(folder, surfaces, sets, list(subjects), trials, seed, document.get("preset"))


def _refuse_constant(name):
    raise ValueError(f"{name} is not a number a design can hold")


def _check_design(document):
    surfaces, sets, subjects = document["surfaces"], document["sets"], document["subjects"]
    seed = document["seed"]
    if not isinstance(seed, int) or seed < 0:
        raise ValueError(f"seed {seed!r} is not a whole number")
    if not isinstance(subjects, list) or not subjects or len(set(map(str, subjects))) != len(subjects):
        raise ValueError("subjects must be a list of distinct names")
    for subject in subjects:
        if not is_name(subject):
            raise ValueError(f"subject {subject!r} is not a name (letters, digits, - and _)")
    for name, surface in surfaces.items():
        dimension, rq, file = surface["dimension"], surface["rq"], surface["file"]
        if not (_number(dimension) and _number(rq) and rq > 0):
            raise ValueError(f"surface {name}: D and Rq must be finite numbers, Rq positive")
        parts = pathlib.PurePosixPath(file).parts if isinstance(file, str) else ()
        if not parts or file.startswith("/") or "\\" in file or ".." in parts:
            raise ValueError(f"surface {name}: file {file!r} is not a path inside the study folder")
    ids = [entry["id"] for entry in sets]
    if not sets or len(set(ids)) != len(ids) or not all(isinstance(i, int) and not isinstance(i, bool) for i in ids):
        raise ValueError("sets need distinct whole-number ids")
    for entry in sets:
        if entry["reference"] not in surfaces or not all(n in surfaces for n in entry["neighbours"]):
            raise ValueError(f"set {entry['id']} names an unknown surface")
    return surfaces, sets, subjects, seed


def _number(value):
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def read_rows(path, fields, what):
    """The rows of the CSV file ``path`` with exactly the columns ``fields``, as
    ``(line, dict)``; an InputError naming the file (and line) otherwise."""
    if not path.is_file():
        raise InputError(f"{path}: {what} is missing or not a regular file")
    try:
        rows = list(csv.reader(io.StringIO(path.read_text(encoding="utf-8"), newline="")))
    except (UnicodeError, csv.Error) as error:
        raise InputError(f"{path}: not a readable {what} ({error})") from None
    except OSError as error:
        raise InputError(f"{path}: cannot read the {what} ({error.strerror})") from None
    if not rows or tuple(rows[0]) != tuple(fields):
        raise InputError(f"{path}: expected the columns {', '.join(fields)}")
    result = []
    for line, row in enumerate(rows[1:], start=2):
        if not row:
            continue
        if len(row) != len(fields):
            raise InputError(f"{path}, line {line}: {len(row)} fields, expected {len(fields)} (a cut or damaged row)")
        result.append((line, dict(zip(fields, row))))
    return result


def _write_trials(path, trials):
    with open(path, "w", newline="") as stream:
        writer = csv.DictWriter(stream, TRIAL_FIELDS)
        writer.writeheader()
        writer.writerows(trials)


def _read_trials(path, surfaces, sets, subjects):
    by_id = {entry["id"]: entry for entry in sets}
    trials, seen = [], set()
    for line, row in read_rows(path, TRIAL_FIELDS, "trial list trials.csv"):
        try:
            trial = {**row, "trial": int(row["trial"]), "set": int(row["set"])}
        except ValueError:
            raise InputError(f"{path}, line {line}: trial and set must be whole numbers") from None
        entry = by_id.get(trial["set"])
        if (
            trial["subject"] not in subjects
            or entry is None
            or trial["reference"] != entry["reference"]
            or trial["test"] not in entry["neighbours"]
            or sorted((trial["first"], trial["second"])) != sorted((trial["test"], trial["reference"]))
        ):
            raise InputError(f"{path}, line {line}: unknown surface, set or subject, or first/second not the pair")
        if trial["trial"] < 1 or (trial["subject"], trial["trial"]) in seen:
            raise InputError(f"{path}, line {line}: trial {trial['trial']} of {trial['subject']} is not a new number")
        seen.add((trial["subject"], trial["trial"]))
        trials.append(trial)
    return trials


def is_name(name):
    """Letters, digits, ``-`` and ``_``: a subject name that is safe as a file name."""
    return isinstance(name, str) and re.fullmatch(r"[A-Za-z0-9_-]+", name) is not None
