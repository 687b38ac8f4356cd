"""The watershed under :func:`rough.metrology.segmentation.segment`: one region per
regional minimum, the figures of each region and the saddles between them, and Wolf
pruning on that graph of regions (the definitions: :mod:`rough.metrology.segmentation`).

Two routes give the same regions. On maps of :data:`COMPILED_MIN` points or more,
compiled passes (numba, loaded on first use: :func:`rough.compiled.compiled`) take the
regions by steepest descent where that decides them and gather each region's figures
and the pour heights in one sweep; on smaller maps, scikit-image's watershed and
whole-array operations do, without loading numba, unless two pits have one height:
the descent then settles the regions by rough's rule (:func:`descend`: the pit first
in row-major order wins), where scikit-image's heap history would. Kruskal's loop
over the saddles is compiled from :data:`COMPILED_SADDLES` saddles.
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
PLATEAU = 1 << 12  # the most points of a plateau the steepest descent floods itself
# the order in which scikit-image's watershed visits a point's 8 neighbours: rows, columns
VISIT_ROWS, VISIT_COLUMNS = (-1, 0, 0, 1, -1, -1, 1, 1), (0, -1, 1, 0, -1, 1, -1, 1)
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
    decides (:func:`descend`) on maps large enough to pay for it, and on any map with
    two pits of one height, which the descent settles by rough's rule (the pit first
    in row-major order) where scikit-image's heap history would."""
    markers, count = basin_markers(filled, valid)
    labels = None
    if filled.size >= COMPILED_MIN or tied_pits(filled, markers, count):
        labels = descend(filled, valid, markers)
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


def tied_pits(filled, markers, count):
    """Whether two of the ``count`` markers (pits) lie at one height: where two such
    meet, scikit-image's flood and rough's rule (:func:`descend`) may part."""
    if count < 2:
        return False
    levels = ndimage.minimum(filled, markers, np.arange(1, count + 1))
    return np.unique(levels).size < count


def descend(filled, valid, markers):
    """The regions of :func:`basins` by steepest descent, or None where it does not
    decide them.

    scikit-image's watershed floods from the markers, lowest first, and labels a point
    from the first labelled neighbour that reaches it. When every valid point that is
    not a marker has a neighbour strictly lower than itself, the flood reaches it first
    from its lowest neighbours (all lower points are flooded before any higher one), so
    it takes their label, when they share one. That holds for almost every map of
    float heights. Where a point's lowest neighbours lie in two basins, the one the
    flood took first wins: of two points of one height, the one pushed onto the
    flood's queue earlier, that is the one whose own first neighbour reached (its
    lowest, when that is unique) was taken earlier, down the two descents until they
    differ in height or meet (then the order in which scikit-image visits a point's
    neighbours decides; a marker, queued first, comes before any other point of its
    height) (:func:`_first_taken`).

    Tied pits, rough's own rule: when the two descents reach two markers (pits) of
    one height at the same step, as when two equal pits touch one point, the basin
    whose pit comes first in row-major order wins (markers are numbered so: the
    lower number). scikit-image queues all its markers at once with one age, so
    there its binary heap's history decides, an order-dependent choice among equal
    candidates; this rule depends on the heights and positions alone, so on 1–6
    points of some quantised maps the regions differ from scikit-image's.

    On a plateau of more than :data:`PLATEAU` points, one that holds a marker, or
    where the order of arrival rests on ties the descent cannot tell (a point with
    two lowest neighbours, or a plateau, on the way down), this returns None and
    scikit-image floods the map. Compiled, a band of rows a call, so that Ctrl-C
    stops it between bands."""
    ny, nx = filled.shape
    kernel, labels = compiled(_descend_rows, _visit, _first_taken, _flood_plateau, _lowest_label), markers.copy()
    band = max(1, BAND // nx)
    stack, plateau = np.empty(1024, dtype=np.int64), np.empty(PLATEAU, dtype=np.int64)
    heights, inside, flat = filled.ravel(), valid.ravel(), labels.ravel()
    marked = markers.ravel()  # the markers' numbers, 0 elsewhere
    for first in range(0, ny, band):
        stack = kernel(heights, inside, flat, marked, nx, first * nx, min(ny, first + band) * nx, stack, plateau)
        if stack.size == 0:
            return None
    return labels


def _descend_rows(heights, valid, labels, marked, nx, start, stop, stack, plateau):
    """Label the points start … stop - 1 (and those their descents pass through) for
    :func:`descend`, all arrays flat (``marked``: the markers' numbers, 0 elsewhere);
    returns the stack, grown as needed, or an empty one where the descent does not
    decide. Plain Python, compiled by :func:`rough.compiled.compiled`."""
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
            if below < 0:  # on a plateau: labelled with all of it, once its exits are
                waiting = _flood_plateau(heights, valid, labels, marked, nx, point, plateau)
            else:
                waiting = _lowest_label(heights, valid, labels, marked, nx, point, lowest)
            if waiting == -1:  # ties decide the order of arrival (or a plateau too large)
                return stack[:0]
            if waiting < 0:  # labelled
                top -= 1
                continue
            top += 1
            if top == stack.size:
                grown = np.empty(2 * stack.size, dtype=stack.dtype)
                grown[: stack.size] = stack
                stack = grown
            stack[top] = waiting
    return stack


def _lowest_label(heights, valid, labels, marked, nx, point, lowest):
    """Label ``point`` from its lowest neighbours (of height ``lowest``, below it) and
    return -2; or return one of them still unlabelled, to descend from first; or -1
    when ties decide which of them the flood took first. Plain Python, compiled
    inside :func:`_descend_rows`."""
    ny, i, j = heights.size // nx, point // nx, point % nx
    label, waiting, split = 0, -1, False
    for row in range(max(i - 1, 0), min(i + 2, ny)):
        for q in range(row * nx + max(j - 1, 0), row * nx + min(j + 2, nx)):
            if valid[q] and heights[q] == lowest:
                if labels[q] == 0:
                    waiting = q
                elif label == 0:
                    label = labels[q]
                elif labels[q] != label:  # lowest neighbours in two basins
                    split = True
    if waiting >= 0:
        return waiting
    if split:  # the one the flood took first labels the point
        first = -1
        for row in range(max(i - 1, 0), min(i + 2, ny)):
            for q in range(row * nx + max(j - 1, 0), row * nx + min(j + 2, nx)):
                if valid[q] and heights[q] == lowest:
                    first = q if first < 0 else _first_taken(heights, valid, marked, nx, first, q)
                    if first < 0:
                        return -1
        label = labels[first]
    labels[point] = label
    return -2


def _first_taken(heights, valid, marked, nx, a, b):
    """Of two labelled points ``a`` and ``b`` of one height, the one scikit-image's
    watershed takes from its queue first (see :func:`descend`), or -1 when ties decide
    that: down the two descents (each point's one lowest neighbour, which queued it)
    until they differ in height, meet, or reach a marker (``marked``: the markers'
    numbers; a marker is queued before any other point of its height). When both
    reach a marker at once, rough's rule for tied pits: the lower marker number, the
    pit first in row-major order (scikit-image's heap holds its markers in an order
    of its own). Plain Python, compiled inside :func:`_descend_rows`."""
    ny, first, second = heights.size // nx, a, b
    below = np.empty(2, dtype=np.int64)
    while True:
        if marked[a] != 0 or marked[b] != 0:  # two markers: the pit first in row-major order
            return first if marked[a] != 0 and (marked[b] == 0 or marked[a] <= marked[b]) else second
        for side in range(2):
            point = a if side == 0 else b
            i, j = point // nx, point % nx
            lowest, below[side] = heights[point], -1
            for row in range(max(i - 1, 0), min(i + 2, ny)):
                for q in range(row * nx + max(j - 1, 0), row * nx + min(j + 2, nx)):
                    if valid[q] and heights[q] < lowest:
                        lowest, below[side] = heights[q], q
                    elif valid[q] and heights[q] == lowest and below[side] >= 0:
                        return -1  # two lowest neighbours: ties decide which queued it
            if below[side] < 0:  # a plateau
                return -1
        if below[0] == below[1]:  # both queued when that point was taken: in the order of its visits
            return first if _visit(nx, below[0], a) < _visit(nx, below[1], b) else second
        if heights[below[0]] != heights[below[1]]:
            return first if heights[below[0]] < heights[below[1]] else second
        a, b = below[0], below[1]


def _flood_plateau(heights, valid, labels, marked, nx, point, plateau):
    """Label the plateau of ``point`` (the 8-connected points of its height; not a
    regional minimum, so some of them, its exits, have a lower neighbour) as the flood
    does: its exits are queued before any point of the plateau is taken (from lower
    points), in the order :func:`_first_taken` finds; then the plateau is taken in
    the order of its queue (one height: first in, first out), each point queuing its
    unlabelled neighbours on the plateau in the order of its visits. Returns -2 when
    done, an unlabelled exit to descend from first, or -1 when the plateau has more
    points than ``plateau`` holds or ties decide the order of its exits. Plain
    Python, compiled inside :func:`_descend_rows`."""
    ny, level, count = heights.size // nx, heights[point], 1
    plateau[0] = point
    head = 0
    while head < count:  # the plateau, breadth first
        i, j = plateau[head] // nx, plateau[head] % nx
        head += 1
        for row in range(max(i - 1, 0), min(i + 2, ny)):
            for q in range(row * nx + max(j - 1, 0), row * nx + min(j + 2, nx)):
                if valid[q] and heights[q] == level and q not in plateau[:count]:
                    if count == plateau.size or marked[q] != 0:  # a marker's own order decides
                        return -1
                    plateau[count] = q
                    count += 1
    exits = 0
    for k in range(count):  # the exits to the front, in the order they were queued
        q = plateau[k]
        i, j = q // nx, q % nx
        lower = False
        for row in range(max(i - 1, 0), min(i + 2, ny)):
            for r in range(row * nx + max(j - 1, 0), row * nx + min(j + 2, nx)):
                lower |= valid[r] and heights[r] < level
        if not lower:
            continue
        if labels[q] == 0:
            return q
        place = exits
        while place > 0:
            earlier = _first_taken(heights, valid, marked, nx, plateau[place - 1], q)
            if earlier < 0:
                return -1
            if earlier == plateau[place - 1]:
                break
            place -= 1
        plateau[place + 1 : k + 1] = plateau[place:k].copy()
        plateau[place] = q
        exits += 1
    head, count = 0, exits
    while head < count:  # first in, first out
        i, j = plateau[head] // nx, plateau[head] % nx
        for k in range(8):
            row, column = i + VISIT_ROWS[k], j + VISIT_COLUMNS[k]
            q = row * nx + column
            if 0 <= row < ny and 0 <= column < nx and valid[q] and heights[q] == level and labels[q] == 0:
                labels[q] = labels[plateau[head]]
                plateau[count] = q
                count += 1
        head += 1
    return -2


def _visit(nx, point, neighbour):
    """The place of ``neighbour`` among the 8 neighbours of ``point`` in the order
    scikit-image's watershed visits them: up, left, right, down, then up-left,
    up-right, down-left, down-right."""
    key = 3 * (neighbour // nx - point // nx) + neighbour % nx - point % nx
    if key % 2:  # a side: -3, -1, 1, 3
        return (key + 3) // 2
    return 4 + (key + 4) // 2 - (key > 0)  # a corner: -4, -2, 2, 4


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
