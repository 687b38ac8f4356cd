"""The ISO parameters of a surface as ``rough features`` reports them: a profile's or a
map's, on the data as given or on its roughness at a cut-off, every family of them
(field, functional, feature), with one warning naming the parameters that came out
undefined and why."""

import logging
import math

from ..errors import InputError
from .areal import areal_parameters
from .filters import split
from .material_ratio import functional_parameters
from .profile import PROFILE, combined, joint_roughness_coefficient, map_profiles, profile_parameters
from .segmentation import motif_parameters, segment, undefined_reasons

log = logging.getLogger("rough")

#: The families of parameters :func:`parameters` returns: ``field`` (ISO 4287/21920
#: and ISO 25178-2's height, spatial and hybrid parameters, :data:`PROFILE` or
#: :data:`AREAL`), ``functional`` (the material-ratio parameters of ISO 13565 and
#: ISO 25178-2, volumes included, :data:`PROFILE_FUNCTIONAL` or
#: :data:`AREAL_FUNCTIONAL`) and ``feature`` (ISO 25178-2's feature parameters of the
#: watershed segmentation, :data:`FEATURE`: maps evaluated as maps only).
FAMILIES = ("field", "functional", "feature")


def parameters(
    surface,
    cutoff=None,
    ends="trim",
    sampling_lengths=None,
    slope="2point",
    along=None,
    jrc_spacing=0.5e-3,
    sampling_length=None,
    acf="iso",
    pruning=5.0,
    edge_features="exclude",
    height=0.0,
    ratio=10.0,
    dc_ratios=(10.0, 80.0),
    volume_ratios=(10.0, 80.0),
    families=None,
):
    """ISO parameters of a profile (Ra … JRC, Rmr … Rmq) or map (Sa … Std, Smr … Smq,
    Spd … Shv), in SI units: the numbers ``rough features`` prints.

    Computed on the data as given with the mean of the valid points removed (no
    levelling: detrend first to remove form), or on the roughness at ``cutoff``.

    Parameters
    ----------
    surface : Surface
        A profile or map; NaN points are left out of every parameter (slopes use
        pairs of neighbouring valid points; invalid points split the hills and dales
        as the border does).
    cutoff : float, optional
        A Gaussian filter cut-off λc in metres: the parameters are then those of the
        roughness (:func:`~rough.metrology.split`). None (the default) evaluates the data as given.
    ends : {"trim", "correct"}, default "trim"
        How the filter treats the ends (see :func:`~rough.metrology.split`); only with ``cutoff``.
    sampling_lengths : int, optional
        Profiles: the number of sampling lengths that Rp, Rv and Rz are averaged
        over (ISO 4287/4288): by default every whole sampling length the profile
        holds, or 5 equal sections when there is no sampling length.
    slope : {"2point", "7point"}, default "2point"
        Forward differences, or ISO 4287's seven-point derivative, for Rdq, Sdq, Sdr.
    along : {None, "x", "y"}, optional
        Evaluate a map as the set of its profiles in that direction, each with its
        own mean, and combine them (field and functional families).
    jrc_spacing : float, default 0.5e-3
        Profiles: the spacing in metres at which Z2 (and so JRC) is evaluated.
    sampling_length : float, optional
        Profiles: the sampling length lr in metres; by default ``cutoff`` (ISO 4288:
        lr = λc). Give it to evaluate a roughness that was filtered beforehand.
    acf : {"iso", "per-lag"}, default "iso"
        Maps: the autocorrelation function of Sal and Str, ISO 25178-2's or the
        mean product per lag (see :func:`rough.metrology.spatial.autocorrelation`).
    pruning : float, default 5.0
        Maps: Wolf pruning of hills and dales lower than this percentage of Sz
        (see :func:`~rough.metrology.segment`).
    edge_features : {"exclude", "include"}, default "exclude"
        Maps: whether hills and dales that touch the border or invalid points count
        in the feature parameters.
    height, ratio, dc_ratios, volume_ratios : float, float, tuple, tuple
        The material-ratio settings: the height c of Rmr(c)/Smr(c) in metres about
        the mean (default 0), the material ratio mr of Rmc/Smc and Vm, Vv in %
        (default 10), the two ratios of Rδc/Sdc and the p:q of Vmp … Vvv in %
        (default (10, 80) each); see :func:`~rough.metrology.functional_parameters`.
    families : sequence of str, optional
        Which of :data:`FAMILIES` to compute; default all that apply (``feature``
        only for a map evaluated as a map). The feature family costs a watershed
        segmentation: leave it out when only heights are wanted.

    Returns
    -------
    dict of str to float
        Keyed as :data:`PROFILE` then :data:`PROFILE_FUNCTIONAL` for a profile (or
        a map with ``along``), and :data:`AREAL`, :data:`AREAL_FUNCTIONAL` then
        :data:`FEATURE` for a map, each value in the unit given there (metres, 1/m,
        m³/m², %, degrees, or a pure number). NaN (with one warning naming the
        parameters and the reason) for a parameter that is undefined for the data.

    Raises
    ------
    rough.InputError
        For a surface with no valid points, a bad ``slope``, ``along`` or family,
        the feature family asked of a profile, too many sampling lengths, or a
        cut-off the data cannot take.

    See Also
    --------
    profile_parameters, areal_parameters, functional_parameters, feature_parameters

    Notes
    -----
    With ``along``, RMS quantities (Rq, Rdq, Z2) combine as the quadratic mean over
    profiles (pooling the points, as SurfaceTopography's ``rms_height_from_profile``
    does), the others as the arithmetic mean; profiles with fewer than two valid
    points are left out. Definitions: docs/conventions.rst ("Metrology conventions").

    Examples
    --------
    >>> import rough
    >>> from rough.metrology import PROFILE, PROFILE_FUNCTIONAL, detrend, parameters
    >>> scan = rough.read(rough.sample("rock-profile.tsv"))
    >>> values = parameters(detrend(scan, order=2))
    >>> list(values) == [*PROFILE, *PROFILE_FUNCTIONAL]
    True
    >>> print(f"Ra {values['Ra'] * 1e6:.1f} µm, Rq {values['Rq'] * 1e6:.1f} µm, Rku {values['Rku']:.2f}")
    Ra 219.2 µm, Rq 273.7 µm, Rku 2.65

    Ra/Rq is close to √(2/π) = 0.798, as for Gaussian heights. With a cut-off the
    parameters are those of the roughness:

    >>> round(values["Ra"] / values["Rq"], 3)
    0.801
    >>> f"{parameters(scan, cutoff=0.8e-3, families=['field'])['Rq'] * 1e6:.2f} µm"
    '20.92 µm'

    A map gives the areal parameters, over its valid points, with the volumes and
    the feature parameters of its hills and dales:

    >>> scan = rough.read(rough.sample("rock-map.x3p"))
    >>> values = parameters(scan)
    >>> f"Sq {values['Sq'] * 1e6:.1f} µm, Sk {values['Sk'] * 1e6:.1f} µm, Spd {values['Spd'] * 1e-6:.2f} /mm²"
    'Sq 100.0 µm, Sk 286.3 µm, Spd 0.42 /mm²'
    >>> f"Rq {parameters(scan, along='x')['Rq'] * 1e6:.1f} µm"  # rows, each about its own mean
    'Rq 93.7 µm'
    """
    wanted = _families(families, surface.is_profile or along is not None)
    evaluated = surface if cutoff is None else split(surface, cutoff, "roughness", ends)
    lr = cutoff if sampling_length is None else sampling_length
    values, reasons = {}, {}
    if "field" in wanted:
        if surface.is_profile:
            values = profile_parameters(evaluated, sampling_lengths, slope, jrc_spacing, sampling_length=lr)
        elif along is None:
            values = areal_parameters(evaluated, slope, acf=acf)
        else:
            values = _profiles_of_map(evaluated, along, sampling_lengths, slope, jrc_spacing, lr)
    if "functional" in wanted:
        values |= functional_parameters(evaluated, height, ratio, dc_ratios, volume_ratios, along=along)
    if "feature" in wanted:
        hills, dales = (segment(evaluated, kind, pruning) for kind in ("hills", "dales"))
        values |= motif_parameters(evaluated, hills, dales, edge_features)
        reasons = undefined_reasons(hills, dales, edge_features)
    announce_undefined(values, reasons)
    return values


def _families(families, profiles):
    """The families to compute: all that apply by default; the feature family of a
    profile (or of a map's profiles) refused."""
    if families is None:
        return FAMILIES[:2] if profiles else FAMILIES
    families = [families] if isinstance(families, str) else list(families)
    unknown = [name for name in families if name not in FAMILIES]
    if unknown:
        raise InputError(
            f"unknown parameter families {', '.join(map(repr, unknown))}: choose from {', '.join(FAMILIES)}"
        )
    if profiles and "feature" in families:
        raise InputError("the feature parameters need a map evaluated as a map (not a profile, not along x or y)")
    return families


UNDEFINED = {
    "no height variation": ("Rsk", "Rku", "Ssk", "Sku", "Sal", "Str", "Std"),
    "the profile is shorter than one sampling length, the cut-off λc": ("Rp", "Rv", "Rz", "peak_density"),
    "no profile element rises and falls 10 % of Rz across the mean line": ("RSm",),
    "the profile spans fewer than three JRC spacings": ("Z2",),
    "Z2 is zero or undefined": ("JRC",),
    "no two neighbouring points are valid": ("Rdq", "Sdq", "Sdr"),
    "fewer than 40 points within ±3 standard deviations": ("Rpq", "Rvq", "Rmq", "Spq", "Svq", "Smq"),
    "no significant hill clear of the edge and invalid points; on a tilted or curved map, detrend first": (
        "Spc",
        "S5p",
        "Sha",
        "Shv",
    ),
    "no significant dale clear of the edge and invalid points": ("S5v", "Sda", "Sdv"),
    "S5p or S5v is undefined": ("S10z",),
}


def announce_undefined(values, reasons=None):
    """One warning naming each parameter of ``values`` that came out undefined (NaN)
    and why (Str has its own warning when Sal is defined); ``reasons`` (key: reason)
    says why for the data at hand, before the general reasons of :data:`UNDEFINED`
    (e.g. :func:`rough.metrology.segmentation.undefined_reasons`)."""
    undefined = {key for key, value in values.items() if math.isnan(value)}
    if "Str" in undefined and "Sal" not in undefined:
        undefined.discard("Str")
    given = {key: reason for key, reason in (reasons or {}).items() if key in undefined}
    grouped = {
        reason: [key for key in keys if key in undefined and key not in given] for reason, keys in UNDEFINED.items()
    }
    for key, reason in given.items():
        grouped.setdefault(reason, []).append(key)
    reasons = [f"{', '.join(named)} ({reason})" for reason, named in grouped.items() if named]
    explained = {key for keys in UNDEFINED.values() for key in keys} | set(given)
    others = sorted(undefined - explained)
    if others:
        reasons.append(
            f"{', '.join(others)} (outside the range of float64 arithmetic at this spacing and height scale)"
        )
    if reasons:
        log.warning(f"undefined for this surface: {'; '.join(reasons)}")


def _profiles_of_map(surface, along, sampling_lengths, slope, jrc_spacing, sampling_length):
    each = [
        profile_parameters(p, sampling_lengths, slope, jrc_spacing, sampling_length=sampling_length)
        for p in map_profiles(surface, along)
    ]
    values = combined(each, PROFILE, quadratic=("Rq", "Rdq", "Z2"))
    values["JRC"] = joint_roughness_coefficient(values["Z2"])
    return values
