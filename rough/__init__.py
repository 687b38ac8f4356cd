"""rough: surface metrology on the command line and in notebooks.

Read a scan, remove its form, and compute its ISO parameters and fractal dimension:

>>> import rough
>>> scan = rough.read(rough.sample("rock-profile.tsv"))
>>> scan.is_profile, len(scan.heights), scan.spacing
(True, 2048, (3.09e-05,))
>>> roughness = rough.detrend(scan, order=2)
>>> round(rough.parameters(roughness)["Rq"] * 1e6)      # µm
274
>>> fit = rough.fit_fractal(roughness)
>>> 1 < fit.fractal_dimension < 2
True

Every function takes and returns SI units (metres, seconds, newtons) and marks invalid
points with NaN. The names below load their modules on first use, so ``import rough``
is cheap and the command line starts quickly. ``rough.metrology``, ``rough.fractal``,
``rough.render`` and ``rough.experiment`` hold the rest of the library.
"""

import importlib
import os
import sys

# OpenBLAS's worker threads cost more than they give in the small solves and optimisers of
# the fits: on a busy 2-core machine an L-BFGS-B fit took 20 times longer with them
# (docs/design.rst, "Threads"). Only before numpy loads OpenBLAS, and never over a choice
# already made in the environment.
if "numpy" not in sys.modules:
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

__version__ = "0.11.0"

# public name -> module that defines it (imported on first use)
_LAZY = {
    "Surface": "rough.surface",
    "Units": "rough.surface",
    "read": "rough.io",
    "write": "rough.io",
    "sample": "rough.samples",
    "detrend": "rough.metrology",
    "parameters": "rough.metrology",
    "profile_parameters": "rough.metrology",
    "areal_parameters": "rough.metrology",
    "mean_line": "rough.metrology",
    "detect_features": "rough.metrology",
    "rq_versus_length": "rough.metrology",
    "traced": "rough.metrology.tip",
    "closing_envelope": "rough.metrology.tip",
    "fit_fractal": "rough.fractal.fit",
    "FractalFit": "rough.fractal.fit",
    "rose": "rough.fractal.rose",
    "Rose": "rough.fractal.rose",
    "synthesize_profile": "rough.fractal.synth",
    "synthesize_map": "rough.fractal.synth",
    "resample": "rough.fractal.resample",
    "Track": "rough.render",
    "simulate": "rough.render",
    "forces": "rough.render",
    "RoughError": "rough.errors",
    "InputError": "rough.errors",
}

__all__ = ["__version__", *_LAZY]


def __getattr__(name):
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'rough' has no attribute {name!r}")


def __dir__():
    return sorted({*globals(), *__all__})
