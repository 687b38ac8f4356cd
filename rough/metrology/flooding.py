"""The watershed under :func:`rough.metrology.segmentation.segment`: one region per
regional minimum, the figures of each region and the saddles between them, and Wolf
pruning on that graph of regions (the definitions: :mod:`rough.metrology.segmentation`).

Two routes give the same regions. On maps of :data:`COMPILED_MIN` points or more,
compiled passes (numba, loaded on first use: :func:`rough.compiled.compiled`) take the
regions by steepest descent where that decides them and gather each region's figures
and the pour heights in one sweep; on smaller maps, scikit-image's watershed and
whole-array operations do, without loading numba. Kruskal's loop over the saddles is
compiled from :data:`COMPILED_SADDLES` saddles.
"""

import numpy as np
from scipy import ndimage
from skimage.morphology import local_minima
from skimage.segmentation import watershed

from ..compiled import compiled

EIGHT = np.ones((3, 3), dtype=bool)
COMPILED_MIN = 1 << 20  # points from which the compiled passes pay for loading numba (~0.35 s)
COMPILED_SADDLES = 1 << 16  # saddles from which the compiled Kruskal loop pays for it
BAND = 1 << 20  # points a call of a compiled pass covers, between chances to stop it
# one of each pair of opposite 8-neighbours: along x, along y, and the two diagonals
NEIGHBOURS = (
    (np.s_[:, :-1], np.s_[:, 1:]),
    (np.s_[:-1, :], np.s_[1:, :]),
    (np.s_[:-1, :-1], np.s_[1:, 1:]),
    (np.s_[:-1, 1:], np.s_[1:, :-1]),
)


def route(size):
    """How a map of ``size`` points is segmented: ``"compiled passes"`` or ``"array operations"``."""
    return "compiled passes" if size >= COMPILED_MIN else "array operations"


def basins(filled, valid):
    """One watershed region per regional minimum of ``filled`` (8-connected), within
    ``valid``; a connected part of the valid points without a minimum (a constant
    one) gets one at its lowest point. Returns the labels (0 outside) and their count:
    scikit-image's watershed from those markers, taken by steepest descent where that
    gives the same regions (:func:`descend`) on maps large enough to pay for it."""
    markers, count = basin_markers(filled, valid)
    labels = descend(filled, valid, markers) if filled.size >= COMPILED_MIN else None
    if labels is None:
        labels = watershed(filled, markers, connectivity=2, mask=valid)
    return labels, count


def basin_markers(filled, valid):
    """The markers of :func:`basins`, numbered 1 … count, and their count."""
    minima = local_minima(filled, connectivity=2, allow_borders=True) & valid
    markers, count = ndimage.label(minima, structure=EIGHT)
    parts, part_count = ndimage.label(valid, structure=EIGHT)
    marked = np.zeros(part_count + 1, dtype=bool)
    marked[parts[minima]] = True
    missing = np.flatnonzero(~marked[1:]) + 1
    for position in ndimage.minimum_position(filled, parts, missing) if missing.size else ():
        count += 1
        markers[position] = count
    return markers, count


def descend(filled, valid, markers):
    """The regions of :func:`basins` by steepest descent, or None where it does not
    decide them.

    scikit-image's watershed floods from the markers, lowest first, and labels a point
    from the first labelled neighbour that reaches it. When every valid point that is
    not a marker has a neighbour strictly lower than itself, the flood reaches it first
    from its lowest neighbours (all lower points are flooded before any higher one), so
    it takes their label, when they share one. That holds for almost every map of
    float heights; on a plateau, or where a point's lowest neighbours lie in two
    basins, the order of arrival decides and this returns None. Compiled, a band of
    rows a call, so that Ctrl-C stops it between bands."""
    kernel, labels = compiled(_descend_rows), markers.copy()
    ny, nx = filled.shape
    band = max(1, BAND // nx)
    stack = np.empty(1024, dtype=np.int64)
    heights, inside, flat = filled.ravel(), valid.ravel(), labels.ravel()
    for first in range(0, ny, band):
        stack = kernel(heights, inside, flat, nx, first * nx, min(ny, first + band) * nx, stack)
        if stack.size == 0:
            return None
    return labels


def _descend_rows(heights, valid, labels, nx, start, stop, stack):
    """Label the points start … stop - 1 (and those their descents pass through) for
    :func:`descend`, all arrays flat; returns the stack, grown as needed, or an empty
    one where the descent does not decide. Plain Python, compiled by
    :func:`rough.compiled.compiled`."""
    ny = heights.size // nx
    for origin in range(start, stop):
        if labels[origin] != 0 or not valid[origin]:
            continue
        top = 0
        stack[0] = origin
        while top >= 0:
            point = stack[top]
            if labels[point] != 0:
                top -= 1
                continue
            i, j = point // nx, point % nx
            lowest, below = heights[point], -1
            for row in range(max(i - 1, 0), min(i + 2, ny)):
                for q in range(row * nx + max(j - 1, 0), row * nx + min(j + 2, nx)):
                    if valid[q] and heights[q] < lowest:
                        lowest, below = heights[q], q
            if below < 0:  # a plateau: the order of arrival decides
                return stack[:0]
            label, waiting = 0, -1
            for row in range(max(i - 1, 0), min(i + 2, ny)):
                for q in range(row * nx + max(j - 1, 0), row * nx + min(j + 2, nx)):
                    if valid[q] and heights[q] == lowest:
                        if labels[q] == 0:
                            waiting = q
                        elif label == 0:
                            label = labels[q]
                        elif labels[q] != label:  # lowest neighbours in two basins
                            return stack[:0]
            if waiting < 0:
                labels[point] = label
                top -= 1
                continue
            top += 1
            if top == stack.size:
                grown = np.empty(2 * stack.size, dtype=stack.dtype)
                grown[: stack.size] = stack
                stack = grown
            stack[top] = waiting
    return stack


def region_figures(filled, labels, count):
    """Per region (index 1..count; index 0 is the invalid points): the lowest value and
    the index of its first point in row-major order, the highest value, the number of
    points, whether it touches the border or an invalid point; and the pairs of
    8-neighbouring points in different regions with their pour heights (the higher of
    the two values; some pairs of the same two regions may be kept as one, at the
    lowest of their pour heights). Compiled passes on large maps, whole-array
    operations on small ones."""
    if filled.size < COMPILED_MIN:
        return _regions_by_masks(filled, labels, count)
    kernel, heights, flat_labels = compiled(_region_pass), filled.ravel(), labels.ravel()
    low, high = np.full(count + 1, np.inf), np.full(count + 1, -np.inf)
    pit, area, edge = np.zeros(count + 1, np.int64), np.zeros(count + 1, np.int64), np.zeros(count + 1, bool)
    figures = (heights, flat_labels, labels.shape[1], low, high, pit, area, edge)

    def sweep(listing, first, second, pour):  # a band at a time: between them, Ctrl-C can stop it
        pairs = 0
        for start in range(0, heights.size, BAND):
            pairs = kernel(*figures, listing, first, second, pour, start, min(start + BAND, heights.size), pairs)
        return pairs

    pairs = sweep(False, np.empty(0, flat_labels.dtype), np.empty(0, flat_labels.dtype), np.empty(0))
    first, second, pour = np.empty(pairs, flat_labels.dtype), np.empty(pairs, flat_labels.dtype), np.empty(pairs)
    sweep(True, first, second, pour)
    edge[0] = False
    return dict(low=low, high=high, pit=pit, area=area, edge=edge, first=first, second=second, pour=pour)


def _regions_by_masks(filled, labels, count):
    """:func:`region_figures` by whole-array operations, for small maps."""
    flat_labels, flat = labels.ravel(), filled.ravel()
    low = np.full(count + 1, np.inf)
    np.minimum.at(low, flat_labels, flat)
    high = np.full(count + 1, -np.inf)
    np.maximum.at(high, flat_labels, flat)
    lowest = np.flatnonzero((flat == low[flat_labels]) & (flat_labels > 0))
    pit = np.zeros(count + 1, dtype=np.int64)
    owners, first_index = np.unique(flat_labels[lowest], return_index=True)
    pit[owners] = lowest[first_index]  # the first lowest point in row-major order
    edge = np.zeros(count + 1, dtype=bool)
    for border in (labels[0], labels[-1], labels[:, 0], labels[:, -1]):
        edge[border] = True
    first, second, pour = [], [], []
    for one, other in NEIGHBOURS:
        a, b = labels[one], labels[other]
        differ = a != b
        a, b = a[differ], b[differ]
        heights = np.maximum(filled[one][differ], filled[other][differ])
        inside = (a > 0) & (b > 0)
        edge[a[~inside]] = True  # one side is an invalid point (label 0)
        edge[b[~inside]] = True
        first.append(a[inside])
        second.append(b[inside])
        pour.append(heights[inside])
    edge[0] = False
    return {
        "low": low,
        "high": high,
        "pit": pit,
        "area": np.bincount(flat_labels, minlength=count + 1),
        "edge": edge,
        "first": np.concatenate(first),
        "second": np.concatenate(second),
        "pour": np.concatenate(pour),
    }


def _region_pass(heights, labels, nx, low, high, pit, area, edge, listing, first, second, pour, start, stop, pairs):
    """Points start … stop - 1 of a pass of :func:`region_figures` over the flat arrays, the
    pairs numbered from ``pairs`` on: not ``listing``, the regions' figures and the
    number of neighbouring pairs in different regions; ``listing``, the pairs
    themselves into ``first``, ``second``, ``pour``. Returns the number of pairs so
    far. A pair of the same two regions as the pair before it is kept as one, at the
    lower pour height (what the pairs are used for is a minimum over each two
    regions' pairs). Plain Python, compiled by :func:`rough.compiled.compiled`."""
    ny, last_label, last_other = heights.size // nx, 0, 0
    for point in range(start, stop):
        i, j, label = point // nx, point % nx, labels[point]
        if not listing and label > 0:
            value = heights[point]
            if value < low[label]:
                low[label], pit[label] = value, point
            high[label] = max(high[label], value)
            area[label] += 1
            if i == 0 or j == 0 or i == ny - 1 or j == nx - 1:
                edge[label] = True
        for row, column in ((i, j + 1), (i + 1, j - 1), (i + 1, j), (i + 1, j + 1)):  # the pairs onwards
            if row >= ny or not 0 <= column < nx or labels[row * nx + column] == label:
                continue
            q = row * nx + column
            other = labels[q]
            if label == 0 or other == 0:
                edge[label + other] = True  # the other one borders an invalid point
                continue
            height = max(heights[point], heights[q])
            if label == last_label and other == last_other:
                if listing:
                    pour[pairs - 1] = min(pour[pairs - 1], height)
                continue
            if listing:
                first[pairs], second[pairs], pour[pairs] = label, other, height
            pairs += 1
            last_label, last_other = label, other
    return pairs


def prune(regions, threshold):
    """Wolf pruning on the graph of regions. Returns the lookup table from region
    labels to motif labels (0 stays 0; motifs numbered in row-major order of their
    pits) and, for each motif label, the region whose pit is its pit.

    Kruskal's algorithm over the saddles, lowest first: at each saddle between two
    motifs, the one with the higher pit is merged into the other when its height
    below the saddle is less than ``threshold`` (all its lower saddles have been
    seen, so this saddle is its lowest). Saddles that cannot merge anything (their
    height above the higher of the two regions' own pits is at least the
    threshold) are left out of the loop."""
    low, pit = regions["low"], regions["pit"]
    first, second, pour = regions["first"], regions["second"], regions["pour"]
    count = low.size - 1
    near = np.empty(first.size, dtype=bool)
    for block in blocks(first.size):  # no temporaries as long as the pairs
        near[block] = pour[block] - np.maximum(low[first[block]], low[second[block]]) < threshold
    one, other = np.minimum(first[near], second[near]), np.maximum(first[near], second[near])
    parent = np.arange(count + 1)
    if one.size:
        key = one.astype(np.int64) * (count + 1) + other
        order = np.argsort(key, kind="stable")
        key, heights = key[order], pour[near][order]
        starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
        saddles = np.minimum.reduceat(heights, starts)
        one, other = np.divmod(key[starts], count + 1)
        order = np.lexsort((other, one, saddles))
        parent = _kruskal(one[order], other[order], saddles[order], low, pit, threshold, count)
    while True:
        grand = parent[parent]
        if np.array_equal(grand, parent):
            break
        parent = grand
    roots = np.unique(parent[1:])
    roots = roots[np.argsort(pit[roots], kind="stable")]
    numbers = np.zeros(count + 1, dtype=np.int64)
    numbers[roots] = np.arange(1, roots.size + 1)
    return numbers[parent], np.r_[0, roots]


def _kruskal(one, other, saddles, low, pit, threshold, count):
    """The union-find forest of :func:`prune`, a loop over the saddles: compiled for
    many saddles, in plain Python over lists for a few."""
    if one.size < COMPILED_SADDLES:
        lists = (one.tolist(), other.tolist(), saddles.tolist(), low.tolist(), pit.tolist())
        return np.array(_kruskal_loop(*lists, threshold, list(range(count + 1))))
    return compiled(_kruskal_loop)(one, other, saddles, low, pit, threshold, np.arange(count + 1))


def _kruskal_loop(one, other, saddles, low, pit, threshold, parent):
    """Plain Python, compiled by :func:`rough.compiled.compiled` for arrays."""
    for k in range(len(one)):
        a, b = one[k], other[k]
        while parent[a] != a:  # the roots, halving the paths
            parent[a] = parent[parent[a]]
            a = parent[a]
        while parent[b] != b:
            parent[b] = parent[parent[b]]
            b = parent[b]
        if a == b:
            continue
        if low[b] < low[a] or (low[b] == low[a] and pit[b] < pit[a]):
            a, b = b, a
        if saddles[k] - low[b] < threshold:
            parent[b] = a
    return parent


def blocks(size, block=1 << 18):
    """Slices covering ``range(size)``, ``block`` at a time."""
    return (slice(start, start + block) for start in range(0, size, block))
