"""The full material-ratio set against surfalize's, and one sort against one rfft2.

Run:  .venv/bin/python bench/bench_material_ratio.py --surfalize /path/to/venv/bin/python
      [--sizes 1024,2048,4096] [--repeat 5]

``--surfalize`` is a Python with surfalize installed (GPL-3.0; its own venv). It runs
as one child process per map size that reads the map once and then, each time it is
asked, builds a fresh ``surfalize.Surface`` (so nothing is cached between runs) and
computes its whole material-ratio set (Sk, Spk, Svk, Smr1, Smr2, Smrk1, Smrk2, Spkx,
Svkx, Sak1, Sak2, Sdc, Sxp, Vmp, Vmc, Vvc, Vvv; Smr(0), Smc(10 %), Vm, Vv at 10 %), reporting the
seconds that took. rough's side is ``rough.metrology.functional_parameters`` on the
same heights (Smr…Vvv and Spq, Svq, Smq, which surfalize has not). Pairs are
interleaved (which goes first alternates); the lines give the ratio rough/surfalize,
min and median over the pairs (goal ≤ 1×).

The second part measures the floor the README quotes: one ``np.sort`` of every point
of the map against one single-threaded ``scipy.fft.rfft2`` of it, interleaved the
same way (bench/timing.py).
"""

import argparse
import json
import logging
import pathlib
import statistics
import subprocess
import tempfile
import time

import numpy as np
from scipy import fft, ndimage
from timing import compare

import rough
from rough.metrology import functional_parameters

SURFALIZE_SIDE = """
import json, sys, time
import numpy as np
from surfalize import Surface

heights = np.load(sys.argv[1])
step = float(sys.argv[2])
NAMES = ("Sk", "Spk", "Svk", "Smr1", "Smr2", "Smrk1", "Smrk2", "Spkx", "Svkx", "Sak1", "Sak2", "Sdc",
         "Sxp", "Vmp", "Vmc", "Vvc", "Vvv")
ARGUMENTS = {"Smr": 0.0, "Smc": 10.0, "Vm": 10.0, "Vv": 10.0}  # rough's defaults
for line in sys.stdin:
    started = time.perf_counter()
    surface = Surface(heights, step, step)
    values = {name: float(getattr(surface, name)()) for name in NAMES}
    values |= {name: float(getattr(surface, name)(value)) for name, value in ARGUMENTS.items()}
    print(json.dumps({"seconds": time.perf_counter() - started, "Sk": values["Sk"]}), flush=True)
"""


def heights_of(n, seed=1):
    """A smoothed-noise map of n × n points, 1 µm high (no ties)."""
    noise = ndimage.gaussian_filter(np.random.default_rng(seed).standard_normal((n, n)), 3.0)
    return noise / noise.std() * 1e-6


def versus_surfalize(python, n, repeat, folder):
    heights = heights_of(n)
    path = pathlib.Path(folder) / f"heights{n}.npy"
    np.save(path, heights)
    side = pathlib.Path(folder) / "side.py"
    side.write_text(SURFALIZE_SIDE)
    surface = rough.Surface(heights, (1e-6, 1e-6))
    child = subprocess.Popen(
        [python, str(side), str(path), "1e-6"], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )

    def theirs():
        child.stdin.write("go\n")
        child.stdin.flush()
        return json.loads(child.stdout.readline())["seconds"]

    def ours():
        started = time.perf_counter()
        functional_parameters(surface)
        return time.perf_counter() - started

    try:
        theirs(), ours()  # warm: imports, caches, page faults
        ratios, mine, their = [], [], []
        for index in range(repeat):
            first, second = (ours, theirs) if index % 2 == 0 else (theirs, ours)
            a, b = first(), second()
            r, s = (a, b) if first is ours else (b, a)
            ratios.append(r / s)
            mine.append(r)
            their.append(s)
    finally:
        child.stdin.close()
        child.wait()
    print(
        f"material-ratio set {n}²: rough {statistics.median(mine):7.3f} s, surfalize {statistics.median(their):7.3f} s"
        f" = {min(ratios):5.2f}× (median {statistics.median(ratios):5.2f}×)   (goal ≤ 1×)",
        flush=True,
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--surfalize", help="a Python with surfalize installed (else only the sort is measured)")
    parser.add_argument("--sizes", default="1024,2048,4096")
    parser.add_argument("--repeat", type=int, default=5)
    options = parser.parse_args()
    logging.getLogger("rough").setLevel(logging.ERROR)
    sizes = [int(size) for size in options.sizes.split(",")]
    print(f"rough {rough.__version__}")
    if options.surfalize:
        with tempfile.TemporaryDirectory() as folder:
            for n in sizes:
                versus_surfalize(options.surfalize, n, options.repeat, folder)
    for n in sizes:
        heights = heights_of(n)
        compare(
            f"one sort of {n}² points",
            lambda heights=heights: np.sort(heights, axis=None),
            lambda heights=heights: fft.rfft2(heights),
            "one rfft2",
            options.repeat,
            record=False,
        )


if __name__ == "__main__":
    main()
