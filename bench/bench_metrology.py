"""Benchmark of the metrology: parameters of a large map and a long profile.

Run:  .venv/bin/python bench/bench_metrology.py [--size 4096] [--points 10000000]

Each figure is a ratio against one ``numpy.std`` over the same data, measured in the
same run, with the absolute times alongside. The map's parameters include the
autocorrelation (Sal, Str) and angular spectrum (Std), which need FFTs; the
profile's include RSm, peak density and the JRC resampling.
"""

import argparse
import logging

import numpy as np
from timing import median_time

import rough
from rough.metrology import detrend, parameters


def report(name, surface, repeat):
    baseline = median_time(lambda: np.std(surface.heights), repeat)
    features = median_time(lambda: parameters(surface), repeat)
    levelling = median_time(lambda: detrend(surface, order=2), repeat)
    print(
        f"{name:<22} parameters {features:7.3f} s = {features / baseline:6.0f}× numpy.std ({baseline * 1e3:.1f} ms)   "
        f"detrend order 2 {levelling:6.3f} s = {levelling / baseline:5.0f}×"
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=int, default=4096)
    parser.add_argument("--points", type=int, default=10_000_000)
    parser.add_argument("--repeat", type=int, default=3)
    options = parser.parse_args()
    logging.getLogger("rough").setLevel(logging.ERROR)  # the random-walk map's Str warning
    rng = np.random.default_rng(0)
    surface = rough.Surface(np.cumsum(rng.standard_normal((options.size, options.size)), axis=1) * 1e-9, (1e-6, 1e-6))
    profile = rough.Surface(np.cumsum(rng.standard_normal(options.points)) * 1e-9, (1e-6,))
    print(f"rough {rough.__version__}, median of {options.repeat} runs")
    report(f"map {options.size}×{options.size}", surface, options.repeat)
    report(f"profile {options.points} pts", profile, options.repeat)


if __name__ == "__main__":
    main()
