"""Paired-comparison designs: reference surfaces, their neighbours on a (D, Rq) grid,
and the trial list, written to a study folder.

A study folder holds ``study.json`` (the design: every surface's D, Rq and seed, the
subjects, the randomisation seed), ``surfaces/*.x3p`` (the profiles, synthesised with
their recorded seeds), ``trials.csv`` (subject, trial, set, reference, test, first,
second: the order and sides, randomised per subject) and, once sessions run,
``answers/<subject>.csv``. The analysis uses the nominal D and Rq of the design;
``study.json`` also records each surface's Rq as stored (``rq_measured``, after
resampling), which differs slightly (MATH.md §6.3).

The ``costa2000`` preset is the paper's design: references D = 1.275, Rq = 0.2781 mm
and D = 1.425, Rq = 0.75 mm, each compared with the eight neighbours of a 3 × 3 grid of
D ± 0.075 and Rq × (1.2593)^±1, 80 mm profiles synthesised at 0.0309 mm (the
encoder's resolution) and stored at 0.1545 mm, 14 subjects. The paper states only one
neighbour's Rq (0.3502 mm, Rq × 1.2593 for the first set); the other levels follow the
same ratio, an assumption (MATH.md §6.1).
"""

import csv
import dataclasses
import io
import json
import math
import os
import pathlib
import shutil
import tempfile

import numpy as np

from ..errors import InputError

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
    """A study folder's design (see the module notes); ``folder`` is where it lives."""

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
        return self.folder / "answers" / f"{subject}.csv"


def grid_design(references, dimension_step, rq_factor):
    """Surfaces and sets for ``references`` [(D, Rq m), ...]: each with the eight
    neighbours of its 3 × 3 grid D + {-1, 0, 1}·step, Rq × factor^{-1, 0, 1}."""
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
    if len(set(names)) != len(names) or not all(_safe_name(n) for n in names):
        raise InputError("subject names must be distinct and use letters, digits, - and _ only")
    return names


def write_study(folder, surfaces, sets, subjects, seed, length, synthesis_spacing, spacing, preset=None):
    """Synthesise every surface (whole-length spectral synthesis with its own seed,
    then band-limited resampling to ``spacing``) and write the study folder, atomically:
    it appears complete or not at all. Refuses an existing non-empty folder."""
    from ..fractal.resample import resample
    from ..fractal.synth import synthesize_profile

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
    """Read and check a study folder; any fault is an InputError naming the folder."""
    folder = pathlib.Path(folder)
    path = folder / "study.json"
    if not path.is_file():
        raise InputError(f"{folder}: not a study folder (no study.json; make one with rough experiment design)")
    try:
        document = json.loads(path.read_text())
    except (UnicodeError, json.JSONDecodeError) as error:
        raise InputError(f"{path}: not valid JSON ({error})") from None
    if not isinstance(document, dict) or document.get("format") != FORMAT:
        raise InputError(f"{path}: not a {FORMAT} file")
    try:
        surfaces, sets, subjects, seed = (
            document["surfaces"],
            document["sets"],
            document["subjects"],
            int(document["seed"]),
        )
        for surface in surfaces.values():
            float(surface["dimension"]), float(surface["rq"]), str(surface["file"])
        for entry in sets:
            if entry["reference"] not in surfaces or not all(n in surfaces for n in entry["neighbours"]):
                raise KeyError("a set names an unknown surface")
    except (KeyError, TypeError, ValueError, AttributeError) as error:
        raise InputError(f"{path}: incomplete or malformed design ({error})") from None
    for name, surface in surfaces.items():
        if not (folder / surface["file"]).is_file():
            raise InputError(f"{folder}: surface {name} is missing ({surface['file']})")
    trials = _read_trials(folder / "trials.csv", surfaces, subjects)
    return Study(folder, surfaces, sets, list(subjects), trials, seed, document.get("preset"))


def _write_trials(path, trials):
    with open(path, "w", newline="") as stream:
        writer = csv.DictWriter(stream, TRIAL_FIELDS)
        writer.writeheader()
        writer.writerows(trials)


def _read_trials(path, surfaces, subjects):
    if not path.is_file():
        raise InputError(f"{path.parent}: the trial list trials.csv is missing")
    rows = list(csv.DictReader(io.StringIO(path.read_text())))
    if not rows or set(rows[0]) != set(TRIAL_FIELDS):
        raise InputError(f"{path}: expected the columns {', '.join(TRIAL_FIELDS)}")
    trials = []
    for line, row in enumerate(rows, start=2):
        try:
            trial = {**row, "trial": int(row["trial"]), "set": int(row["set"])}
        except ValueError:
            raise InputError(f"{path}, line {line}: trial and set must be whole numbers") from None
        names = {trial["reference"], trial["test"]}
        if not names <= set(surfaces) or {trial["first"], trial["second"]} != names or trial["subject"] not in subjects:
            raise InputError(f"{path}, line {line}: unknown surface or subject, or first/second not the pair")
        trials.append(trial)
    return trials


def _safe_name(name):
    return all(c.isalnum() or c in "-_" for c in name)
