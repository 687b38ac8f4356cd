"""The fractal fit of a map larger than memory (:class:`~rough.io.TiledSurface`), a
tile at a time.

The in-memory fit (:func:`~rough.fractal.fit_fractal`) fits the ring-averaged,
periodic-Hann-windowed 2-D periodogram of the whole map less its polynomial form.
That periodogram needs the whole map at once, so on tiles it is replaced by a stated
estimator of the same spectrum, in the same normalisation (so C compares):

- above the *join* frequency, the Welch average of the periodograms of equal tiles
  that overlap their neighbours by half along each axis, each less its own polynomial
  of the same order and periodic-Hann-windowed; the ring means of the tiles are
  averaged and their ordinates counted together, the Whittle weights divided by the
  overlap's variance factor (Welch 1967: per axis ``1 + 2 (1 - 1/t) ρ`` over t tiles,
  ρ = 3/35 for half-overlapping periodic Hann windows);
- below it, the periodogram of the *coarse level*: the whole map block-averaged by an
  integer factor k (so that it fits about one tile), levelled and windowed as the map
  would be. Block averaging is a low-pass: its power transfer is
  ``|H(fx)|² |H(fy)|²`` with ``H(f) = sin(πfkΔ) / (k sin(πfΔ))``; every coarse
  ordinate is divided by it, and only the coarse spectrum below a quarter of its
  Nyquist frequency is used (there H² > 0.95 and what folds back from above the coarse
  Nyquist frequency is below 10⁻³ of a fractal's power). The join is that quarter;
  k is at most the tile's side / 32, so the tiles' part starts above their own
  fourth ring.

Both parts are rings of their own grid's frequency step, with the Hann window's
smoothing terms of that grid, so the ring fit (:func:`~rough.fractal.whittle.fit_rings`)
takes them as they are: the band search and the Whittle likelihood are those of the
in-memory fit. Invalid points: as in memory, refused unless ``fill``, which fills each
tile's invalid points (biharmonic, with a halo of :data:`HALO` points around the
tile, so a hole smaller than the halo is filled as in the whole map) and leaves out
of the average a tile more than :data:`MOST_INVALID` invalid; the coarse level
averages the filled heights (the valid ones of a tile left out), and its blocks with
no valid point are filled in turn.
"""

import dataclasses
import logging
import math

import numpy as np
from scipy import fft

from .. import tasks
from ..errors import InputError
from ..io.tiled import memory_budget, tile_points
from ..surface import Surface
from ..units import format_length
from .choices import SAMPLINGS
from .filling import fill_invalid, filled
from .fit import GAPS_REFUSED
from .psd import binned_rings, sector_spectra, windowed_map
from .result import FractalFit, announce
from .whittle import FLAT, LOWEST_RING, Options, default_top, fit_rings, history_sampling, sampling_of

log = logging.getLogger("rough")

COARSE_TOP = 0.25  # of the coarse level's Nyquist frequency: the join
HALO = 16  # points read around a tile to fill its holes
MOST_INVALID = 0.25  # a tile with more invalid points is left out of the average
#: The correlation of the band-averaged periodograms of two periodic-Hann-windowed
#: segments that overlap by half: Σ w²(k) w²(k + n/2) / Σ w⁴(k) = 3/35.
OVERLAP_CORRELATION = 3 / 35


@dataclasses.dataclass
class TiledFractalFit(FractalFit):
    """A :class:`~rough.fractal.FractalFit` of a map read in tiles, with how.

    Attributes
    ----------
    tiled : dict
        ``tiles`` (averaged), ``skipped`` (left out, mostly invalid), ``tile_shape``
        (rows, columns), ``coarse_factor`` k, ``coarse_shape``, ``join`` (1/m: the
        coarse level below, the tiles above), ``exact`` (nothing: every value is fitted
        on an estimated spectrum) and ``estimated`` ({name: how}).
    spectrum : dict or None
        With ``spectrum=True``: the log-binned joined spectrum (``frequency`` 1/m,
        ``density`` m⁴, ``count``), as :func:`~rough.fractal.binned_spectrum` gives a
        map's. Not in ``as_dict()``.
    """

    tiled: dict = None
    spectrum: dict = dataclasses.field(default=None, repr=False)

    def as_dict(self):
        values = super().as_dict()
        del values["spectrum"]
        return values


@dataclasses.dataclass(frozen=True)
class Tiling:
    """How a map is cut: ``tile`` (rows, columns) of every tile, ``counts`` (tiles
    along y, along x, from the first row and column; the rows and columns left over
    at the ends go to the coarse level only), the coarse ``factor`` k, and the tiles'
    fit settings: ``order``, ``fill``, ``band`` (low, high) of their rings (1/m)
    and ``full`` (the top of the output spectrum, or None)."""

    shape: tuple
    spacing: tuple
    tile: tuple
    counts: tuple
    factor: int
    order: int = 1
    fill: bool = False
    band: tuple = (0.0, math.inf)
    full: float = None

    @property
    def coarse_shape(self):
        return tuple(n // self.factor for n in self.shape)

    @property
    def join(self):
        """The frequency below which the coarse level's spectrum is used, 1/m."""
        return COARSE_TOP * 0.5 / (self.factor * max(self.spacing))

    @property
    def step(self):
        """The tiles' ring step, 1/m."""
        return max(1 / (n * d) for n, d in zip(self.tile[::-1], self.spacing))

    @property
    def overlap(self):
        """How much the half-overlap of neighbouring tiles inflates the variance of
        their average (Welch 1967), per axis ``1 + 2 (1 - 1/t) ρ`` over t tiles."""
        return math.prod(1 + 2 * (1 - 1 / count) * OVERLAP_CORRELATION for count in self.counts)


def tiling(shape, spacing, budget=None, **settings):
    """The :class:`Tiling` of a map of ``shape`` (rows, columns) within ``budget``
    bytes (default :func:`rough.io.memory_budget`): tiles of about the most points the
    budget allows, as many along each axis as cover it (sides rounded down to a fast
    FFT length), and the coarse factor that brings the map to one tile's points (at
    most the smaller side / 32)."""
    points = tile_points(memory_budget() if budget is None else budget)
    halves = tuple(max(2, math.ceil(n / max(1, math.isqrt(points) // 2))) for n in shape)
    tile = tuple(2 * _fast_below(n // count) for n, count in zip(shape, halves))
    counts = tuple(count - 1 for count in halves)
    most = max(1, int(COARSE_TOP * min(tile) / (2 * LOWEST_RING)))
    factor = min(max(1, math.ceil(math.sqrt(shape[0] * shape[1] / points))), most)
    return Tiling(tuple(shape), tuple(spacing), tile, counts, factor, **settings)


def _fast_below(n):
    """The largest FFT-friendly length (a product of 2, 3 and 5) not above ``n``."""
    for m in range(n, 0, -1):
        if fft.next_fast_len(m, real=True) == m:
            return m
    return n


#: The spectral model's keywords of the tiled fits and their defaults (those of
#: :func:`~rough.fractal.fit_fractal` and :func:`~rough.fractal.fit_profiles`).
MODEL = {"band": None, "resolution": None, "order": 1, "sampling": None, "noise": True, "rolloff": False, "level": 0.01}


def model_of(model):
    """The keywords ``model`` with the defaults of :data:`MODEL`, in its order."""
    unknown = sorted(set(model) - set(MODEL))
    if unknown:
        raise TypeError(f"unexpected keyword arguments: {', '.join(unknown)}")
    return {**MODEL, **model}


def fit_fractal_tiles(tiled, *, fill=False, spectrum=False, jobs=1, scheduler=None, budget=None, **model):
    """The surface dimension Ds and amplitude coefficient C of a map read in tiles.

    The estimator is described in :mod:`rough.fractal.tiled`: the Welch average of
    the tiles' Hann periodograms above the join frequency and the transfer-corrected
    periodogram of the block-averaged map below it, fitted as
    :func:`~rough.fractal.fit_fractal` fits a map's ring spectrum.

    Parameters
    ----------
    tiled : rough.io.TiledSurface
        The map.
    fill : bool, default False
        Fill invalid (NaN) points tile by tile (see the module); without it a map with
        invalid points is refused, as in memory.
    spectrum : bool, default False
        Also give the log-binned joined spectrum (for ``--psd`` and ``--plot``).
    jobs, scheduler
        How the tiles are worked on (:func:`rough.tasks.map_ordered`).
    budget : int, optional
        The memory budget in bytes that sizes the tiles (default
        :func:`rough.io.memory_budget`).
    **model
        ``band``, ``resolution``, ``order``, ``sampling``, ``noise``, ``rolloff`` and
        ``level``, as for :func:`~rough.fractal.fit_fractal` (the default band starts at
        the whole map's fourth ring, as in memory).

    Returns
    -------
    TiledFractalFit
        The fit, its method naming the tiling, and ``tiled`` saying how.

    Raises
    ------
    rough.InputError
        For invalid points without ``fill``, an unknown sampling, a level outside
        (0, 1), a map flat once its form is removed, every tile mostly invalid, or too
        few rings in the band.

    Examples
    --------
    >>> import rough
    >>> from rough.fractal.tiled import fit_fractal_tiles
    >>> scan = rough.synthesize_map((512, 512), (1e-6, 1e-6), 2.3, rq=1e-6, seed=1)
    >>> fit = fit_fractal_tiles(rough.io.TiledSurface.of(scan), budget=80 * 128 * 128)
    >>> fit.tiled["tiles"], fit.tiled["tile_shape"], fit.tiled["coarse_factor"], round(fit.fractal_dimension, 1)
    (9, [256, 256], 2, 2.3)
    """
    band, resolution, order, sampling, noise, rolloff, level = model_of(model).values()
    if sampling is not None and sampling not in SAMPLINGS:
        raise InputError(f"sampling must be one of {', '.join(SAMPLINGS)}, not {sampling!r}")
    if not 0 < level < 1:
        raise InputError(f"the test's level must lie between 0 and 1, not {level}")
    source = "option" if sampling else "history" if history_sampling(tiled) else "maps: band"
    sampling = sampling or sampling_of(tiled)
    resolution = resolution or min(tiled.spacing)
    (ny, nx), (dx, dy) = tiled.shape, tiled.spacing
    low, high = band or (None, None)
    low = LOWEST_RING * max(1 / (nx * dx), 1 / (ny * dy)) if low is None else low
    top = min(0.5 / dx, 0.5 / dy)
    high = default_top(tiled, top, sampling) if high is None else high
    plan = tiling(tiled.shape, tiled.spacing, budget, order=order, fill=fill)
    plan = dataclasses.replace(plan, band=(max(low, plan.join), high), full=top if spectrum else None)
    items = [(tiled, plan, (i, j)) for i in range(plan.counts[0]) for j in range(plan.counts[1])]
    sums, counts, used = np.zeros(plan.coarse_shape), np.zeros(plan.coarse_shape, np.float32), []
    for part in tasks.map_ordered(_tile_part, items, jobs=jobs, scheduler=scheduler):
        blocks = part.pop("blocks")
        if blocks is not None:  # the coarse level's block sums, added as they come
            row, col, total, number = blocks
            sums[row : row + total.shape[0], col : col + total.shape[1]] += total
            counts[row : row + total.shape[0], col : col + total.shape[1]] += number
        if part["rings"] is not None:
            used.append(part)
    if not used:
        raise InputError(f"every tile has more than {MOST_INVALID:.0%} invalid points: no spectrum to fit")
    _refuse_flat(used)
    coarse = _coarse_level(sums, counts, plan)
    del sums, counts
    rings = _joined(coarse.rings(low, min(plan.join, high)), [part["rings"] for part in used], plan.overlap)
    method = (
        f"whittle (ring-binned 2-D periodogram: Welch average of {len(used)} tiles of {plan.tile[0]} × "
        f"{plan.tile[1]} + coarse level ×{plan.factor})"
    )
    fit = fit_rings(rings, tiled.spacing, band, resolution, (sampling, source), Options(noise, rolloff, level), method)
    if fit.verdict == "no power-law range":
        log.warning("scale_dependent: the roughness against scale of a map read in tiles is not measured")
    announce(fit, level)
    values = {field.name: getattr(fit, field.name) for field in dataclasses.fields(FractalFit)}
    joined = None
    if spectrum:
        joined = binned_rings(_joined(coarse.rings(0.0, plan.join), [part["full"] for part in used], plan.overlap))
    return TiledFractalFit(**values, tiled=_description(plan, len(used), len(items) - len(used)), spectrum=joined)


def _description(plan, used, skipped):
    how = (
        f"Welch average of {used} half-overlapping, periodic-Hann-windowed tiles of {plan.tile[0]} × "
        f"{plan.tile[1]} points (each less its own polynomial of order {plan.order}) at wavelengths below "
        f"{format_length(1 / plan.join)}; above, the periodogram of the map block-averaged ×{plan.factor}, "
        f"divided by the block average's power transfer"
    )
    return {
        "tiles": used,
        "skipped": skipped,
        "tile_shape": list(plan.tile),
        "coarse_factor": plan.factor,
        "coarse_shape": list(plan.coarse_shape),
        "join": plan.join,
        "exact": [],
        "estimated": {"spectrum": how},
    }


def _tile_part(item):
    """One tile's ring spectrum (None when it is mostly invalid), its windowed sum of
    squares, largest height and block sums for the coarse level."""
    tiled, plan, (i, j) = item
    first = (i * plan.tile[0] // 2, j * plan.tile[1] // 2)
    owned = [  # the part of the map whose block sums this tile gives: a quarter, to the ends for the last
        (start, n if index == count - 1 else start + size // 2)
        for n, index, count, start, size in zip(tiled.shape, (i, j), plan.counts, first, plan.tile)
    ]
    halo = HALO if plan.fill else 0
    window = [
        (max(0, start - halo), min(n, max(start + size, stop) + halo))
        for (start, stop), size, n in zip(owned, plan.tile, tiled.shape)
    ]
    heights = tiled.read(*(slice(a, b) for a, b in window))
    inside = tuple(slice(a - w[0], b - w[0]) for (a, b), w in zip(owned, window))
    tile = tuple(slice(a - w[0], a - w[0] + size) for a, w, size in zip(first, window, plan.tile))
    invalid = np.isnan(heights)
    part = {"rings": None, "full": None}
    if invalid.any() and not plan.fill:
        raise InputError(GAPS_REFUSED)
    if invalid[tile].mean() <= MOST_INVALID:
        if invalid.any():
            heights = filled(Surface(heights, tiled.spacing))
        part.update(_tile_spectrum(heights[tile], plan))
    part["blocks"] = _block_sums(heights[inside], first, plan)
    return part


def _tile_spectrum(heights, plan):
    surface = Surface(heights, plan.spacing)
    field, power = windowed_map(surface, plan.order)
    transform = fft.rfft2(field, workers=-1)
    low, high = plan.band
    spectra = {"rings": sector_spectra(field, power, plan.spacing, low, high, plan.step, transform=transform)[0]}
    if plan.full is not None:
        spectra["full"] = sector_spectra(
            field, power, plan.spacing, plan.join, plan.full, plan.step, transform=transform
        )[0]
    spectra["squares"] = (float(np.sum(np.square(field, dtype=np.float64))), field.size)
    spectra["largest"] = float(np.max(np.abs(heights)))
    return spectra


def _block_sums(heights, first, plan):
    """``(first block row, first block column, sums, counts)`` of the valid heights of
    the part of the map from ``first`` over the coarse level's k × k blocks."""
    k, shape = plan.factor, plan.coarse_shape
    index = [np.arange(start, min(start + n, m * k)) // k for start, n, m in zip(first, heights.shape, shape)]
    if not (index[0].size and index[1].size):
        return None
    starts = [np.flatnonzero(np.r_[True, np.diff(where) != 0]) for where in index]
    sums = np.empty((starts[0].size, starts[1].size))
    counts = np.empty(sums.shape, np.float32)
    edges = np.r_[starts[0], index[0].size]
    for chunk in np.array_split(np.arange(starts[0].size), max(1, starts[0].size // 64)):  # 64 block rows at a time
        rows = slice(edges[chunk[0]], edges[chunk[-1] + 1])
        inside = heights[rows, : index[1].size]  # the columns of whole blocks
        valid = np.isfinite(inside)
        values = inside if valid.all() else np.where(valid, inside, 0.0)
        local = starts[0][chunk] - rows.start
        sums[chunk] = np.add.reduceat(np.add.reduceat(values, local, axis=0), starts[1], axis=1)
        counts[chunk] = np.add.reduceat(np.add.reduceat(valid, local, axis=0, dtype=np.int64), starts[1], axis=1)
    return int(index[0][0]), int(index[1][0]), sums, counts


def _refuse_flat(parts):
    """As in memory: refuse a map whose windowed residual is rounding next to its heights."""
    squares = sum(part["squares"][0] for part in parts)
    count = sum(part["squares"][1] for part in parts)
    if not math.sqrt(squares / count) > FLAT * max(part["largest"] for part in parts):
        raise InputError("the surface is flat once its form is removed: there is no roughness to fit")


@dataclasses.dataclass
class _Coarse:
    """The coarse level's levelled, windowed field and its transfer-corrected transform."""

    field: np.ndarray
    power: float
    spacing: tuple
    transform: np.ndarray

    def rings(self, low, high):
        """Its ring spectrum between ``low`` and ``high`` (1/m, the top left out)."""
        ny, nx = self.field.shape
        step = max(1 / (nx * self.spacing[0]), 1 / (ny * self.spacing[1]))
        top = high * (1 - 1e-12)
        return sector_spectra(self.field, self.power, self.spacing, low, top, step, transform=self.transform)[0]


def _coarse_level(sums, counts, plan):
    """The block-averaged map (its blocks without a valid point filled), levelled,
    windowed and transformed, each ordinate divided by the block average's transfer."""
    with np.errstate(invalid="ignore", divide="ignore"):
        means = np.divide(sums, counts, out=sums)
    spacing = tuple(plan.factor * d for d in plan.spacing)
    surface = fill_invalid(Surface(means, spacing))
    field, power = windowed_map(surface, plan.order)
    transform = fft.rfft2(field, workers=-1)
    ny, nx = field.shape
    along_y = _transfer(np.fft.fftfreq(ny, spacing[1]), plan.spacing[1], plan.factor)
    along_x = _transfer(np.fft.rfftfreq(nx, spacing[0]), plan.spacing[0], plan.factor)
    transform /= (along_y[:, np.newaxis] * along_x).astype(transform.real.dtype)
    return _Coarse(field, power, spacing, transform)


def _transfer(frequencies, spacing, factor):
    """The amplitude transfer of a block average of ``factor`` points, H(f) =
    sin(πfkΔ) / (k sin(πfΔ)) (1 at f = 0; positive up to the coarse Nyquist frequency)."""
    phase = np.pi * np.abs(frequencies) * spacing
    with np.errstate(invalid="ignore", divide="ignore"):
        values = np.sin(factor * phase) / (factor * np.sin(phase))
    return np.where(phase > 0, values, 1.0)


RING_KEYS = ("log_radius", "log_spread", "window_a", "window_b")


def _joined(coarse, tiles, overlap):
    """One ring spectrum: the coarse level's rings, then the tiles' rings averaged
    (their ordinates counted together, the variance factor of their window times
    ``overlap``, that of their overlap); the variance factor per ring."""
    first = tiles[0]
    joined = {
        "count": np.concatenate([coarse["count"], first["count"] * len(tiles)]),
        "density": np.concatenate([coarse["density"], np.mean([part["density"] for part in tiles], axis=0)]),
        "window_factor": np.concatenate(
            [
                np.full(coarse["count"].size, coarse["window_factor"]),
                np.full(first["count"].size, first["window_factor"] * overlap),
            ]
        ),
    }
    for key in RING_KEYS:
        joined[key] = np.concatenate([coarse[key], first[key]])
    return joined
