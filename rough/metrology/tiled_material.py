"""The material-ratio parameters of a map read a strip at a time
(:func:`rough.metrology.tiled_parameters`).

Order statistics are selected exactly without sorting the map: a histogram of the
heights in :data:`BINS` equal bins between the exact lowest and highest (made in the
moments pass), then, while the bins holding the wanted ranks hold more than
:data:`GATHER` points, each of them is cut into finer cells in one more pass, and
a last pass gathers the distinct heights in the cells that hold the wanted ranks
(with their counts, so that ties cost one entry). A height's bin and cell come from
the same arithmetic in every pass and never decrease with the height, so cells
are ordered and the wanted ranks fall on the very heights a full sort would give.

Exact for the data (to the rounding of sums): Smr(c), Smc(mr), Sdc, Sxp and the
volumes Vm, Vv, Vmp, Vmc, Vvc, Vvv (sums over the points once their levels are
known). Estimated: Sk, Spk, Svk, Smr1, Smr2 on the curve sampled at
:data:`SAMPLES` equally spaced material ratios (exact heights there), and Spq, Svq,
Smq on the curve sampled at as many equally spaced Hazen probabilities; with no
more points than that, both are the whole curve and exact too.
"""

import math

import numpy as np

from .. import tasks
from ..errors import InputError
from .heights import ROUNDING
from .material_ratio import AREAL_FUNCTIONAL, MaterialRatioCurve

BINS = 1 << 20  # bins of the first histogram between the lowest and highest height
CELLS = 1 << 22  # the most counters of a refining pass
GATHER = 1 << 22  # the most points gathered at once; more are refined first
SAMPLES = 1 << 16  # points of the sampled curves of the core and probability fits
ESTIMATED = {
    **dict.fromkeys(
        ("Sk", "Spk", "Svk", "Smr1", "Smr2"), "ISO 13565-2 construction on the curve at 65536 exact order statistics"
    ),
    **dict.fromkeys(
        ("Spq", "Svq", "Smq"), "ISO 13565-3 fit on the curve at 65536 equally spaced probabilities (exact heights)"
    ),
}


class Grid:
    """Where a height falls: its bin of the first histogram and, after a refining
    pass, its cell within that bin. Small and picklable: it travels with each strip."""

    def __init__(self, low, high, bins=BINS):
        self.low, self.bins = float(low), int(bins)
        self.scale = bins / (high - low) if high > low else 0.0
        self.targets, self.cells, self._index = None, 1, None

    def __getstate__(self):  # the lookup is made where it is used, never shipped
        return {**self.__dict__, "_index": None}

    def bin_of(self, values):
        index = ((values - self.low) * self.scale).astype(np.int64)
        return np.clip(index, 0, self.bins - 1, out=index)

    def refined(self, targets, cells):
        """This grid with each bin of ``targets`` (sorted) cut into ``cells`` cells."""
        grid = Grid.__new__(Grid)
        grid.__dict__.update(self.__dict__, targets=np.asarray(targets, dtype=np.int64), cells=int(cells), _index=None)
        return grid

    def key_of(self, values):
        """``(key, inside)``: the cell of each height (its bin, without refining) and
        whether it lies in a refined bin."""
        bins = self.bin_of(values)
        if self.targets is None:
            return bins, np.ones(bins.size, dtype=bool)
        if self._index is None:  # each bin's place among the targets, -1 elsewhere
            self._index = np.full(self.bins, -1, dtype=np.int64)
            self._index[self.targets] = np.arange(self.targets.size)
        where = self._index[bins]
        inside = where >= 0
        low = self.low + bins[inside] / self.scale
        cell = ((values[inside] - low) * (self.scale * self.cells)).astype(np.int64)
        np.clip(cell, 0, self.cells - 1, out=cell)
        return where[inside] * self.cells + cell, inside

    @property
    def size(self):
        return self.bins if self.targets is None else self.targets.size * self.cells


def valid_heights(tiled, first, rows):
    """The valid heights of ``rows`` rows of ``tiled`` from row ``first``, flat."""
    heights = tiled.read(slice(first, first + rows)).reshape(-1)
    return heights[~np.isnan(heights)]


def chunks(values, size=1 << 20):
    """``values`` a slice at a time, so that no temporary is as large as a strip."""
    return (values[start : start + size] for start in range(0, values.size, size))


def count_cells(item):
    """Points per cell of ``grid`` in one strip (a refining pass)."""
    tiled, first, rows, grid = item
    counts = np.zeros(grid.size, dtype=np.int64)
    for chunk in chunks(valid_heights(tiled, first, rows)):
        counts += np.bincount(grid.key_of(chunk)[0], minlength=grid.size)
    return counts


def gather_cells(item):
    """The distinct heights of one strip that fall in the cells ``wanted`` (sorted),
    with their counts."""
    tiled, first, rows, grid, wanted = item
    found, chosen = [], np.zeros(grid.size, dtype=bool)
    chosen[wanted] = True
    for chunk in chunks(valid_heights(tiled, first, rows)):
        keys, inside = grid.key_of(chunk)
        found.append(chunk[inside][chosen[keys]])
    return np.unique(np.concatenate(found) if found else np.empty(0), return_counts=True)


def level_sums(item):
    """For each level (about the mean): the sums of ``h - level`` over the points
    above it and of ``level - h`` over the points below it, ``h`` the heights less
    ``mean``."""
    tiled, first, rows, mean, levels = item
    sums = [([], []) for _ in levels]
    for chunk in chunks(valid_heights(tiled, first, rows)):
        heights = chunk - mean
        for (above, below), level in zip(sums, levels):
            above.append(float(np.sum(np.maximum(heights - level, 0.0))))
            below.append(float(np.sum(np.maximum(level - heights, 0.0))))
    return [(math.fsum(above), math.fsum(below)) for above, below in sums]


def select(tiled, strips, counts, grid, ranks, jobs=1, scheduler=None):
    """The heights at ascending ``ranks`` (0 the lowest valid point) exactly, from the
    first histogram ``counts`` over ``grid``: refine while the wanted bins hold more
    than :data:`GATHER` points, then gather them."""
    ranks = np.asarray(ranks, dtype=np.int64)
    keys, below, counts = _cells_of(counts, ranks, np.zeros(ranks.size, dtype=np.int64))
    wanted = np.unique(keys)
    while counts[wanted].sum() > GATHER and grid.targets is None and grid.scale > 0:
        cells = int(min(4096, max(2, CELLS // wanted.size)))
        grid = grid.refined(wanted, cells)
        counts = _summed(
            tasks.map_ordered(count_cells, [(tiled, f, r, grid) for f, r in strips], jobs=jobs, scheduler=scheduler)
        )
        # each rank's bin is the index of its key in ``wanted``; its offset within that bin is known
        inner = np.searchsorted(wanted, keys) * cells
        keys, below, counts = _refine(counts, cells, inner, ranks - below, below)
        wanted = np.unique(keys)
    parts = tasks.map_ordered(
        gather_cells, [(tiled, f, r, grid, wanted) for f, r in strips], jobs=jobs, scheduler=scheduler
    )
    values, multiplicity = _merged(parts)
    if multiplicity.sum() != counts[wanted].sum():
        raise InputError("the heights changed between two readings of the map; read it again")
    before = np.concatenate([[0], np.cumsum(counts[wanted])[:-1]])[np.searchsorted(wanted, keys)]
    position = before + ranks - below
    return values[np.searchsorted(np.cumsum(multiplicity), position, side="right")]


def order_statistics(tiled, ranks, rows=None, jobs=1, scheduler=None):
    """The valid heights of ``tiled`` at ascending ``ranks`` (0 the lowest), exactly
    as a sort of them would give, read ``rows`` rows at a time: one pass for the
    extremes, one for the histogram, then :func:`select`."""
    rows = rows or tiled.strip_rows()
    strips = [(first, min(rows, tiled.shape[0] - first)) for first in range(0, tiled.shape[0], rows)]
    run = dict(jobs=jobs, scheduler=scheduler)
    parts = [p for p in tasks.map_ordered(_extremes, [(tiled, f, r) for f, r in strips], **run) if p]
    if not parts:
        raise InputError("no valid points: nothing to evaluate")
    grid = Grid(min(low for low, _ in parts), max(high for _, high in parts))
    counts = _summed(tasks.map_ordered(count_cells, [(tiled, f, r, grid) for f, r in strips], **run))
    if np.any(np.asarray(ranks) >= counts.sum()) or np.any(np.asarray(ranks) < 0):
        raise InputError(f"ranks must lie between 0 and {counts.sum() - 1}")
    return select(tiled, strips, counts, grid, ranks, jobs, scheduler)


def _extremes(item):
    values = valid_heights(*item)
    return (float(values.min()), float(values.max())) if values.size else None


def _cells_of(counts, ranks, below):
    """The cell of each rank from ``counts`` per cell (in order), and the points below it."""
    running = np.cumsum(counts)
    keys = np.searchsorted(running, ranks - below, side="right")
    return keys, below + running[keys] - counts[keys], counts


def _refine(counts, cells, inner, offsets, below):
    """The cell of each rank within the refined bins: ``inner`` the first cell of its
    bin, ``offsets`` its rank within that bin."""
    running = np.cumsum(counts)
    start = np.where(inner > 0, running[np.maximum(inner - 1, 0)], 0)
    keys = np.searchsorted(running, start + offsets, side="right")
    return keys, below + running[keys] - counts[keys] - start, counts


def _summed(parts):
    total = None
    for part in parts:
        total = part if total is None else total + part
    return total


def _merged(parts):
    values, counts = zip(*parts)
    values, inverse = np.unique(np.concatenate(values), return_inverse=True)
    return values, np.bincount(inverse, weights=np.concatenate(counts)).astype(np.int64)


def functional(tiled, strips, pass_one, counts, grid, settings, jobs=1, scheduler=None):
    """The areal material-ratio parameters (:data:`AREAL_FUNCTIONAL`) of ``tiled``:
    ``pass_one`` holds ``count``, ``mean``, ``low``, ``high`` of its valid heights,
    ``counts`` their histogram over ``grid`` and ``above`` the points at or above
    Smr's level; ``settings`` the keywords of :func:`functional_parameters`."""
    n, mean = pass_one["count"], pass_one["mean"]
    if n < 2:
        raise InputError("the material-ratio curve needs at least two valid points")
    step = 100.0 / (n - 1)
    samples = min(SAMPLES, n)
    ratio, (d1, d2), (p, q) = settings["ratio"], settings["dc_ratios"], settings["volume_ratios"]
    heights_at = {mr: _bracket(mr * (n - 1) / 100.0, n) for mr in {ratio, d1, d2, p, q, 2.5, 50.0}}
    after = pass_one["above"] - 1
    inner = min(max(after, 0), n - 2)
    core_at = np.linspace(0.0, n - 1.0, samples)
    hazen = np.clip((np.arange(samples) + 0.5) / samples * n - 0.5, 0.0, n - 1.0)
    descending = {k for k, _ in heights_at.values()} | {k + 1 for k, _ in heights_at.values()} | {inner, inner + 1}
    ascending = np.concatenate(
        [[n - 1 - k for k in descending], np.floor(core_at), np.ceil(core_at), np.floor(hazen), np.ceil(hazen)]
    )
    ranks = np.unique(np.clip(ascending, 0, n - 1).astype(np.int64))
    values = select(tiled, strips, counts, grid, ranks, jobs, scheduler) - mean

    def ascending_at(position):  # the curve between order statistics, ascending
        lower, upper = np.floor(position), np.ceil(position)
        low, high = (values[np.searchsorted(ranks, end.astype(np.int64))] for end in (lower, upper))
        return low + (position - lower) * (high - low)

    def h(k):  # the k-th highest height about the mean
        return float(values[np.searchsorted(ranks, n - 1 - k)])

    def smc(mr):
        k, fraction = heights_at[mr]
        return h(k) + fraction * (h(min(k + 1, n - 1)) - h(k))

    result = {"Smr": _smr(settings["height"], pass_one, h, inner, after, n, step)}
    result["Smc"] = smc(ratio)
    result["Sdc"] = smc(d1) - smc(d2)
    levels = sorted({ratio, p, q})
    sums = dict(zip(levels, _level_sums(tiled, strips, mean, [smc(mr) for mr in levels], jobs, scheduler)))
    volume = {mr: _volumes(mr, smc(mr), sums[mr], heights_at[mr], h, n, step) for mr in levels}
    core = MaterialRatioCurve(ascending_at(core_at)).core()  # shifted by its sample mean: no parameter moves
    fit = MaterialRatioCurve(ascending_at(hazen)).probability()
    result.update(Sk=core.height, Spk=core.reduced_peak, Svk=core.reduced_valley, Smr1=core.mr1, Smr2=core.mr2)
    result["Sxp"] = smc(2.5) - smc(50.0)
    result.update(Vm=volume[ratio][0], Vv=volume[ratio][1], Vmp=volume[p][0], Vmc=volume[q][0] - volume[p][0])
    result.update(Vvc=volume[p][1] - volume[q][1], Vvv=volume[q][1], Spq=fit.plateau, Svq=fit.valley)
    result["Smq"] = fit.transition
    return {key: float(result[key]) for key in AREAL_FUNCTIONAL}


def _bracket(position, n):
    """``(k, fraction)``: the curve point at or before ``position`` (a fractional
    index from the highest point) and how far on towards the next."""
    k = min(int(math.floor(position)), n - 1)
    return k, position - k


def smr_level(height, low, high):
    """The height (about the mean) from which points count as material for Smr(c):
    ``c`` less the heights' rounding, as :class:`MaterialRatioCurve` takes it."""
    return height - ROUNDING * max(abs(low), abs(high))


def _smr(height, pass_one, h, inner, after, n, step):
    if after < 0:
        return 0.0
    if after >= n - 1:
        return 100.0
    upper, lower = h(inner), h(inner + 1)
    fraction = min(max((upper - height) / (upper - lower), 0.0), 1.0) if upper > lower else 0.0
    return inner * step + fraction * step


def _level_sums(tiled, strips, mean, levels, jobs, scheduler):
    parts = list(
        tasks.map_ordered(level_sums, [(tiled, f, r, mean, levels) for f, r in strips], jobs=jobs, scheduler=scheduler)
    )
    return [tuple(math.fsum(part[i][side] for part in parts) for side in (0, 1)) for i in range(len(levels))]


def _volumes(mr, level, sums, at, h, n, step):
    """``(Vm(mr), Vv(mr))`` of the piecewise-linear curve whose level at ``mr`` is
    ``level``: its trapezia written as sums over points (``sums``: above, below)."""
    k, fraction = at
    above, below = sums
    top, bottom = h(0), h(n - 1)
    material = step * (above - (top - level) / 2 - (h(k) - level) / 2 + fraction * (h(k) - level) / 2)
    if k >= n - 1:
        void = 0.0
    else:
        void = step * (below - (level - bottom) / 2 - fraction * (level - h(k + 1)) / 2)
    return max(0.0, material) / 100.0, max(0.0, void) / 100.0
