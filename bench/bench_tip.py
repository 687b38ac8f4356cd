"""Speed of the probe-size operations: a 10^6-point profile and a 2048 × 2048 map with a
0.5 mm tip at 0.01 mm spacing (a disk of 101 samples; a ball of 7845), as ratios to one
FFT of the same data (numpy's rfft, rfft2), timed in interleaved pairs (bench/timing.py).

Both are exact on the grid. The ball is taken a row of offsets at a time: here every
row of it (at most 101 samples wide) is maximised over directly, vectorised, so the map
costs about 0.15 ns per point and pair of offsets (±x) of the ball; rows wider than
about 220 samples are swept in O(1) per point instead (rough/metrology/tip.py).

    python bench/bench_tip.py            # about a minute
    python bench/bench_tip.py --quick    # a 1024 × 1024 map, fewer repetitions
"""

import argparse
import os

import numpy as np
from timing import compare

from rough import Surface, __version__
from rough.fractal import synthesize_map, synthesize_profile
from rough.metrology.tip import closing_envelope, traced

SPACING, RADIUS = 1e-5, 0.5e-3


def measure(surface, label, transform, baseline_name, repeat, goal=None):
    traced(surface, RADIUS)  # numba compiles (or loads its cache) on the first call: not timed
    heights = surface.heights

    def baseline():
        return transform(heights)

    compare(f"{label}: traced", lambda: traced(surface, RADIUS), baseline, baseline_name, repeat, heights.nbytes, goal)
    compare(f"{label}: closing envelope", lambda: closing_envelope(surface, RADIUS), baseline, baseline_name, repeat,
            heights.nbytes)  # fmt: skip


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true", help="a 1024 × 1024 map instead of 2048 × 2048")
    arguments = parser.parse_args()
    print(f"rough {__version__}, {RADIUS * 1e3:g} mm tip at {SPACING * 1e3:g} mm spacing, {os.cpu_count()} cores")
    repeat = 3 if arguments.quick else 7
    profile = synthesize_profile(10**6, SPACING, 1.275, rq=0.2781e-3, seed=1)
    measure(profile, "profile 10^6 points", np.fft.rfft, "rfft", repeat)
    n = 1024 if arguments.quick else 2048
    heights = synthesize_map((n, n), (SPACING, SPACING), 2.3, rq=0.1e-3, seed=1).heights
    measure(Surface(heights, (SPACING, SPACING)), f"map {n} × {n}", np.fft.rfft2, "rfft2", repeat, "≤ 50× rfft2")


if __name__ == "__main__":
    main()
