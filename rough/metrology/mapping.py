"""Roughness maps: areal parameters, the fractal fit and the lay, window by window over a map.

A window of ``wy × wx`` points is moved over the map by a step; each window has its own
least-squares polynomial form removed (the Legendre basis of :mod:`rough.metrology.form`,
fitted on its valid points) before its parameters are taken. The output is a grid of the
window centres, whose spacing is the step. The work goes one row of windows at a time
(:func:`_row_of_windows` takes the band of input rows those windows cover), in tasks of a
few rows of windows each (:func:`_band_of_rows`): a task reads its own band of input rows,
from a :class:`~rough.io.TiledSurface` (a map larger than memory, read a strip at a time)
or from the map in memory, so the tasks can run in worker processes or on a cluster
(:func:`rough.tasks.map_ordered`). Each window is computed whole in every case, so the
results are the same bit for bit however the work is split and wherever it runs.

The cheap moments (Sa, Sq, Ssk, Sku, Sp, Sv, Sz) and the form are computed for a whole
row of windows at once with numpy; the other parameters (Sdq, Sdr, Sal, Str, Std and the
lay, the fractal fit) call the library's function on each window in a Python loop, which
Ctrl-C stops between windows.
"""

import collections
import contextlib
import dataclasses
import logging
import math
import numbers
import re
import warnings

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from numpy.polynomial import legendre

from .. import fractal, tasks
from ..errors import InputError, RoughError
from ..io import geotiff, writing
from ..io.atomic import atomic_output
from ..io.tiled import ArraySource, TiledSurface, memory_budget, tile_points
from ..progress import progress
from ..surface import Surface
from .areal import AREAL, gradient_means
from .heights import ROUNDING
from .spatial import autocorrelation_lengths, texture_direction

SMALLEST_WINDOW = 16  # points along each axis
FRACTAL = {
    "hurst": ("1", "Hurst exponent H = 3 - Ds of the window's fractal fit"),
    "dimension": ("1", "surface fractal dimension Ds of the window's fractal fit"),
    "amplitude": ("m", "amplitude coefficient C at the spacing, from the window's fractal fit"),
}
MAP_PARAMETERS = {**AREAL, **FRACTAL, "lay": ("deg", "texture (lay) direction Std from +x")}
MOMENTS = ("Sa", "Sq", "Ssk", "Sku", "Sp", "Sv", "Sz")
NUMBER = re.compile(r"[-+]?\d+(?:\.\d*)?(?:e[-+]?\d+)?(?:/?[a-zµ]*m\b)?")
TOO_FEW = "fewer than half the window's points are valid"


@dataclasses.dataclass
class RoughnessMap:
    """Parameters per window of a map, on the grid of the window centres.

    Attributes
    ----------
    values : dict of str to numpy.ndarray
        Per parameter, a 2-D float64 array ``[row, column]`` of windows, oriented as the
        input (row 0 holds the windows over the input's first rows, at its smallest y);
        NaN where the window has too few valid points or the parameter is undefined.
    units : dict of str to str
        Per parameter, its unit (``m``, ``1``, ``%``, ``deg``).
    origin : tuple of float
        ``(x, y)`` of the centre of window ``[0, 0]``, metres.
    spacing : tuple of float
        ``(dx, dy)`` between window centres: the step, metres.
    window : tuple of int
        The window in points, ``(nx, ny)``.
    step : tuple of int
        The step in points, ``(nx, ny)``.
    order : int
        The degree of the polynomial form removed from each window.
    reasons : dict of str to dict of str to int
        Per parameter, why windows got NaN: reason → number of windows.
    metadata : dict of str
        The input's metadata (its ``crs`` among them), carried to the output.
    tiled : dict or None
        For a :class:`~rough.io.TiledSurface` input, how it was read: ``tile_rows``
        (input rows a band reads at most), ``tiles`` (bands), ``exact`` (every
        parameter: each window is computed whole) and ``estimated`` (none); None for a
        map in memory.
    """

    values: dict
    units: dict
    origin: tuple
    spacing: tuple
    window: tuple
    step: tuple
    order: int
    reasons: dict
    metadata: dict
    tiled: dict = None

    def surface(self, name):
        """The map of parameter ``name`` as a :class:`~rough.Surface` on the window-centre
        grid (a parameter that is not a height is stored as it is, in its own unit)."""
        units = dataclasses.replace(Surface(np.zeros((1, 1)), 1.0).units, z=self.units[name])
        parameters = {"window": list(self.window), "step": list(self.step), "order": self.order, "parameter": name}
        surface = Surface(self.values[name], self.spacing, self.origin, units, dict(self.metadata))
        return surface.derive("map", parameters)

    def as_dict(self):
        """JSON-able: per parameter min, median, max, unit and NaN count; the grid and window."""
        summary = {}
        for name, values in self.values.items():
            valid = values[~np.isnan(values)]
            low, middle, high = (float(f(valid)) if valid.size else math.nan for f in (np.min, np.median, np.max))
            summary[name] = {"min": low, "median": middle, "max": high, "unit": self.units[name]}
            summary[name].update(undefined=int(values.size - valid.size), reasons=dict(self.reasons[name]))
        shape = next(iter(self.values.values())).shape
        grid = {"origin": list(self.origin), "spacing": list(self.spacing), "shape": [shape[1], shape[0]]}
        document = {"parameters": summary, "grid": grid, "window": list(self.window), "step": list(self.step)}
        if self.tiled is not None:
            document["tiled"] = dict(self.tiled)
        return document

    @staticmethod
    def output_format(path, parameters):
        """The format ``path`` will be written in (GeoTIFF: one band per parameter; other
        writable formats: one parameter only); an InputError before any work otherwise."""
        format_name = writing.format_for_path(path)
        if format_name != "geotiff" and len(parameters) > 1:
            raise InputError(
                f"only GeoTIFF (.tif) holds several parameters as bands; write {format_name.upper()} with one "
                "parameter",
                filename=path,
            )
        return format_name

    def write(self, path):
        """Write the map to ``path``: a GeoTIFF with one float32 band per parameter, named
        by its description and with its unit in the band's metadata (``UNIT``), in the
        input's CRS with each value at its window centre; or, for another writable format,
        the single parameter as a surface. Written atomically."""
        format_name = self.output_format(path, self.values)
        if format_name != "geotiff":
            writing.write(self.surface(next(iter(self.values))), path, format=format_name)
            return
        bands = [(name, values, {"UNIT": self.units[name]}) for name, values in self.values.items()]
        tags = {"ROUGH_WINDOW": " ".join(map(str, self.window)), "ROUGH_STEP": " ".join(map(str, self.step))}
        with atomic_output(path) as stream:
            geotiff.write_bands(stream, bands, self.spacing, self.origin, self.metadata.get("crs"), "float32", tags)


def roughness_map(surface, window, step=None, parameters=("Sq",), order=1, *, jobs=1, scheduler=None, budget=None):
    """Parameters of a map in windows moved over it: a roughness map.

    Parameters
    ----------
    surface : Surface or rough.io.TiledSurface
        A map, in memory or read a band of rows at a time (a map larger than memory:
        :func:`rough.io.open_surface`); the results are the same. NaN points are left
        out of each window's form and parameters; a window with fewer than half its
        points valid gives NaN for every parameter. The fractal
        fit needs a gap-free window: windows with any NaN point get NaN for ``hurst``,
        ``dimension`` and ``amplitude``.
    window : int or float or tuple
        The window's size: an int is a number of points, a float a length in metres
        (rounded to the nearest number of points along each axis); a pair gives
        ``(x, y)`` separately. At least 16 points and at most the map along each axis.
    step : int or float or tuple, optional
        The distance between window starts, in the same convention (default: the window,
        windows side by side without overlap). Points past the last whole window along
        an axis are left out.
    parameters : sequence of str, default ("Sq",)
        Names from :data:`MAP_PARAMETERS`: the areal parameters of :data:`AREAL` (Sa …
        Std), ``hurst``, ``dimension`` and ``amplitude`` (the Whittle fit of
        :func:`rough.fractal.fit_fractal` on the window, with its default band), and
        ``lay`` (Std).
    order : int, default 1
        The degree of the polynomial form removed from each window (1: a plane).
    jobs : int, default 1
        Worker processes working on bands of windows at once (0: one per core).
    scheduler : str or distributed.Client, optional
        A Dask scheduler's address (``tcp://host:8786``) or client: the bands are
        worked on by its workers, which need ``rough`` and, for a tiled input, its
        file (see :func:`rough.tasks.map_ordered`).
    budget : int, optional
        The memory budget in bytes that sizes the bands (default
        :func:`rough.io.memory_budget`); a band holds at most
        :func:`rough.io.tile_points` of it.

    Returns
    -------
    RoughnessMap
        One 2-D array per parameter on the grid of window centres (spacing = step),
        row 0 over the input's first rows, and why windows are NaN.

    Raises
    ------
    rough.InputError
        For a profile, an unknown parameter (the known ones are listed), a window
        under 16 points or larger than the map, or a step under one point.

    Examples
    --------
    Four quadrants of white noise with RMS 1, 2, 3 and 4 µm, in windows of 32 points:

    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology import roughness_map
    >>> rng = np.random.default_rng(1)
    >>> z = rng.standard_normal((64, 64)) * np.kron([[1, 2], [3, 4]], np.ones((32, 32))) * 1e-6
    >>> result = roughness_map(rough.Surface(z, 1e-6), window=32, parameters=["Sq"])
    >>> np.round(result.values["Sq"] * 1e6, 1)
    array([[1., 2.],
           [3., 4.]])
    >>> result.origin, result.spacing  # the first window's centre, and the step
    ((1.55e-05, 1.55e-05), (3.2e-05, 3.2e-05))
    """
    if surface.is_profile:
        raise InputError("a roughness map needs a map, not a profile")
    parameters = list(dict.fromkeys(parameters))
    unknown = [name for name in parameters if name not in MAP_PARAMETERS]
    if unknown or not parameters:
        raise InputError(
            f"unknown parameter {', '.join(unknown) or '(none given)'}; known: {', '.join(MAP_PARAMETERS)}"
        )
    ny, nx = surface.shape if isinstance(surface, TiledSurface) else surface.heights.shape
    size = _points(window, surface.spacing, "window")
    stride = size if step is None else _points(step, surface.spacing, "step")
    if min(size) < SMALLEST_WINDOW:
        raise InputError(f"the window is {size[0]} × {size[1]} points; it needs at least {SMALLEST_WINDOW} a side")
    if size[0] > nx or size[1] > ny:
        raise InputError(f"the window ({size[0]} × {size[1]} points) is larger than the map ({nx} × {ny})")
    if min(stride) < 1:
        raise InputError("the step must be at least one point")
    columns, rows = ((n - w) // s + 1 for n, w, s in zip((nx, ny), size, stride))
    values = {name: np.full((rows, columns), math.nan) for name in parameters}
    reasons = {name: collections.Counter() for name in parameters}
    tiled = isinstance(surface, TiledSurface)
    per_task = _rows_per_task(nx, rows, size[1], stride[1], budget)
    settings = _Settings(size, stride, order, parameters, tuple(surface.spacing), surface.units, surface.history)
    items = (_item(surface, first, min(per_task, rows - first), settings) for first in range(0, rows, per_task))
    done = 0
    with progress(total=rows, description="windows", unit="row") as bar:
        for found, counts in tasks.map_ordered(_band_of_rows, items, jobs=jobs, scheduler=scheduler):
            for row_values in found:
                for name, row in row_values.items():
                    values[name][done] = row
                done += 1
            for name, counted in counts.items():
                reasons[name].update(counted)
            bar.update(len(found))
    metadata = dict(surface.metadata)
    if tiled and surface.geo and "crs" not in metadata:
        metadata["crs"] = surface.geo["crs"]
    (dx, dy), (x0, y0) = surface.spacing, surface.origin
    return RoughnessMap(
        values,
        {name: MAP_PARAMETERS[name][0] for name in parameters},
        (x0 + (size[0] - 1) / 2 * dx, y0 + (size[1] - 1) / 2 * dy),
        (stride[0] * dx, stride[1] * dy),
        size,
        stride,
        order,
        {name: dict(counts) for name, counts in reasons.items()},
        metadata,
        _tiling(rows, per_task, size[1], stride[1], parameters) if tiled else None,
    )


@dataclasses.dataclass(frozen=True)
class _Settings:
    """What every band's task needs besides its rows (small: it travels with each)."""

    size: tuple
    stride: tuple
    order: int
    parameters: list
    spacing: tuple
    units: object
    history: list


#: Bands a map is cut into at least (when it has that many rows of windows), so that
#: workers finish together; the same with and without them, so the output is too.
LEAST_BANDS = 16


def _rows_per_task(nx, rows, window, stride, memory):
    """Rows of windows a task works on: as many as fit :func:`~rough.io.tiled.tile_points`
    of the ``memory`` budget (at least one), and few enough to make :data:`LEAST_BANDS`
    bands."""
    points = tile_points(memory_budget() if memory is None else memory)
    fitting = max(1, (points // nx - window) // stride + 1)
    return min(fitting, max(1, -(-rows // LEAST_BANDS)))


def _item(surface, first, count, settings):
    """A task's item: ``(source, base, first, count, settings)``: the rows of windows
    ``first`` … ``first + count - 1``, read from ``source`` whose row 0 is input row
    ``base``. A tiled map is its own source (the task reads its band); a map in memory
    gives a view of the band alone (so that only the band travels to a cluster)."""
    if isinstance(surface, TiledSurface):
        return surface, 0, first, count, settings
    top = first * settings.stride[1]
    band = surface.heights[top : top + (count - 1) * settings.stride[1] + settings.size[1]]
    return TiledSurface(ArraySource(band), band.shape, settings.spacing), top, first, count, settings


def _band_of_rows(item):
    """One task: ``(found, reasons)``, the parameters of each of the item's rows of
    windows (a list of ``{name: values}``) and why windows were NaN (``{name: Counter}``)."""
    source, base, first, count, settings = item
    size, stride = settings.size, settings.stride
    top = first * stride[1]
    band = source.read(rows=slice(top - base, top - base + (count - 1) * stride[1] + size[1]))
    basis = _basis(size, settings.order)
    template = Surface(np.zeros((2, 2)), settings.spacing, None, settings.units, {}, settings.history)
    reasons = {name: collections.Counter() for name in settings.parameters}
    found = []
    for row in range(count):
        rows = band[row * stride[1] : row * stride[1] + size[1]]
        found.append(
            _row_of_windows(rows, template, size, stride[0], settings.order, basis, settings.parameters, reasons)
        )
    return found, reasons


def _tiling(rows, per_task, window, stride, parameters):
    """The ``tiled`` record of a map read in bands: every window is computed whole."""
    return {
        "tile_rows": (per_task - 1) * stride + window,
        "tiles": -(-rows // per_task),
        "exact": list(parameters),
        "estimated": {},
    }


def _points(length, spacing, what):
    """``(nx, ny)`` points for a window or step given in points (int) or metres (float)."""
    pair = tuple(length) if isinstance(length, tuple | list) else (length, length)
    if len(pair) != 2:
        raise InputError(f"the {what} is one size or a pair (x, y), not {length!r}")
    counts = []
    for value, delta in zip(pair, spacing):
        if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value) or value <= 0:
            raise InputError(f"the {what} must be a positive number of points (int) or length in metres (float)")
        counts.append(int(value) if isinstance(value, numbers.Integral) else round(value / delta))
    return tuple(counts)


def _basis(size, order):
    """The ``(points × terms)`` Legendre basis of the form, x fastest, with the terms
    ``x^i y^j``, ``i + j <= order``, on coordinates scaled to [-1, 1] as in :mod:`.form`."""
    along_x = legendre.legvander(np.linspace(-1.0, 1.0, size[0]), order)
    along_y = legendre.legvander(np.linspace(-1.0, 1.0, size[1]), order)
    terms = [(i, j) for j in range(order + 1) for i in range(order + 1 - j)]
    return np.stack([np.outer(along_y[:, j], along_x[:, i]).ravel() for i, j in terms], axis=1)


def _row_of_windows(band, template, size, stride, order, basis, parameters, reasons):
    """The parameters of the windows side by side in ``band`` (the ``size[1]`` input rows
    they cover): one array per parameter, one value per window. ``template`` is a small
    surface with the input's spacing, units and history, from which the windows the
    per-window functions need are derived; ``reasons`` counts why windows are NaN."""
    windows = sliding_window_view(band, (size[1], size[0]))[0, ::stride]
    group = max(1, GROUP_POINTS // (size[0] * size[1]))
    parts = [
        _group_of_windows(windows[start : start + group], template, size, order, basis, parameters, reasons)
        for start in range(0, len(windows), group)
    ]
    return {name: np.concatenate([part[name] for part in parts]) for name in parameters}


#: Points of the windows levelled at once: the arrays of a group (heights, weights,
#: residuals) stay near 32 MB each, whatever the window, so a band of 1024-point windows
#: across a 32768-point DEM does not take gigabytes.
GROUP_POINTS = 1 << 22


def _group_of_windows(windows, template, size, order, basis, parameters, reasons):
    """:func:`_row_of_windows` for some of the row's windows (``windows``: a view)."""
    heights = windows.reshape(len(windows), -1)
    valid = ~np.isnan(heights)
    count = valid.sum(axis=1)
    enough = 2 * count >= heights.shape[1]
    residual, determined = _residual(heights, valid, basis)
    found = {name: np.full(len(windows), math.nan) for name in parameters}
    if (~enough).any():
        for name in parameters:
            reasons[name][TOO_FEW] += int((~enough).sum())
    if (enough & ~determined).any():
        for name in parameters:
            reasons[name]["the valid points do not determine the form"] += int((enough & ~determined).sum())
    usable = enough & determined
    moments = _moments(residual[usable], count[usable])
    for name in parameters:
        if name in moments:
            found[name][usable] = moments[name]
    slow = [name for name in parameters if name not in MOMENTS]
    for index in np.flatnonzero(usable) if slow else ():
        levelled = template.derive("detrend", {"order": order}, heights=residual[index].reshape(size[1], size[0]))
        for name, value in _per_window(levelled, template.derive("map", {}, heights=windows[index]), order, slow):
            found[name][index] = value[0]
            if value[1]:
                reasons[name][value[1]] += 1
    return found


def _residual(heights, valid, basis):
    """Each row of ``heights`` less its least-squares form on its valid points (NaN stays
    NaN), and whether the valid points determine the form."""
    filled = np.where(valid, heights, 0.0)
    weights = valid.astype(np.float64)
    terms = basis.shape[1]
    products = (basis[:, :, None] * basis[:, None, :]).reshape(len(basis), -1)
    gram = (weights @ products).reshape(-1, terms, terms)
    right = filled @ basis
    scale = np.abs(np.diagonal(gram, axis1=1, axis2=2)).max(axis=1)
    smallest = np.linalg.eigvalsh(gram).min(axis=1)
    determined = (scale > 0) & (smallest > 1e-12 * scale)
    gram[~determined] = np.eye(terms)
    coefficients = np.linalg.solve(gram, right[:, :, None])[:, :, 0]
    return heights - coefficients @ basis.T, determined


def _moments(residual, count):
    """Sa … Sz of each row of ``residual`` (NaN left out; ``count`` valid points a row),
    about the mean of its valid points, as :func:`rough.metrology.heights.amplitude`
    takes them (a row that differs from its mean only by rounding is constant)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.nansum(residual, axis=1) / count
        top, bottom = np.nanmax(residual, axis=1) - mean, mean - np.nanmin(residual, axis=1)
        constant = np.maximum(top, bottom) <= ROUNDING * np.abs(mean)
        deviation = residual - mean[:, None]
        squared = deviation * deviation
        sa = np.nansum(np.abs(deviation), axis=1) / count
        sq = np.sqrt(np.nansum(squared, axis=1) / count)
        ssk = np.nansum(squared * deviation, axis=1) / count / sq**3
        sku = np.nansum(squared * squared, axis=1) / count / sq**4
    sa, sq, top, bottom = (np.where(constant, 0.0, values) for values in (sa, sq, top, bottom))
    ssk, sku = (np.where(constant | (sq == 0), math.nan, values) for values in (ssk, sku))
    return {"Sa": sa, "Sq": sq, "Ssk": ssk, "Sku": sku, "Sp": top, "Sv": bottom, "Sz": top + bottom}


def _per_window(levelled, window, order, names):
    """``(value, reason or None)`` per parameter of ``names`` for one window: the form-free
    window ``levelled`` for the areal parameters and the lay, the window as read for the
    fractal fit (which removes its own form of ``order``). The functions' warnings and log
    lines, once a window, are not shown: a NaN value keeps the first as its reason."""
    found = {}
    with _captured() as messages:
        if {"Sdq", "Sdr"} & set(names):
            found["Sdq"], found["Sdr"] = gradient_means(levelled)
        if {"Sal", "Str"} & set(names):
            found["Sal"], found["Str"] = autocorrelation_lengths(levelled)
        if {"Std", "lay"} & set(names):
            found["Std"] = found["lay"] = texture_direction(levelled)
        if set(FRACTAL) & set(names):
            found.update(_fractal(window, order))
    warned = _general(messages[0]) if messages else "undefined"
    result = {}
    for name in names:
        value = found[name]
        if isinstance(value, tuple):
            result[name] = value
        else:
            result[name] = (float(value), warned if math.isnan(value) else None)
    return result.items()


def _fractal(window, order):
    """``hurst``, ``dimension``, ``amplitude`` of a window's fractal fit, each as ``(value,
    reason)``: NaN with the reason where the fit refuses, finds no power law, or ends at a
    bound of the fractal range (a bound is not an estimate)."""
    if np.isnan(window.heights).any():
        reason = "the fractal fit needs a window without invalid points"
        return {name: (math.nan, reason) for name in FRACTAL}
    try:
        fit = fractal.fit_fractal(window, order=order)
    except RoughError as error:
        return {name: (math.nan, _general(str(error))) for name in FRACTAL}
    if fit.verdict != "power law":
        reason = f"{fit.verdict}: {_general(fit.hint)}" if fit.hint else fit.verdict
        return {name: (math.nan, reason) for name in FRACTAL}
    values = {"hurst": fit.hurst, "dimension": fit.fractal_dimension, "amplitude": fit.amplitude_coefficient}
    return {name: (float(value), None) for name, value in values.items()}


@contextlib.contextmanager
def _captured():
    """The warnings and the ``rough`` log lines (warning and above) given inside the block,
    as a list of messages, instead of shown."""
    messages, logger = [], logging.getLogger("rough")
    handler = logging.Handler(logging.WARNING)
    handler.emit = lambda record: messages.append(record.getMessage())
    saved = logger.handlers, logger.propagate
    logger.handlers, logger.propagate = [handler], False
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            yield messages
    finally:
        logger.handlers, logger.propagate = saved
        messages.extend(str(warning.message) for warning in caught)


def _general(message):
    """A message's first line with its numbers replaced by ``…``, so that windows that
    fail for one reason count together."""
    return NUMBER.sub("…", message.splitlines()[0] if message else "undefined")
