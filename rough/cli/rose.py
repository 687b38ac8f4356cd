"""rough rose: direction-dependent fractal dimension and amplitude coefficient."""

import click

from .options import BAND, LENGTH, crop_option, model_options, plot_option, report_format, surface_input
from .report import echo, emit, on_stdout


@click.command(short_help="D(θ) and C(θ) by direction for maps (the amplitude coefficient rose); Str, Std.")
@surface_input
@crop_option
@click.option(
    "--step",
    type=click.FloatRange(1, 90),
    default=10.0,
    show_default=True,
    help="Angle between sector centres (degrees; must divide 180).",
)
@click.option(
    "--width",
    type=click.FloatRange(1, 180),
    help="Sector width in degrees (default: the step, sectors not overlapping).",
)
@click.option("--band", type=BAND, help="Fit band FMIN:FMAX in cycles per length (bare numbers per mm).")
@click.option("--resolution", type=LENGTH, help="The resolution η at which C is stated (default: the smaller spacing).")
@click.option(
    "--order", type=click.IntRange(0, 10), default=1, show_default=True, help="Polynomial form removed first."
)
@click.option("--sampling", type=click.Choice(["point", "band-limited"]), help="As for fit-fractal.")
@click.option("--fill", is_flag=True, help="Fill invalid points first (biharmonic inpainting).")
@model_options
@plot_option("Draw polar roses of C(θ) and D(θ), mirrored to 360°; - is standard output, instead of the report.")
@report_format
def rose(
    surface, input, step, width, band, resolution, order, sampling, fill, noise, rolloff, level, plot, as_json, as_tsv
):
    """Fit the surface dimension Ds(θ) and amplitude coefficient C(θ) of the map
    INPUT (default: standard input) in direction sectors of its Hann-windowed 2-D
    power spectrum, with the axis lines, where a map's edges leak, left out. θ is the
    wavevector direction, counter-clockwise from +x (the direction in which heights
    vary; ridges run at right angles). The band is the whole map's scaling range
    (as for fit-fractal) unless --band is given; each sector gets its own noise
    floor. Reports the principal direction (largest C), Ds and C along it and
    across it, the lay at the long-wavelength end and at the resolution η (on a
    fault surface read the long-wavelength lay as the slip direction), χ² tests of
    isotropy over the sectors not at a bound, and ISO 25178-2 Str and Std. Unequal
    x and y spacing is handled exactly (physical frequencies).

    \b
    Examples:
        rough rose scan.x3p
        rough rose --step 15 --plot rose.png --json fault.x3p
        rough synth --size 1024x1024 --spacing 10um --anisotropy 2.2,1um,2.5,3um,30 | rough rose
    """

    from ..fractal.resample import fill_invalid
    from ..fractal.rose import rose as directions

    if fill:
        surface = fill_invalid(surface)
    result = directions(
        surface,
        step=step,
        width=width,
        band=band,
        resolution=resolution,
        order=order,
        sampling=sampling,
        noise=noise,
        rolloff=rolloff,
        level=level,
    )
    if plot:
        from .. import plots

        plots.save(plots.rose_figure(result, surface.metadata.get("title", "direction dependence")), plot)
    if on_stdout(plot=plot):
        return
    if as_tsv:
        _print_tsv(result)
        return
    emit(_rows(result), result.as_dict(), as_json, False)


def _print_tsv(result):
    echo(
        "angle_deg\tfractal_dimension\tfractal_dimension_stderr\tamplitude_coefficient_m"
        "\tamplitude_coefficient_stderr_m\tat_bound"
    )
    for *row, bound in zip(
        result.angles,
        result.fractal_dimension,
        result.fractal_dimension_stderr,
        result.amplitude_coefficient,
        result.amplitude_coefficient_stderr,
        result.at_bound,
    ):
        echo("\t".join(["" if value is None else repr(float(value)) for value in row] + [str(bound).lower()]))


def _sector_text(dimension, dimension_error, amplitude, amplitude_error):
    from ..units import format_length

    if dimension_error is None:
        return f"Ds = {dimension:.4f} (bound)   C = {format_length(amplitude)}"
    spread = f"{format_length(amplitude)} ± {format_length(amplitude_error)}"
    return f"Ds = {dimension:.4f} ± {dimension_error:.4f}   C = {spread}"


def _rows(result):
    from ..units import format_length, format_quantity

    rows = [
        (f"θ = {angle:5.1f}°", [d, c], "", _sector_text(d, de, c, ce))
        for angle, d, de, c, ce in zip(
            result.angles,
            result.fractal_dimension,
            result.fractal_dimension_stderr,
            result.amplitude_coefficient,
            result.amplitude_coefficient_stderr,
        )
    ]
    principal, across = result.principal, result.perpendicular
    isotropy = result.isotropy_p_value
    long_lay, fine_lay = result.lay["long_wavelength"], result.lay["resolution"]
    bound = sum(result.at_bound)
    rows += [
        (
            "principal",
            result.principal_direction,
            "deg",
            f"{result.principal_direction:.1f}° (largest C of the rose's cos 2θ part): "
            + _sector_text(
                principal["dimension"],
                principal["dimension_error"],
                principal["amplitude"],
                principal["amplitude_error"],
            ),
        ),
        (
            "perpendicular",
            (result.principal_direction + 90) % 180,
            "deg",
            f"{(result.principal_direction + 90) % 180:.1f}°: "
            + _sector_text(
                across["dimension"], across["dimension_error"], across["amplitude"], across["amplitude_error"]
            ),
        ),
        (
            "lay_long_wavelength",
            long_lay["direction"],
            "deg",
            f"{long_lay['direction']:.1f}° (ridges at wavelength {format_length(long_lay['wavelength'])}, the band's "
            "long end: on a fault, the slip direction)",
        ),
        (
            "lay_resolution",
            fine_lay["direction"],
            "deg",
            f"{fine_lay['direction']:.1f}° (ridges at η = {format_length(fine_lay['wavelength'])}, the finest texture)",
        ),
        (
            "largest_sector",
            result.largest_sector,
            "deg",
            f"{result.largest_sector:.1f}° (the sector with the largest C)",
        ),
        ("at_bound", bound, "1", f"{bound} of {len(result.angles)} sectors have Ds at a bound (left out of the tests)"),
        (
            "isotropy",
            isotropy,
            "",
            "not tested (overlapping sectors, or fewer than two sectors inside the range)"
            if isotropy["fractal_dimension"] is None
            else f"χ² p-values: Ds flat {isotropy['fractal_dimension']:.3g}, "
            f"C flat {isotropy['amplitude_coefficient']:.3g}",
        ),
        ("Str", result.Str, "1", f"{format_quantity(result.Str, '1')} (texture aspect ratio, ISO 25178-2)"),
        ("Std", result.Std, "deg", f"{format_quantity(result.Std, 'deg')} (lay direction from the angular spectrum)"),
        (
            "band",
            list(result.band),
            "1/m",
            (
                f"{result.band[0] * 1e-3:.4g} to {result.band[1] * 1e-3:.4g} /mm ({result.verdict} over the whole map, "
                f"p = {result.p_value:.3g}), sectors {result.width:g}° wide every {result.step:g}°, C at "
                f"η = {format_length(result.resolution)}, sampling {result.sampling}"
            ),
        ),
    ]
    return rows
