"""Analysis of paired comparisons (docs/math.rst §6): multiple logistic regression of "the test
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
from statistics import NormalDist

import numpy as np
from scipy.stats import chi2, norm

from ..errors import InputError
from ..extras import require
from .session import read_answers

SEPARATED_LOGIT = 15.0  # |linear predictor| beyond which a fitted probability is 1 - 3e-7: certainty


def wald_p(statistic):
    """Two-sided p-value of a Wald statistic: 2(1 − Φ(|W|))."""
    return float(2.0 * norm.sf(abs(statistic)))


@dataclasses.dataclass
class Analysis:
    """The result of :func:`fit`: the logistic regression, as the paper's tables print it.

    Attributes
    ----------
    coefficients : dict
        Name → ``{"estimate", "stderr", "wald", "p", "unit"}``, for
        ``fractal_dimension`` (per unit of D), ``rq`` (per mm of Rq), one
        ``subject_<ID>`` per subject but the first (logit) and ``constant`` (logit);
        ``wald`` is ``W = β/SE`` and ``p = 2(1 − Φ(|W|))`` (NaN when SE is 0).
    n : int
        The number of answers.
    subjects : list of str
        The subjects, the first being the baseline.
    log_likelihood : float
        Of the full model.
    likelihood_ratio : dict
        ``fractal_dimension`` and ``rq`` → ``{"statistic", "p"}``: likelihood-ratio
        tests (χ², one degree of freedom) of leaving each out, a cross-check of the
        Wald tests.
    separation : bool
        True when the data are (quasi-)separated (the fit did not converge, or some
        fitted probability is within 3e-7 of certainty), where Wald tests mislead.
    converged : bool
        Whether the maximum-likelihood fit converged.
    sets : list of int
        The reference sets the answers came from.

    Notes
    -----
    ``as_dict()`` gives the fields as a JSON-able dict.

    Examples
    --------
    >>> import numpy as np
    >>> from rough.experiment.analysis import fit
    >>> table = {
    ...     "rougher": np.array([0.0, 1, 1, 0, 1, 0, 1, 1]),
    ...     "dimension": np.array([-0.075, 0.075, 0, 0, 0.075, -0.075, 0, 0.075]),
    ...     "rq": np.array([0.0, 0, 0.07, -0.06, 0.07, -0.06, 0.07, 0]),  # mm
    ...     "subject": ["S01"] * 8,
    ...     "set": [1] * 8,
    ... }
    >>> analysis = fit(table)
    >>> analysis.n, analysis.subjects, list(analysis.coefficients)
    (8, ['S01'], ['fractal_dimension', 'rq', 'constant'])
    >>> sorted(analysis.coefficients["rq"])
    ['estimate', 'p', 'stderr', 'unit', 'wald']
    """

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
    """All answers of a study as columns for :func:`fit`.

    Parameters
    ----------
    study : Study
        The study, from :func:`~rough.experiment.design.load_study`.
    set_id : int, optional
        Only the answers of this reference set; default all.

    Returns
    -------
    dict
        ``rougher``: 1.0 where the test was judged rougher, else 0.0;
        ``dimension``: ΔD and ``rq``: ΔRq in mm (test minus reference, nominal
        values of the design), as float arrays; ``subject`` and ``set``: lists.

    Raises
    ------
    rough.InputError
        For answers from subjects not in the study, an unknown set, no answers yet,
        or an answers file that does not match the trial list.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from rough.experiment.design import grid_design, write_study
    >>> surfaces, sets = grid_design([(1.275, 0.2781e-3)], 0.075, 1.2593)
    >>> folder = tempfile.TemporaryDirectory()
    >>> place = pathlib.Path(folder.name) / "study"
    >>> study = write_study(place, surfaces, sets, ["S01", "S02"], 5, 4e-3, 30.9e-6, 0.1545e-3)
    >>> from rough.experiment.analysis import answers_table
    >>> from rough.experiment.session import run_session
    >>> for subject in study.subjects:
    ...     _ = run_session(study, subject, lambda trial: ("first", 1.0, 1), "script")
    >>> table = answers_table(study)
    >>> sorted(table), table["rougher"].size
    (['dimension', 'rougher', 'rq', 'set', 'subject'], 16)
    >>> sorted(set(table["dimension"].round(3).tolist()))  # ΔD
    [-0.075, 0.0, 0.075]
    >>> sorted(set(table["rq"].round(4).tolist()))  # ΔRq, mm
    [-0.0573, 0.0, 0.0721]
    >>> folder.cleanup()
    """
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
    surfaces = study.surfaces
    return {
        "rougher": np.array([int(r["test_rougher"]) for r in rows], dtype=float),
        "dimension": np.array([surfaces[r["test"]]["dimension"] - surfaces[r["reference"]]["dimension"] for r in rows]),
        "rq": np.array([(surfaces[r["test"]]["rq"] - surfaces[r["reference"]]["rq"]) * 1e3 for r in rows]),
        "subject": [r["subject"] for r in rows],
        "set": [int(r["set"]) for r in rows],
    }


def fit(table, subject_order=None):
    """The logistic regression of "the test was judged rougher" on ΔD, ΔRq and subject.

    ``logit P = β0 + β_D ΔD + β_Rq ΔRq + Σ γ_s S_s``, by maximum likelihood
    (statsmodels' Newton), with one indicator per subject but the first.

    Parameters
    ----------
    table : dict
        Columns as :func:`answers_table` gives them (or the same from elsewhere):
        ``rougher`` (0/1), ``dimension`` (ΔD) and ``rq`` (ΔRq, mm) as arrays,
        ``subject`` and ``set`` as lists.
    subject_order : list of str, optional
        The order of the subjects; the first one present is the baseline. Default:
        sorted.

    Returns
    -------
    Analysis
        Estimates, standard errors, Wald statistics and p-values, likelihood-ratio
        tests, and whether the data are separated.

    Raises
    ------
    rough.InputError
        When ΔD or ΔRq does not vary across the trials, or the design is degenerate
        (a predictor is a combination of others: too few trials or subjects).

    Notes
    -----
    Wald tests mislead under (quasi-)separation (the Hauck–Donner effect);
    ``Analysis.separation`` flags it. ML logistic regression is biased away from
    zero in small samples.

    Examples
    --------
    2000 simulated answers with known slopes, -4 per unit of D and 12 per mm of Rq:
    the estimates lie within about one standard error of them.

    >>> import numpy as np
    >>> from rough.experiment.analysis import fit
    >>> rng = np.random.default_rng(0)
    >>> delta_d = rng.choice([-0.075, 0.0, 0.075], 2000)
    >>> delta_rq = rng.choice([-0.06, 0.0, 0.07], 2000)  # mm
    >>> probability = 1 / (1 + np.exp(-(0.2 - 4 * delta_d + 12 * delta_rq)))
    >>> table = {
    ...     "rougher": (rng.random(2000) < probability).astype(float),
    ...     "dimension": delta_d,
    ...     "rq": delta_rq,
    ...     "subject": [f"S{k % 4}" for k in range(2000)],
    ...     "set": [1] * 2000,
    ... }
    >>> analysis = fit(table)
    >>> for name in ("fractal_dimension", "rq"):
    ...     c = analysis.coefficients[name]
    ...     print(f"{name}: {c['estimate']:.1f} ± {c['stderr']:.1f} {c['unit']}, W = {c['wald']:.1f}, ", end="")
    ...     print(f"p < 1e-4: {c['p'] < 1e-4}")
    fractal_dimension: -3.4 ± 0.8 1/unit of D, W = -4.4, p < 1e-4: True
    rq: 11.8 ± 0.9 1/mm, W = 12.8, p < 1e-4: True
    >>> analysis.n, analysis.separation, analysis.converged
    (2000, False, True)
    """
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
    sm = require("statsmodels.api")

    design = np.column_stack(list(columns.values()))
    if not (np.isfinite(design).all() and np.isfinite(response).all()):
        raise InputError("the answers hold values that are not finite numbers")
    if np.linalg.matrix_rank(design) < design.shape[1]:
        raise InputError(
            "the design is degenerate: a predictor is a combination of others (too few trials or subjects)"
        )
    with warnings.catch_warnings(), np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        warnings.simplefilter("ignore")
        try:
            return sm.Logit(response, design).fit(disp=0, method="newton", maxiter=100)
        except np.linalg.LinAlgError as error:
            raise InputError(f"the logistic fit failed on these answers ({error})") from None


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


def proportion_interval(successes, trials, level=0.95):
    """The Wilson score interval for a proportion: ``successes`` of ``trials``.

    Uses :func:`statsmodels.stats.proportion.proportion_confint` (``method="wilson"``)
    when statsmodels is installed, else the same closed form.

    Parameters
    ----------
    successes, trials : int
        Counts, ``0 <= successes <= trials``, ``trials > 0``.
    level : float, default 0.95
        The confidence level.

    Returns
    -------
    tuple of float
        ``(low, high)``, proportions in [0, 1].

    Examples
    --------
    >>> from rough.experiment import proportion_interval
    >>> [round(p, 4) for p in proportion_interval(6, 8)]
    [0.4093, 0.9285]
    >>> [round(p, 4) for p in proportion_interval(0, 8)]
    [0.0, 0.3244]
    """
    try:
        from statsmodels.stats.proportion import proportion_confint  # optional: experiment
    except ImportError:
        z = NormalDist().inv_cdf(0.5 + level / 2)
        p = successes / trials
        denominator = 1 + z**2 / trials
        centre = (p + z**2 / (2 * trials)) / denominator
        half = z / denominator * math.sqrt(p * (1 - p) / trials + z**2 / (4 * trials**2))
        return max(0.0, centre - half), min(1.0, centre + half)
    low, high = proportion_confint(successes, trials, alpha=1 - level, method="wilson")
    return float(low), float(high)
