"""Benchmark of the fractal tools on a square map (default 4096 × 4096).

Run:  .venv/bin/python bench/bench_fractal.py [--size 4096] [--repeat 3] [--only rose]

Figures, paired and interleaved with their baseline (bench/timing.py), with peak
memory as a multiple of the map's float64 size:
  - synth (with a C, and scaled to an Rq) against one single-threaded
    scipy.fft.irfft2 of the same size (synth itself uses every core);
  - fit-fractal (map) against one scipy.fft.rfft2 of the map;
  - rose on a map of half the side against one rfft2 of it (its fits run with
    BLAS on one thread: rough.compiled.one_blas_thread);
  - rough against SurfaceTopography's fourier_synthesis and
    power_spectrum_from_area at the same size, when it is installed
    (pip install SurfaceTopography).
"""

import argparse
import contextlib
import logging

import numpy as np
from scipy import fft
from timing import compare

import rough
from rough import compiled
from rough.fractal.fit import fit_fractal
from rough.fractal.sectors import rose
from rough.fractal.synth_map import synthesize_map


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=int, default=4096)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--only", choices=["rose"], help="only this line (rose: on a map of half --size)")
    options = parser.parse_args()
    logging.getLogger("rough").setLevel(logging.ERROR)
    n, repeat = options.size, options.repeat
    spacing = 1e-6
    spectrum = np.zeros((n, n // 2 + 1), dtype=np.complex128)
    size = n * n * 8
    print(f"rough {rough.__version__}, {n}×{n} map ({size / 1e6:.0f} MB float64)")

    def make(**scale):
        return synthesize_map((n, n), (spacing, spacing), 2.3, seed=1, **(scale or {"amplitude": 1e-6}))

    def irfft2():
        return fft.irfft2(spectrum, (n, n))

    if options.only == "rose":
        return rose_line(n // 2, spacing, repeat)
    compare(f"synth {n}²", make, irfft2, "one irfft2", repeat, size, goal="≤ 1.5×")
    compare(f"synth {n}² --rq", lambda: make(rq=1e-6), irfft2, "one irfft2", repeat, size)
    surface = make()
    compare(
        f"fit-fractal {n}²", lambda: fit_fractal(surface), lambda: fft.rfft2(surface.heights), "one rfft2", repeat, size
    )
    rose_line(n // 2, spacing, repeat)
    try:
        from SurfaceTopography.Generation import fourier_synthesis
    except ImportError:
        print("SurfaceTopography is not installed (pip install SurfaceTopography): no comparison")
        return
    physical = (n * spacing, n * spacing)
    theirs = fourier_synthesis((n, n), physical, 0.7, rms_height=1e-6)
    compare(
        f"synth {n}² against SurfaceTopography",
        make,
        lambda: fourier_synthesis((n, n), physical, 0.7, rms_height=1e-6),
        "fourier_synthesis",
        repeat,
    )
    compare(
        f"fit-fractal {n}² against SurfaceTopography",
        lambda: fit_fractal(surface),
        theirs.power_spectrum_from_area,
        "power_spectrum_from_area",
        repeat,
    )


def rose_line(half, spacing, repeat):
    small = synthesize_map((half, half), (spacing, spacing), 2.3, amplitude=1e-6, seed=2, rolloff=half * spacing / 16)
    compare(
        f"rose {half}²",
        lambda: rose(small),
        lambda: fft.rfft2(small.heights),
        "one rfft2",
        repeat,
        small.heights.nbytes,
        goal="≤ 8×, memory ≤ 4×",
    )
    limited = compiled._blas_limited

    def with_blas_pool():  # as before one_blas_thread: the fits on OpenBLAS's own pool
        compiled._blas_limited = contextlib.nullcontext
        try:
            return rose(small)
        finally:
            compiled._blas_limited = limited

    compare(f"  rose {half}², fits on one BLAS thread", lambda: rose(small), with_blas_pool, "BLAS's pool", repeat)


if __name__ == "__main__":
    main()
