"""Analysis of paired comparisons (MATH.md §6): multiple logistic regression of "the test
surface was judged rougher" on its D and Rq and on subject indicators, by maximum
likelihood (statsmodels), with Wald statistics W = β/SE and p = 2(1 − Φ(|W|)) as the
paper printed them, likelihood-ratio tests as a cross-check, and a warning when the
data are (quasi-)separated, where Wald tests mislead (the Hauck–Donner effect).

D and Rq enter as differences from the set's reference (test minus reference; Rq in
mm): within one reference set this is the paper's model (the shift goes into the
constant), and sets with different references can be pooled.
"""

import dataclasses
import math
import warnings

import numpy as np

from ..errors import InputError
from .session import read_answers

SEPARATED_LOGIT = 15.0  # |linear predictor| beyond which a fitted probability is 1 - 3e-7: certainty


def wald_p(statistic):
    """Two-sided p-value of a Wald statistic: 2(1 − Φ(|W|))."""
    from scipy.stats import norm

    return float(2.0 * norm.sf(abs(statistic)))


@dataclasses.dataclass
class Analysis:
    coefficients: dict  # name -> {"estimate", "stderr", "wald", "p", "unit"}
    n: int
    subjects: list
    log_likelihood: float
    likelihood_ratio: dict  # name -> {"statistic", "p"}
    separation: bool
    converged: bool
    sets: list

    def as_dict(self):
        return dataclasses.asdict(self)


def answers_table(study, set_id=None):
    """All answers of the study (optionally of one reference set) as columns: test
    judged rougher (0/1), ΔD, ΔRq (mm), subject, set."""
    rows = []
    for subject in study.subjects:
        rows += read_answers(study, subject)
    known = {path.stem for path in (study.folder / "answers").glob("*.csv")} - set(study.subjects)
    if known:
        raise InputError(f"{study.folder}: answers from subjects not in the study: {', '.join(sorted(known))}")
    if set_id is not None:
        if set_id not in {s["id"] for s in study.sets}:
            raise InputError(
                f"{study.folder}: no reference set {set_id} (sets: {', '.join(str(s['id']) for s in study.sets)})"
            )
        rows = [row for row in rows if int(row["set"]) == set_id]
    if not rows:
        raise InputError(
            f"{study.folder}: no answers yet{'' if set_id is None else f' for set {set_id}'} (run "
            f"sessions with rough experiment run)"
        )
    return {
        "rougher": np.array([int(r["test_rougher"]) for r in rows], dtype=float),
        "dimension": np.array([float(r["test_dimension"]) - float(r["reference_dimension"]) for r in rows]),
        "rq": np.array([(float(r["test_rq_m"]) - float(r["reference_rq_m"])) * 1e3 for r in rows]),
        "subject": [r["subject"] for r in rows],
        "set": [int(r["set"]) for r in rows],
    }


def fit(table, subject_order=None):
    """The logistic regression of ``table`` (from :func:`answers_table`, or the same
    columns from elsewhere). The first subject (in ``subject_order``) is the baseline."""
    subjects = [s for s in (subject_order or sorted(set(table["subject"]))) if s in set(table["subject"])]
    columns = {"fractal_dimension": table["dimension"], "rq": table["rq"]}
    for name, values in columns.items():
        if np.ptp(values) == 0:
            raise InputError(f"{name.replace('_', ' ')} does not vary across these trials: it cannot be estimated")
    for subject in subjects[1:]:
        columns[f"subject_{subject}"] = np.array([s == subject for s in table["subject"]], dtype=float)
    columns["constant"] = np.ones_like(table["rougher"])
    full = _logit(table["rougher"], columns)
    units = {"fractal_dimension": "1/unit of D", "rq": "1/mm"}
    coefficients = {}
    for name, estimate, stderr in zip(columns, full.params, full.bse):
        wald = float(estimate / stderr) if stderr > 0 else math.nan
        coefficients[name] = {
            "estimate": float(estimate),
            "stderr": float(stderr),
            "wald": wald,
            "p": wald_p(wald) if math.isfinite(wald) else math.nan,
            "unit": units.get(name, "logit"),
        }
    ratio = {}
    for name in ("fractal_dimension", "rq"):
        reduced = _logit(table["rougher"], {k: v for k, v in columns.items() if k != name})
        statistic = max(0.0, 2.0 * (full.llf - reduced.llf))
        from scipy.stats import chi2

        ratio[name] = {"statistic": statistic, "p": float(chi2.sf(statistic, 1))}
    design = np.column_stack(list(columns.values()))
    separation = (not full.mle_retvals.get("converged", True)) or bool(
        np.abs(design @ full.params).max() > SEPARATED_LOGIT
    )
    return Analysis(
        coefficients,
        int(table["rougher"].size),
        subjects,
        float(full.llf),
        ratio,
        separation,
        bool(full.mle_retvals.get("converged", True)),
        sorted(set(table["set"])),
    )


def _logit(response, columns):
    import statsmodels.api as sm

    design = np.column_stack(list(columns.values()))
    if np.linalg.matrix_rank(design) < design.shape[1]:
        raise InputError(
            "the design is degenerate: a predictor is a combination of others (too few trials or subjects)"
        )
    with warnings.catch_warnings(), np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        warnings.simplefilter("ignore")
        return sm.Logit(response, design).fit(disp=0, method="newton", maxiter=100)


def percentages(study, set_id):
    """Per test surface of a set: (surface id, D, Rq m, % of answers judging it rougher, answers)."""
    table = answers_table(study, set_id)
    entry = next(s for s in study.sets if s["id"] == set_id)
    reference = study.surfaces[entry["reference"]]
    result = []
    for name in entry["neighbours"]:
        test = study.surfaces[name]
        chosen = [
            r
            for r, d, q in zip(table["rougher"], table["dimension"], table["rq"])
            if math.isclose(d, test["dimension"] - reference["dimension"], abs_tol=1e-9)
            and math.isclose(q, (test["rq"] - reference["rq"]) * 1e3, abs_tol=1e-9)
        ]
        result.append(
            (name, test["dimension"], test["rq"], 100.0 * np.mean(chosen) if chosen else math.nan, len(chosen))
        )
    return result
