"""Regenerates the sample files in this folder with rough itself
(run: python sample_profiles/make_samples.py; SOURCE_DATE_EPOCH fixes the time stamps,
so the files come out byte-identical).

    rock-profile.tsv   a fractal profile like the paper's stimuli: D = 1.3, Rq 0.28 mm,
                       2048 points at 0.0309 mm (the paper's encoder resolution), seed 2000
    rock-map.x3p       a fractal map: surface dimension 2.3, Sq 0.1 mm, 128 × 96 points at
                       0.05 mm, seed 2001, with a 3 × 2 patch of invalid points (NaN)
"""

import os
import pathlib

os.environ.setdefault("SOURCE_DATE_EPOCH", "1767225600")  # 2026-01-01

import numpy as np

from rough.fractal import synthesize_map, synthesize_profile

HERE = pathlib.Path(__file__).resolve().parent


def main():
    profile = synthesize_profile(2048, 0.0309e-3, 1.3, rq=0.28e-3, seed=2000)
    profile.metadata["title"] = "synthetic rock-like profile, D = 1.3 (sample)"
    profile.write(HERE / "rock-profile.tsv")
    surface = synthesize_map((128, 96), (0.05e-3, 0.05e-3), 2.3, rq=0.1e-3, seed=2001)
    heights = surface.heights.copy()
    heights[40:42, 60:63] = np.nan
    hole = surface.derive("mask", {"rows": [40, 42], "columns": [60, 63], "why": "a sample dropout"}, heights=heights)
    hole.metadata["title"] = "synthetic rock-like map, Ds = 2.3 (sample)"
    hole.write(HERE / "rock-map.x3p")


if __name__ == "__main__":
    main()
