"""Speed of the probe-size operations: a 10^6-point profile and a 2048 × 2048 map with a
0.5 mm tip at 0.01 mm spacing (a disk of 101 samples; a ball of 7845), as ratios to one
FFT of the same data. Both are exact brute force in compiled code (scikit-image's
rolling-ball kernel, in tiles over the cores), so the cost grows with the tip's
footprint in samples.

    python bench/bench_tip.py            # about two minutes
    python bench/bench_tip.py --quick    # a 1024 × 1024 map
"""

import argparse
import os

import numpy as np
from timing import median_time

from rough import Surface, __version__
from rough.fractal.synth import synthesize_map, synthesize_profile
from rough.metrology.tip import closing_envelope, traced

SPACING, RADIUS = 1e-5, 0.5e-3


def measure(surface, label, transform, repeat):
    baseline = median_time(lambda: transform(surface.heights), max(repeat, 3))
    path = median_time(lambda: traced(surface, RADIUS), repeat)
    envelope = median_time(lambda: closing_envelope(surface, RADIUS), repeat)
    print(
        f"{label:<22} traced {path:7.2f} s = {path / baseline:6.0f}× one FFT ({baseline * 1e3:.1f} ms)   "
        f"closing envelope {envelope:7.2f} s = {envelope / baseline:6.0f}×"
    )


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true", help="a 1024 × 1024 map instead of 2048 × 2048")
    arguments = parser.parse_args()
    print(f"rough {__version__}, {RADIUS * 1e3:g} mm tip at {SPACING * 1e3:g} mm spacing, {os.cpu_count()} cores")
    profile = synthesize_profile(10**6, SPACING, 1.275, rq=0.2781e-3, seed=1)
    measure(profile, "profile 10^6 points", np.fft.rfft, 3)
    n = 1024 if arguments.quick else 2048
    heights = synthesize_map((n, n), (SPACING, SPACING), 2.3, rq=0.1e-3, seed=1).heights
    measure(Surface(heights, (SPACING, SPACING)), f"map {n} × {n}", np.fft.rfft2, 1)


if __name__ == "__main__":
    main()
