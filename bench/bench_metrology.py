"""Benchmark of ``rough features``: what each part of its work costs on a large map,
as ratios to one ``scipy.fft.rfft2`` of the map (single-threaded), paired and
interleaved (bench/timing.py), with peak memory as a multiple of the map's float64
size (tracemalloc; the map itself not counted).

Run:  .venv/bin/python bench/bench_metrology.py [--size 4096] [--repeat 3]

Lines: the ISO field parameters Sa…Std (with the autocorrelation's and the angular
spectrum's FFTs); the material-ratio family Smr…Smq (one sort of every point: its
floor, measured alone); everything ``features`` computes on a map but the watershed
(goal ≤ 8× rfft2, ≤ 4× memory); the watershed segmentation and feature parameters
Spd…Shv on a map of half the side (its cost is a multiple of the whole sort), and a
profile of 10⁷ points against one rfft of it.
"""

import argparse
import logging

import numpy as np
from scipy import fft
from timing import compare

import rough
from rough import metrology


def everything_but_the_watershed(surface):
    metrology.parameters(surface)
    metrology.functional_parameters(surface)
    metrology.amplitude_density(surface)


def watershed(surface):
    hills, dales = (metrology.segment(surface, kind, 5.0) for kind in ("hills", "dales"))
    metrology.motif_parameters(surface, hills, dales, "exclude")


def random_walk(shape, seed):
    return np.cumsum(np.random.default_rng(seed).standard_normal(shape), axis=-1) * 1e-9


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=int, default=4096)
    parser.add_argument("--points", type=int, default=10_000_000)
    parser.add_argument("--repeat", type=int, default=3)
    options = parser.parse_args()
    logging.getLogger("rough").setLevel(logging.ERROR)  # the random-walk map's Str warning
    n, repeat = options.size, options.repeat
    surface = rough.Surface(random_walk((n, n), 0), (1e-6, 1e-6))
    heights, size = surface.heights, surface.heights.nbytes
    print(f"rough {rough.__version__}, map {n} × {n} ({size / 1e6:.0f} MB float64)")

    def baseline():
        return fft.rfft2(heights)

    name = "one rfft2"
    compare(
        f"features {n}²: ISO parameters Sa…Std", lambda: metrology.parameters(surface), baseline, name, repeat, size
    )
    compare(f"features {n}²: Smr…Smq", lambda: metrology.functional_parameters(surface), baseline, name, repeat, size)
    compare(f"  its floor: one sort of {n}² points", lambda: np.sort(heights, axis=None), baseline, name, repeat, size)
    compare(
        f"features {n}² but the watershed",
        lambda: everything_but_the_watershed(surface),
        baseline,
        name,
        repeat,
        size,
        goal="≤ 8×, memory ≤ 4×",
    )
    half = rough.Surface(heights[: n // 2, : n // 2].copy(), (1e-6, 1e-6))
    watershed(half)  # numba compiles the passes (or loads them from its cache) once per process
    compare(
        f"features {n // 2}²: watershed, Spd…Shv",
        lambda: watershed(half),
        lambda: fft.rfft2(half.heights),
        name,
        1,
        half.heights.nbytes,
    )
    profile = rough.Surface(random_walk(options.points, 1), (1e-6,))
    compare(
        f"features profile {options.points:.0e} points",
        lambda: (metrology.parameters(profile), metrology.functional_parameters(profile)),
        lambda: fft.rfft(profile.heights),
        "one rfft",
        repeat,
        profile.heights.nbytes,
    )


if __name__ == "__main__":
    main()
