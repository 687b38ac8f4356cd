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

Both are exact on the sample grid (every offset within r, unequal x and y spacing
handled through physical distances), computed by brute force in compiled code:
scikit-image's rolling-ball kernel (a profile is a map of one row), in tiles of about
0.1 s shared by all cores, so that Ctrl-C stops a pass within a tile. The cost
is one comparison per point and tip offset, so it grows as (r/Δx)² for maps; an exact
envelope sweep (O(N·r/Δx)) would need compiled code of our own and would not beat the
vectorised brute force at tips of ~100 samples.

Invalid points (NaN) never touch the tip; results are NaN where the input is.
Beyond the ends there is no surface: a tip over an end rests on the points inside.
"""

import logging
import math
import os

import numpy as np

from ..errors import InputError

log = logging.getLogger("rough")

PRESETS = {"needle": 0.05e-3, "fingernail": 0.5e-3, "fingertip": 8e-3}
SECONDS_PER_COMPARISON = 1e-9  # on one core, measured on the 2-core build machine (estimates only)
MAX_SECONDS = 3600  # a pass estimated longer is refused
MAX_SECONDS_WIDER = 60  # ... and with a tip wider than the scan (see _check_cost)
CHUNK_SECONDS = 0.1  # the work of one tile: Ctrl-C waits for at most one tile per thread


def tip_profile(radius, spacing, shape=None):
    """``√(r² - |o|²)`` on the grid of offsets within the radius (1-D or 2-D, metres),
    -inf outside the disk. ``spacing`` is (dx,) or (dx, dy). With the data's ``shape``
    ((n,) or (ny, nx)) offsets that reach past every sample are left out: they never
    touch the surface, and a tip far wider than the scan stays small."""
    if not radius > 0:
        raise InputError(f"the tip radius must be positive, not {radius} m")
    axes = [np.arange(-reach, reach + 1) * d for reach, d in zip(_reach(radius, spacing, shape), spacing)]
    squared = axes[0] ** 2 if len(axes) == 1 else axes[1][:, None] ** 2 + axes[0][None, :] ** 2
    inside = squared <= radius * radius * (1 + 1e-12)  # offsets on the rim count, whatever the rounding
    return np.where(inside, np.sqrt(np.maximum(radius * radius - squared, 0.0)), -np.inf)


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
    distances), by brute force: the cost grows as (r/Δx)² per point for maps.
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
    """Half-width of the tip in samples along x (and y), at most one less than the data's length."""
    reach = [math.floor(radius / d) for d in spacing]
    if shape is not None:
        reach = [min(r, n - 1) for r, n in zip(reach, reversed(shape))]
    return reach


def _lowering(radius, spacing, shape):
    """``-s(o)``: 0 at the apex, -inf outside the tip."""
    kernel = tip_profile(radius, spacing, shape)
    return kernel - kernel[tuple(n // 2 for n in kernel.shape)]


def _dilate(heights, radius, spacing, passes=1):
    """max_o [z(p + o) - s(o)] with NaN ignored; NaN where the input is NaN."""
    _check_cost(heights, radius, spacing, passes)
    lowering = _lowering(radius, spacing, heights.shape)
    invalid = np.isnan(heights)
    surface = np.where(invalid, -np.inf, heights)
    if heights.ndim == 1:  # a one-row map; 0 - x, never -0: as scipy's grey_dilation, bit for bit
        path = 0.0 - _rolling_ball(-surface[np.newaxis], lowering[np.newaxis], "tip")[0]
    else:
        path = -_rolling_ball(-surface, lowering, "tip")
    return np.where(invalid | ~np.isfinite(path), np.nan, np.fmax(path, heights))


def _erode(path, radius, spacing):
    """min_o [T(p + o) + s(o)] over the finite points of the traced path ``T``."""
    lowering = _lowering(radius, spacing, path.shape)
    known = np.where(np.isnan(path), np.inf, path)
    if path.ndim == 1:
        return _rolling_ball(known[np.newaxis], lowering[np.newaxis], "envelope")[0]
    return _rolling_ball(known, lowering, "envelope")


def _rolling_ball(image, lowering, label="tip"):
    """min_o [image(p + o) + s(o)] (scikit-image's exact rolling-ball kernel); +inf in
    ``image`` never limits, and offsets outside the tip are left out.

    The map is cut into tiles of about CHUNK_SECONDS of work, shared by one thread per
    core (the kernel releases the GIL); the main thread waits with a timeout, so that
    Ctrl-C stops the workers after their current tile and cancels the rest. Every
    point's result is what one call over the whole map gives, bit for bit: the same
    sums compared in the same order."""
    import threading
    from concurrent.futures import FIRST_EXCEPTION, ThreadPoolExecutor, wait

    from ..progress import progress

    kernel = np.where(np.isfinite(lowering), lowering, np.inf)
    difference = kernel[tuple(n // 2 for n in kernel.shape)] - kernel  # as scikit-image's rolling_ball
    difference[kernel == np.inf] = np.inf
    (halo_y, halo_x), (rows, columns) = (n // 2 for n in kernel.shape), image.shape
    padded = np.full((rows + 2 * halo_y, columns + 2 * halo_x), np.inf)
    padded[halo_y : halo_y + rows, halo_x : halo_x + columns] = image
    compute = _tile_kernel(padded, kernel, difference)
    tiles = _tiles(rows, columns, kernel.size, whole_rows=compute is None, least_rows=2 * halo_y + 1)
    threads = min(_cores(), len(tiles))
    kernel_size = " × ".join(str(n) for n in reversed(kernel.shape)) if rows > 1 else str(kernel.shape[1])
    extent = f"{columns} × {rows}" if rows > 1 else str(columns)
    shared = f"{_count(len(tiles), 'tile')} on {_count(threads, 'thread')}"
    log.info(f"{label}: a kernel of {kernel_size} samples over {extent} points, {shared}")
    result = np.empty_like(image)
    stop, lock, queue, finished = threading.Event(), threading.Lock(), list(reversed(tiles)), [0]

    def work():
        while not stop.is_set():
            with lock:
                if not queue:
                    return
                top, bottom, left, right = queue.pop()
            if compute is None:
                block = padded[top : bottom + 2 * halo_y, left : right + 2 * halo_x]
                piece = _public_rolling_ball(block, kernel)[
                    halo_y : halo_y + bottom - top, halo_x : halo_x + right - left
                ]
            else:
                piece = compute(top, bottom, left, right)
            result[top:bottom, left:right] = piece
            with lock:
                finished[0] += piece.size

    pool = ThreadPoolExecutor(threads)
    try:
        workers = [pool.submit(work) for _ in range(threads)]
        with progress(total=image.size, description=label, unit="point") as bar:
            pending = workers
            while pending:
                done, pending = wait(pending, timeout=0.1, return_when=FIRST_EXCEPTION)
                for worker in done:
                    worker.result()  # a worker's exception, here
                bar.update(finished[0] - bar.n)
    finally:
        stop.set()  # Ctrl-C or a failure: the workers end after their current tile
        pool.shutdown(wait=False, cancel_futures=True)
    return result


def _tile_kernel(padded, kernel, difference):
    """A function computing one tile from the padded image with scikit-image's
    compiled rolling-ball loop on one core, reading the tile's window of ``padded`` in
    place; None when this scikit-image does not have it where expected."""
    try:
        from skimage.restoration._rolling_ball_cy import apply_kernel
    except ImportError:
        return None
    flat, width, differences = padded.reshape(-1), padded.shape[1], difference.reshape(-1)
    shape = np.array(kernel.shape, dtype=np.intp)

    def compute(top, bottom, left, right):
        piece = np.zeros((bottom - top, right - left))
        window = np.array([bottom - top + kernel.shape[0] - 1, width], dtype=np.intp)
        # positional: the last argument was num_threads before scikit-image 0.26, workers since
        corner = flat[top * width + left :]
        apply_kernel(corner, differences, piece.reshape(-1), np.array(piece.shape, dtype=np.intp), window, shape, 1)
        return piece

    return compute


def _public_rolling_ball(block, kernel):
    from skimage.restoration import rolling_ball

    return rolling_ball(block, kernel=kernel)


def _tiles(rows, columns, kernel_points, whole_rows=False, least_rows=1):
    """(top, bottom, left, right) tiles of about CHUNK_SECONDS of work on one core:
    bands of whole rows, or pieces of single rows when one row is more than that.
    ``whole_rows``: bands only, of at least ``least_rows`` (for the public
    rolling_ball, which also computes a tile's margins)."""
    points = max(1, int(CHUNK_SECONDS / (kernel_points * SECONDS_PER_COMPARISON)))
    if points >= columns or whole_rows:
        height = min(rows, max(least_rows if whole_rows else 1, points // columns, 1))
        return [(top, min(rows, top + height), 0, columns) for top in range(0, rows, height)]
    pieces = math.ceil(columns / points)
    edges = np.linspace(0, columns, pieces + 1).astype(int).tolist()
    return [(row, row + 1, left, right) for row in range(rows) for left, right in zip(edges[:-1], edges[1:])]


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
    as the fourth power of the spacing) does not show in seconds."""
    from ..units import format_length

    reach = _reach(radius, spacing, heights.shape)
    kernel_points = math.prod(2 * r + 1 for r in reach)  # the compiled loops visit the whole box
    seconds = heights.size * kernel_points * SECONDS_PER_COMPARISON / _cores()
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
