"""rough show: a quick look at a profile or map, as a PNG, SVG or PDF figure."""

import os

import click

from .. import extras, metrology
from .. import plot as figures
from .options import FIGURE, Command, check_target, crop_option, surface_input
from .report import shown
from .work_options import jobs_option

FORMATS = ("png", "svg", "pdf")


def _needs_matplotlib(ctx, param, value):
    """Check, before any work, that matplotlib is installed, that the output can be
    written (:func:`~rough.cli.options.check_target`) and that its format is known
    (from ``--format`` or the file's extension)."""
    extras.require("matplotlib")
    given = {**ctx.params, param.name: value}
    if "plot" in given and "figure_format" in given:
        check_target(given["plot"], "--plot", FIGURE if given["plot"] == "-" else None)  # the suffix: _format
        _format(given["plot"], given["figure_format"])
    return value


def _format(output, format):
    """The output's format: ``--format``, else the extension, else PNG."""
    if format:
        return format
    extension = os.path.splitext(output)[1].lstrip(".").lower()
    if output == "-" or not extension:
        return "png"
    if extension not in FORMATS:
        raise click.BadParameter(
            f"{output!r}: cannot tell the format from .{extension}; name a .png, .svg or .pdf file or give --format",
            param_hint="'--plot'",
        )
    return extension


@click.command(
    cls=Command, short_help="Draw a profile or map: height colour map (or hill shade) with units, scale bar and NaN."
)
@surface_input
@jobs_option
@crop_option
@click.option(
    "--plot",  # a side file (rough.cli.batch.SIDE_FILES): {stem} in its name names one per input
    default="-",
    metavar="FILE",
    show_default=True,
    callback=_needs_matplotlib,
    help="Figure file (.png, .svg or .pdf), written atomically; - is standard output (PNG unless --format). "
    "With several inputs, put {stem} (the input's name without extension) in it.",
)
@click.option(
    "-f",
    "--format",
    "figure_format",
    type=click.Choice(FORMATS),
    callback=_needs_matplotlib,
    help="Figure format (default: from the output file's extension; PNG on standard output).",
)
@click.option("--title", help="Title of the figure (default: the input's file name).")
@click.option(
    "--hillshade",
    is_flag=True,
    help="Maps: shade the colours by a light from the upper left, so texture shows as relief.",
)
@click.option(
    "--order",
    type=click.IntRange(0, 10),
    help="Remove the least-squares polynomial form of this degree first (0: the mean, 1: a plane); "
    "default: heights as in the file.",
)
@click.option(
    "--colormap",
    type=click.Choice(["viridis", "cividis", "magma", "inferno", "plasma", "gray"]),
    default="viridis",
    show_default=True,
    help="Colour map of the heights (cividis reads the same to colour-blind eyes).",
)
@click.option("--dpi", type=click.IntRange(30, 1200), default=150, show_default=True, help="Resolution of PNG output.")
def show(surface, input, plot, figure_format, title, hillshade, order, colormap, dpi):
    """Draw the profile or map in INPUT (default: standard input), for a quick look.

    A map is drawn as a height colour map at equal physical aspect (a 10 mm × 0.5 mm
    scan is a wide strip, and the figure takes its shape), y upwards (row 0 at the
    bottom: a DEM is north up, and directions read as rose and Std give them), with
    x and y in a length unit chosen from the extent, a colour bar in a unit chosen
    from the height range (clipped, with arrows, when a few spikes would wash out the
    rest), a scale bar, and invalid (NaN) points in light grey, counted in a legend.
    A profile is drawn as height against position, with its invalid runs as shaded
    gaps. The title is the input's file name; the line under it gives the points,
    size and spacing.
    Heights are as in the file unless --order removes a polynomial form.

    \b
    Examples:
        rough show scan.x3p --plot scan.png
        rough show --hillshade --order 1 --plot scan.pdf scan.x3p
        rough synth --size 512x64 --step 10um --dimension 2.3 --rq 1um | rough show --plot strip.svg
        rough show scan.x3p | display
        rough show a.x3p b.x3p --plot {stem}.png
    """
    format = _format(plot, figure_format)
    note = None
    if order is not None:
        surface = metrology.detrend(surface, order=order)
        note = {0: "mean removed", 1: "least-squares plane removed"}.get(
            order, f"least-squares polynomial of degree {order} removed"
        )
    figure = figures.surface_figure(
        surface, title=title or shown(input), hillshade=hillshade, note=note, colormap=colormap
    )
    figures.save(figure, plot, format=format, dpi=dpi)
