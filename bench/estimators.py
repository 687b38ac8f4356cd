"""The cost of the H estimators (issue 32, ``--estimator``) and of their calibration,
against one FFT of the same data (``numpy.fft.rfft`` of the profile, or of the map's
rows at once), paired and interleaved in one process (bench/timing.py).

Run:  PYTHONPATH=. .venv/bin/python bench/estimators.py [--repeat 5] [--calibration-repeat 2]

Cases: one exact fBm profile of 1024 points, one of 4096, and the Corona Heights fault
map's rows (388 × 537 at 5.7 mm, each row's longest finite run, a line removed; from
../shared/data, skipped when it is absent). Subjects: each estimator's raw H, all five
(``--estimator all`` without calibration), and the calibration of all five with an
empty cache (``compare``, default replicates), which is what a first ``--estimator all``
costs. The machine's load average is printed first: the figures are ratios, but a
loaded machine still stretches them.
"""

import argparse
import os
import pathlib
import sys

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # as `import rough` sets it; numpy loads first here

import numpy as np  # noqa: E402
from timing import compare  # noqa: E402

import rough  # noqa: E402
from rough.fractal import calibrate  # noqa: E402
from rough.fractal.estimators import ESTIMATORS  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
from fbm import fbm  # noqa: E402

CORONA = ROOT.parent / "shared" / "data" / "dem" / "coronaA_grids.npz"
CORONA_SPACING = 0.005685771715431078


def without_line(profile):
    x = np.linspace(-1.0, 1.0, profile.size)
    return profile - np.polyval(np.polyfit(x, profile, 1), x)


def cases():
    rng = np.random.default_rng(1)
    yield "profile 1024", [without_line(fbm(1024, 0.7, rng, 1e-6, 1e-6))], 1e-6
    yield "profile 4096", [without_line(fbm(4096, 0.7, rng, 1e-6, 1e-6))], 1e-6
    if CORONA.is_file():
        from rough.fractal.profile_set import take_profiles

        grid = np.load(CORONA)["Z_grid"]
        rows = take_profiles(rough.Surface(grid, (CORONA_SPACING, CORONA_SPACING)), "x").heights
        yield f"Corona rows ({len(rows)} × {rows[0].size})", rows, CORONA_SPACING
    else:
        print(f"({CORONA} is absent: no map case)")


def fft_of(profiles):
    stacked = np.array(profiles) if len({profile.size for profile in profiles}) == 1 else None
    if stacked is not None:
        return lambda: np.fft.rfft(stacked, axis=1)
    return lambda: [np.fft.rfft(profile) for profile in profiles]


def calibration(profiles, spacing):
    def run():
        calibrate.clear_cache()
        calibrate.compare(profiles, spacing)

    return run


def load():
    return " ".join(f"{value:.2f}" for value in os.getloadavg())


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--calibration-repeat", type=int, default=2)
    options = parser.parse_args()
    print(f"rough {rough.__version__}; load average {load()} on {os.cpu_count()} cores")
    for case, profiles, spacing in cases():
        print(f"\n{case}:")
        baseline = fft_of(profiles)
        for name, estimate in ESTIMATORS.items():
            compare(f"  {name}", lambda: estimate(profiles, spacing), baseline, "rfft", options.repeat, record=False)
        everything = [(estimate, profiles, spacing) for estimate in ESTIMATORS.values()]
        compare(
            f"  all five (raw) [{case}]",
            lambda: [estimate(p, s) for estimate, p, s in everything],
            baseline,
            "rfft",
            options.repeat,
        )
        compare(
            f"  calibration of all five [{case}]",
            calibration(profiles, spacing),
            baseline,
            "rfft",
            options.calibration_repeat,
        )
        print(
            f"  (default replicates: {calibrate.default_replicates(profiles, 'variogram')} per grid H, Whittle "
            f"{calibrate.default_replicates(profiles, 'whittle')}; {calibrate.GRID.size} grid H)"
        )
    print(f"\nload average afterwards {load()}")


if __name__ == "__main__":
    main()
