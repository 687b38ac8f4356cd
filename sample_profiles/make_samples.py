"""Regenerates the sample files in this folder (run: python sample_profiles/make_samples.py).

They are synthetic, made here with plain numpy spectral synthesis and written by rough:
    rock-profile.tsv   a 2048-point profile at 0.0309 mm (the paper's encoder resolution),
                       power spectrum ∝ f^-(5-2D) with D = 1.3, Rq 0.28 mm, seed 2000
    rock-map.x3p       a 128 × 96 height map at 0.05 mm, isotropic, surface dimension 2.3,
                       Sq 0.1 mm, seed 2001, with a 3 × 2 patch of invalid points (NaN)
"""

import os
import pathlib

import numpy as np

import rough

HERE = pathlib.Path(__file__).resolve().parent
os.environ.setdefault("SOURCE_DATE_EPOCH", "1767225600")  # 2026-01-01, for byte-identical files


def spectral(shape, exponent, seed):
    rng = np.random.default_rng(seed)
    spectrum = np.fft.rfftn(rng.standard_normal(shape))
    frequencies = np.sqrt(sum(np.meshgrid(*[np.fft.fftfreq(n) ** 2 for n in shape[:-1]], np.fft.rfftfreq(shape[-1]) ** 2, indexing="ij")))
    frequencies.flat[0] = np.inf
    heights = np.fft.irfftn(spectrum * frequencies ** (-exponent / 2), shape, axes=range(len(shape)))
    return heights - heights.mean()


def main():
    profile = spectral((2048,), 5 - 2 * 1.3, 2000)
    profile *= 0.28e-3 / profile.std()
    surface = rough.Surface(profile, (0.0309e-3,), units=rough.Units("mm", "mm"),
                            metadata={"title": "synthetic rock-like profile, D = 1.3 (sample)"})
    surface.derive("make_samples", {"dimension": 1.3, "rq": 0.28e-3, "seed": 2000}).write(HERE / "rock-profile.tsv")

    heights = spectral((96, 128), 8 - 2 * 2.3, 2001)
    heights *= 0.1e-3 / heights.std()
    heights[40:42, 60:63] = np.nan
    surface = rough.Surface(heights, (0.05e-3, 0.05e-3), units=rough.Units("mm", "mm"),
                            metadata={"title": "synthetic rock-like map, Ds = 2.3 (sample)"})
    surface.derive("make_samples", {"surface_dimension": 2.3, "sq": 0.1e-3, "seed": 2001}).write(HERE / "rock-map.x3p")


if __name__ == "__main__":
    main()
