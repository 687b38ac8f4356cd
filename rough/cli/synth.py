"""rough synth: fractal profiles and maps with chosen D and C or Rq."""

import math

import click

from .. import errors, fractal, units
from .options import LENGTH, Command, FloatRange, surface_output


class SizeType(click.ParamType):
    """``NXxNY`` points → (nx, ny)."""

    name = "NXxNY"

    def convert(self, value, param, ctx):
        if isinstance(value, tuple):
            return value
        parts = str(value).lower().replace("×", "x").split("x")
        if len(parts) != 2 or not all(part.strip().isdigit() and int(part) >= 2 for part in parts):
            self.fail(f"{value!r}: give the map size in points as NXxNY, e.g. 1024x512", param, ctx)
        return int(parts[0]), int(parts[1])


class AnisotropyType(click.ParamType):
    """``DS1,C1,DS2,C2,ANGLE`` → (Ds1, C1 m, Ds2, C2 m, angle in radians)."""

    name = "DS1,C1,DS2,C2,ANGLE"

    def convert(self, value, param, ctx):
        if isinstance(value, tuple):
            return value
        parts = str(value).split(",")
        if len(parts) != 5:
            self.fail(f"{value!r}: give Ds1,C1,Ds2,C2,ANGLE, e.g. 2.2,1um,2.4,3um,30", param, ctx)
        ds1, ds2 = (SURFACE_DIMENSION.convert(part, param, ctx) for part in parts[0:3:2])
        angle = math.radians(ANGLE.convert(parts[4], param, ctx))
        return ds1, LENGTH.convert(parts[1], param, ctx), ds2, LENGTH.convert(parts[3], param, ctx), angle


SURFACE_DIMENSION = FloatRange(2, 3, min_open=True, max_open=True)
ANGLE = FloatRange(-360, 360)


@click.command(cls=Command, short_help="Synthesise a fractal profile or map with chosen D and C or Rq.")
@click.option("--length", type=LENGTH, help="Profile length, e.g. 80mm (a profile; or give --points).")
@click.option("--points", type=click.IntRange(2, None), help="Profile length in points.")
@click.option("--size", type=SizeType(), help="Map size in points, NXxNY (a map).")
@click.option(
    "--step",
    type=LENGTH,
    default="0.0309mm",
    show_default=True,
    help="Sampling interval of the surface made (the default is the paper's encoder resolution).",
)
@click.option(
    "--dimension",
    type=FloatRange(1, 3, min_open=True, max_open=True),
    help="Fractal dimension: D in (1, 2) for a profile, the surface dimension Ds in (2, 3) for a map.",
)
@click.option(
    "--amplitude",
    type=LENGTH,
    help="Amplitude coefficient C at --resolution: G(f) = C η^(2D-3) f^-(5-2D) (maps: C of their profiles).",
)
@click.option("--resolution", type=LENGTH, help="The resolution η that C refers to (default: the step).")
@click.option(
    "--rq",
    type=LENGTH,
    help="RMS height instead of C: the realisation is scaled so its Rq (Sq), mean removed, is exactly this.",
)
@click.option(
    "--seed",
    type=click.IntRange(0, 2**63 - 1),
    help="Random seed; the same seed gives bit-identical output (recorded in the history either way).",
)
@click.option(
    "--anisotropy",
    type=AnisotropyType(),
    help="Map: Ds and C along the wavevector direction ANGLE (degrees from +x) and at right angles, e.g. "
    "2.2,1um,2.4,3um,30.",
)
@click.option(
    "--rolloff-wavelength",
    type=LENGTH,
    help="Wavelength beyond which the spectrum is flat: self-affine only below it (rock is, over finite scales).",
)
@click.option(
    "--fragments",
    type=click.IntRange(4, None),
    is_flag=False,
    flag_value=128,
    help="The paper's method, for comparison: fragments of this many points (default 128), each started "
    "where the last ended.",
)
@click.option("--as-printed", is_flag=True, help="With --fragments: also apply the paper's printed (k+1) index shift.")
@surface_output
def synth(
    length,
    points,
    size,
    step,
    dimension,
    amplitude,
    resolution,
    rq,
    seed,
    anisotropy,
    rolloff_wavelength,
    fragments,
    as_printed,
    output,
):
    """Synthesise a fractal profile (--length or --points) or map (--size) whose
    power spectrum is G(f) = C η^(2D-3) f^-(5-2D), in one inverse transform over
    the whole length: independent Gaussian coefficients, no DC term, so the
    realised Rq has the spectrum's expectation (with --rq it is exact). Lengths
    name their unit.

    \b
    Examples:
        rough synth --length 80mm --dimension 1.275 --rq 0.2781mm --seed 1 -o rock.x3p
        rough synth --size 1024x1024 --step 10um --dimension 2.3 --amplitude 1um | rough fit-fractal
        rough synth --size 512x512 --step 10um --dimension 2.3 --anisotropy 2.2,1um,2.5,1um,30 -o layered.x3p
        rough synth --length 80mm --dimension 1.275 --rq 0.2781mm --fragments | rough fit-fractal
    """
    if size is None and length is None and points is None:
        raise errors.InputError("give --length or --points for a profile, or --size for a map")
    if dimension is None and anisotropy is None:
        raise errors.InputError("give the fractal dimension (--dimension)")
    if size is not None:
        if fragments or length is not None or points is not None:
            raise errors.InputError("a map takes --size only (no --length, --points or --fragments)")
        surface = fractal.synthesize_map(
            size, (step, step), dimension, amplitude, rq, resolution, seed, anisotropy, rolloff_wavelength
        )
    else:
        if anisotropy is not None:
            raise errors.InputError("--anisotropy needs a map (--size)")
        count = points if points is not None else round(length / step)
        if count < 2:
            raise errors.InputError(
                f"--length {units.format_length(length)} holds fewer than two samples at the step "
                f"{units.format_length(step)}"
            )
        if fragments:
            if rolloff_wavelength is not None:
                raise errors.InputError("--rolloff-wavelength does not apply to the paper's fragments")
            surface = fractal.synthesize_fragments(
                count, step, dimension, amplitude, rq, resolution, seed, fragments, as_printed
            )
        else:
            surface = fractal.synthesize_profile(
                count, step, dimension, amplitude, rq, resolution, seed, rolloff_wavelength
            )
    output.write(surface)
