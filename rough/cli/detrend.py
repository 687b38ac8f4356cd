"""rough detrend: polynomial form removal and the ISO Gaussian roughness/waviness split."""

import click

from .options import LENGTH, crop_option, surface_input, surface_output


@click.command(short_help="Remove polynomial form; split roughness and waviness (ISO 16610).")
@surface_input
@crop_option
@click.option("--order", type=click.IntRange(0, 20), default=2, show_default=True,
              help="Degree of the least-squares polynomial removed (maps: total degree in x and y).")
@click.option("--cutoff", type=LENGTH, help="Gaussian filter cut-off λc (ISO 16610-21; 16610-61 for maps), e.g. 0.8mm.")
@click.option("--keep", type=click.Choice(["roughness", "waviness", "form"]), default="roughness", show_default=True,
              help="What to output: the roughness (form removed, filtered with --cutoff), the waviness (the Gaussian mean line) or the fitted form.")
@click.option("--ends", type=click.Choice(["trim", "correct"]), default="trim", show_default=True,
              help="Filter end effects: trim λc/2 at each end, or keep the full length with the renormalised kernel (ISO 16610-28).")
@surface_output
def detrend(surface, input, order, cutoff, keep, ends, output):
    """Remove the least-squares polynomial form of degree --order (default 2, as the
    source slides do) from INPUT, fitted on the valid points only, and with --cutoff
    split the rest into roughness and waviness with the ISO Gaussian filter.
    Lengths take a unit; a bare number is in mm. NaN points stay NaN.

    \b
    Examples:
        rough detrend scan.x3p -o levelled.x3p
        rough detrend --order 1 --crop 468um:733um dektak.csv | rough features
        rough detrend --cutoff 0.8mm --keep waviness scan.x3p -o waviness.x3p
    """
    from ..metrology import detrend as remove

    output.write(remove(surface, order=order, cutoff=cutoff, keep=keep, ends=ends))
