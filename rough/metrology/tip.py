"""Probe size: what a round tip of radius r traces over a surface, and the ISO
16610-41 closing envelope.

A tip touches from above. With ``s(o) = r - √(r² - |o|²)`` the height of the tip's
surface above its apex at the lateral offset o (a disk for profiles, a ball for maps):

* the **traced** surface (the path of the apex, what a stylus of tip radius r records
  and what a hand holding such a probe feels) is the grey dilation
  ``T(p) = max_o [z(p + o) - s(o)]``, over offsets |o| <= r on the sample grid;
* the **closing envelope** (ISO 16610-41's closing filter with a disk or ball) is its
  erosion by the same tip, ``C(p) = min_o [T(p + o) + s(o)]``: the lowest surface the
  tip cannot tell from the measured one, the best estimate of the material surface
  from a traced one. It never lies below the surface and is idempotent.

Both are exact on the sample grid: every offset within r counts (those on the rim
too, whatever the rounding), unequal x and y spacing handled through physical
distances. The ball is taken a row of offsets at a time: the offsets k rows above
and k rows below a point form the same semicircle, of radius √(r² - (kΔy)²), along
x, so the dilation is the maximum over k = 0 … R (R = r/Δy; a profile is a map of
one row) of one 1-D dilation by that semicircle of the pointwise maximum of the rows
k above and k below. Each 1-D dilation is done in compiled code (numba), in the
quicker of two ways for its width w (in samples):

* directly, over the offsets 0, ±1 … ±w, vectorised: about w/6 ns per point, the
  way for rows up to about 220 samples wide;
* by a sweep along the row keeping the upper envelope of the semicircles of radius
  √(r² - (kΔy)²) about every point (equal semicircles cross at most once, so a stack
  holds it, as in Felzenszwalb and Huttenlocher's distance transform): about 35 ns
  per point whatever the width. Where two semicircles cross is estimated in closed
  form, then settled by comparing the very sums the direct way compares.

Each result is the sum ``z(p + o) - s(o)`` of one offset of the tip, the greatest:
the direct way gives brute force's value to the last bit, and so does the sweep,
but where two offsets' sums tie within a rounding error (it may then settle on
either). A map of N points costs about N · Σ_k min(w_k / 6, 35) ns on one core,
growing as (r/Δx)² for small tips and as r/Δx for big ones (a 0.5 mm ball at 0.01
mm spacing: 0.3 µs per point). The rows (long ones cut into tiles) are handed out in
chunks of about 0.1 s of work to one thread per core, so that Ctrl-C stops a pass
within a chunk.

Invalid points (NaN) never touch the tip; results are NaN where the input is.
Beyond the ends there is no surface: a tip over an end rests on the points inside.
"""

import logging
import math
import os
import threading
from concurrent.futures import FIRST_EXCEPTION, ThreadPoolExecutor, wait

import numpy as np

from ..compiled import compiled
from ..errors import InputError
from ..progress import progress
from ..units import format_length

log = logging.getLogger("rough")

PRESETS = {"needle": 0.05e-3, "fingernail": 0.5e-3, "fingertip": 8e-3}
# Estimates only, on one core of the 2-core build machine (bench/bench_tip.py):
SECONDS_PER_PAIR = 0.17e-9  # one point and one pair of offsets ±x of a row of the tip, the direct way
SECONDS_PER_SWEEP = 37e-9  # one point and one row of the tip, swept
MAX_SECONDS = 3600  # a pass estimated longer is refused
MAX_SECONDS_WIDER = 60  # ... and with a tip wider than the scan (see _check_cost)
CHUNK_SECONDS = 0.1  # the work of one chunk: Ctrl-C waits for at most one chunk per thread


def tip_profile(radius, spacing, shape=None):
    """``√(r² - |o|²)`` on the grid of offsets within the radius (1-D or 2-D, metres),
    -inf outside the disk. ``spacing`` is (dx,) or (dx, dy). With the data's ``shape``
    ((n,) or (ny, nx)) offsets that reach past every sample are left out: they never
    touch the surface, and a tip far wider than the scan stays small."""
    if not radius > 0:
        raise InputError(f"the tip radius must be positive, not {radius} m")
    axes = [np.arange(-reach, reach + 1) * d for reach, d in zip(_reach(radius, spacing, shape), spacing)]
    squared = axes[0] ** 2 if len(axes) == 1 else axes[1][:, None] ** 2 + axes[0][None, :] ** 2
    return _tip_heights(radius, squared)


def traced(surface, radius):
    """The path of the apex of a round tip drawn over a surface.

    What a stylus of this tip radius records, and what a hand holding such a probe
    feels: the grey dilation ``T(p) = max_o [z(p + o) - s(o)]`` over the offsets
    ``|o| <= r`` on the sample grid, with ``s(o) = r - √(r² - |o|²)`` the height of the
    tip's surface above its apex (a disk for profiles, a ball for maps).

    Parameters
    ----------
    surface : Surface
        A profile or map; NaN points never touch the tip.
    radius : float
        The tip radius r, metres (``PRESETS`` has ``needle`` 0.05 mm, ``fingernail``
        0.5 mm and ``fingertip`` 8 mm).

    Returns
    -------
    Surface
        The traced heights in metres, never below the surface, with a ``tip`` history
        entry; NaN where the input is NaN.

    Raises
    ------
    rough.InputError
        For a radius that is not positive, or a tip so wide for the spacing that one
        pass would take more than an hour (a warning past ten seconds), or more than
        a minute with a tip wider than the scan (a warning whenever it is wider).

    See Also
    --------
    closing_envelope : The best estimate of the material surface under a trace.

    Notes
    -----
    Exact on the sample grid (unequal x and y spacing handled through physical
    distances): every offset within r counts. The ball is taken a row of offsets at
    a time, each row by the quicker of a direct maximum over its offsets and a sweep
    along the surface's rows keeping the upper envelope of semicircles (see the
    module's description), so the cost per point grows as (r/Δx)² for small tips
    and as r/Δx for big ones. The first call in a process compiles the loops with
    numba (a few seconds, then cached on disk where a cache directory is writable).
    Beyond the ends there is no surface: a tip over an end rests on the points
    inside.

    Examples
    --------
    A 10 µm spike under a 0.5 mm tip is felt as a cap of the tip's radius: 50 µm
    away the apex is still 10 - (r - √(r² - (50 µm)²)) = 7.49 µm high.

    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology.tip import traced
    >>> heights = np.zeros(101)
    >>> heights[50] = 10e-6  # one spike in a flat 1 mm profile at 10 µm spacing
    >>> path = traced(rough.Surface(heights, 10e-6), 0.5e-3)
    >>> (path.heights[45:56:5] * 1e6).round(2).tolist()  # µm, at -50, 0, +50 µm
    [7.49, 10.0, 7.49]
    >>> path.history[-1]["command"], path.history[-1]["parameters"]
    ('tip', {'radius': 0.0005})
    """
    heights = _dilate(surface.heights, radius, surface.spacing)
    return surface.derive("tip", {"radius": radius}, heights=heights)


def closing_envelope(surface, radius):
    """The ISO 16610-41 closing envelope of a surface, with a disk or ball.

    The erosion of the traced surface by the same tip, ``C(p) = min_o [T(p + o) +
    s(o)]``: the lowest surface the tip cannot tell from the measured one, and so the
    best estimate of the material surface from a traced one.

    Parameters
    ----------
    surface : Surface
        A profile (closed with a disk) or map (with a ball); NaN points never touch
        the tip.
    radius : float
        The disk's or ball's radius, metres.

    Returns
    -------
    Surface
        The envelope in metres, with an ``envelope`` history entry. It never lies
        below the surface and is idempotent; NaN where the input is NaN.

    Raises
    ------
    rough.InputError
        For a radius that is not positive, or a tip too wide to compute within an
        hour (within a minute when it is wider than the scan).

    See Also
    --------
    traced : The path of the apex (the dilation alone).

    Notes
    -----
    Two passes, each exact on the sample grid and of the cost of :func:`traced`: the
    dilation, then the erosion, done as the dilation of the negated path.

    Examples
    --------
    A 0.5 mm disk cannot enter a pit 30 µm wide and 50 µm deep: resting on its rims,
    20 µm from the centre, it reaches r - √(r² - (20 µm)²) = 0.40 µm down.

    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology.tip import closing_envelope
    >>> heights = np.zeros(101)  # 1 mm at 10 µm
    >>> heights[49:52] = -50e-6
    >>> heights[10] = np.nan
    >>> envelope = closing_envelope(rough.Surface(heights, 10e-6), 0.5e-3)
    >>> (envelope.heights[48:53] * 1e6).round(2).tolist()  # µm
    [0.0, -0.3, -0.4, -0.3, 0.0]
    >>> bool(np.isnan(envelope.heights[10]))  # invalid stays invalid
    True

    On a map it never lies below the valid points, and closing again changes nothing:

    >>> scan = rough.read(rough.sample("rock-map.x3p"))
    >>> envelope = closing_envelope(scan, 0.5e-3)
    >>> bool(np.all(envelope.heights[scan.valid] >= scan.heights[scan.valid]))
    True
    >>> again = closing_envelope(envelope, 0.5e-3)
    >>> bool(np.nanmax(np.abs(again.heights - envelope.heights)) < 1e-15)
    True
    """
    path = _dilate(surface.heights, radius, surface.spacing, passes=2)
    # exactly, the closing never lies below the surface; the clamp only removes rounding
    heights = np.fmax(_erode(path, radius, surface.spacing), surface.heights)
    return surface.derive("envelope", {"radius": radius}, heights=np.where(np.isnan(surface.heights), np.nan, heights))


def _reach(radius, spacing, shape):
    """Half-width of the tip in samples along x (and y), at most one less than the data's length;
    with the offsets on the rim, whatever the rounding of r/Δ (0.3 mm / 0.1 mm = 2.9999999999999996)."""
    reach = [math.floor(radius * (1 + 1e-12) / d) for d in spacing]
    if shape is not None:
        reach = [min(r, n - 1) for r, n in zip(reach, reversed(shape))]
    return reach


def _tip_heights(radius, squared):
    """``√(r² - |o|²)`` for the squared offsets ``|o|²``, -inf outside the tip."""
    inside = squared <= radius * radius * (1 + 1e-12)  # offsets on the rim count, whatever the rounding
    return np.where(inside, np.sqrt(np.maximum(radius * radius - squared, 0.0)), -np.inf)


def _quadrant(radius, spacing, shape):
    """``-s(o)`` at the offsets ``(x Δx, k Δy)``, k and x >= 0, as ``quadrant[k, x]`` (one
    row for a profile): the tip is symmetric about both axes. The very values of
    :func:`tip_profile` less its apex; 0 at the apex, -inf outside the tip."""
    reach = _reach(radius, spacing, shape)
    x = np.arange(reach[0] + 1) * spacing[0]
    y = np.arange(reach[1] + 1) * spacing[1] if len(spacing) == 2 else np.zeros(1)
    heights = _tip_heights(radius, y[:, None] ** 2 + x[None, :] ** 2)
    return heights - heights[0, 0]


def _dilate(heights, radius, spacing, passes=1):
    """max_o [z(p + o) - s(o)] with NaN ignored; NaN where the input is NaN."""
    _check_cost(heights, radius, spacing, passes)
    invalid = np.isnan(heights)
    path = _max_plus(np.where(invalid, -np.inf, heights), radius, spacing, "tip")
    return np.where(invalid | ~np.isfinite(path), np.nan, np.fmax(path, heights))


def _erode(path, radius, spacing):
    """min_o [T(p + o) + s(o)] over the finite points of the traced path ``T``: the
    dilation of -T, negated (as 0 - x, so that a zero is +0, as the sums' minimum is)."""
    return 0.0 - _max_plus(np.where(np.isnan(path), -np.inf, -path), radius, spacing, "envelope")


def _max_plus(image, radius, spacing, label="tip"):
    """``max_o [image(p + o) - s(o)]`` over the tip's offsets; -inf in ``image`` never
    wins, and there is nothing beyond the ends.

    The rows are cut into tasks (a row, or a tile of a long row), and the tasks into
    chunks of about CHUNK_SECONDS of work, shared by one thread per core (the compiled
    loop releases the GIL); the main thread waits with a timeout, so that Ctrl-C stops
    the workers after their current chunk and cancels the rest. A point's result does
    not depend on how the work is cut."""
    quadrant = _quadrant(radius, spacing, image.shape)
    widths = np.isfinite(quadrant).sum(axis=1) - 1  # row k of the tip spans the offsets -w … w along x
    swept = _swept(widths)
    squared_radii = radius * radius - (np.arange(len(widths)) * spacing[-1]) ** 2  # of each row's semicircle
    rows = np.ascontiguousarray(image.reshape(-1, image.shape[-1]))  # a profile is a map of one row
    count, columns = rows.shape
    tiles = max(1, columns // max(2048, 16 * quadrant.shape[1]))  # the margins of a tile cost little
    tasks = count * tiles
    per_task = _seconds_per_point(widths) * columns / tiles
    chunk = max(1, min(round(CHUNK_SECONDS / per_task), math.ceil(tasks / _cores())))  # every core gets some
    queue = [(first, min(tasks, first + chunk)) for first in reversed(range(0, tasks, chunk))]
    threads = min(_cores(), len(queue))
    kernel, result = compiled(_rows), np.empty_like(rows)
    # compiled (or loaded from numba's cache) here, before the workers start; Ctrl-C stops the wait
    kernel(rows, quadrant, widths, swept, squared_radii, spacing[0], tiles, 0, 0, result)
    across = [2 * n - 1 for n in reversed(quadrant.shape)]  # x first
    kernel_size = f"{across[0]} × {across[1]}" if count > 1 else str(across[0])
    extent = f"{columns} × {count}" if count > 1 else str(columns)
    shared = f"{_count(len(queue), 'chunk')} on {_count(threads, 'thread')}"
    rows_swept = f" ({_count(int(swept.sum()), 'row')} of it swept)" if swept.any() else ""
    log.info(f"{label}: a kernel of {kernel_size} samples{rows_swept} over {extent} points, {shared}")
    stop, lock, finished = threading.Event(), threading.Lock(), [0]

    def start(task):  # the index of the task's first point
        return task // tiles * columns + task % tiles * columns // tiles

    def work():
        while not stop.is_set():
            with lock:
                if not queue:
                    return
                first, last = queue.pop()
            kernel(rows, quadrant, widths, swept, squared_radii, spacing[0], tiles, first, last, result)
            with lock:
                finished[0] += start(last) - start(first)

    pool = ThreadPoolExecutor(threads)
    try:
        workers = [pool.submit(work) for _ in range(threads)]
        with progress(total=rows.size, description=label, unit="point") as bar:
            pending = workers
            while pending:
                done, pending = wait(pending, timeout=0.1, return_when=FIRST_EXCEPTION)
                for worker in done:
                    worker.result()  # a worker's exception, here
                bar.update(finished[0] - bar.n)
    finally:
        stop.set()  # Ctrl-C or a failure: the workers end after their current chunk
        pool.shutdown(wait=False, cancel_futures=True)
    return result.reshape(image.shape)


def _swept(widths):
    """Which rows of the tip are swept rather than maximised over directly: those for
    which the sweep is estimated quicker."""
    return (widths + 1) * SECONDS_PER_PAIR > SECONDS_PER_SWEEP


def _seconds_per_point(widths):
    """The estimated work per point, on one core, for the tip's rows of these widths:
    for each row, building the maximum of the two rows of the surface and then the
    quicker of the two ways."""
    widths = np.asarray(widths)[np.asarray(widths) >= 0]
    return float(np.sum(SECONDS_PER_PAIR + np.minimum((widths + 1) * SECONDS_PER_PAIR, SECONDS_PER_SWEEP)))


def _rows(image, quadrant, widths, swept, squared_radii, dx, tiles, first, last, out):
    """Tasks ``first`` … ``last - 1`` of the dilation, task i being the tile
    ``i % tiles`` (of ``tiles`` equal ones) of the row ``i // tiles``::

        out[y, c] = max over k and |x| <= widths[k] of
                    max(image[y - k, c + x], image[y + k, c + x]) + quadrant[k, |x|]

    with -inf beyond the ends, row k of the tip directly or (``swept[k]``) by the
    envelope sweep. Plain Python, compiled by :func:`rough.compiled.compiled`."""
    count, columns = image.shape
    size = columns // tiles + 1 + 2 * (quadrant.shape[1] - 1)
    line = np.empty(size)  # the two rows' maximum, with margins
    stack = np.empty(size, np.int64)  # the sweep's points on the envelope, left to right ...
    starts = np.empty(size, np.int64)  # ... and where each takes the lead
    for task in range(first, last):
        y = task // tiles
        left = task % tiles * columns // tiles
        width = (task % tiles + 1) * columns // tiles - left
        best = out[y, left : left + width]
        best[:] = -np.inf
        for k in range(quadrant.shape[0]):
            reach = widths[k]
            above = y - k
            below = y + k
            if reach < 0 or (above < 0 and below >= count):
                continue
            if above < 0:
                above = below
            elif below >= count:
                below = above
            # line[j]: the higher of the two rows at the column left - reach + j
            n = width + 2 * reach
            inside = max(0, reach - left)
            outside = min(n, columns - left + reach)
            line[:inside] = -np.inf
            line[outside:n] = -np.inf
            upper = image[above, left - reach + inside : left - reach + outside]
            lower = image[below, left - reach + inside : left - reach + outside]
            middle = line[inside:outside]
            for j in range(outside - inside):
                u = upper[j]
                v = lower[j]
                middle[j] = u if u > v else v
            lowering = quadrant[k]
            if not swept[k]:
                # directly: best[p] = max over x of max(line[p + reach ± x]) + lowering[x], two x at a time
                centre = line[reach : reach + width]
                c = lowering[0]
                for p in range(width):
                    u = centre[p] + c
                    held = best[p]
                    best[p] = u if u > held else held
                x = 1
                while x <= reach:
                    c = lowering[x]
                    right = line[reach + x : reach + x + width]
                    left_ = line[reach - x : reach - x + width]
                    if x < reach:
                        d = lowering[x + 1]
                        right2 = line[reach + x + 1 : reach + x + 1 + width]
                        left2 = line[reach - x - 1 : reach - x - 1 + width]
                        for p in range(width):
                            u = right[p]
                            v = left_[p]
                            u = (u if u > v else v) + c
                            w = right2[p]
                            v = left2[p]
                            w = (w if w > v else v) + d
                            u = u if u > w else w
                            held = best[p]
                            best[p] = u if u > held else held
                        x += 2
                    else:
                        for p in range(width):
                            u = right[p]
                            v = left_[p]
                            u = (u if u > v else v) + c
                            held = best[p]
                            best[p] = u if u > held else held
                        x += 1
                continue
            # the sweep: the point q of the line offers line[q] + lowering[|p - q|] to the
            # positions p within reach; of two points a < b, b's offer gains on a's as p
            # grows (the semicircles are equal and cross at most once), so the leaders
            # from left to right form a stack, each with where it takes the lead
            final = reach + width - 1
            head = 0
            tail = 0
            b = 0
            for p in range(reach, reach + width):
                while b <= p + reach:  # the point coming within reach of p joins
                    zb = line[b]
                    if zb > -np.inf:
                        s = p
                        while tail > head:
                            a = stack[tail - 1]
                            t = max(starts[tail - 1], p)
                            if t > a + reach:  # a leads nowhere from p on
                                tail -= 1
                                continue
                            za = line[a]
                            if zb + lowering[abs(t - b)] >= za + lowering[abs(t - a)]:
                                tail -= 1  # b leads wherever a would have
                                continue
                            # the first position in (t, end] where b's offer reaches a's, end + 1
                            # if none: where the semicircles about (a, za) and (b, zb) cross
                            # (their upper intersection, on both upper halves), then
                            # settled on the very sums compared above
                            end = min(a + reach, final)
                            s = end + 1
                            run = (b - a) * dx
                            rise = zb - za
                            squared = run * run + rise * rise
                            height = squared_radii[k] - 0.25 * squared
                            if height > 0.0:
                                ratio = math.sqrt(height / squared)
                                if 0.5 * rise + ratio * run >= 0.0:
                                    at = a + (0.5 * run - ratio * rise) / dx
                                    if at <= t + 1:
                                        s = t + 1
                                    elif at < end + 1:
                                        s = int(math.ceil(at))
                            if s <= end and zb + lowering[abs(s - b)] < za + lowering[abs(s - a)]:
                                s += 1
                                while s <= end and zb + lowering[abs(s - b)] < za + lowering[abs(s - a)]:
                                    s += 1
                            else:
                                while s - 1 > t and zb + lowering[abs(s - 1 - b)] >= za + lowering[abs(s - 1 - a)]:
                                    s -= 1
                            break
                        stack[tail] = b
                        starts[tail] = s
                        tail += 1
                    b += 1
                while head < tail:  # leaders out of reach, or overtaken, go
                    q = stack[head]
                    if p > q + reach or (head + 1 < tail and starts[head + 1] <= p):
                        head += 1
                    else:
                        break
                if head < tail and starts[head] <= p:
                    q = stack[head]
                    u = line[q] + lowering[abs(p - q)]
                    held = best[p - reach]
                    best[p - reach] = u if u > held else held


def _cores():
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def _check_cost(heights, radius, spacing, passes=1):
    """Warn when the tip is wider than the scan, and when a pass takes more than ten
    seconds; refuse a pass of more than an hour, or of more than a minute with a tip
    wider than the scan.

    Why refuse the wider tip sooner: it rests, wherever it is, on a few of the scan's
    highest points, and its path depends on where the scan ends (nothing is assumed
    beyond), so minutes of exact work buy little that a resampled scan (the cost falls
    as the third or fourth power of the spacing) does not show in seconds."""
    reach = _reach(radius, spacing, heights.shape)
    # the rows' widths, as the tip's table has them but for an offset on the rim, whichever the rounding
    rows = np.arange(reach[1] + 1) * spacing[1] if len(reach) == 2 else np.zeros(1)
    widths = np.floor(np.sqrt(np.maximum(radius * radius * (1 + 1e-12) - rows**2, 0.0)) / spacing[0])
    seconds = heights.size * _seconds_per_point(np.minimum(widths, reach[0])) / _cores()
    extents = [n * d for n, d in zip(reversed(heights.shape), spacing)]
    scan = " × ".join(format_length(extent, 4) for extent in extents)
    tip = f"a {format_length(radius, 4)} tip ({format_length(2 * radius, 4)} across)"
    wider = any(2 * radius > extent for extent in extents)
    hint = "resample the surface to a coarser spacing first"
    if wider:
        if seconds > MAX_SECONDS_WIDER:
            raise InputError(
                f"{tip} is wider than the {scan} scan, and one pass would take about {_duration(seconds)}: {hint}"
            )
        log.warning(f"{tip} is wider than the {scan} scan: its path depends on where the scan ends")
    samples = " × ".join(str(2 * r + 1) for r in reach)
    size = f"a {format_length(radius, 4)} tip spans {samples} samples of this surface"
    if seconds > MAX_SECONDS:
        raise InputError(f"{size}: one pass would take about {_duration(seconds)}; {hint}")
    if seconds > 10:
        log.warning(
            f"{size}: this takes about {_duration(seconds)} per pass (resample to a coarser spacing for a quicker "
            "answer)"
        )
    else:
        log.info(f"{size}: {_count(passes, 'pass')} of about {_duration(seconds)}")


def _duration(seconds):
    if seconds >= 5400:
        return f"{seconds / 3600:.0f} h"
    if seconds >= 90:
        return f"{seconds / 60:.0f} min"
    return f"{seconds:.2g} s"


def _count(number, noun):
    return f"{number} {noun}" if number == 1 else f"{number} {noun}{'es' if noun.endswith('s') else 's'}"
