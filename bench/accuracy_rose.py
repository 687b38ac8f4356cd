"""Accuracy of rough rose over many synthetic maps (the figures in the README and the
issue note): false rejections of the isotropy tests, principal-direction error, bias
and calibration of the standard errors. Run: python bench/accuracy_rose.py (about a
minute)."""

import logging
import math

import numpy as np

from rough.fractal.sectors import rose
from rough.fractal.synth_map import synthesize_map


def isotropic(maps=60):
    p_dimension, p_amplitude, str_ratio = [], [], []
    for seed in range(maps):
        result = rose(synthesize_map((512, 512), (1e-6, 1e-6), 2.4, amplitude=2e-6, seed=seed, rolloff=32e-6))
        p_dimension.append(result.isotropy_p_value["fractal_dimension"])
        p_amplitude.append(result.isotropy_p_value["amplitude_coefficient"])
        str_ratio.append(result.Str)
    print(
        f"isotropic 512², {maps} maps: rejected at 5 %: Ds {np.mean(np.array(p_dimension) < 0.05):.3f}, "
        f"C {np.mean(np.array(p_amplitude) < 0.05):.3f}; Str {np.nanmin(str_ratio):.3f} to {np.nanmax(str_ratio):.3f} "
        f"(median {np.nanmedian(str_ratio):.3f})"
    )


def anisotropic(angles=(0, 30, 45, 75, 110, 160), seeds=8):
    direction_error, dimension_error, log_c_error, z_dimension, z_amplitude = [], [], [], [], []
    for angle in angles:
        for seed in range(seeds):
            spec = (2.2, 1e-6, 2.5, 4e-6, math.radians(angle))
            result = rose(synthesize_map((512, 512), (1e-6, 1e-6), None, seed=100 * angle + seed, anisotropy=spec))
            direction_error.append(abs((result.principal_direction - angle) % 180 - 90))
            for fit, (dimension, amplitude) in ((result.principal, spec[2:4]), (result.perpendicular, spec[:2])):
                dimension_error.append(fit["dimension"] - dimension)
                log_c_error.append(math.log(fit["amplitude"] / amplitude))
                z_dimension.append(dimension_error[-1] / fit["dimension_error"])
                z_amplitude.append(log_c_error[-1] / (fit["amplitude_error"] / fit["amplitude"]))
    print(
        f"anisotropic 512² (Ds 2.2/2.5, C 1/4 µm), {len(direction_error)} maps: principal direction error "
        f"median {np.median(direction_error):.2f}°, max {np.max(direction_error):.2f}°"
    )
    for name, errors, z in (("Ds", dimension_error, z_dimension), ("log C", log_c_error, z_amplitude)):
        print(
            f"  {name}: bias {np.mean(errors):+.4f}, RMS {np.sqrt(np.mean(np.square(errors))):.4f}, "
            f"SD of error/SE {np.std(z):.2f}"
        )


if __name__ == "__main__":
    logging.getLogger("rough").setLevel(logging.ERROR)
    isotropic()
    anisotropic()
