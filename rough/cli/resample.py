"""rough resample: a new spacing, band-limited."""

import click

from .options import SPACING, input_options, surface_output


@click.command(short_help="Resample to a new spacing without aliasing.")
@input_options("--input-spacing")
@click.option(
    "--spacing", "new_spacing", type=SPACING, required=True, help="The new spacing, e.g. 0.1545mm (or DX,DY for maps)."
)
@click.option("--fill", is_flag=True, help="Fill invalid points first (they are NaN again in the result).")
@surface_output
def resample(surface, input, new_spacing, fill, output):
    """Resample INPUT (default: standard input) to the spacing --spacing with a
    polyphase anti-aliasing filter: coarsening removes the wavelengths the new
    spacing cannot hold instead of folding them back; refining interpolates without
    adding roughness above the old Nyquist frequency. The fractal D and C in the
    remaining band are kept (fit them below ~80 % of the new Nyquist frequency).

    \b
    Examples:
        rough resample --spacing 0.1545mm rock.x3p -o coarse.x3p
        rough synth --length 80mm --spacing 0.0309mm --dimension 1.3 --rq 0.3mm | rough resample --spacing 0.1545mm
    """
    from ..fractal.resample import resample as change

    output.write(change(surface, new_spacing[: surface.heights.ndim], fill=fill))
