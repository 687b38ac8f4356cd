"""rough resample: a new spacing, band-limited."""

import click

from .. import fractal
from .options import SPACING, Command, crop_option, surface_input, surface_output
from .work_options import jobs_option


@click.command(cls=Command, short_help="Resample to a new spacing without aliasing.")
@surface_input
@jobs_option
@crop_option
@click.option("--step", type=SPACING, required=True, help="The new spacing, e.g. 0.1545mm (or DX,DY for maps).")
@click.option("--fill", is_flag=True, help="Fill invalid points first (they are NaN again in the result).")
@surface_output
def resample(surface, input, step, fill, output):
    """Resample INPUT (default: standard input) to the spacing --step with a
    polyphase anti-aliasing filter: coarsening removes the wavelengths the new
    spacing cannot hold instead of folding them back; refining interpolates without
    adding roughness above the old Nyquist frequency. The fractal D and C in the
    remaining band are kept (fit them below ~80 % of the new Nyquist frequency).
    --spacing gives the spacing of input data that carry none, as on every command
    (until rough 0.14 it was --input-spacing here).

    \b
    Examples:
        rough resample --step 0.1545mm rock.x3p -o coarse.x3p
        rough synth --length 80mm --step 30.9um --dimension 1.3 --rq 0.3mm | rough resample --step 154.5um -o coarse.x3p
    """
    output.write(fractal.resample(surface, step[: surface.heights.ndim], fill=fill))
