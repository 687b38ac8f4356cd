"""rough map: roughness maps, areal parameters and fractal fits window by window, as a GeoTIFF."""

import functools

import click

from .. import metrology
from ..units import format_length, format_quantity
from .options import LENGTH, crop_option, report_format, side_file, split_input
from .report import Report
from .targets import SURFACE
from .work_options import jobs_option


class SizeType(click.ParamType):
    """A window or step: points (``256px``) → int, or a length with its unit (``2mm``) →
    float metres (the convention of :func:`rough.metrology.roughness_map`). A bare
    number is refused: it could be either."""

    name = "SIZE"

    def convert(self, value, param, ctx):
        if isinstance(value, int | float):
            return value
        text = str(value).strip()
        if text.endswith("px"):
            try:
                points = int(text[:-2])
            except ValueError:
                self.fail(f"{value!r}: a number of points is a whole number, e.g. 256px", param, ctx)
            if points < 1:
                self.fail(f"{value!r}: a number of points must be positive", param, ctx)
            return points
        try:
            float(text)
        except ValueError:
            return LENGTH.convert(text, param, ctx)
        self.fail(f"{value!r}: give points (256px) or a length with its unit (2mm)", param, ctx)


SIZE = SizeType()


def _one_output(command):
    """With ``-o`` there must be one input: several would overwrite the one file."""

    @functools.wraps(command)
    def wrapper(**kwargs):
        if kwargs.get("target") and len(kwargs.get("input") or ()) > 1:
            raise click.UsageError("-o writes one map: give one INPUT")
        return command(**kwargs)

    return wrapper


@click.command(short_help="Roughness maps: parameters and fractal fits per window, as a multi-band GeoTIFF.")
@_one_output
@split_input
@jobs_option
@crop_option
@click.option(
    "--window",
    type=SIZE,
    required=True,
    help="Window size: points (256px, at least 16) or a length (2mm), the same along x and y.",
)
@click.option("--step", type=SIZE, help="Distance between windows, as --window (default: the window, no overlap).")
@click.option(
    "--parameters",
    default="Sq",
    show_default=True,
    metavar="NAME,...",
    help="Comma-separated: features' areal parameters (Sa, Sq, Ssk, Sku, Sp, Sv, Sz, Sdq, Sdr, Sal, Str, Std), "
    "hurst, dimension, amplitude (the fractal fit of each window) and lay (Std).",
)
@click.option(
    "--order", type=click.IntRange(0, 10), default=1, help="Form removed from each window (default 1, a plane)."
)
@click.option(
    "-o",
    "--output",
    "target",
    type=click.Path(dir_okay=False),
    callback=side_file(SURFACE),
    metavar="FILE",
    help="Write the map: GeoTIFF (.tif, one float32 band per parameter) or, for one parameter, any "
    "format rough writes (.x3p, .npy …). Without it, print a summary.",
)
@report_format
def map_command(surface, input, window, step, parameters, order, target, work):
    """Compute areal parameters, the fractal fit (hurst, dimension, amplitude) and the
    lay in windows of the map INPUT moved by --step, each window levelled by its own
    least-squares polynomial of degree --order, and write them with -o as a
    GeoTIFF with one band per parameter: the bands are named after the parameters,
    carry their unit (band metadata UNIT), and keep the input's CRS, with each value
    at its window's centre, so the map lies over the input in QGIS. A window with
    fewer than half its points valid is NaN; the fractal fit needs a window without
    invalid points. Without -o, prints each parameter's minimum, median and maximum
    over the windows.

    A map too large for --memory is read a band of windows at a time, with the same
    results. --jobs works on several bands at once, --scheduler on a Dask cluster's
    workers (which must reach INPUT); the map is written here.

    \b
    Examples:
        rough map dem.tif --window 256px --parameters Sq,Ssk,hurst -o roughness.tif
        rough map dem.tif --window 50m --step 25m --parameters Sq,lay
        rough map scan.x3p --window 64px --parameters Sq -o sq.x3p
        rough map big.tif --window 256px --parameters Sq,hurst --jobs auto -o big_map.tif
        rough map big.tif --window 256px --scheduler tcp://head:8786 -o big_map.tif
    """
    names = [name.strip() for name in parameters.split(",") if name.strip()]
    if target:
        metrology.RoughnessMap.output_format(target, names)
    result = metrology.roughness_map(surface, window, step=step, parameters=names, order=order, **work)
    if target:
        result.write(target)
        return None
    return _report(result)


def _report(result):
    document = result.as_dict()
    grid = document["grid"]
    (nx, ny), (sx, sy) = result.window, result.step
    rows = [
        ("window", document["window"], "1", f"{nx} × {ny} points"),
        ("step", document["step"], "1", f"{sx} × {sy} points"),
        ("grid.shape", grid["shape"], "1", "{} × {} windows".format(*grid["shape"])),
        ("grid.spacing", grid["spacing"], "m", " × ".join(format_length(value) for value in grid["spacing"])),
        (
            "grid.origin",
            grid["origin"],
            "m",
            ", ".join(format_length(value, scale=step) for value, step in zip(grid["origin"], grid["spacing"])),
        ),
    ]
    for name, summary in document["parameters"].items():
        unit = summary["unit"]
        for statistic in ("min", "median", "max"):
            value = summary[statistic]
            rows.append((f"parameters.{name}.{statistic}", value, unit, format_quantity(value, unit)))
        undefined = summary["undefined"]
        if undefined:
            why = "; ".join(f"{count}: {reason}" for reason, count in summary["reasons"].items())
            rows.append((f"parameters.{name}.undefined", undefined, "1", f"{undefined} windows NaN ({why})"))
    if "tiled" in document:
        tiled = document["tiled"]
        bands = "1 band" if tiled["tiles"] == 1 else f"{tiled['tiles']} bands"
        text = f"read in {bands} of up to {tiled['tile_rows']} rows; every window computed whole (exact)"
        rows.append(("tiled.tiles", tiled["tiles"], "1", text))
    return Report(rows, document)
