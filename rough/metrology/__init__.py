"""Metrology: form removal, ISO 16610 Gaussian filters, ISO 4287/25178-2 parameters,
the source slides' feature detection and the scale dependence of Rq.

    >>> from rough.metrology import detrend, parameters
    >>> roughness = detrend(scan, order=2, cutoff=0.8e-3)     # form, then λc = 0.8 mm
    >>> parameters(roughness)["Ra"]
"""

import logging
import math

import numpy as np

from ..errors import InputError
from .features import Feature, detect_features
from .filters import mean_line, split, transmission
from .form import polynomial_form, remove_form
from .parameters import (
    AREAL,
    PROFILE,
    amplitude_density,
    areal_parameters,
    joint_roughness_coefficient,
    profile_parameters,
)
from .scale import rq_versus_length

KEEP = ("roughness", "waviness", "form")
log = logging.getLogger("rough")

__all__ = [
    "AREAL",
    "KEEP",
    "PROFILE",
    "Feature",
    "amplitude_density",
    "areal_parameters",
    "detect_features",
    "detrend",
    "mean_line",
    "parameters",
    "polynomial_form",
    "profile_parameters",
    "remove_form",
    "rq_versus_length",
    "split",
    "transmission",
]


def detrend(surface, order=2, cutoff=None, keep="roughness", ends="trim"):
    """Remove the least-squares polynomial form of degree ``order`` and, with a
    ``cutoff`` (metres), split what is left with the ISO 16610-21/61 Gaussian filter.

    ``keep`` chooses the output: ``roughness`` (the default: the form-free surface, or
    its roughness with a cut-off), ``waviness`` (the Gaussian mean line; needs a
    cut-off) or ``form`` (the fitted polynomial). ``ends`` is ``trim`` (drop λc/2 at
    each end) or ``correct`` (keep the full length). NaN stays NaN.
    """
    if keep not in KEEP:
        raise InputError(f"keep must be one of {', '.join(KEEP)}, not {keep!r}")
    if keep == "waviness" and cutoff is None:
        raise InputError("the waviness needs a cut-off (--cutoff)")
    if keep == "form":
        form = polynomial_form(surface, order)
        return surface.derive(
            "detrend", {"order": order, "keep": "form"}, heights=np.where(np.isnan(surface.heights), np.nan, form)
        )
    levelled = remove_form(surface, order)
    return levelled if cutoff is None else split(levelled, cutoff, keep, ends)


def parameters(surface, cutoff=None, ends="trim", sampling_lengths=5, slope="2point", along=None, jrc_spacing=0.5e-3):
    """ISO parameters of a profile (Ra … JRC) or map (Sa … Std), in SI units, on the
    data as given with the mean removed, or on the roughness at ``cutoff``.

    ``along="x"`` or ``"y"`` evaluates a map as the set of its profiles in that
    direction, each with its own mean: RMS quantities (Rq, Rdq, Z2) combine as the
    quadratic mean over profiles (pooling the points, as SurfaceTopography's
    ``rms_height_from_profile`` does), the others as the arithmetic mean.
    """
    evaluated = surface if cutoff is None else split(surface, cutoff, "roughness", ends)
    if surface.is_profile:
        values = profile_parameters(evaluated, sampling_lengths, slope, jrc_spacing)
    elif along is None:
        values = areal_parameters(evaluated, slope)
    else:
        values = _profiles_of_map(evaluated, along, sampling_lengths, slope, jrc_spacing)
    _announce_undefined(values)
    return values


UNDEFINED = {
    "no height variation": ("Rsk", "Rku", "Ssk", "Sku", "Sal", "Str", "Std"),
    "no profile element rises and falls 10 % of Rz across the mean line": ("RSm",),
    "the profile spans fewer than three JRC spacings": ("Z2",),
    "Z2 is zero or undefined": ("JRC",),
    "no two neighbouring points are valid": ("Rdq", "Sdq", "Sdr"),
}


def _announce_undefined(values):
    """One warning naming each parameter that came out undefined (NaN) and why (Str has
    its own warning when Sal is defined)."""
    undefined = {key for key, value in values.items() if math.isnan(value)}
    if "Str" in undefined and "Sal" not in undefined:
        undefined.discard("Str")
    reasons = []
    for reason, keys in UNDEFINED.items():
        named = [key for key in keys if key in undefined]
        if named:
            reasons.append(f"{', '.join(named)} ({reason})")
    if reasons:
        log.warning(f"undefined for this surface: {'; '.join(reasons)}")


def _profiles_of_map(surface, along, sampling_lengths, slope, jrc_spacing):
    from ..surface import Surface

    if along not in ("x", "y"):
        raise InputError(f"along must be x or y, not {along!r}")
    rows = surface.heights if along == "x" else surface.heights.T
    spacing = surface.spacing[0 if along == "x" else 1]
    each = [
        profile_parameters(Surface(row, (spacing,)), sampling_lengths, slope, jrc_spacing)
        for row in rows
        if np.count_nonzero(~np.isnan(row)) > 1
    ]
    if not each:
        raise InputError(f"no profile along {along} has two valid points")
    combined = {}
    for key in PROFILE:
        values = np.array([p[key] for p in each])
        finite = values[np.isfinite(values)]
        if not finite.size:
            combined[key] = float("nan")
        elif key in ("Rq", "Rdq", "Z2"):
            combined[key] = float(np.sqrt(np.mean(finite**2)))
        else:
            combined[key] = float(np.mean(finite))
    combined["JRC"] = joint_roughness_coefficient(combined["Z2"])
    return combined
