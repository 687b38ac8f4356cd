"""Benchmark of the fractal tools on a square map (default 4096 × 4096).

Run:  .venv/bin/python bench/bench_fractal.py [--size 4096] [--repeat 3]

Figures, each measured in the same run (median of --repeat):
  - synth as a ratio to one scipy.fft.irfft2 of the same size (single-threaded, scipy's
    default, and on all cores, which synth itself uses);
  - fit-fractal (map) as a ratio to one scipy.fft.rfft2 of the map;
  - SurfaceTopography's fourier_synthesis and power_spectrum_from_area at the same
    size, when it is installed (pip install SurfaceTopography);
  - peak memory of synth and fit-fractal (tracemalloc, which numpy reports to) as a
    multiple of the map's float64 size;
  - rose on a 2048 × 2048 map as a ratio to one rfft2 of it.
"""

import argparse
import tracemalloc

import numpy as np
from scipy import fft
from timing import median_time

import rough
from rough.fractal.fit import fit_fractal
from rough.fractal.rose import rose
from rough.fractal.synth import synthesize_map


def peak_memory(action):
    tracemalloc.start()
    action()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return peak


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=int, default=4096)
    parser.add_argument("--repeat", type=int, default=3)
    options = parser.parse_args()
    n, repeat = options.size, options.repeat
    spacing = 1e-6
    spectrum = np.zeros((n, n // 2 + 1), dtype=np.complex128)
    field = np.random.default_rng(0).standard_normal((n, n))
    irfft_single = median_time(lambda: fft.irfft2(spectrum, (n, n)), repeat)
    irfft_all = median_time(lambda: fft.irfft2(spectrum, (n, n), workers=-1), repeat)
    rfft_single = median_time(lambda: fft.rfft2(field), repeat)

    def make():
        return synthesize_map((n, n), (spacing, spacing), 2.3, amplitude=1e-6, seed=1)

    surface = make()
    synth_time = median_time(make, repeat)
    fit_time = median_time(lambda: fit_fractal(surface), repeat)
    size = n * n * 8
    synth_memory = peak_memory(make) / size
    fit_memory = peak_memory(lambda: fit_fractal(surface)) / size
    print(f"rough {rough.__version__}, {n}×{n} map ({size / 1e6:.0f} MB float64), median of {repeat}")
    print(
        f"synth        {synth_time:6.3f} s = {synth_time / irfft_single:4.2f}× irfft2 single-threaded "
        f"({irfft_single:.3f} s), "
        f"{synth_time / irfft_all:4.2f}× irfft2 on all cores ({irfft_all:.3f} s)   goal ≤ 1.5×"
    )
    print(
        f"fit-fractal  {fit_time:6.3f} s = {fit_time / rfft_single:4.2f}× rfft2 single-threaded "
        f"({rfft_single:.3f} s)   goal ≤ 3×"
    )
    print(f"peak memory  synth {synth_memory:.2f}×, fit-fractal {fit_memory:.2f}× the map's float64 size   goal ≤ 4×")
    half = n // 2
    small = synthesize_map((half, half), (spacing, spacing), 2.3, amplitude=1e-6, seed=2, rolloff=half * spacing / 16)
    small_field = np.random.default_rng(1).standard_normal((half, half))
    rfft_small = median_time(lambda: fft.rfft2(small_field), repeat)
    rose_time = median_time(lambda: rose(small), repeat)
    print(
        f"rose {half}×{half} {rose_time:6.3f} s = {rose_time / rfft_small:4.1f}× rfft2 single-threaded "
        f"({rfft_small:.3f} s)"
    )
    try:
        from SurfaceTopography.Generation import fourier_synthesis
    except ImportError:
        print("SurfaceTopography is not installed (pip install SurfaceTopography) — no comparison")
        return
    physical = (n * spacing, n * spacing)
    theirs = fourier_synthesis((n, n), physical, 0.7, rms_height=1e-6)
    their_synth = median_time(lambda: fourier_synthesis((n, n), physical, 0.7, rms_height=1e-6), repeat)
    their_psd = median_time(lambda: theirs.power_spectrum_from_area(), repeat)
    print(
        f"SurfaceTopography fourier_synthesis {their_synth:.3f} s: rough synth is "
        f"{their_synth / synth_time:.1f}× faster (goal ≥ 3×)"
    )
    print(
        f"SurfaceTopography power_spectrum_from_area {their_psd:.3f} s: rough fit-fractal is "
        f"{their_psd / fit_time:.1f}× faster (goal ≥ 2×)"
    )


if __name__ == "__main__":
    main()
