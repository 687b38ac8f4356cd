"""rough resample: a new spacing, band-limited."""

import click

from .. import fractal
from .options import SPACING, input_options, jobs_option, renamed, surface_output


@click.command(short_help="Resample to a new spacing without aliasing.")
@renamed("--spacing", "--step", "step", SPACING, required=True)  # outside input_options: checked before reading
@input_options("--input-spacing")
@jobs_option
@click.option("--step", type=SPACING, help="The new spacing (required), e.g. 0.1545mm (or DX,DY for maps).")
@click.option("--fill", is_flag=True, help="Fill invalid points first (they are NaN again in the result).")
@surface_output
def resample(surface, input, step, fill, output):
    """Resample INPUT (default: standard input) to the spacing --step with a
    polyphase anti-aliasing filter: coarsening removes the wavelengths the new
    spacing cannot hold instead of folding them back; refining interpolates without
    adding roughness above the old Nyquist frequency. The fractal D and C in the
    remaining band are kept (fit them below ~80 % of the new Nyquist frequency).
    --input-spacing gives the spacing of input data that carry none.

    \b
    Examples:
        rough resample --step 0.1545mm rock.x3p -o coarse.x3p
        rough synth --length 80mm --step 0.0309mm --dimension 1.3 --rq 0.3mm | rough resample --step 0.1545mm
    """
    output.write(fractal.resample(surface, step[: surface.heights.ndim], fill=fill))
