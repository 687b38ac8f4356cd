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
points with NaN. The names in ``__init__.pyi`` beside this file load their modules on
first use (``lazy_loader``, as scikit-image does), so ``import rough`` is cheap and the
command line starts quickly. ``rough.metrology``, ``rough.fractal``, ``rough.render``
and ``rough.experiment`` hold the rest of the library.
"""

import os
import sys

import lazy_loader

# OpenBLAS's worker threads cost more than they give in the small solves and optimisers of
# the fits: on a busy 2-core machine an L-BFGS-B fit took 20 times longer with them
# (docs/design.rst, "Threads"). Only before numpy loads OpenBLAS, and never over a choice
# already made in the environment.
if "numpy" not in sys.modules:
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

__version__ = "0.15.0"

__getattr__, _, __all__ = lazy_loader.attach_stub(__name__, __file__)
__all__ = ["__version__", *__all__]
__dir__ = __all__.copy  # dir(rough): the stub's names and the version
