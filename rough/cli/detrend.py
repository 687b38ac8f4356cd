"""rough detrend: polynomial form removal, the ISO Gaussian roughness/waviness split,
and what a round tip traces (the ISO 16610-41 closing envelope)."""

import click

from .. import metrology
from .options import LENGTH, TIP, RegistryChoice, crop_option, surface_input, surface_output
from .work_options import jobs_option


@click.command(short_help="Remove polynomial form; split roughness and waviness (ISO 16610); trace with a round tip.")
@surface_input
@jobs_option
@crop_option
@click.option(
    "--order",
    type=click.IntRange(0, 20),
    help="Degree of the least-squares polynomial removed (maps: total degree in x and y); "
    "default 2, or none with --tip/--envelope.",
)
@click.option("--cutoff", type=LENGTH, help="Gaussian filter cut-off λc (ISO 16610-21; 16610-61 for maps), e.g. 0.8mm.")
@click.option(
    "--keep",
    type=RegistryChoice(lambda: metrology.KEEP),
    default="roughness",
    show_default=True,
    help="What to output: the roughness (form removed, filtered with --cutoff), the waviness (the "
    "Gaussian mean line) or the fitted form.",
)
@click.option(
    "--ends",
    type=RegistryChoice(lambda: metrology.ENDS),
    default="trim",
    show_default=True,
    help="Filter end effects: trim λc/2 at each end, or keep the full length with the renormalised "
    "kernel (ISO 16610-28).",
)
@click.option(
    "--tip",
    type=TIP,
    help="Output the path of a round tip's apex drawn over the surface (disk for profiles, ball for maps): "
    "a radius, or needle (0.05 mm), fingernail (0.5 mm), fingertip (8 mm).",
)
@click.option(
    "--envelope",
    type=TIP,
    help="Output the ISO 16610-41 closing envelope with a disk or ball of this radius (or a preset).",
)
@surface_output
def detrend(surface, input, order, cutoff, keep, ends, tip, envelope, output):
    """Remove the least-squares polynomial form of degree --order (default 2, as the
    source slides do) from INPUT, fitted on the valid points only, and with --cutoff
    split the rest into roughness and waviness with the ISO Gaussian filter. With --tip,
    output instead what a round tip of that radius traces (the path of its apex, as a
    stylus profilometer records it and a hand holding the probe feels it); with
    --envelope, the closing envelope (the best estimate of the material surface from a
    traced one). These remove no polynomial unless --order is given too. Lengths name
    their unit. NaN points stay NaN and never touch the tip.

    \b
    Examples:
        rough detrend scan.x3p -o levelled.x3p
        rough detrend --order 1 --crop 468um:733um dektak.csv | rough features
        rough detrend --cutoff 0.8mm --keep waviness scan.x3p -o waviness.x3p
        rough detrend --tip fingernail rock.x3p | rough features
        rough detrend --envelope 2um stylus-scan.x3p -o material.x3p
    """
    if tip is not None and envelope is not None:
        raise click.UsageError("give --tip or --envelope, not both")
    probe = tip if tip is not None else envelope
    if probe is None:
        output.write(
            metrology.detrend(surface, order=2 if order is None else order, cutoff=cutoff, keep=keep, ends=ends)
        )
        return
    if keep == "form":
        raise click.UsageError("--keep form needs a polynomial, not --tip/--envelope")
    if keep == "waviness" and cutoff is None:
        raise click.UsageError("the waviness needs a cut-off (--cutoff)")
    if order is not None:
        surface = metrology.detrend(surface, order=order)
    surface = metrology.traced(surface, probe) if tip is not None else metrology.closing_envelope(surface, probe)
    if cutoff is not None:
        surface = metrology.split(surface, cutoff, keep, ends)
    output.write(surface)
