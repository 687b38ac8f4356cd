"""A scripted observer for headless sessions: judges the test surface rougher with
probability ``logistic(bias + u_s + rq·ΔRq + dimension·ΔD)``, ΔRq in mm and ΔD in units
of D (test minus reference), ``u_s`` a per-subject intercept drawn from N(0, spread²).
Every draw is seeded by (seed, subject, trial), so a resumed session answers as an
unbroken one would."""

import dataclasses
import math
import zlib

import numpy as np

from ..errors import InputError

KEYS = {"rq": "per mm of Rq", "dimension": "per unit of D", "bias": "logit", "spread": "logit", "seed": "integer"}


@dataclasses.dataclass(frozen=True)
class Observer:
    rq: float = 0.0
    dimension: float = 0.0
    bias: float = 0.0
    spread: float = 0.0
    seed: int = 0

    def subject_offset(self, subject):
        generator = np.random.default_rng([self.seed, zlib.crc32(subject.encode())])
        return float(generator.normal(0.0, self.spread)) if self.spread > 0 else 0.0

    def probability(self, subject, delta_dimension, delta_rq):
        """P(test judged rougher) for a test differing by ``delta_dimension`` and ``delta_rq`` (m)."""
        logit = self.bias + self.subject_offset(subject) + self.rq * delta_rq * 1e3 + self.dimension * delta_dimension
        return 1.0 / (1.0 + math.exp(-logit))

    def judges_test_rougher(self, subject, trial, delta_dimension, delta_rq):
        generator = np.random.default_rng([self.seed, zlib.crc32(subject.encode()), trial, 1])
        return bool(generator.random() < self.probability(subject, delta_dimension, delta_rq))


def parse_observer(spec):
    """A scripted observer for headless sessions, from its command-line spec.

    The observer judges the test surface rougher with probability
    ``logistic(bias + u_s + rq·ΔRq + dimension·ΔD)``, ΔRq in mm and ΔD in units of D
    (test minus reference), ``u_s`` a per-subject intercept drawn from
    N(0, spread²). Every draw is seeded by (seed, subject, trial), so a resumed
    session answers as an unbroken one would.

    Parameters
    ----------
    spec : str
        Comma-separated ``key=value`` pairs: ``rq`` (logit per mm of Rq),
        ``dimension`` (logit per unit of D), ``bias`` (logit), ``spread`` (logit, not
        negative) and ``seed`` (an integer); each defaults to 0.

    Returns
    -------
    Observer
        With ``probability(subject, delta_dimension, delta_rq)`` (ΔRq in metres) and
        ``judges_test_rougher(subject, trial, delta_dimension, delta_rq)``.

    Raises
    ------
    rough.InputError
        For an unknown key, a value that is not a number, or one that is not finite
        (or a negative spread).

    Examples
    --------
    >>> from rough.experiment.observer import parse_observer
    >>> observer = parse_observer("rq=12,dimension=-4,seed=7")
    >>> observer
    Observer(rq=12.0, dimension=-4.0, bias=0.0, spread=0.0, seed=7)
    >>> round(observer.probability("S01", 0.0, 0.1e-3), 4)  # Rq 0.1 mm higher: logistic(1.2)
    0.7685
    >>> round(observer.probability("S01", 0.075, 0.0), 4)  # D 0.075 higher: logistic(-0.3)
    0.4256
    """
    values = {}
    for item in filter(None, (part.strip() for part in spec.split(","))):
        key, equals, value = item.partition("=")
        key = key.strip()
        if not equals or key not in KEYS:
            raise InputError(
                f"--observer takes {', '.join(f'{k}=' for k in KEYS)} "
                f"({', '.join(f'{k}: {v}' for k, v in KEYS.items())}); not {item!r}"
            )
        try:
            values[key] = int(value) if key == "seed" else float(value)
        except ValueError:
            raise InputError(f"--observer {key}={value!r} is not a number") from None
        if not math.isfinite(values[key]) or (key == "spread" and values[key] < 0):
            raise InputError(f"--observer {key}={value!r} is not usable")
    return Observer(**values)
