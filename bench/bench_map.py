"""Speed of roughness maps (rough/metrology/mapping.py), timed in interleaved pairs (bench/timing.py):

* the vectorised moments (Sa … Sz, each window's plane removed in one batch of least squares) against the
  loop they replace, :func:`rough.metrology.remove_form` and the amplitude moments window by window;
* the same moments as a ratio to one rfft2 of the map (a floor: every spectral command pays it);
* the fractal fit per window (``hurst``), as a ratio to the moments;
* the moments of the map read in bands (a :class:`rough.io.TiledSurface`, as a map larger
  than memory is) against the map in memory: what cutting the work into bands costs.

    python bench/bench_map.py            # a 2048 × 2048 map, windows of 64 points; about two minutes
    python bench/bench_map.py --quick    # 1024 × 1024
"""

import argparse
import os

import numpy as np
from timing import compare

from rough import Surface, __version__
from rough.fractal import synthesize_map
from rough.io import TiledSurface
from rough.metrology import remove_form, roughness_map
from rough.metrology.heights import amplitude

MOMENTS = ["Sa", "Sq", "Ssk", "Sku", "Sp", "Sv", "Sz"]


def window_loop(surface, window):
    """The baseline: each window levelled and its moments taken, one call each."""
    ny, nx = surface.heights.shape
    for top in range(0, ny - window + 1, window):
        for left in range(0, nx - window + 1, window):
            part = Surface(surface.heights[top : top + window, left : left + window], surface.spacing)
            amplitude(remove_form(part, 1).heights)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true", help="a 1024 × 1024 map instead of 2048 × 2048")
    arguments = parser.parse_args()
    n, window, repeat = (1024, 64, 3) if arguments.quick else (2048, 64, 5)
    print(f"rough {__version__}, map {n} × {n}, windows of {window} points, {os.cpu_count()} cores")
    surface = synthesize_map((n, n), (1e-5, 1e-5), 2.3, rq=1e-4, seed=1)
    size = surface.heights.nbytes

    def moments():
        return roughness_map(surface, window, parameters=MOMENTS)

    compare("moments, vectorised", moments, lambda: window_loop(surface, window), "per-window loop", repeat, size)
    compare("moments, vectorised", moments, lambda: np.fft.rfft2(surface.heights), "rfft2", repeat, size)
    tiled = TiledSurface.of(surface)
    compare(
        "moments, read in bands",
        lambda: roughness_map(tiled, window, parameters=MOMENTS, budget=64 << 20),
        moments,
        "in memory",
        repeat,
        size,
    )
    part = Surface(surface.heights[: n // 4, : n // 4], surface.spacing)  # the fit is slow: a sixteenth of the map
    compare(
        "hurst (fit per window, 1/16 of the map)",
        lambda: roughness_map(part, window, parameters=["hurst"]),
        lambda: roughness_map(part, window, parameters=MOMENTS),
        "moments of the same windows",
        repeat,
    )


if __name__ == "__main__":
    main()
