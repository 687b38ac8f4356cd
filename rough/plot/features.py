"""The features figure (``rough features --plot``): the surface with its detected
features, the amplitude density of its heights, and the material-ratio curve with the
ISO 13565-2 construction.
"""

import numpy as np

from .common import length_unit, pyplot, styled
from .surfaces import MapLayout, draw_map, draw_profile, facts_line


@styled
def features_figure(surface, features=(), density=None, material_ratio=None, title=None):
    """A profile with its detected features shaded, or a map as :func:`~rough.plot.surface_figure`
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
    plt = pyplot()
    title = title or surface.metadata.get("title") or surface.kind
    heights = surface.heights - np.nanmean(surface.heights)
    below = density is not None or material_ratio is not None
    density_height = 3.0 if below else 0.0
    if surface.is_profile:
        figure = plt.figure(figsize=(8, 3.6 + density_height))
        grid = figure.add_gridspec(2 if below else 1, 2)
        top = figure.add_subplot(grid[0, :])
        centred = surface.derive("centre", {}, heights=heights)
        scale = draw_profile(top, centred, quantity="height about the mean")
        for feature in features:
            top.axvspan(
                feature.start * scale,
                feature.end * scale,
                color="tab:red" if feature.kind == "peak" else "tab:blue",
                alpha=0.2,
                lw=0,
            )
        top.set_title(f"{facts_line(surface)}: {len(features)} features shaded", fontsize=9, color="0.25")
        panels = [figure.add_subplot(grid[1, 0]), figure.add_subplot(grid[1, 1])] if below else []
    else:
        layout = MapLayout(surface.size[0] / surface.size[1], width=7.0, height=5.0, below=density_height)
        figure, top, bar = layout.figure(plt, least_width=8.0 if below else 0.0)
        centred = surface.derive("centre", {}, heights=heights)
        draw_map(figure, top, bar, layout.location, centred, quantity="height about the mean")
        top.set_title(facts_line(surface), fontsize=9, color="0.25")
        width, height = figure.get_size_inches()
        half = (width - MapLayout.LEFT - 0.35 - 0.8) / 2
        rectangles = [(MapLayout.LEFT + k * (half + 0.8), 0.55, half, density_height - 0.85) for k in (0, 1)]
        panels = [figure.add_axes(MapLayout._fraction(r, width, height)) for r in rectangles] if below else []
    if material_ratio is not None:
        draw_abbott(panels[1], material_ratio, "R" if surface.is_profile else "S")
    if panels and density is None:
        panels[0].remove()
    bottom = panels[0] if panels else None
    if density is not None:
        centres, values, outside = shown_density(heights, density)
        z_scale, z_unit = length_unit(float(centres[-1] - centres[0]) if len(centres) > 1 else 0.0)
        width = centres[1] - centres[0] if len(centres) > 1 else 1.0 / z_scale
        label = "amplitude density" + (f" ({_tails(outside)} the range shown)" if any(outside) else "")
        bottom.bar(centres * z_scale, values / z_scale, width=width * z_scale, color="0.7", label=label)
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


#: The quantiles (%) between which the amplitude density is drawn when outliers
#: would squash it: a few deep pits or spikes beyond them are counted, not drawn.
DENSITY_QUANTILES = (0.1, 99.9)


def shown_density(heights, density):
    """The amplitude density as drawn: ``density`` (``(centres, values)``) as it is,
    unless heights beyond :data:`DENSITY_QUANTILES` stretch its range past that range
    widened by half on each side (a Gaussian's range stays within it up to 10⁸
    points); then the valid ``heights`` re-binned into as many bins over the
    quantile range (normalised by all valid points, so that the bars still compare
    with the Gaussian). Returns ``(centres, values, (below, above))``, the counts of
    the valid points left out at each end."""
    centres, values = (np.asarray(a, dtype=float) for a in density)
    valid = heights[~np.isnan(heights)]
    if valid.size < 2 or len(centres) < 2:
        return centres, values, (0, 0)
    low, high = np.percentile(valid, DENSITY_QUANTILES)
    margin = (high - low) / 2
    low, high = max(low - margin, valid.min()), min(high + margin, valid.max())
    if valid.min() >= low and valid.max() <= high:
        return centres, values, (0, 0)
    counts, edges = np.histogram(valid, bins=len(centres), range=(low, high))
    shown = counts / (valid.size * np.diff(edges))
    return (edges[:-1] + edges[1:]) / 2, shown, (int(np.sum(valid < low)), int(np.sum(valid > high)))


def _tails(outside):
    """``(below, above)`` counts as words: "3 points below and 1 point above"."""
    ends = zip(outside, ("below", "above"))
    return " and ".join(f"{count} point{'s' if count != 1 else ''} {side}" for count, side in ends if count)


def draw_abbott(axes, curve, prefix):
    """Draw the material-ratio curve ``curve`` (a
    :class:`~rough.metrology.MaterialRatioCurve`: height about the mean against
    material ratio, %) on ``axes`` with the ISO 13565-2 construction: the 40 %
    central region, the equivalent straight line, the core height ``prefix`` + k and
    the triangles of ``prefix`` + pk and + vk (``prefix``: ``"R"`` or ``"S"``)."""
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
