"""Figures that the commands draw (``show``, and ``--plot FILE`` elsewhere), with
matplotlib and no display needed. Each figure function returns a matplotlib Figure
drawn in one shared style (:data:`STYLE`, applied by :func:`style`) and takes a
``title`` (the commands pass the input's file name); :func:`save` writes one
atomically as PNG, SVG or PDF.

Maps are drawn by one piece of code everywhere (:func:`surface_figure`, and the map
panel of :func:`features_figure`): heights in a perceptual colour map with a colour
bar in a length unit chosen from the height range, axes in a length unit chosen from
the extent, y upwards (row 0 at the bottom, so a georeferenced DEM is north up and
angles counter-clockwise from +x, as ``rose`` and Std give them, are counter-clockwise
on the page), equal physical aspect (the figure's shape follows the map's, within
limits), a scale bar, and invalid (NaN) points in light grey, counted in a legend.
"""

import functools
import math
import os

import numpy as np

MM = 1e3
UM = 1e6

#: The rcParams of every rough figure: font sizes, a light grid, constrained layout
#: (the successor of tight layout: it makes room for colour bars, legends and titles),
#: reproducible SVG ids and PDF text that stays text.
STYLE = {
    "font.size": 10,
    "axes.titlesize": 10,
    "axes.labelsize": 10,
    "xtick.labelsize": 9,
    "ytick.labelsize": 9,
    "legend.fontsize": 8,
    "legend.framealpha": 0.9,
    "figure.titlesize": 12,
    "figure.titleweight": "bold",
    "axes.grid": True,
    "grid.color": "0.88",
    "grid.linewidth": 0.6,
    "axes.axisbelow": True,
    "lines.linewidth": 1.0,
    "image.cmap": "viridis",
    "figure.constrained_layout.use": True,
    "figure.facecolor": "white",
    "savefig.facecolor": "white",
    "savefig.dpi": 150,
    "svg.hashsalt": "rough",
    "pdf.fonttype": 42,
}
#: Formats :func:`save` writes (``--format`` of ``rough show``).
FORMATS = ("png", "svg", "pdf")
#: The colour of invalid (NaN) points: light grey, in no perceptual colour map.
INVALID_COLOUR = "#d4d4d4"
#: Longest side, in samples, of a map as drawn: larger maps are block-averaged first
#: (a figure has fewer pixels than this at any usual dpi).
MOST_SAMPLES = 3000

# (metres in one unit, units in one metre, symbol)
_LENGTH_UNITS = [
    (1e3, 1e-3, "km"),
    (1.0, 1.0, "m"),
    (1e-3, 1e3, "mm"),
    (1e-6, 1e6, "µm"),
    (1e-9, 1e9, "nm"),
    (1e-12, 1e12, "pm"),
]


def _pyplot():
    from .extras import require

    matplotlib = require("matplotlib")
    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


def style():
    """A context in which matplotlib draws in rough's style (:data:`STYLE`).

    Every figure function of this module builds its figure inside it, and
    :func:`save` writes inside it, so all of rough's figures share font sizes, grid
    and layout. Use it to draw your own figures to match.

    Returns
    -------
    contextlib.AbstractContextManager
        :func:`matplotlib.pyplot.rc_context` with :data:`STYLE`.

    Examples
    --------
    >>> from rough import plots
    >>> with plots.style():
    ...     import matplotlib.pyplot as plt
    ...     figure, axes = plt.subplots()
    >>> axes.xaxis.get_gridlines()[0].get_visible()
    True
    >>> plt.close(figure)
    """
    return _pyplot().rc_context(STYLE)


def _styled(function):
    """Build the figure of ``function`` inside :func:`style`."""

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with style():
            return function(*args, **kwargs)

    return wrapper


def save(figure, path, format=None, dpi=150):
    """Write ``figure`` to ``path`` atomically and close it.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        The figure, e.g. from :func:`surface_figure`.
    path : str or os.PathLike
        The file; ``-`` is standard output (refused when it is a terminal).
    format : str, optional
        ``png``, ``svg``, ``pdf`` (or another that matplotlib writes: ``eps``,
        ``jpg``, ...). Default: from the file's extension; PNG for ``-`` and for a
        name without one.
    dpi : float, default 150
        Resolution of PNG output (and of the images inside SVG and PDF).

    Raises
    ------
    rough.InputError
        For a format matplotlib does not write, standard output on a terminal, or a
        folder that does not exist.
    """
    import sys

    from .errors import InputError
    from .io.atomic import atomic_output

    path = os.fspath(path)
    try:
        if format is None:
            format = os.path.splitext(path)[1].lstrip(".").lower() or "png"
        if format not in figure.canvas.get_supported_filetypes():
            raise InputError(f"{path}: cannot write a figure as {format!r} (use .png, .svg or .pdf)", filename=path)
        if path == "-" and sys.stdout is not None and sys.stdout.isatty():
            raise InputError("refusing to write a plot to a terminal: give a file name or a pipe", filename="-")
        with style(), atomic_output(path) as stream:
            figure.savefig(stream, format=format, dpi=dpi, bbox_inches="tight", pad_inches=0.08)
    finally:
        _pyplot().close(figure)


# -- lengths and the surface image -----------------------------------------------------------


def length_unit(metres):
    """The unit (factor, symbol) in which a length of ``metres`` reads naturally, as
    :func:`rough.units.format_length` chooses it: ``length_unit(6.4e-3)`` →
    ``(1000.0, 'mm')``; 0 and NaN give metres.

    Examples
    --------
    >>> from rough.plots import length_unit
    >>> length_unit(6.4e-3), length_unit(5e-4), length_unit(7.7e-8)
    ((1000.0, 'mm'), (1000000.0, 'µm'), (1000000000.0, 'nm'))
    """
    magnitude = abs(float(metres))
    if magnitude == 0 or not math.isfinite(magnitude):
        return 1.0, "m"
    _, per_metre, symbol = next((u for u in _LENGTH_UNITS if magnitude >= u[0] * 0.9999995), _LENGTH_UNITS[-1])
    return per_metre, symbol


def _nice_length(longest):
    """The largest 1, 2 or 5 × 10^k not above ``longest``."""
    if longest <= 0 or not math.isfinite(longest):
        return 0.0
    power = 10.0 ** math.floor(math.log10(longest))
    return max(step * power for step in (1, 2, 5) if step * power <= longest * (1 + 1e-9))


def _runs(mask):
    """(start, stop) index pairs of the runs where ``mask`` holds."""
    edges = np.flatnonzero(np.diff(np.concatenate(([0], mask.astype(np.int8), [0]))))
    return list(zip(edges[::2], edges[1::2]))


def _block_mean(heights, most=MOST_SAMPLES):
    """``heights`` block-averaged (NaN left out) so that no side has more than
    ``most`` samples; returns the array and the block size (fy, fx)."""
    factor = max(1, math.ceil(max(heights.shape) / most))
    if factor == 1:
        return heights, (1, 1)
    ny, nx = (n // factor * factor for n in heights.shape)
    blocks = heights[:ny, :nx].reshape(ny // factor, factor, nx // factor, factor)
    valid = ~np.isnan(blocks)
    counts = valid.sum(axis=(1, 3))
    sums = np.where(valid, blocks, 0.0).sum(axis=(1, 3))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(counts > 0, sums / np.maximum(counts, 1), np.nan), (factor, factor)


def _colour_range(values):
    """Colour limits for ``values`` (finite, metres): the full range, unless spikes or
    dropouts stretch it past four times the 1-99 % range (a Gaussian's full range is
    about twice that), then that range widened by half on each side. Returns (low,
    high, extend, points outside), ``extend`` saying which ends were clipped (the
    colour bar's arrows)."""
    low, high = float(values.min()), float(values.max())
    if values.size < 100 or high == low:
        return low, high, "neither", 0
    inner_low, inner_high = (float(v) for v in np.percentile(values, [1, 99]))
    spread = inner_high - inner_low
    if high - low <= 4 * spread:
        return low, high, "neither", 0
    inner_low, inner_high = max(low, inner_low - spread / 2), min(high, inner_high + spread / 2)
    clipped = (low < inner_low, high > inner_high)
    outside = int(np.count_nonzero((values < inner_low) | (values > inner_high)))
    extend = {(True, True): "both", (True, False): "min", (False, True): "max"}[clipped]
    return inner_low, inner_high, extend, outside


def _image_box(aspect, width=8.0, height=6.0):
    """Width and height (inches) of a map of ``aspect`` (x extent / y extent) drawn as
    large as fits in ``width`` × ``height``."""
    box_width = min(width, height * aspect)
    return box_width, box_width / aspect


class _MapLayout:
    """Where a map figure's parts go, in inches, so that the figure takes the map's
    shape: the image at equal physical aspect as large as fits in ``width`` ×
    ``height``, its colour bar at the right (below a map more than 1.6 times wider
    than high), room above for a title and ``lines`` lines of facts, and ``below``
    inches under it all for another panel. (Fixed inches rather than a layout engine:
    an engine leaves a strip floating in white space.)"""

    LEFT, RIGHT_BAR, BOTTOM, GAP = 0.85, 1.35, 0.6, 0.12

    def __init__(self, aspect, width=8.0, height=6.0, lines=1, below=0.0):
        self.image = _image_box(aspect, width, height)
        w, h = self.image
        self.location = "bottom" if aspect > 1.6 else "right"
        self.top = 0.36 + 0.17 * lines  # facts (the axes title), then the title
        if self.location == "right":
            self.bottom = below + self.BOTTOM
            self.size = (self.LEFT + w + self.RIGHT_BAR, self.bottom + h + self.top)
            self.colour_bar = (self.LEFT + w + 0.15, self.bottom + 0.05 * h, 0.17, 0.9 * h)
        else:
            bar = 0.16
            self.bottom = below + 0.42 + bar + 0.55  # the bar's label, the bar, the x axis's labels
            self.size = (self.LEFT + w + 0.35, self.bottom + h + self.top)
            self.colour_bar = (self.LEFT + 0.2 * w, below + 0.42, 0.6 * w, bar)

    def figure(self, plt, least_width=0.0):
        """A figure of this layout's size (at least ``least_width`` wide, the map
        centred), with no layout engine; returns (figure, image axes, colour bar axes)."""
        width, height = max(self.size[0], least_width), self.size[1]
        self.shift = (width - self.size[0]) / 2
        figure = plt.figure(figsize=(width, height), layout="none")
        w, h = self.image
        axes = figure.add_axes(self._fraction((self.LEFT + self.shift, self.bottom, w, h), width, height))
        left, bottom, w, h = self.colour_bar
        bar = figure.add_axes(self._fraction((left + self.shift, bottom, w, h), width, height))
        return figure, axes, bar

    def title(self, figure, text):
        """The figure's title, just above the facts over the image."""
        height = figure.get_size_inches()[1]
        x = (self.LEFT + self.shift + self.image[0] / 2) / figure.get_size_inches()[0]
        figure.suptitle(text, x=x, y=(self.bottom + self.image[1] + self.top - 0.05) / height, va="top")

    @staticmethod
    def _fraction(rectangle, width, height):
        left, bottom, w, h = rectangle
        return (left / width, bottom / height, w / width, h / height)


def _facts(surface):
    """One line: kind, points, size and spacing."""
    from .units import format_length

    cross = " × ".join
    if surface.is_profile:
        return (
            f"profile, {surface.points[0]} points, {format_length(surface.size[0])} long, "
            f"spacing {format_length(surface.spacing[0])}"
        )
    spacing = surface.spacing
    steps = format_length(spacing[0]) if math.isclose(*spacing, rel_tol=1e-9) else cross(map(format_length, spacing))
    return f"map, {cross(map(str, surface.points))} points, {cross(map(format_length, surface.size))}, spacing {steps}"


def _invalid_handle(count):
    from matplotlib.patches import Patch

    return Patch(facecolor=INVALID_COLOUR, edgecolor="0.55", lw=0.6, label=f"invalid (NaN): {count:,} points")


def _draw_map(
    figure, axes, bar_axes, location, surface, hillshade=False, colormap="viridis", scale_bar=True, quantity="height"
):
    """Draw the map ``surface`` on ``axes``: heights in colour at equal physical aspect,
    y upwards (row 0 at the bottom: north up for a DEM),
    x and y in a length unit chosen from the extent, a colour bar in ``bar_axes`` (at
    the ``location`` ``"right"`` or ``"bottom"``) in a length unit chosen from the
    height range, a scale bar, and NaN points in :data:`INVALID_COLOUR` with a
    legend that counts them. Returns the colour bar."""
    import matplotlib as mpl
    from matplotlib.colors import LightSource, Normalize

    nx, ny = surface.points
    dx, dy = surface.spacing
    x0, y0 = surface.origin
    width, height = nx * dx, ny * dy
    scale, unit = length_unit(max(width, height))
    valid = surface.heights[~np.isnan(surface.heights)]
    invalid = surface.heights.size - valid.size
    low, high, extend, outside = _colour_range(valid) if valid.size else (0.0, 0.0, "neither", 0)
    if high > low:
        z_scale, z_unit = length_unit(high - low)
    else:  # flat: one unit either side of the value (the unit of the value, or of the extent)
        z_scale, z_unit = length_unit(abs(low) or max(width, height))
        low, high = low - 1 / z_scale, high + 1 / z_scale
    shown, (fy, fx) = _block_mean(surface.heights)
    colours = mpl.colormaps[colormap].with_extremes(bad=INVALID_COLOUR)
    norm = Normalize(low * z_scale, high * z_scale)
    left, bottom = x0 - dx / 2, y0 - dy / 2  # each sample at the centre of its pixel
    extent = (left * scale, (left + width) * scale, bottom * scale, (bottom + height) * scale)  # row 0 at the bottom
    if hillshade:
        nan = np.isnan(shown)
        filled = np.where(nan, np.nanmean(shown) if valid.size else 0.0, shown)
        slopes = np.gradient(filled, dy * fy, dx * fx) if min(filled.shape) > 1 else [np.zeros_like(filled)]
        slope = np.hypot(*slopes)[~nan] if len(slopes) == 2 else np.zeros(1)
        typical = float(np.median(slope)) if slope.size else 0.0  # the median: spikes do not set it
        exaggeration = 0.5 / typical if typical > 0 else 1.0  # relief legible whatever the surface's slope
        light = LightSource(azdeg=315, altdeg=45)  # it takes row 0 as the top: shade the rows top down
        rgba = light.shade(
            filled[::-1],
            colours,
            norm=Normalize(low, high),
            blend_mode="soft",
            vert_exag=exaggeration,
            dx=dx * fx,
            dy=dy * fy,
        )[::-1]
        rgba[nan] = mpl.colors.to_rgba(INVALID_COLOUR)
        axes.imshow(rgba, extent=extent, origin="lower", interpolation="auto")
        mappable = mpl.cm.ScalarMappable(norm=norm, cmap=colours)
    else:
        mappable = axes.imshow(
            np.ma.masked_invalid(shown * z_scale), cmap=colours, norm=norm, extent=extent, origin="lower"
        )
    axes.set_aspect("equal")
    axes.grid(False)
    axes.set_xlabel(f"x ({unit})")
    axes.set_ylabel(f"y ({unit})")
    aspect = width / height
    bar = figure.colorbar(
        mappable, cax=bar_axes, orientation="vertical" if location == "right" else "horizontal", extend=extend
    )
    label = f"{quantity} ({z_unit})" + (", hill-shaded" if hillshade else "")
    if outside:
        label += f"\n{outside:,} points beyond the arrows"
    bar.set_label(label)
    if scale_bar and 0.12 <= aspect <= 8:
        _scale_bar(axes, width, scale)
    if invalid:
        box = bar_axes.get_position()
        if location == "right":  # under the colour bar
            anchor, where = (box.x0, box.y0 - 0.01), "upper left"
        else:  # right of the colour bar
            anchor, where = (box.x1 + 0.02, (box.y0 + box.y1) / 2), "center left"
        figure.legend(
            handles=[_invalid_handle(invalid)], loc=where, bbox_to_anchor=anchor, borderaxespad=0.0, handlelength=1.2
        )
    return bar


def _scale_bar(axes, width, scale):
    """A bar a fifth of the map's ``width`` (metres) or less, at the lower right, in a
    unit of its own (100 m, not 0.1 km); ``scale``: the axes' units per metre."""
    from matplotlib.font_manager import FontProperties
    from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar

    length = _nice_length(width / 5)
    if not length:
        return
    per_metre, unit = length_unit(length)
    label = f"{round(length * per_metre, 9):g} {unit}"
    bar = AnchoredSizeBar(
        axes.transData,
        length * scale,
        label,
        "lower right",
        pad=0.35,
        borderpad=0.5,
        sep=3,
        color="black",
        frameon=True,
        size_vertical=0,
        fontproperties=FontProperties(size=8),
    )
    bar.patch.set(facecolor="white", alpha=0.75, edgecolor="none")
    axes.add_artist(bar)


def _draw_profile(axes, surface, colour="0.15", quantity="height"):
    """Draw the profile ``surface`` on ``axes``: height against position, lengths in
    units chosen from the extent and the height range, invalid runs as gaps shaded
    grey (isolated valid points as dots). Returns the length scale (per metre)."""
    x = surface.positions(0)
    heights = surface.heights
    nan = np.isnan(heights)
    scale, unit = length_unit(max(abs(x[0]), abs(x[-1]), surface.size[0]))
    valid = heights[~nan]
    span = float(valid.max() - valid.min()) if valid.size else 0.0
    z_scale, z_unit = length_unit(span or (float(np.abs(valid).max()) if valid.size else 0.0))
    axes.plot(x * scale, heights * z_scale, color=colour, lw=0.8)
    alone = ~nan & np.concatenate(([True], nan[:-1])) & np.concatenate((nan[1:], [True]))
    if alone.any() and nan.any():
        axes.plot(x[alone] * scale, heights[alone] * z_scale, ".", color=colour, ms=2.5)
    if nan.any():
        step = surface.spacing[0] * scale
        runs = [(x[start] * scale - step / 2, (stop - start) * step) for start, stop in _runs(nan)]
        axes.broken_barh(
            runs, (0, 1), transform=axes.get_xaxis_transform(), facecolor=INVALID_COLOUR, edgecolor="none", alpha=0.7
        )
        axes.legend(handles=[_invalid_handle(int(nan.sum()))], loc="upper right")
    axes.set_xlim(x[0] * scale, x[-1] * scale)
    axes.set_xlabel(f"x ({unit})")
    axes.set_ylabel(f"{quantity} ({z_unit})")
    return scale


@_styled
def surface_figure(surface, title=None, hillshade=False, note=None, colormap="viridis"):
    """A quick look at a surface: a map's heights in colour, or a profile's heights
    against position (what ``rough show`` draws).

    A map is drawn at equal physical aspect (a 10 mm × 0.5 mm map is a wide strip),
    in a figure whose shape follows the map's within limits, with y upwards (row 0 at
    the bottom, so a DEM is north up; Gwyddion draws row 0 at the top), x and y in a
    length unit chosen from the extent, a colour bar in a unit chosen from the height
    range (clipped, with arrows, when a few spikes would wash out the rest), a scale
    bar, and invalid (NaN) points in light grey with a legend that counts them. A
    profile is drawn as a line with its invalid runs as shaded gaps. Heights are as
    in the surface (level it first with :func:`rough.metrology.detrend`).

    Parameters
    ----------
    surface : Surface
        A profile or map.
    title : str, optional
        The figure's title, e.g. the file name; default the surface's ``title``
        metadata, else ``"surface"``.
    hillshade : bool, default False
        Maps: shade the colours by a light from the upper left (north-west, 45°
        high), with the heights exaggerated to an RMS slope of 1, so that texture
        shows as relief.
    note : str, optional
        A line added under the facts below the title (e.g. how the heights were
        processed).
    colormap : str, default "viridis"
        A matplotlib colour map for the heights (perceptual ones: viridis, cividis,
        magma, ...).

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import rough
    >>> from rough import plots
    >>> scan = rough.read(rough.sample("rock-map.x3p"))
    >>> figure = plots.surface_figure(scan, title="rock-map.x3p")
    >>> figure.get_suptitle()
    'rock-map.x3p'
    >>> figure.axes[0].get_xlabel(), figure.axes[1].get_ylabel()  # the map, its colour bar
    ('x (mm)', 'height (µm)')
    >>> plots.save(figure, "rock-map.png")
    """
    plt = _pyplot()
    title = title or surface.metadata.get("title") or "surface"
    facts = _facts(surface) + (f"\n{note}" if note else "")
    if surface.is_profile:
        figure, axes = plt.subplots(figsize=(9, 3.8))
        _draw_profile(axes, surface)
        axes.set_title(facts, fontsize=9, color="0.25")
        figure.suptitle(title)
        return figure
    layout = _MapLayout(surface.size[0] / surface.size[1], lines=1 + facts.count("\n"))
    figure, axes, bar = layout.figure(plt)
    _draw_map(figure, axes, bar, layout.location, surface, hillshade=hillshade, colormap=colormap)
    axes.set_title(facts, fontsize=9, color="0.25")
    layout.title(figure, title)
    return figure


@_styled
def features_figure(surface, features=(), density=None, material_ratio=None, title=None):
    """A profile with its detected features shaded, or a map as :func:`surface_figure`
    draws it; given ``density``, the amplitude probability density of the heights
    with the Gaussian of the same Rq; given ``material_ratio``, beside it the
    Abbott–Firestone curve with the ISO 13565-2 construction (the 40 % central
    region, the equivalent straight line, and the triangles of Rpk and Rvk).

    Parameters
    ----------
    surface : Surface
        The evaluated profile or map.
    features : sequence, optional
        Detected features (``kind``, ``start``, ``end``), profiles only.
    density : tuple of numpy.ndarray, optional
        ``(centres, density)`` from :func:`rough.metrology.amplitude_density`.
    material_ratio : rough.metrology.MaterialRatioCurve, optional
        The curve to draw, with its :meth:`~rough.metrology.MaterialRatioCurve.core`.
    title : str, optional
        The figure's title, e.g. the file name; default the surface's ``title``
        metadata, else ``"profile"`` or ``"map"``.

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _pyplot()
    title = title or surface.metadata.get("title") or surface.kind
    heights = surface.heights - np.nanmean(surface.heights)
    below = density is not None or material_ratio is not None
    density_height = 3.0 if below else 0.0
    if surface.is_profile:
        figure = plt.figure(figsize=(8, 3.6 + density_height))
        grid = figure.add_gridspec(2 if below else 1, 2)
        top = figure.add_subplot(grid[0, :])
        centred = surface.derive("centre", {}, heights=heights)
        scale = _draw_profile(top, centred, quantity="height about the mean")
        for feature in features:
            top.axvspan(
                feature.start * scale,
                feature.end * scale,
                color="tab:red" if feature.kind == "peak" else "tab:blue",
                alpha=0.2,
                lw=0,
            )
        top.set_title(f"{_facts(surface)}: {len(features)} features shaded", fontsize=9, color="0.25")
        panels = [figure.add_subplot(grid[1, 0]), figure.add_subplot(grid[1, 1])] if below else []
    else:
        layout = _MapLayout(surface.size[0] / surface.size[1], width=7.0, height=5.0, below=density_height)
        figure, top, bar = layout.figure(plt, least_width=8.0 if below else 0.0)
        centred = surface.derive("centre", {}, heights=heights)
        _draw_map(figure, top, bar, layout.location, centred, quantity="height about the mean")
        top.set_title(_facts(surface), fontsize=9, color="0.25")
        width, height = figure.get_size_inches()
        half = (width - _MapLayout.LEFT - 0.35 - 0.8) / 2
        rectangles = [(_MapLayout.LEFT + k * (half + 0.8), 0.55, half, density_height - 0.85) for k in (0, 1)]
        panels = [figure.add_axes(_MapLayout._fraction(r, width, height)) for r in rectangles] if below else []
    if material_ratio is not None:
        _draw_abbott(panels[1], material_ratio, "R" if surface.is_profile else "S")
    if panels and density is None:
        panels[0].remove()
    bottom = panels[0] if panels else None
    if density is not None:
        centres, values = density
        z_scale, z_unit = length_unit(float(centres[-1] - centres[0]) if len(centres) > 1 else 0.0)
        width = centres[1] - centres[0] if len(centres) > 1 else 1.0 / z_scale
        bottom.bar(centres * z_scale, values / z_scale, width=width * z_scale, color="0.7", label="amplitude density")
        rq = np.sqrt(np.nanmean(heights**2))
        grid = np.linspace(centres[0], centres[-1], 400)
        gaussian = np.exp(-0.5 * (grid / rq) ** 2) / (rq * np.sqrt(2 * np.pi))
        bottom.plot(
            grid * z_scale,
            gaussian / z_scale,
            color="tab:orange",
            label=f"Gaussian, same Rq ({rq * z_scale:.4g} {z_unit})",
        )
        bottom.set_xlabel(f"height about the mean ({z_unit})")
        bottom.set_ylabel(f"probability density (1/{z_unit})")
        bottom.legend()
    if surface.is_profile:
        figure.suptitle(title)
    else:
        layout.title(figure, title)
    return figure


def _draw_abbott(axes, curve, prefix):
    """The material-ratio curve (height against %) with the ISO 13565-2 construction."""
    core = curve.core()
    scale, unit = length_unit(float(curve.heights[0] - curve.heights[-1]))
    step = max(1, curve.heights.size // 4000)
    ratios, heights = curve.ratios[::step], curve.heights[::step] * scale
    axes.plot(ratios, heights, color="0.2", lw=1.2, label="material-ratio curve")
    axes.axvspan(*core.window, color="tab:green", alpha=0.12, lw=0, label="40 % central region")
    top, bottom = core.top * scale, core.bottom * scale
    axes.plot([0, 100], [top, bottom], color="tab:green", lw=1.2, label="equivalent straight line")
    for level in (top, bottom):
        axes.axhline(level, color="tab:green", lw=0.6, ls="--")
    peak, valley = core.reduced_peak * scale, core.reduced_valley * scale
    axes.fill([0, 0, core.mr1], [top, top + peak, top], color="tab:red", alpha=0.35, lw=0, label=f"{prefix}pk")
    axes.fill([100, 100, core.mr2], [bottom, bottom - valley, bottom], color="tab:blue", alpha=0.35, lw=0)
    axes.annotate(f"{prefix}vk", (100, bottom - valley), ha="right", va="top", fontsize=8, color="tab:blue")
    axes.annotate(
        f"{prefix}k = {core.height * scale:.4g} {unit}", (50, (top + bottom) / 2), ha="left", va="bottom", fontsize=8
    )
    axes.set_xlim(0, 100)
    axes.set_xlabel("material ratio (%)")
    axes.set_ylabel(f"height about the mean ({unit})")
    axes.legend(fontsize=7, loc="upper right")


@_styled
def spectrum_figure(frequencies, density, fit, spacing, title="power spectrum"):
    """The binned spectrum on log-log axes, the fit band shaded and the fitted model
    (power law plus its noise floor) drawn over that band only (profiles: the Hann
    periodogram G in m³, one-sided; maps: the ring-averaged P2 in m⁴). Without a
    power-law range only the data are drawn. ``title``: e.g. the file name."""
    plt = _pyplot()
    figure, axes = plt.subplots(figsize=(7, 5))
    axes.loglog(frequencies * 1e-3, density, "o", ms=3.5, color="0.35", label="binned periodogram")
    profile = fit.profile_dimension is None
    if fit.fit_band is not None:
        low, high = fit.fit_band
        grid = np.geomspace(low, high, 200)
        exponent = 5 - 2 * fit.fractal_dimension if profile else 8 - 2 * fit.fractal_dimension
        power = fit.psd_prefactor * grid**-exponent
        if fit.rolloff_wavelength:
            power = power * np.exp(-((grid * fit.rolloff_wavelength) ** 2))
        floor = (fit.noise_rms or 0.0) ** 2 * (2 * spacing[0] if profile else spacing[0] * spacing[1])
        key = "D" if profile else "Ds"
        label = (
            f"{key} = {fit.fractal_dimension:.4f} (bound)"
            if fit.at_bound
            else f"{key} = {fit.fractal_dimension:.4f} ± {fit.fractal_dimension_stderr:.4f}"
        )
        axes.loglog(grid * 1e-3, power + floor, color="tab:red", lw=2, label=f"model: {label}")
        if floor:
            axes.loglog(grid * 1e-3, power, ":", color="tab:red", lw=1, label="power law alone")
            axes.axhline(floor, xmin=0, xmax=1, color="tab:blue", lw=0.8, ls="--", label="noise floor")
        axes.axvspan(low * 1e-3, high * 1e-3, color="tab:red", alpha=0.06, label=f"fit band, p = {fit.p_value:.2g}")
        if fit.band and fit.band[1] < high:
            axes.axvline(fit.band[1] * 1e-3, color="tab:blue", lw=0.8, label="noise crossover")
        axes.set_title("power spectrum", fontsize=9, color="0.25")
    else:
        axes.set_title("power spectrum: no power-law range", fontsize=9, color="0.25")
    axes.set_xlabel("spatial frequency (1/mm)")
    axes.set_ylabel("PSD G(f) (m³)" if profile else "ring-averaged P2 (m⁴)")
    axes.legend()
    figure.suptitle(title)
    return figure


def _errors(values):
    """Standard errors with None (a sector at a bound) drawn as zero."""
    return np.array([0.0 if value is None else value for value in values])


@_styled
def rose_figure(rose, title="direction dependence"):
    """Polar roses of C(θ) and D(θ) with their standard errors, mirrored to 360°
    (a spectrum is symmetric, P(-f) = P(f)), the principal direction and the lay
    marked. θ is the wavevector direction, counter-clockwise from +x. ``title``:
    e.g. the file name."""
    plt = _pyplot()
    figure, axes = plt.subplots(1, 2, subplot_kw={"projection": "polar"}, figsize=(10, 5.6))
    figure.get_layout_engine().set(h_pad=0.12)  # room between the title and the panels' titles
    theta = np.radians(np.concatenate([rose.angles, np.add(rose.angles, 180.0), [rose.angles[0] + 360.0]]))
    panels = (
        (
            axes[0],
            np.array(rose.amplitude_coefficient) * 1e9,
            _errors(rose.amplitude_coefficient_stderr) * 1e9,
            f"C(θ) (nm) at η = {rose.resolution * 1e6:.4g} µm",
            "tab:red",
        ),
        (axes[1], np.array(rose.fractal_dimension), _errors(rose.fractal_dimension_stderr), "Ds(θ)", "tab:blue"),
    )
    for axis, values, errors, label, colour in panels:
        closed = np.concatenate([values, values, values[:1]])
        spread = np.concatenate([errors, errors, errors[:1]])
        axis.plot(theta, closed, color=colour, lw=2)
        axis.fill_between(theta, closed - spread, closed + spread, color=colour, alpha=0.2)
        if axis is axes[1] and np.ptp(values) > 0:
            axis.set_ylim(max(2.0, float(np.min(values)) - 0.05), min(3.0, float(np.max(values)) + 0.05))
        inner, outer = axis.get_ylim()
        lays = (rose.lay["long_wavelength"]["direction"], ":"), (rose.lay["resolution"]["direction"], "--")
        for angle, style_ in ((rose.principal_direction, "-"), *lays):
            for direction in (angle, angle + 180):
                axis.plot(np.radians([direction, direction]), [inner, outer], style_, color="0.3", lw=1)
        axis.set_title(label, pad=14)
    figure.suptitle(title)
    figure.supxlabel(
        f"principal wavevector {rose.principal_direction:.1f}° (solid); lay "
        f"{rose.lay['resolution']['direction']:.1f}° at η (dashed), "
        f"{rose.lay['long_wavelength']['direction']:.1f}° at long wavelengths (dotted); "
        f"Str {'undefined' if np.isnan(rose.Str) else format(rose.Str, '.3g')}, Std {rose.Std:.1f}°",
        fontsize=9,
        color="0.25",
    )
    return figure


@_styled
def scale_dependent_figure(table, title="roughness against scale", cutoff=None):
    """RMS height, slope and curvature against scale on log-log axes, three panels
    side by side (``table`` as :func:`rough.fractal.scales.scale_dependent` gives it;
    scales and heights in the unit that reads naturally, curvature in 1/that unit).
    A reliability cut-off (m) is drawn where the tip stops following the surface.
    ``title``: e.g. the file name.

    Examples
    --------
    >>> import numpy as np
    >>> from rough.fractal.scales import scale_dependent
    >>> from rough.plots import scale_dependent_figure
    >>> heights = np.cumsum(np.random.default_rng(0).standard_normal(1024)) * 1e-8
    >>> figure = scale_dependent_figure(scale_dependent(heights, 1e-6), "random walk")
    >>> [axes.get_ylabel() for axes in figure.axes]
    ['RMS height (nm)', 'RMS slope', 'RMS curvature (1/µm)']
    >>> import matplotlib.pyplot as plt
    >>> plt.close(figure)
    """
    plt = _pyplot()
    scale = np.asarray(table["scale"], float)
    per_scale, scale_symbol = length_unit(float(np.max(scale)) if scale.size else 0.0)
    heights = np.asarray(table["rms_height"], float)
    per_height, height_symbol = length_unit(float(np.max(heights)) if heights.size else 0.0)
    figure, axes = plt.subplots(1, 3, figsize=(12, 4.2))
    direction = table.get("direction")
    panels = (
        (heights * per_height, f"RMS height ({height_symbol})", "tab:red"),
        (np.asarray(table["rms_slope"], float), "RMS slope", "tab:green"),
        (np.asarray(table["rms_curvature"], float) / per_scale, f"RMS curvature (1/{scale_symbol})", "tab:blue"),
    )
    for axis, (values, label, colour) in zip(axes, panels):
        shown = values > 0
        axis.loglog(scale[shown] * per_scale, values[shown], "o-", ms=3.5, lw=1.2, color=colour)
        if cutoff:
            axis.axvline(cutoff / 2 * per_scale, color="0.3", lw=0.8, ls="--", label="tip reliability cut-off")
            axis.legend(fontsize=7)
        axis.set_xlabel(f"scale λ ({scale_symbol})")
        axis.set_ylabel(label)
    along = {"x": " (profiles along x)", "y": " (profiles along y)"}.get(direction, "")
    figure.suptitle(f"{title}{along}")
    return figure


@_styled
def force_figure(runs, title=None):
    """Force profiles of render runs ``[(label, Run), ...]``: for each, the surface
    height under the stylus and the hand's height (top), and F_y and F_x against the
    position along the profile (bottom), with the ticks out of contact shaded. For a
    map, the height under the point and the force along and across the motion
    against time. ``title``: e.g. the file name (default none)."""
    plt = _pyplot()
    figure, axes = plt.subplots(
        2, len(runs), figsize=(5.5 * len(runs), 6), sharex="col", squeeze=False, gridspec_kw={"height_ratios": [1, 1.4]}
    )
    for column, (label, result) in enumerate(runs):
        trace = result.trace
        top, bottom = axes[0, column], axes[1, column]
        heading = label if result.speed is None else f"{result.speed * 1e3:g} mm/s"
        out = 100 * (1 - trace["contact"].mean())
        if "y_i" in trace.dtype.names:
            x = trace["x"] * MM
            top.plot(x, trace["h"] * MM, color="0.3", lw=0.8, label="surface h")
            top.plot(x, trace["y_i"] * MM, color="tab:green", lw=0.8, label="hand y_i")
            bottom.plot(x, trace["F_y"], color="tab:blue", lw=0.7, label="F_y")
            bottom.plot(x, trace["F_x"], color="tab:orange", lw=0.7, label="F_x")
            top.set_title(f"{heading}: F_y std {trace['F_y'].std():.3f} N, out of contact {out:.1f} %", fontsize=9)
            bottom.set_xlabel("x (mm)")
        else:
            from .render import along_and_across

            x = trace["t"]
            along, across = along_and_across(trace)
            top.plot(x, trace["h"] * MM, color="0.3", lw=0.8, label="surface h under the point")
            bottom.plot(x, along, color="tab:orange", lw=0.7, label="F along the motion")
            bottom.plot(x, across, color="tab:blue", lw=0.7, label="F across the motion")
            top.set_title(f"{heading}: map, off the map {out:.1f} %", fontsize=9)
            bottom.set_xlabel("t (s)")
        for axis in (top, bottom):
            _shade(axis, x, ~trace["contact"])
        top.set_ylabel("height (mm)")
        bottom.set_ylabel("force on the hand (N)")
        top.legend(fontsize=7, loc="upper right")
        bottom.legend(fontsize=7, loc="upper right")
    if title:
        figure.suptitle(title)
    return figure


def _shade(axis, x, mask):
    """Grey spans where ``mask`` holds (ticks out of contact)."""
    for start, stop in _runs(mask):
        axis.axvspan(x[start], x[min(stop, x.size - 1)], color="0.85", lw=0)


def proportion_interval(successes, trials, level=0.95):
    """The Wilson score interval for a proportion: ``successes`` of ``trials``.

    Uses :func:`statsmodels.stats.proportion.proportion_confint` (``method="wilson"``)
    when statsmodels is installed, else the same closed form.

    Parameters
    ----------
    successes, trials : int
        Counts, ``0 <= successes <= trials``, ``trials > 0``.
    level : float, default 0.95
        The confidence level.

    Returns
    -------
    tuple of float
        ``(low, high)``, proportions in [0, 1].

    Examples
    --------
    >>> from rough.plots import proportion_interval
    >>> [round(p, 4) for p in proportion_interval(6, 8)]
    [0.4093, 0.9285]
    >>> [round(p, 4) for p in proportion_interval(0, 8)]
    [0.0, 0.3244]
    """
    try:
        from statsmodels.stats.proportion import proportion_confint
    except ImportError:
        from statistics import NormalDist

        z = NormalDist().inv_cdf(0.5 + level / 2)
        p = successes / trials
        denominator = 1 + z**2 / trials
        centre = (p + z**2 / (2 * trials)) / denominator
        half = z / denominator * math.sqrt(p * (1 - p) / trials + z**2 / (4 * trials**2))
        return max(0.0, centre - half), min(1.0, centre + half)
    low, high = proportion_confint(successes, trials, alpha=1 - level, method="wilson")
    return float(low), float(high)


@_styled
def percentage_figure(study, set_ids, title=None):
    """For each reference set, the percentage of answers that judged each test surface
    rougher than the reference, grouped by Rq and coloured by D (the paper's Figures
    4 and 5), each bar with its number of answers n and the 95 % Wilson score
    interval of the proportion as an error bar. ``title``: e.g. the study's name."""
    from .experiment.analysis import percentages

    plt = _pyplot()
    figure, axes = plt.subplots(1, len(set_ids), figsize=(5.5 * len(set_ids), 4.6), squeeze=False)
    for axis, set_id in zip(axes[0], set_ids):
        cells = percentages(study, set_id)
        entry = next(s for s in study.sets if s["id"] == set_id)
        reference = study.surfaces[entry["reference"]]
        levels_rq = sorted({round(rq, 12) for _, _, rq, _, _ in cells} | {round(reference["rq"], 12)})
        levels_d = sorted({d for _, d, _, _, _ in cells} | {reference["dimension"]})
        width = 0.8 / len(levels_d)
        colours = plt.get_cmap("viridis")(np.linspace(0.15, 0.85, len(levels_d)))
        for k, dimension in enumerate(levels_d):
            label = f"D = {dimension:g}"
            for g, rq in enumerate(levels_rq):
                cell = next(
                    (c for c in cells if math.isclose(c[1], dimension) and math.isclose(c[2], rq, rel_tol=1e-6)), None
                )
                if cell is None:
                    continue
                x = g + (k - (len(levels_d) - 1) / 2) * width
                percent, answers = cell[3], cell[4]
                if not answers:
                    axis.text(x, 1, "n = 0", ha="center", va="bottom", fontsize=6.5, color="0.4")
                    continue
                axis.bar(x, percent, width, color=colours[k], label=label)
                low, high = (100 * p for p in proportion_interval(round(percent * answers / 100), answers))
                axis.errorbar(
                    x,
                    percent,
                    yerr=[[max(0.0, percent - low)], [max(0.0, high - percent)]],
                    fmt="none",
                    ecolor="0.2",
                    elinewidth=0.8,
                    capsize=2,
                )
                axis.text(x, high + 1.5, f"{percent:.0f} %\nn = {answers}", ha="center", va="bottom", fontsize=6.5)
                label = None
        axis.axhline(50, color="0.5", lw=0.8, ls="--")
        axis.set_xticks(range(len(levels_rq)), [f"Rq {rq * 1e3:.4g} mm" for rq in levels_rq])
        axis.set_ylim(0, 128)
        axis.set_yticks(range(0, 101, 20))
        axis.grid(False, axis="x")
        axis.set_ylabel("judged rougher than the reference (%)")
        axis.set_title(
            f"set {set_id}: reference D = {reference['dimension']:g}, Rq = {reference['rq'] * 1e3:.4g} mm\n"
            "bars: 95 % Wilson interval; n: answers",
            fontsize=9,
        )
        handles, labels = axis.get_legend_handles_labels()
        unique = dict(zip(labels, handles))
        axis.legend(unique.values(), unique.keys(), loc="upper left", ncols=len(unique))
    if title:
        figure.suptitle(title)
    return figure
