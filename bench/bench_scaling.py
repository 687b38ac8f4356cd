"""The cost of the default fractal fit (issue 16: noise floor, automatic scaling range,
sampling model by likelihood) against one FFT of the same data, paired and repeated
in one process. Run it on any checkout (``PYTHONPATH=<checkout> python
bench/bench_scaling.py``) to compare before and after."""

import statistics
import sys
import time

import numpy as np

from rough import Surface
from rough.fractal.fit import fit_fractal

sys.path.insert(0, "tests")
from fourier import fourier_map  # noqa: E402

from fbm import fbm  # noqa: E402


def paired(work, baseline, repeat):
    ratios = []
    for _ in range(repeat):
        start = time.perf_counter()
        work()
        middle = time.perf_counter()
        baseline()
        ratios.append((middle - start) / (time.perf_counter() - middle))
    return min(ratios), statistics.median(ratios)


def main():
    rng = np.random.default_rng(1)
    cases = {
        "profile fBm 2^16": Surface(fbm(2**16, 0.5, rng, 1e-6, 1e-6), (1e-6,)),
        "map 1024²": Surface(fourier_map(1024, 0.5, rng, 1e-6) * 1e-3, (1e-6, 1e-6)),
    }
    for name, surface in cases.items():
        transform = np.fft.rfft if surface.is_profile else np.fft.rfft2
        low, middle = paired(lambda: fit_fractal(surface), lambda: transform(surface.heights), 5)
        print(f"{name}: default fit costs {low:.0f}× (min) / {middle:.0f}× (median) one FFT")


if __name__ == "__main__":
    main()
