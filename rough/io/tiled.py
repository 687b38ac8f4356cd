"""Height maps larger than memory, read a window at a time.

A :class:`TiledSurface` holds a map's shape, spacing and provenance and reads any
window of its heights on demand from a *source*: a picklable object whose
``window(rows, cols)`` returns float64 metres with NaN for invalid points (so a
worker process or a cluster node can reopen the file). Formats that can read a
window from disk define ``open_tiles(path, options)`` returning a TiledSurface
(GeoTIFF/COG/VRT through rasterio, memory-mapped NPY, binary X3P);
:func:`open_surface` gives one instead of a :class:`~rough.surface.Surface` when the
whole map would not fit the memory budget.
"""

import dataclasses
import logging
import os
import re
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..surface import Surface, Units, history_entry, index_range
from ..units import format_length
from . import limits, registry
from .reading import _malformed, _named, held_warnings, read
from .reading import read_options as read_options_of

log = logging.getLogger("rough")

#: Bytes of memory per height that the in-memory commands peak at (``rough features``
#: measured 0.2 GB + 9.3 bytes per byte of float64 heights: ~75 bytes a point).
BYTES_PER_POINT = 80
#: The default memory budget, as a fraction of the machine's physical memory.
DEFAULT_FRACTION = 0.5
#: The most points a tile holds (128 MiB of float64 heights), whatever the budget: the
#: tiled path's own peak stays near 1 GB.
MAX_TILE_POINTS = 1 << 24

_SIZE = re.compile(r"^\s*(\d+(?:\.\d+)?)\s*([KMGT]?)(i?B)?\s*$", re.IGNORECASE)


def memory_budget(text=None):
    """The memory budget in bytes: ``text`` (``"4GB"``, ``"512MiB"``, ``"2G"``) or, for
    None, :data:`DEFAULT_FRACTION` of the machine's physical memory (``ROUGH_MEMORY``
    overrides the default). Raises InputError for text that is not a size."""
    text = text or os.environ.get("ROUGH_MEMORY")
    if not text:
        return int(DEFAULT_FRACTION * _physical_memory())
    match = _SIZE.match(str(text))
    if not match or float(match.group(1)) <= 0:
        raise InputError(f"memory budget {text!r} is not a size (write e.g. 4GB, 512MB or 2GiB)")
    number, prefix, suffix = match.groups()
    base = 1024 if (suffix or "").lower() != "b" or not prefix else 1000
    return int(float(number) * base ** "_KMGT".index(prefix.upper() or "_"))


def _physical_memory():
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return 8 << 30


def tile_points(budget):
    """The points one tile may hold within ``budget`` bytes (at most :data:`MAX_TILE_POINTS`)."""
    return int(max(1 << 16, min(MAX_TILE_POINTS, budget // BYTES_PER_POINT)))


@dataclass(eq=False)
class TiledSurface:
    """A height map read a window at a time (see the module's description).

    Attributes
    ----------
    source : object
        Reads windows: ``source.window(rows, cols)`` (two slices of the whole map)
        gives float64 metres, NaN for invalid points. It must pickle.
    shape : tuple of int
        ``(ny, nx)``, row-major as ``Surface.heights.shape``.
    spacing, origin, units, metadata, history, source_format
        As :class:`~rough.surface.Surface`'s.
    geo : dict or None
        For georeferenced sources: ``{"crs": text}`` (WKT or EPSG), kept by outputs.
    offset : tuple of int
        ``(row, column)`` of this view's first point in the source (a crop).
    """

    source: object
    shape: tuple
    spacing: tuple
    origin: tuple = (0.0, 0.0)
    units: Units = field(default_factory=Units)
    metadata: dict = field(default_factory=dict)
    history: list = field(default_factory=list)
    source_format: str = None
    geo: dict = None
    offset: tuple = (0, 0)

    is_profile = False
    kind = "map"

    @property
    def points(self):
        """Points along each axis, x first: ``(nx, ny)``."""
        return self.shape[1], self.shape[0]

    @property
    def size(self):
        """Physical size along each axis, x first, in metres."""
        return tuple(n * d for n, d in zip(self.points, self.spacing))

    @property
    def point_count(self):
        return self.shape[0] * self.shape[1]

    def read(self, rows=slice(None), cols=slice(None)):
        """Heights (float64 metres, NaN invalid) of rows × cols of this view."""
        rows, cols = (_bounded(s, n, offset) for s, n, offset in zip((rows, cols), self.shape, self.offset))
        return self.source.window(rows, cols)

    def strips(self, rows, halo=0):
        """``(first_row, heights)`` of consecutive strips of ``rows`` full-width rows,
        each with up to ``halo`` more rows after it (the next strip's first rows)."""
        for start in range(0, self.shape[0], rows):
            yield start, self.read(slice(start, min(start + rows + halo, self.shape[0])))

    def strip_rows(self, budget=None, halo=0):
        """Rows per strip so that a strip (with its halo) holds at most
        :func:`tile_points` points of ``budget`` (default :func:`memory_budget`)."""
        points = tile_points(memory_budget() if budget is None else budget)
        return max(1, points // self.shape[1] - halo)

    def crop(self, x=None, y=None):
        """The view between two positions on each axis (metres; None keeps that end),
        as :meth:`Surface.crop`."""
        (x0, x1), (y0, y1) = (
            index_range(bound, self.origin[axis], self.spacing[axis], self.points[axis], "xy"[axis])
            for axis, bound in enumerate((x, y))
        )
        origin = (self.origin[0] + x0 * self.spacing[0], self.origin[1] + y0 * self.spacing[1])
        offset = (self.offset[0] + y0, self.offset[1] + x0)
        history = [*self.history, history_entry("crop", {"x": list(x) if x else None, "y": list(y) if y else None})]
        return dataclasses.replace(self, shape=(y1 - y0, x1 - x0), origin=origin, offset=offset, history=history)

    def whole(self):
        """The whole view as an in-memory :class:`~rough.surface.Surface`."""
        return Surface(
            self.read(),
            self.spacing,
            origin=self.origin,
            units=self.units,
            metadata=dict(self.metadata),
            history=list(self.history),
            source_format=self.source_format,
        )

    @classmethod
    def of(cls, surface):
        """A tiled view of an in-memory map (tests, and maps made in memory)."""
        if surface.is_profile:
            raise InputError("a profile is read whole; tiles are for maps")
        return cls(
            ArraySource(surface.heights),
            surface.heights.shape,
            tuple(surface.spacing),
            origin=tuple(surface.origin),
            units=surface.units,
            metadata=dict(surface.metadata),
            history=list(surface.history),
            source_format=surface.source_format,
        )

    def __repr__(self):
        return f"<TiledSurface map {self.shape[1]} × {self.shape[0]} points, spacing {self.spacing} m>"


def _bounded(part, count, offset):
    start, stop, _ = part.indices(count)
    return slice(offset + start, offset + stop)


@dataclass(eq=False)
class ArraySource:
    """Windows of an array in memory (or memory-mapped)."""

    heights: np.ndarray

    def window(self, rows, cols):
        return np.array(self.heights[rows, cols], dtype=np.float64)


def open_surface(source, *, memory=None, **options):
    """The surface in ``source``: a :class:`~rough.surface.Surface` read whole, or a
    :class:`TiledSurface` when its format reads windows (``rough formats``: "tiles")
    and the whole map would take more than the ``memory`` budget (bytes, default
    :func:`memory_budget`) at :data:`BYTES_PER_POINT`. ``options`` are those of
    :func:`rough.io.read`; a crop is applied to the tiled view. The map is described
    from its header first and its data checked (checksums) only once: by the whole
    read, or before the first tile."""
    budget = memory_budget() if memory is None else memory
    with held_warnings() as said:  # given out only when the map is read in tiles: read() says its own
        tiled = _described(source, options) if isinstance(source, (str, os.PathLike)) else None
    if tiled is None or tiled.point_count * BYTES_PER_POINT <= budget:
        return read(source, **options)
    for record in said:
        log.handle(record)
    _checked(tiled)
    log.info(
        "%s: %s points would need ~%s in memory, over the budget of %s: read in tiles of up to %s points",
        source,
        " × ".join(map(str, tiled.points)),
        limits.human(tiled.point_count * BYTES_PER_POINT),
        limits.human(budget),
        f"{tile_points(budget):,}",
    )
    return tiled


def open_tiles(path, **options):
    """A :class:`TiledSurface` of the map in ``path`` when its format reads windows,
    else None (options as :func:`rough.io.read`'s); its data are checked (checksums)
    as a whole read checks them."""
    tiled = _described(path, options)
    return None if tiled is None else _checked(tiled)


def _checked(tiled):
    """``tiled``, once its source's data pass the checks a whole read makes."""
    path = tiled.source.path
    with _named(path), _malformed(lambda: registry.describe(tiled.source_format)), np.errstate(all="ignore"):
        tiled.source.check()
    return tiled


def _described(path, options):
    """The tiled view of ``path`` from its header (data not yet checked), or None."""
    path = os.fspath(path)
    if path == "-" or not os.path.isfile(path):
        return None
    with open(path, "rb") as stream:
        head = stream.read(registry.HEAD)
    try:
        module = registry.module_of(registry.sniff(head, path))
    except InputError:
        return None
    if not hasattr(module, "open_tiles"):
        return None
    read_options = read_options_of(**options)
    with _named(path), _malformed(lambda: module.FORMAT.title), np.errstate(all="ignore"):
        tiled = module.open_tiles(path, read_options)
    if tiled is None:
        return None
    tiled.source_format = module.FORMAT.name
    tiled.metadata.setdefault("source", path)
    if read_options.spacing is not None:
        given = tuple(read_options.spacing[:2])
        given *= 2 // len(given)
        if given != tuple(tiled.spacing):
            log.warning(
                "the spacing given, %s, overrides the file's own, %s",
                " × ".join(map(format_length, given)),
                " × ".join(map(format_length, tiled.spacing)),
            )
        tiled.spacing = given
    if read_options.window is not None:
        x, y = read_options.window
        tiled = tiled.crop(x, y)
    return tiled
