"""Benchmark of the tribology parameters: the material-ratio family (ISO 13565,
ISO 25178-2 Sk…Vvv) and the feature parameters (watershed segmentation with Wolf
pruning) of a 2048² map, as ratios to one FFT of the same map.

Run:  .venv/bin/python bench/bench_tribology.py [--size 2048] [--repeat 5]

Each measurement is paired with a baseline ``scipy.fft.rfft2`` of the map run just
before it (the machines are shared and noisy); the ratio of each pair is reported
as the minimum and the median over the repeats, with the absolute times.
"""

import argparse
import statistics
import time

import numpy as np
from scipy import fft, ndimage

import rough
from rough.metrology import MaterialRatioCurve, feature_parameters, functional_parameters, segment


def seconds(action):
    started = time.perf_counter()
    action()
    return time.perf_counter() - started


def paired(action, baseline, repeat):
    """(min ratio, median ratio, median seconds) of ``action`` against ``baseline``."""
    ratios, times = [], []
    for _ in range(repeat):
        base = seconds(baseline)
        took = seconds(action)
        ratios.append(took / base)
        times.append(took)
    return min(ratios), statistics.median(ratios), statistics.median(times)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=int, default=2048)
    parser.add_argument("--repeat", type=int, default=5)
    options = parser.parse_args()
    rng = np.random.default_rng(0)
    noise = ndimage.gaussian_filter(rng.standard_normal((options.size, options.size)), 4.0, mode="wrap")
    surface = rough.Surface(noise * 1e-6, (1e-6, 1e-6))
    one_fft = seconds(lambda: fft.rfft2(surface.heights))
    print(f"rough {rough.__version__}: map {options.size}², smoothed noise; one rfft2 ≈ {one_fft * 1e3:.0f} ms")
    print(f"{'':<34}{'min':>8}{'median':>9}  (× one rfft2)   median time")
    cases = {
        "material-ratio curve (sort)": lambda: MaterialRatioCurve(surface),
        "functional parameters (Sk…Vvv)": lambda: functional_parameters(surface),
        "segment hills": lambda: segment(surface, "hills"),
        "segment dales": lambda: segment(surface, "dales"),
        "feature parameters (Spd…Shv)": lambda: feature_parameters(surface),
    }
    for name, action in cases.items():
        low, middle, took = paired(action, lambda: fft.rfft2(surface.heights), options.repeat)
        print(f"{name:<34}{low:7.1f}×{middle:8.1f}×{'':17}{took:6.2f} s")


if __name__ == "__main__":
    main()
