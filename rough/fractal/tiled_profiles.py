"""The profiles of a map larger than memory along x or y (:func:`fit_profiles_tiles`),
exactly as in memory (:func:`~rough.fractal.fit_profiles`).

The rows lie whole in full-width strips and the columns in column strips, so the
profile set is the one taken in memory: each strip's profiles are taken by
:func:`~rough.fractal.take_profiles` and their periodograms pooled where they are.
The pooled Whittle likelihood is a sum over ordinates, so a block of neighbouring
profiles is its ordinates' sums and counts at each frequency: the strips give each
jackknife block's sums, and the fit, the design effect and the jackknife run on the
16 blocks' sums as on the profiles. The blocks are first cut as if every line kept
enough points; when some did not, the strips are read again with the blocks of the
profiles kept. The per-profile spread of H needs the band, found only by the fit: the
strips are read once more for it (``spread=False`` leaves it out).
"""

import dataclasses
import math

import numpy as np

from .. import tasks
from ..errors import InputError
from ..io.tiled import memory_budget, tile_points
from ..surface import Surface
from .choices import GAPS, SAMPLINGS
from .jackknife import neighbour_blocks
from .pooled import periodograms, pooled
from .profile_set import take_profiles
from .profiles import ProfileFit, _limits, pooled_fit
from .scaling import fit_spectrum
from .tiled import model_of
from .whittle import BETA_RANGE, FLAT, Options, history_sampling

EMPTY = (np.empty(0), np.empty(0))
MIN_POINTS = 64  # take_profiles' default


@dataclasses.dataclass
class TiledProfileFit(ProfileFit):
    """A :class:`~rough.fractal.ProfileFit` of a map read in strips, with ``tiled``:
    ``strips`` (read per pass), ``strip_lines`` (profiles a strip), ``passes`` (reads
    of the map), ``exact`` (every value: the same profiles and arithmetic as in memory,
    up to the order of summation) and ``estimated`` (nothing). ``profile_set`` is None."""

    tiled: dict = None


@dataclasses.dataclass(frozen=True)
class _Taken:
    """What stands for the profile set in the pooled fit (its heights are not kept)."""

    spacing: float
    label: str
    angle: float
    gaps: str
    points: int
    interpolation: str = "none (grid lines)"
    heights: list = None


def fit_profiles_tiles(
    tiled, direction="x", gaps="longest", *, spread=True, jobs=1, scheduler=None, budget=None, **model
):
    """H, D = 2 - H and C of the rows or columns of a map read in strips, as
    :func:`~rough.fractal.fit_profiles` finds them in memory.

    Parameters
    ----------
    tiled : rough.io.TiledSurface
        The map; invalid (NaN) points are handled by the gap rule, as in memory.
    direction : {"x", "y"}, default "x"
        The rows or the columns (an angle needs the map whole).
    gaps, spread
        As for :func:`~rough.fractal.fit_profiles`.
    jobs, scheduler, budget
        How many strips are worked on at once and where (:func:`rough.tasks.map_ordered`),
        and the memory in bytes that one strip may take (default: :func:`rough.io.memory_budget`).
    **model
        ``band``, ``resolution``, ``order``, ``sampling``, ``noise``, ``rolloff`` and
        ``level``, as for :func:`~rough.fractal.fit_profiles`.

    Returns
    -------
    TiledProfileFit
        The fit as in memory (no profile set, and no scale table without a power
        law), with ``tiled`` saying how it was read.

    Raises
    ------
    rough.InputError
        As :func:`~rough.fractal.fit_profiles`, and for a direction other than x or y.

    Examples
    --------
    >>> import rough
    >>> from rough.fractal.tiled_profiles import fit_profiles_tiles
    >>> scan = rough.synthesize_map((512, 256), (1e-6, 1e-6), 2.5, rq=1e-6, seed=2)  # 256 rows of 512
    >>> tiled = fit_profiles_tiles(rough.io.TiledSurface.of(scan), "x", budget=1)  # the smallest strips
    >>> whole = rough.fractal.fit_profiles(scan, "x")
    >>> abs(tiled.fit.hurst - whole.fit.hurst) < 1e-7, tiled.tiled["strips"], tiled.tiled["strip_lines"]
    (True, 2, 128)
    """
    band, resolution, order, sampling, noise, rolloff, level = model_of(model).values()
    if sampling is not None and sampling not in SAMPLINGS:
        raise InputError(f"sampling must be one of {', '.join(SAMPLINGS)}, not {sampling!r}")
    if not 0 < level < 1:
        raise InputError(f"the test's level must lie between 0 and 1, not {level}")
    if gaps not in GAPS:
        raise InputError(f"gaps must be one of {', '.join(GAPS)}, not {gaps!r}")
    if not (isinstance(order, (int, np.integer)) and order >= 0):
        raise InputError(f"the form's order must be a whole number from 0, not {order!r}")
    axis = str(direction).strip().casefold()
    if axis not in ("x", "y"):
        shown = f"{np.degrees(direction):g}°" if isinstance(direction, (float, int)) else repr(direction)
        raise InputError(f"a map read in tiles gives profiles along x or y, not {shown}")
    across = 0 if axis == "x" else 1
    lines, length = tiled.shape[across], tiled.shape[1 - across]
    width = max(1, tile_points(memory_budget() if budget is None else budget) // length)
    strips = [(start, min(start + width, lines)) for start in range(0, lines, width)]
    work = {"jobs": jobs, "scheduler": scheduler}
    spectra, blocks, parts = _block_spectra(tiled, axis, strips, (gaps, order), _block_ids(np.arange(lines)), work)
    passes = 1
    kept = np.concatenate([part["lines"] for part in parts])
    if kept.size < lines:  # some lines kept too few points: cut the blocks among the profiles kept
        ids = np.full(lines, -1)
        ids[kept] = _block_ids(kept)
        spectra, blocks, parts = _block_spectra(tiled, axis, strips, (gaps, order), ids, work)
        passes += 1
    _refuse_flat(parts)
    spacing = tiled.spacing[1 - across]
    taken = _Taken(spacing, axis, 0.0 if axis == "x" else math.pi / 2, gaps, sum(part["points"] for part in parts))
    made = history_sampling(tiled)
    source = "option" if sampling else "history" if made else "default (point samples)"
    sampling = sampling or made or "point"
    options = Options(noise, rolloff, level)
    bands = (_limits(taken, tiled, band, None), band)
    spectra += [EMPTY] * (kept.size - len(spectra))  # the blocks' sums stand for their profiles
    result = pooled_fit(taken, spectra, blocks, bands, (sampling, source), resolution or spacing, options, False)
    hurst = math.nan
    if spread and result.fit.fit_band is not None:
        task = ("hurst", gaps, order, tuple(result.fit.fit_band), sampling)
        items = [(tiled, axis, strip, task) for strip in strips]
        values = np.concatenate([part for part in tasks.map_ordered(_strip_part, items, **work)])
        hurst = float(np.std(values, ddof=1)) if values.size > 1 else math.nan
        passes += 1
    information = {
        "strips": len(strips),
        "strip_lines": width,
        "passes": passes,
        "exact": ["fractal_dimension", "hurst", "amplitude_coefficient", "standard errors", "hurst_spread"],
        "estimated": {},
    }
    values = {field.name: getattr(result, field.name) for field in dataclasses.fields(ProfileFit)}
    values.update(hurst_spread=hurst, profile_set=None)
    return TiledProfileFit(**values, tiled=information)


def _block_ids(positions):
    """The jackknife block of each profile at ``positions`` (as in memory)."""
    ids = np.zeros(positions.size, np.int64)
    for number, block in enumerate(neighbour_blocks(positions) or [np.arange(positions.size)]):
        ids[block] = number
    return ids


def _block_spectra(tiled, axis, strips, taking, ids, work):
    """``(spectra, blocks, parts)``: each block's pooled sums ``(f, ΣI, n)``, the
    blocks as indices of them (None with fewer than 8 profiles, as in memory) and the
    strips' parts."""
    items = [(tiled, axis, strip, ("spectra", *taking, ids[slice(*strip)])) for strip in strips]
    parts = list(tasks.map_ordered(_strip_part, items, **work))
    sums = {}
    for part in parts:
        for block, spectrum in part["blocks"].items():
            sums[block] = _merged(sums.get(block), spectrum)
    kept = sum(part["lines"].size for part in parts)
    if not kept:
        raise InputError(
            f"no profile along {axis} keeps {MIN_POINTS} valid points in a row (gaps: {taking[0]}); "
            "fill the invalid points or take another direction"
        )
    spectra = [sums[block] for block in sorted(sums)]
    blocks = [np.array([index]) for index in range(len(spectra))] if neighbour_blocks(np.arange(kept)) else None
    return spectra, blocks, parts


def _merged(first, second):
    """Two pooled sums ``(f, ΣI, n)`` as one (``first`` may be None)."""
    return second if first is None else _summed([first, second])


def _summed(spectra):
    """Pooled sums ``(f, ΣI, n)`` of several, one entry per distinct frequency."""
    distinct, inverse = np.unique(np.concatenate([spectrum[0] for spectrum in spectra]), return_inverse=True)
    totals = [np.concatenate([spectrum[column] for spectrum in spectra]) for column in (1, 2)]
    return (distinct, *(np.bincount(inverse, weights=total, minlength=distinct.size) for total in totals))


def _strip_part(item):
    """One strip's profiles: with ``("spectra", gaps, order, block ids)`` the lines
    kept, their points, the levelled heights' sum of squares, the largest height and
    each block's pooled sums; with ``("hurst", gaps, order, band, sampling)`` each
    profile's own H over the band (no noise floor), as the spread in memory."""
    tiled, axis, (start, stop), task = item
    window = slice(start, stop)
    heights = tiled.read(window) if axis == "x" else tiled.read(slice(None), window)
    try:
        taken = take_profiles(Surface(heights, tiled.spacing), axis, task[1], task[2], MIN_POINTS)
    except InputError:  # no profile here keeps enough points
        taken = None
    if task[0] == "hurst":
        return _own_hursts(taken, *task[3:])
    finite = np.abs(heights[np.isfinite(heights)])
    part = {
        "lines": np.empty(0, np.int64),
        "points": 0,
        "squares": (0.0, 0),
        "largest": float(finite.max()) if finite.size else 0.0,
        "blocks": {},
    }
    if taken is None:
        return part
    where = start + np.rint(taken.positions / tiled.spacing[1 if axis == "x" else 0]).astype(np.int64)
    residual = np.concatenate(taken.heights)
    part.update(lines=where, points=taken.points, squares=(float(residual @ residual), residual.size))
    ids = task[3][where - start]
    spectra = [(f, values, np.ones(f.size)) for f, values in periodograms(taken.heights, taken.spacing)]
    for block in np.unique(ids):
        part["blocks"][int(block)] = _summed([spectra[index] for index in np.flatnonzero(ids == block)])
    return part


def _own_hursts(taken, band, sampling):
    """Each profile's H over ``band`` (a profile without 8 frequencies there, or flat
    over it, has none)."""
    values = []
    for spectrum in periodograms(taken.heights, taken.spacing) if taken else ():
        bins = pooled([spectrum], taken.spacing, band, sampling)
        if bins is not None and np.any(bins.density > 0):
            values.append((fit_spectrum(bins, BETA_RANGE, False).exponent - 1.0) / 2.0)
    return np.array(values)


def _refuse_flat(parts):
    """As in memory: refuse profiles whose levelled heights are rounding next to the map's."""
    squares = sum(part["squares"][0] for part in parts)
    count = sum(part["squares"][1] for part in parts)
    if not math.sqrt(squares / count) > FLAT * max(part["largest"] for part in parts):
        raise InputError("the surface is flat once its form is removed: there is no roughness to fit")
