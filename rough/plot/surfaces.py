"""The quick look at a surface (what ``rough show`` draws), and the map and profile
panels that other figures share.

Maps are drawn by one piece of code everywhere (:func:`surface_figure`, and the map
panel of :func:`~rough.plot.features.features_figure`): heights in a perceptual
colour map with a colour bar in a length unit chosen from the height range, axes in a
length unit chosen from the extent, y upwards (row 0 at the bottom, so a georeferenced
DEM is north up and angles counter-clockwise from +x, as ``rose`` and Std give them,
are counter-clockwise on the page), equal physical aspect (the figure's shape follows
the map's, within limits), a scale bar, and invalid (NaN) points in light grey,
counted in a legend.
"""

import math

import numpy as np

from ..units import format_length
from .common import length_unit, nice_length, pyplot, runs_of, styled

#: The colour of invalid (NaN) points: light grey, in no perceptual colour map.
INVALID_COLOUR = "#d4d4d4"
#: Longest side, in samples, of a map as drawn: larger maps are block-averaged first
#: (a figure has fewer pixels than this at any usual dpi).
MOST_SAMPLES = 3000


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


class MapLayout:
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


def facts_line(surface):
    """One line: kind, points, size and spacing."""
    cross = " × ".join
    if surface.is_profile:
        return (
            f"profile, {surface.points[0]} points, {format_length(surface.size[0])} long, "
            f"spacing {format_length(surface.spacing[0])}"
        )
    spacing = surface.spacing
    steps = format_length(spacing[0]) if math.isclose(*spacing, rel_tol=1e-9) else cross(map(format_length, spacing))
    return f"map, {cross(map(str, surface.points))} points, {cross(map(format_length, surface.size))}, spacing {steps}"


def invalid_handle(count):
    from matplotlib.patches import Patch  # optional: plot

    return Patch(facecolor=INVALID_COLOUR, edgecolor="0.55", lw=0.6, label=f"invalid (NaN): {count:,} points")


def draw_map(
    figure, axes, bar_axes, location, surface, hillshade=False, colormap="viridis", scale_bar=True, quantity="height"
):
    """Draw the map ``surface`` on ``axes``: heights in colour at equal physical aspect,
    y upwards (row 0 at the bottom: north up for a DEM),
    x and y in a length unit chosen from the extent, a colour bar in ``bar_axes`` (at
    the ``location`` ``"right"`` or ``"bottom"``) in a length unit chosen from the
    height range, a scale bar, and NaN points in :data:`INVALID_COLOUR` with a
    legend that counts them. Returns the colour bar."""
    import matplotlib as mpl  # optional: plot
    from matplotlib.colors import LightSource, Normalize  # optional: plot

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
            handles=[invalid_handle(invalid)], loc=where, bbox_to_anchor=anchor, borderaxespad=0.0, handlelength=1.2
        )
    return bar


def _scale_bar(axes, width, scale):
    """A bar a fifth of the map's ``width`` (metres) or less, at the lower right, in a
    unit of its own (100 m, not 0.1 km); ``scale``: the axes' units per metre."""
    from matplotlib.font_manager import FontProperties  # optional: plot
    from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar  # optional: plot

    length = nice_length(width / 5)
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


def draw_profile(axes, surface, colour="0.15", quantity="height"):
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
        runs = [(x[start] * scale - step / 2, (stop - start) * step) for start, stop in runs_of(nan)]
        axes.broken_barh(
            runs, (0, 1), transform=axes.get_xaxis_transform(), facecolor=INVALID_COLOUR, edgecolor="none", alpha=0.7
        )
        axes.legend(handles=[invalid_handle(int(nan.sum()))], loc="upper right")
    axes.set_xlim(x[0] * scale, x[-1] * scale)
    axes.set_xlabel(f"x ({unit})")
    axes.set_ylabel(f"{quantity} ({z_unit})")
    return scale


@styled
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
    >>> from rough import plot
    >>> scan = rough.read(rough.sample("rock-map.x3p"))
    >>> figure = plot.surface_figure(scan, title="rock-map.x3p")
    >>> figure.get_suptitle()
    'rock-map.x3p'
    >>> figure.axes[0].get_xlabel(), figure.axes[1].get_ylabel()  # the map, its colour bar
    ('x (mm)', 'height (µm)')
    >>> plot.save(figure, "rock-map.png")
    """
    plt = pyplot()
    title = title or surface.metadata.get("title") or "surface"
    facts = facts_line(surface) + (f"\n{note}" if note else "")
    if surface.is_profile:
        figure, axes = plt.subplots(figsize=(9, 3.8))
        draw_profile(axes, surface)
        axes.set_title(facts, fontsize=9, color="0.25")
        figure.suptitle(title)
        return figure
    layout = MapLayout(surface.size[0] / surface.size[1], lines=1 + facts.count("\n"))
    figure, axes, bar = layout.figure(plt)
    draw_map(figure, axes, bar, layout.location, surface, hillshade=hillshade, colormap=colormap)
    axes.set_title(facts, fontsize=9, color="0.25")
    layout.title(figure, title)
    return figure
