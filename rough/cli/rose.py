"""rough rose: direction-dependent fractal dimension and amplitude coefficient."""

import math

import click

from .. import fractal
from .. import plot as figures
from ..units import format_length, format_quantity, format_range
from .options import (
    BAND,
    LENGTH,
    Command,
    FloatRange,
    RegistryChoice,
    crop_option,
    gaps_option,
    model_options,
    plot_option,
    report_format,
    surface_input,
)
from .report import Report, on_stdout, shown
from .work_options import jobs_option


@click.command(
    cls=Command, short_help="D(θ) and C(θ) by direction for maps (the amplitude coefficient rose); Str, Std."
)
@surface_input
@jobs_option
@crop_option
@click.option(
    "--angle-step",
    type=FloatRange(1, 90),
    default=10.0,
    show_default=True,
    help="Angle between sector centres (degrees; must divide 180).",
)
@click.option(
    "--width",
    type=FloatRange(1, 180),
    help="Sector width in degrees (default: the angle step, sectors not overlapping).",
)
@click.option("--band", type=BAND, help="Fit band FMIN:FMAX in cycles per length, e.g. 0.1/mm:20/mm.")
@click.option("--resolution", type=LENGTH, help="The resolution η at which C is stated (default: the smaller spacing).")
@click.option(
    "--order",
    type=click.IntRange(0, 10),
    default=1,
    show_default=True,
    help="Polynomial form removed first (a plane: the spectrum needs only the tilt gone; detrend's default is 2).",
)
@click.option("--sampling", type=RegistryChoice(lambda: fractal.SAMPLINGS), help="As for fit-fractal.")
@click.option("--fill", is_flag=True, help="Fill invalid points first (biharmonic inpainting).")
@click.option(
    "--profiles",
    is_flag=True,
    help="Also fit the map's profiles along each direction (H(θ), D(θ) = 2 - H, C(θ) by the pooled Whittle "
    "fit of 1-D profiles, as the fault literature measures them), beside the 2-D sector rose.",
)
@gaps_option
@model_options
@plot_option("Draw polar roses of C(θ) and D(θ), mirrored to 360°; - is standard output, instead of the report.")
@report_format
def rose(
    surface,
    input,
    angle_step,
    width,
    band,
    resolution,
    order,
    sampling,
    fill,
    profiles,
    gaps,
    noise,
    rolloff,
    level,
    tip_radius,
    plot,
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
    isotropy over the sectors not at a bound, and ISO 25178-2 Str and Std (of the map
    less its least-squares plane, so they can differ from those `features` gives on
    the data as given). Unequal
    x and y spacing is handled exactly (physical frequencies). --profiles adds, beside
    this 2-D sector rose, H(θ), D(θ) and C(θ) fitted on the map's 1-D profiles along
    each direction (what the fault literature reports; see fit-fractal --profiles).

    \b
    Examples:
        rough rose scan.x3p
        rough rose --angle-step 15 --plot rose.png --json fault.x3p
        rough rose --angle-step 15 --profiles fault.npz
        rough synth --size 1024x1024 --step 10um --anisotropy 2.2,1um,2.5,3um,30 | rough rose
    """
    if fill:
        surface = fractal.fill_invalid(surface)
    model = {"band": band, "resolution": resolution, "order": order, "sampling": sampling, "noise": noise}
    model.update(rolloff=rolloff, level=level, tip_radius=tip_radius)
    result = fractal.rose(surface, angle_step, width=width, **model)
    if plot:
        figures.save(figures.rose_figure(result, shown(input)), plot)
    if on_stdout(plot=plot):
        return None
    document, rows = result.as_dict(), _rows(result)
    if profiles:
        along = fractal.profile_rose(surface, math.radians(angle_step), gaps=gaps, **model)
        document["profiles"] = along.as_dict()
        rows += _profile_rows(along)
    return Report(rows, document)


def _sector_text(dimension, dimension_error, amplitude, amplitude_error):
    if dimension_error is None:
        return f"Ds = {dimension:.4f} (bound)   C = {format_length(amplitude)}"
    spread = f"{format_length(amplitude)} ± {format_length(amplitude_error)}"
    return f"Ds = {dimension:.4f} ± {dimension_error:.4f}   C = {spread}"


SECTOR_UNITS = {
    "angle": "deg",
    "fractal_dimension": "1",
    "fractal_dimension_stderr": "1",
    "amplitude_coefficient": "m",
    "amplitude_coefficient_stderr": "m",
    "noise_rms": "m",
}
FIT_UNITS = {
    "dimension": "1",
    "dimension_error": "1",
    "amplitude": "m",
    "amplitude_error": "m",
    "frequencies_used": "1",
}
LAY_UNITS = {"direction": "deg", "wavelength": "m"}


def _fit_text(fit):
    return _sector_text(fit["dimension"], fit["dimension_error"], fit["amplitude"], fit["amplitude_error"])


def _rows(result):
    document = result.as_dict()
    rows = [
        (
            f"sectors.{index}",
            sector,
            SECTOR_UNITS,
            _sector_text(
                sector["fractal_dimension"],
                sector["fractal_dimension_stderr"],
                sector["amplitude_coefficient"],
                sector["amplitude_coefficient_stderr"],
            ),
            f"θ = {sector['angle']:5.1f}°",
        )
        for index, sector in enumerate(document["sectors"])
    ]
    isotropy = result.isotropy_p_value
    long_lay, fine_lay = result.lay["long_wavelength"], result.lay["resolution"]
    bound = document["sectors_at_bound"]
    rows += [
        (
            "principal_direction",
            result.principal_direction,
            "deg",
            f"{result.principal_direction:.1f}° (largest C of the rose's cos 2θ part)",
        ),
        ("principal", result.principal, FIT_UNITS, f"along θp: {_fit_text(result.principal)}"),
        (
            "perpendicular",
            result.perpendicular,
            FIT_UNITS,
            f"across, at {(result.principal_direction + 90) % 180:.1f}°: {_fit_text(result.perpendicular)}",
        ),
        (
            "lay.long_wavelength",
            long_lay,
            LAY_UNITS,
            f"{long_lay['direction']:.1f}° (ridges at wavelength {format_length(long_lay['wavelength'])}, the band's "
            "long end: on a fault, the slip direction)",
        ),
        (
            "lay.resolution",
            fine_lay,
            LAY_UNITS,
            f"{fine_lay['direction']:.1f}° (ridges at η = {format_length(fine_lay['wavelength'])}, the finest texture)",
        ),
        (
            "largest_sector",
            result.largest_sector,
            "deg",
            f"{result.largest_sector:.1f}° (the sector with the largest C)",
        ),
        (
            "sectors_at_bound",
            bound,
            "1",
            f"{bound} of {len(result.angles)} sectors have Ds at a bound (left out of the tests)",
        ),
        (
            "isotropy_p_value",
            isotropy,
            "1",
            "not tested (overlapping sectors, or fewer than two sectors inside the range)"
            if isotropy["fractal_dimension"] is None
            else f"χ² p-values: Ds flat {isotropy['fractal_dimension']:.3g}, "
            f"C flat {isotropy['amplitude_coefficient']:.3g}",
        ),
        (
            "Str",
            result.Str,
            "1",
            f"{format_quantity(result.Str, '1')} (texture aspect ratio, ISO 25178-2, plane removed)",
        ),
        (
            "Std",
            result.Std,
            "deg",
            f"{format_quantity(result.Std, 'deg')} (lay direction from the angular spectrum)",
        ),
        (
            "band",
            list(result.band),
            "1/m",
            (
                f"{format_range(*result.band, '1/m')} ({result.verdict} over the whole map, "
                f"p = {result.p_value:.3g}), sectors {result.width:g}° wide every {result.step:g}°, C at "
                f"η = {format_length(result.resolution)}, sampling {result.sampling}"
            ),
        ),
    ]
    return rows


PROFILE_UNITS = {
    "angle": "deg",
    "hurst": "1",
    "hurst_stderr": "1",
    "fractal_dimension": "1",
    "fractal_dimension_stderr": "1",
    "amplitude_coefficient": "m",
    "amplitude_coefficient_stderr": "m",
    "band": "1/m",
    "profiles": "1",
    "verdict": "",
}


def _profile_rows(along):
    """The profiles' H(θ), D(θ), C(θ): one row per direction, after a header naming them."""
    rows = [
        (
            None,
            None,
            None,
            f"profiles along θ (1-D pooled Whittle fits, {along.interpolation} heights, gaps: {along.gaps}; "
            f"errors: {along.stderr_method})",
            "profiles",
        )
    ]
    for index, record in enumerate(along.directions):
        if record["hurst"] is None or record["hurst"] != record["hurst"]:
            text = record["verdict"]
        else:
            error = record["hurst_stderr"]
            spread = "(bound)" if error is None else f"± {error:.4f}"
            amplitude = format_length(record["amplitude_coefficient"])
            text = f"H = {record['hurst']:.4f} {spread}   D = {record['fractal_dimension']:.4f}   C = {amplitude}"
            text += f"   {record['profiles']} profiles"
        rows.append((f"profiles.directions.{index}", record, PROFILE_UNITS, text, f"θ = {record['angle']:5.1f}°"))
    return rows
