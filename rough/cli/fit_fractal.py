"""rough fit-fractal: fractal dimension D and amplitude coefficient C from the spectrum."""

import click

from .options import BAND, LENGTH, crop_option, model_options, plot_option, report_format, surface_input
from .report import Report, on_stdout, shown


@click.command("fit-fractal", short_help="Fractal dimension D and amplitude coefficient C, with uncertainty.")
@surface_input
@crop_option
@click.option(
    "--band",
    type=BAND,
    help="Fit band FMIN:FMAX in cycles per length, e.g. 0.1/mm:20/mm (bare numbers per mm; an empty end is open).",
)
@click.option("--resolution", type=LENGTH, help="The resolution η at which C is stated (default: the spacing).")
@click.option(
    "--method",
    type=click.Choice(["whittle", "variogram", "madogram", "loglog"]),
    default="whittle",
    show_default=True,
    help="Whittle likelihood of the spectrum (the estimator), or a cross-check (profiles only).",
)
@click.option(
    "--order",
    type=click.IntRange(0, 10),
    default=1,
    show_default=True,
    help="Polynomial form removed first (a plane: the spectrum needs only the tilt gone; detrend's default is 2).",
)
@click.option(
    "--sampling",
    type=click.Choice(["point", "band-limited"]),
    help="Point samples (power above Nyquist folds back) or band-limited data; by default band-limited "
    "when rough synthesised or resampled the surface, point samples otherwise.",
)
@click.option("--fill", is_flag=True, help="Fill invalid points first (linear along profiles, biharmonic in maps).")
@model_options
@click.option(
    "--psd",
    "psd_file",
    metavar="FILE",
    help="Write the log-binned spectrum as TSV (frequency 1/m, density, count); - is standard output, "
    "instead of the report.",
)
@plot_option("Draw the spectrum with the fitted power law on log-log axes; - is standard output, not the report.")
@report_format
def fit_fractal(
    surface,
    input,
    band,
    resolution,
    method,
    order,
    sampling,
    fill,
    noise,
    rolloff,
    level,
    psd_file,
    plot,
):
    """Fit the power law of INPUT's power spectrum (default: standard input): the
    fractal dimension D (a profile's, 1-2; a map's surface dimension Ds, 2-3, with
    the profile-equivalent D = Ds - 1 alongside) and the amplitude coefficient C of
    G(f) = C η^(2D-3) f^-(5-2D) at the resolution η, each with a standard error.

    The estimator maximises the Whittle likelihood of the periodogram of the
    profile's first differences under the exact spectrum of sampled fractal
    surfaces plus a white noise floor (and, with --rolloff, a short-wavelength
    roll-off); maps are fitted on the ring-averaged, Hann-windowed 2-D periodogram.
    Without --band the band is the scaling range: the widest band of at least a
    decade over which the model passes a χ² goodness-of-fit test of the
    periodogram at --level. Where none does, the verdict is "no power-law range"
    and no D is printed; a D on the edge of the range is a bound, printed without
    "±". Every result names its band, test p-value, noise floor, sampling model
    and method.

    \b
    Examples:
        rough fit-fractal rock.x3p
        rough synth --length 80mm --dimension 1.3 --rq 0.3mm | rough fit-fractal --json
        rough fit-fractal --band 0.05/mm:5/mm --resolution 0.0309mm --psd psd.tsv --plot psd.png scan.x3p
    """
    from ..fractal.fit import fit_fractal as fit
    from ..fractal.psd import binned_spectrum
    from ..fractal.resample import fill_invalid
    from ..io.atomic import atomic_output

    report = not on_stdout(psd=psd_file, plot=plot)
    if fill:
        surface = fill_invalid(surface)
    result = fit(
        surface,
        band=band,
        resolution=resolution,
        method=method,
        order=order,
        sampling=sampling,
        noise=noise,
        rolloff=rolloff,
        level=level,
    )
    spectrum = binned_spectrum(surface, order) if (psd_file or plot or surface.is_profile) else None
    document = {**result.as_dict(), "points": surface.heights.size}
    if spectrum and "parseval" in spectrum:
        document["parseval"] = spectrum["parseval"]
    if psd_file:
        unit = "m3" if surface.is_profile else "m4"
        lines = [
            f"# rough fit-fractal: log-binned spectrum "
            f"({'Hann periodogram G' if surface.is_profile else 'ring-averaged P2'})",
            f"frequency_per_m\tdensity_{unit}\tcount",
        ]
        lines += [
            f"{f!r}\t{g!r}\t{n}" for f, g, n in zip(spectrum["frequency"], spectrum["density"], spectrum["count"])
        ]
        with atomic_output(psd_file) as stream:
            stream.write(("\n".join(lines) + "\n").encode())
    if plot:
        import numpy as np

        from .. import plots

        plots.save(
            plots.spectrum_figure(
                np.array(spectrum["frequency"]),
                np.array(spectrum["density"]),
                result,
                surface.spacing,
                _title(input, surface),
            ),
            plot,
        )
    return Report(_rows(result, surface, document), document) if report else None


def _title(input, surface):
    """A figure's title: the input's name, and the surface's own title if it has one."""
    title = surface.metadata.get("title")
    return f"{shown(input)}: {title}" if title else shown(input)


def _rows(result, surface, document):
    from ..units import format_length

    key = "D" if surface.is_profile else "Ds"
    if result.verdict == "no power-law range":
        return [
            ("verdict", result.verdict, "", f"no power-law range: {result.hint}"),
            ("fractal_dimension", None, "1", "none: no band over which the spectrum is a power law"),
            ("p_value", result.p_value, "1", f"{result.p_value:.3g} (the best of any band of a decade)"),
            _method_row(result),
        ]
    rows = [
        ("verdict", result.verdict, "", result.verdict + (f" ({result.hint})" if result.at_bound else "")),
        ("fractal_dimension", result.fractal_dimension, "1", _dimension_text(result, key)),
        (
            "fractal_dimension_stderr",
            result.fractal_dimension_stderr,
            "1",
            "none: a bound has no standard error"
            if result.fractal_dimension_stderr is None
            else f"{result.fractal_dimension_stderr:.4f} (standard error of {key})",
        ),
    ]
    if result.profile_dimension is not None:
        rows.append(
            (
                "profile_dimension",
                result.profile_dimension,
                "1",
                f"D = Ds - 1 = {result.profile_dimension:.4f} (profiles through the map)",
            )
        )
    amplitude = format_length(result.amplitude_coefficient)
    if not result.at_bound:
        amplitude += f" ± {format_length(result.amplitude_coefficient_stderr)}"
    rows += [
        (
            "amplitude_coefficient",
            result.amplitude_coefficient,
            "m",
            f"C = {amplitude} at η = {format_length(result.resolution)}",
        ),
        (
            "amplitude_coefficient_stderr",
            result.amplitude_coefficient_stderr,
            "m",
            "none: a bound has no standard error"
            if result.amplitude_coefficient_stderr is None
            else f"{format_length(result.amplitude_coefficient_stderr)} (standard error of C)",
        ),
        ("resolution", result.resolution, "m", f"η = {format_length(result.resolution)} (C is stated at it)"),
        (
            "psd_prefactor",
            result.psd_prefactor,
            "m^(3-β)" if surface.is_profile else "m^(4-α)",
            f"{result.psd_prefactor:.5g} (the spectrum at f = 1/m, SI units)",
        ),
        ("hurst", result.hurst, "1", f"H = {result.hurst:.4f}"),
        (
            "structure_function_coefficient",
            result.structure_function_coefficient,
            "m",
            f"{format_length(result.structure_function_coefficient)} (Ganti & Bhushan's C_S at η)",
        ),
        ("band", list(result.band), "1/m", _band_text(result.band, "scaling range")),
        (
            "fit_band",
            list(result.fit_band),
            "1/m",
            _band_text(result.fit_band, f"{result.frequencies_used} frequencies"),
        ),
    ]
    if result.p_value is not None and result.p_value == result.p_value:
        rows.append(("p_value", result.p_value, "1", f"{result.p_value:.3g} (goodness of fit: {result.test})"))
    rows.append(("noise_rms", result.noise_rms, "m", _noise_text(result)))
    if result.rolloff_wavelength:
        rows.append(
            ("rolloff_wavelength", result.rolloff_wavelength, "m", f"{format_length(result.rolloff_wavelength)} (1/fc)")
        )
    rows.append(_method_row(result))
    if "parseval" in document:
        rows.append(
            ("parseval", document["parseval"], "1", f"{document['parseval']:.12f} (Σ G Δf over the windowed variance)")
        )
    return rows


def _dimension_text(result, key):
    if result.at_bound:
        return f"{key} = {result.fractal_dimension:.4f}: at the edge of the fractal range, a bound ({result.hint})"
    return f"{key} = {result.fractal_dimension:.4f} ± {result.fractal_dimension_stderr:.4f} (standard error)"


def _band_text(band, what):
    from ..units import format_length

    low, high = band
    return (
        f"{low * 1e-3:.4g} to {high * 1e-3:.4g} /mm (wavelengths {format_length(1 / high)} to "
        f"{format_length(1 / low)}), {what}"
    )


def _noise_text(result):
    from ..units import format_length

    if result.noise_rms is None:
        return "no white noise floor found"
    crossing = (
        f", above the power law from {result.noise_crossover * 1e-3:.4g} /mm"
        if result.noise_crossover
        else ", below the power law throughout the band"
    )
    return f"{format_length(result.noise_rms)} RMS white noise floor{crossing}"


def _method_row(result):
    return (
        "method",
        result.method,
        "",
        f"{result.method}; window {result.window}; sampling {result.sampling} ({result.sampling_source})",
    )
