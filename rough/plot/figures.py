"""One-call figures for a notebook: :func:`surface`, :func:`spectrum`, :func:`rose` and
:func:`abbott` each take what the library returns (a surface, a fractal fit, a rose)
and give back a matplotlib Figure drawn by the same code as the commands' ``--plot``.
"""

import numpy as np

from .. import fractal, metrology
from .common import pyplot, styled
from .features import draw_abbott
from .roses import rose_figure
from .spectra import scale_dependent_figure, spectrum_figure
from .surfaces import surface_figure

_FORMS = {0: "mean removed", 1: "least-squares {} removed"}


def surface(surface, title=None, order=None, hillshade=False, colormap="viridis"):
    """A profile or map as ``rough show`` draws it.

    Parameters
    ----------
    surface : Surface
        A profile or map; invalid (NaN) points are drawn in light grey (maps) or as
        shaded gaps (profiles) and counted.
    title : str, optional
        The figure's title; default the surface's ``title`` metadata, else
        ``"surface"``.
    order : int, optional
        Remove the least-squares polynomial form of this order first (as ``rough show
        --order``; fitted on the valid points), and say so under the title.
    hillshade : bool, default False
        Maps: shade the colours by a light from the north-west (``--hillshade``).
    colormap : str, default "viridis"
        A matplotlib colour map for the heights.

    Returns
    -------
    matplotlib.figure.Figure
        The heights, with a colour bar and scale bar for a map.

    Examples
    --------
    >>> from rough import plot, read, sample
    >>> figure = plot.surface(read(sample("rock-map.x3p")), order=1)
    >>> figure.axes[0].get_xlabel()
    'x (mm)'
    >>> plot.save(figure, "rock-map.png")
    """
    note = None
    if order is not None:
        surface = metrology.detrend(surface, order=order)
        note = _FORMS.get(order, f"least-squares polynomial of degree {order} removed").format(
            "line" if surface.is_profile else "plane"
        )
    return surface_figure(surface, title=title, hillshade=hillshade, note=note, colormap=colormap)


def spectrum(fit, surface, order=1, title=None):
    """The spectrum of ``surface`` with the power law of ``fit`` over its band.

    The log-binned spectrum (profiles: the Hann periodogram G, m³; maps: the
    ring-averaged P2, m⁴) on log-log axes, the fit band shaded, the fitted model
    (power law plus noise floor) over that band, and the noise crossover; as ``rough
    fit-fractal --plot`` draws it. A fit with no power-law range has no spectrum to
    draw: then the RMS height, slope and curvature against scale that describe the
    surface instead are drawn.

    Parameters
    ----------
    fit : FractalFit
        From :func:`rough.fit_fractal` on ``surface``.
    surface : Surface
        The profile or map that was fitted, gap-free (as given to
        :func:`rough.fit_fractal`, after its ``fill``: use
        :func:`rough.fractal.fill_invalid`).
    order : int, default 1
        The polynomial form removed before the transform: the ``order`` given to the fit.
    title : str, optional
        The figure's title; default the surface's ``title`` metadata, else
        ``"power spectrum"``.

    Returns
    -------
    matplotlib.figure.Figure
        One log-log panel, frequencies per length in the prefix that fits (/mm, /km); or three panels
        against scale.

    Examples
    --------
    >>> import rough
    >>> profile = rough.read(rough.sample("rock-profile.tsv"))
    >>> figure = rough.plot.spectrum(rough.fit_fractal(profile), profile)
    >>> figure.axes[0].get_xscale(), figure.axes[0].get_yscale()
    ('log', 'log')
    >>> rough.plot.save(figure, "rock-profile-spectrum.svg")
    """
    if fit.scale_dependent:
        title = title or surface.metadata.get("title") or "roughness against scale"
        return scale_dependent_figure(fit.scale_dependent, f"{title}: no power-law band", fit.reliability_cutoff)
    binned = fractal.binned_spectrum(surface, order)
    title = title or surface.metadata.get("title") or "power spectrum"
    return spectrum_figure(binned["frequency"], binned["density"], fit, surface.spacing, title)


def rose(rose, title=None):
    """Polar roses of C(θ) and Ds(θ) of a map, as ``rough rose --plot`` draws them:
    each with its standard error as a band, mirrored to 360°, the principal direction
    and the lay marked (θ is the wavevector direction, counter-clockwise from +x).

    Parameters
    ----------
    rose : Rose
        From :func:`rough.rose`; a sector whose fit sits at a bound has no standard
        error and is drawn without a band.
    title : str, optional
        The figure's title; default ``"direction dependence"``.

    Returns
    -------
    matplotlib.figure.Figure
        Two polar panels: C(θ) in the length unit that fits (nm, µm), Ds(θ).

    Examples
    --------
    >>> import rough
    >>> result = rough.rose(rough.read(rough.sample("rock-map.x3p")), step=30, fill=True)
    >>> figure = rough.plot.rose(result, title="rock-map.x3p")
    >>> len(figure.axes)
    2
    >>> rough.plot.save(figure, "rock-map-rose.png")
    """
    return rose_figure(rose, title or "direction dependence")


@styled
def abbott(surface, title=None):
    """The Abbott–Firestone (material-ratio) curve of a profile or map with the ISO
    13565-2 construction: the 40 % central region, the equivalent straight line and
    the core height Rk (Sk), and the triangles of Rpk and Rvk (Spk and Svk).

    Parameters
    ----------
    surface : Surface
        A profile or map, evaluated as given (heights about the mean of its valid
        points; remove form or filter first). NaN points are left out of the curve.
    title : str, optional
        The figure's title; default the surface's ``title`` metadata, else
        ``"material ratio"``.

    Returns
    -------
    matplotlib.figure.Figure
        One panel: height about the mean against material ratio (%).

    Examples
    --------
    >>> from rough import plot, read, sample
    >>> figure = plot.abbott(read(sample("rock-profile.tsv")))
    >>> figure.axes[0].get_xlabel()
    'material ratio (%)'
    >>> plot.save(figure, "rock-profile-abbott.pdf")
    """
    plt = pyplot()
    curve = metrology.MaterialRatioCurve(surface)
    figure, axes = plt.subplots(figsize=(6, 4.5))
    draw_abbott(axes, curve, "R" if surface.is_profile else "S")
    valid = int(np.count_nonzero(surface.valid))
    axes.set_title(f"{valid} of {surface.heights.size} points valid", fontsize=9, color="0.25")
    figure.suptitle(title or surface.metadata.get("title") or "material ratio")
    return figure
