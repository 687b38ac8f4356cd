"""ISO parameters of a map larger than memory, read a strip of full rows at a time
(:class:`rough.io.TiledSurface`), each strip's work a task of :mod:`rough.tasks`.

Passes over the strips:

1. the count, sum, lowest and highest valid height, and Sdq and Sdr (each strip
   with the rows its slopes need beyond it, so every neighbouring pair is counted
   once);
2. about the mean: the sums of ``|h|, h², h³, h⁴`` (Sa … Sku, as the in-memory
   :func:`~rough.metrology.heights.amplitude` takes them), the amplitude density,
   a fine histogram of the heights, the points at or above Smr's level, and the
   tile spectra of Sal, Str and Std (:mod:`rough.metrology.tiled_spectrum`);
3. the material-ratio passes of :mod:`rough.metrology.tiled_material`.

The moments are taken about the global mean in the second pass rather than merged
from per-strip moments (Chan's parallel formulas): Sa, the mean absolute deviation,
needs the global mean anyway, and sums about it are the in-memory path's own.
"""

import dataclasses
import logging
import math

import numpy as np

from .. import tasks
from ..errors import InputError
from . import tiled_material, tiled_spectrum
from .areal import AREAL
from .evaluation import announce_undefined
from .heights import MAGNITUDE, ROUNDING, check_slope, exact_mean, slopes, strip_extent
from .material_ratio import AREAL_FUNCTIONAL
from .segmentation import FEATURE

#: The parameters the tiled path gives exactly as the in-memory one (to rounding).
EXACT = (
    *("Sa", "Sq", "Ssk", "Sku", "Sp", "Sv", "Sz", "Sdq", "Sdr"),
    *("Smr", "Smc", "Sdc", "Sxp", "Vm", "Vv", "Vmp", "Vmc", "Vvc", "Vvv"),
)
#: The features that a tiled run leaves undefined, and why.
FEATURE_REASON = (
    "the watershed's Wolf pruning merges motifs across the whole map, which strips cannot reproduce "
    "faithfully; crop the map or give a larger --memory to segment it whole"
)
log = logging.getLogger("rough")
DENSITY_BINS = 50  # bins of the amplitude density, as rough.metrology.amplitude_density's default


@dataclasses.dataclass
class TiledEvaluation:
    """What :func:`tiled_evaluation` found.

    Attributes
    ----------
    values : dict of str to float
        Keyed as :data:`~rough.metrology.AREAL`, :data:`~rough.metrology.AREAL_FUNCTIONAL`
        and :data:`~rough.metrology.FEATURE`; NaN where undefined.
    density : tuple of numpy.ndarray
        The amplitude density ``(centres, density)`` as
        :func:`~rough.metrology.amplitude_density` gives it.
    count : int
        The valid points.
    section : dict
        How the values were had: ``tile_rows``, ``tiles``, ``spectrum_tile``,
        ``exact`` (names), ``estimated`` (name: how), ``undefined`` (name: why),
        ``pruning`` and ``edges``.
    reasons : dict
        Why each parameter the tiles cannot give is undefined (name: reason).
    """

    values: dict
    density: tuple
    count: int
    section: dict
    reasons: dict = dataclasses.field(default_factory=dict)


def tiled_parameters(tiled, **options):
    """The areal, functional and feature parameters of a map read a strip at a time.

    The same keys as :func:`~rough.metrology.parameters`,
    :func:`~rough.metrology.functional_parameters` and
    :func:`~rough.metrology.motif_parameters` of the whole map; the keywords and
    everything else as :func:`tiled_evaluation`, whose ``values`` this returns.

    Parameters
    ----------
    tiled : rough.io.TiledSurface
        The map; NaN points are left out.
    **options
        As :func:`tiled_evaluation`.

    Returns
    -------
    dict of str to float
        NaN where undefined, with one warning naming each such parameter and why.

    Examples
    --------
    The sample map read 32 rows at a time gives the in-memory Sq and Smc exactly;
    the feature parameters are undefined on tiles:

    >>> import math
    >>> import rough
    >>> from rough.io import TiledSurface
    >>> from rough.metrology import functional_parameters, parameters, tiled_parameters
    >>> scan = rough.read(rough.sample("rock-map.x3p"))
    >>> values = tiled_parameters(TiledSurface.of(scan), rows=32)
    >>> math.isclose(values["Sq"], parameters(scan)["Sq"], rel_tol=1e-12)
    True
    >>> math.isclose(values["Smc"], functional_parameters(scan)["Smc"], rel_tol=1e-12)
    True
    >>> math.isnan(values["Spd"])
    True
    """
    return tiled_evaluation(tiled, **options).values


def tiled_evaluation(
    tiled,
    slope="2point",
    acf="iso",
    height=0.0,
    ratio=10.0,
    dc_ratios=(10.0, 80.0),
    volume_ratios=(10.0, 80.0),
    pruning=5.0,
    edges="exclude",
    budget=None,
    rows=None,
    jobs=1,
    scheduler=None,
):
    """ISO 25178-2 parameters of a map larger than memory, a strip of rows at a time.

    Exact (equal to the in-memory values to the rounding of sums): Sa, Sq, Ssk,
    Sku, Sp, Sv, Sz, Sdq, Sdr, Smr, Smc, Sdc, Sxp and the volumes (:data:`EXACT`).
    Estimated, as ``section["estimated"]`` says: Sk, Spk, Svk, Smr1, Smr2 and Spq,
    Svq, Smq on the material-ratio curve sampled at 65 536 exact order statistics
    (exact for maps of no more points); Sal and Str from the autocorrelation of the
    averaged tile spectra (lags up to a quarter of a tile), Std from the averaged
    Hann-windowed tile spectra. The feature parameters are NaN: the watershed's
    pruning is global (:data:`FEATURE_REASON`).

    Parameters
    ----------
    tiled : rough.io.TiledSurface
        The map. NaN points are left out of every parameter (slopes use pairs of
        valid neighbours, the spectra set them to the mean, as in memory).
    slope : {"2point", "7point"}, default "2point"
        The slope of Sdq and Sdr, as :func:`~rough.metrology.areal_parameters`.
    acf : {"iso", "per-lag"}, default "iso"
        The autocorrelation of Sal and Str.
    height, ratio, dc_ratios, volume_ratios
        As :func:`~rough.metrology.functional_parameters`.
    pruning : float, default 5
        Wolf pruning, % of Sz (recorded; the features are not computed on tiles).
    edges : {"exclude", "include"}, default "exclude"
        As :func:`~rough.metrology.motif_parameters` (recorded likewise).
    budget : int, optional
        Memory budget in bytes for one strip (default :func:`rough.io.memory_budget`).
    rows : int, optional
        Rows per strip (default: as many as ``budget`` allows); rounded down to a
        whole number of spectrum tiles. The exact parameters do not depend on it.
    jobs : int, default 1
        Worker processes for the strips (:func:`rough.tasks.map_ordered`).
    scheduler : str, optional
        A Dask scheduler's address to run the strips on instead.

    Returns
    -------
    TiledEvaluation

    Raises
    ------
    rough.InputError
        For a map with fewer than two valid points, a height beyond ±1e60 m, bad
        ratios, an unknown ``slope`` or ``acf``, or a source that changes between
        passes.
    """
    for low, high in (dc_ratios, volume_ratios):
        if not 0 <= low < high <= 100:
            raise InputError(f"material ratios must lie between 0 and 100 % in increasing order, not {low} and {high}")
    if not 0 <= ratio <= 100:
        raise InputError(f"a material ratio must lie between 0 and 100 %, not {ratio}")
    check_slope(slope, min(tiled.shape))
    tiled_spectrum.check_acf(acf)
    ny, nx = tiled.shape
    halo = 1 if slope == "2point" else 6
    rows = tiled.strip_rows(budget, halo) if rows is None else max(1, int(rows))
    tile = tiled_spectrum.tile_size(tiled.shape, rows)
    rows = max(tile, rows // tile * tile)
    strips = [(first, min(rows, ny - first)) for first in range(0, ny, rows)]
    run = dict(jobs=jobs, scheduler=scheduler)
    first = _first_pass(tiled, strips, slope, run)
    if first["count"] < 2:
        raise InputError("fewer than two valid points: nothing to evaluate")
    grid = tiled_material.Grid(first["low"], first["high"])
    level = tiled_material.smr_level(height, first["low"], first["high"])
    second = _second_pass(tiled, strips, first, grid, level, tile, run)
    first["above"] = second["above"]
    values = _height_parameters(first, second)
    values.update(Sdq=first["Sdq"], Sdr=first["Sdr"])
    spatial, reasons = tiled_spectrum.spatial(second["spectra"], tiled.spacing, tile, (ny, nx), acf)
    values.update(spatial)
    settings = {"height": height, "ratio": ratio, "dc_ratios": dc_ratios, "volume_ratios": volume_ratios}
    values.update(tiled_material.functional(tiled, strips, first, second["histogram"], grid, settings, **run))
    values.update(dict.fromkeys(FEATURE, math.nan))
    reasons.update(dict.fromkeys(FEATURE, FEATURE_REASON))
    values = {key: values[key] for key in (*AREAL, *AREAL_FUNCTIONAL, *FEATURE)}
    if "Str" in reasons and not math.isnan(values["Sal"]):  # announce_undefined leaves Str to its own warning
        log.warning("Str is undefined: %s", reasons["Str"])
    announce_undefined(values, reasons)
    estimated = {**tiled_spectrum.estimated(tile), **tiled_material.ESTIMATED}
    section = {
        "tile_rows": rows,
        "tiles": len(strips),
        "spectrum_tile": tile,
        "exact": list(EXACT),
        "estimated": estimated,
        "undefined": {key: why for key, why in reasons.items() if math.isnan(values[key])},
        "pruning": pruning,
        "edges": edges,
    }
    return TiledEvaluation(values, second["density"], first["count"], section, reasons)


def _first_pass(tiled, strips, slope, run):
    items = [(tiled, first, rows, slope) for first, rows in strips]
    parts = list(tasks.map_ordered(first_pass, items, **run))
    count = sum(part["count"] for part in parts)
    found = [part for part in parts if part["count"]]
    low = min((part["low"] for part in found), default=math.nan)
    high = max((part["high"] for part in found), default=math.nan)
    if found and not max(high, -low) <= MAGNITUDE:
        raise InputError(
            f"a height of {high if high > -low else low:.6g} m is beyond ±{MAGNITUDE:g} m, where the "
            "parameters' sums of powers overflow: the data are damaged, or their unit is wrong"
        )
    pairs = sum(part["pairs"] for part in parts)
    square, developed = (math.fsum(part[key] for part in parts) for key in ("square", "developed"))
    mean = exact_mean(sum(part["sum"] for part in parts), count)
    return {
        "count": count,
        "mean": mean,
        "low": low,
        "high": high,
        "Sdq": math.sqrt(square / pairs) if pairs else math.nan,
        "Sdr": 100.0 * developed / pairs if pairs else math.nan,
    }


def first_pass(item):
    """One strip's count, sum, extremes and slope sums (a task of :func:`tiled_evaluation`)."""
    tiled, first, rows, slope = item
    ny = tiled.shape[0]
    before = 0 if slope == "2point" else 3
    after = max(before, 1)
    start = max(first - before, 0)
    heights = tiled.read(slice(start, min(first + rows + after, ny)))
    own = heights[first - start : first - start + rows]
    part = strip_extent(own[~np.isnan(own)])
    # the rows whose slopes are defined: 0 … ny - 2 (forward), 3 … ny - 4 (seven-point), a block at a time
    dx, dy = tiled.spacing
    sums = [(0, 0.0, 0.0)]
    block = max(1, CHUNK // tiled.shape[1])
    for top in range(max(first, before), min(first + rows, ny - after), block):
        bottom = min(top + block, first + rows, ny - after)
        along_x = slopes(heights[top - start : bottom - start], dx, slope, axis=1)
        along_y = slopes(heights[top - start - before : bottom - start + after], dy, slope, axis=0)
        squared = along_x**2 + (along_y[:, :-1] if slope == "2point" else along_y[:, 3:-3]) ** 2
        squared = squared[~np.isnan(squared)]
        sums.append((squared.size, float(squared.sum()), float((np.sqrt(1.0 + squared) - 1.0).sum())))
    pairs, square, developed = zip(*sums)
    part.update(pairs=sum(pairs), square=math.fsum(square), developed=math.fsum(developed))
    return part


CHUNK = 1 << 20  # values at once in a strip: no temporaries as large as the strip (and exact float64 sums)


def _second_pass(tiled, strips, first, grid, level, tile, run):
    mean, low, high = first["mean"], first["low"], first["high"]
    constant = max(high - mean, mean - low) <= ROUNDING * abs(mean)
    edges = np.linspace(low - mean, high - mean, DENSITY_BINS + 1)
    shared = (mean, constant, grid, level, edges, tile)
    parts = tasks.map_ordered(second_pass, [(tiled, f, r, shared) for f, r in strips], **run)
    total = None
    for part in parts:  # lists join, counts and arrays add
        total = part if total is None else {key: total[key] + value for key, value in part.items()}
    total["constant"] = constant
    width = edges[1] - edges[0]
    with np.errstate(invalid="ignore", divide="ignore"):
        total["density"] = ((edges[:-1] + edges[1:]) / 2, total.pop("bins") / (first["count"] * width))
    return total


def second_pass(item):
    """One strip's sums about the mean, histograms, Smr count and tile spectra (a
    task of :func:`tiled_evaluation`)."""
    tiled, first, rows, (mean, constant, grid, level, edges, tile) = item
    heights = tiled.read(slice(first, first + rows))
    values = heights[~np.isnan(heights)]
    part = {"sums": [], "histogram": 0, "bins": 0.0, "above": 0}
    for start in range(0, values.size, CHUNK):
        chunk = values[start : start + CHUNK]
        deviation = np.zeros(chunk.size) if constant else chunk - mean
        squared = deviation * deviation
        part["sums"].append(
            (np.abs(deviation).sum(), squared.sum(), (squared * deviation).sum(), (squared * squared).sum())
        )
        part["histogram"] += np.bincount(grid.bin_of(chunk), minlength=grid.bins)
        part["bins"] += np.histogram(deviation, bins=edges)[0].astype(np.float64)
        part["above"] += int(np.count_nonzero(chunk - mean >= level))
    part["spectra"] = tiled_spectrum.strip_spectra(heights, mean, constant, tile, first, tiled.shape)
    return part


def _height_parameters(first, second):
    """Sa … Sz from the sums about the mean, as the in-memory amplitude moments."""
    count, mean = first["count"], first["mean"]
    if second["constant"]:
        return {"Sa": 0.0, "Sq": 0.0, "Ssk": math.nan, "Sku": math.nan, "Sp": 0.0, "Sv": 0.0, "Sz": 0.0}
    absolute, square, cube, fourth = (math.fsum(column) / count for column in zip(*second["sums"]))
    sq = math.sqrt(square)
    sp, sv = float(first["high"] - mean), 0.0 - float(first["low"] - mean)
    return {
        "Sa": absolute,
        "Sq": sq,
        "Ssk": cube / sq**3 if sq > 0 else math.nan,
        "Sku": fourth / sq**4 if sq > 0 else math.nan,
        "Sp": sp,
        "Sv": sv,
        "Sz": sp + sv,
    }
