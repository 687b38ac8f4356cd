"""One Whittle fit with a noise floor, in fresh processes with OpenBLAS's worker
threads (the library's own default: as many as cores) and with one thread (what
``import rough`` sets when the environment has not chosen), interleaved
(docs/design.rst, "Threads").

Run: ``python bench/bench_threads.py`` (check ``uptime`` first).
"""

import os
import statistics
import subprocess
import sys

FIT = """
import time, numpy as np
from rough.fractal.pooled import whittle_hurst
walk = np.cumsum(np.random.default_rng(1).standard_normal(1024))
heights = [walk - np.polyval(np.polyfit(np.arange(1024), walk, 1), np.arange(1024))]
whittle_hurst(heights, 1.0)
times = []
for _ in range(5):
    start = time.perf_counter()
    whittle_hurst(heights, 1.0)
    times.append(time.perf_counter() - start)
print(min(times))
"""


def fit_seconds(threads):
    environment = dict(os.environ, OPENBLAS_NUM_THREADS=str(threads))
    output = subprocess.run([sys.executable, "-c", FIT], env=environment, capture_output=True, text=True, check=True)
    return float(output.stdout)


def main(repeats=5):
    cores = os.cpu_count()
    one, many = [], []
    for _ in range(repeats):
        one.append(fit_seconds(1))
        many.append(fit_seconds(cores))
    ratios = [m / o for m, o in zip(many, one)]
    print(f"load {os.getloadavg()[0]:.2f} on {cores} cores")
    print(f"Whittle fit with a floor, 1024 points, 1 thread: {statistics.median(one) * 1e3:.1f} ms (median)")
    print(
        f"the same with {cores} OpenBLAS threads: {min(ratios):.2f}× (median {statistics.median(ratios):.2f}×) "
        "the one-thread time"
    )


if __name__ == "__main__":
    main()
