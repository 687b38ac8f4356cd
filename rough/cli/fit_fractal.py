"""rough fit-fractal: fractal dimension D and amplitude coefficient C from the spectrum."""

import click

from .. import fractal, io, units
from .. import plot as figures
from ..errors import InputError
from .options import (
    BAND,
    DIRECTION,
    LENGTH,
    TABLE,
    RegistryChoice,
    crop_option,
    gaps_option,
    model_options,
    plot_option,
    report_format,
    side_file,
    tiled_input,
)
from .report import Report, on_stdout, shown
from .work_options import jobs_option


@click.command("fit-fractal", short_help="Fractal dimension D and amplitude coefficient C, with uncertainty.")
@tiled_input
@jobs_option
@crop_option
@click.option(
    "--band",
    type=BAND,
    help="Fit band FMIN:FMAX in cycles per length, e.g. 0.1/mm:20/mm (an empty end is open).",
)
@click.option("--resolution", type=LENGTH, help="The resolution η at which C is stated (default: the spacing).")
@click.option(
    "--profiles",
    "direction",
    type=DIRECTION,
    help="Fit the map's profiles along x, y or an angle (degrees from +x) instead of its 2-D spectrum: "
    "H, D = 2 - H and C of the profiles, as the fault literature measures them.",
)
@gaps_option
@click.option(
    "--estimator",
    type=RegistryChoice(lambda: [*fractal.ESTIMATOR_NAMES, "all"]),
    help="H by this estimator of profiles (or all side by side), calibrated on exact fBm of the data's "
    "size, sampling, gaps and noise: bias-corrected H with a 95 % interval, and the raw value.",
)
@click.option(
    "--replicates",
    type=click.IntRange(2, 10000),
    help="With --estimator: synthetic replicates per calibration point (default: as the data's size allows).",
)
@click.option("--seed", type=click.IntRange(0), default=0, show_default=True, help="Seed of the calibration's data.")
@click.option(
    "--order",
    type=click.IntRange(0, 10),
    default=1,
    show_default=True,
    help="Polynomial form removed first (a plane: the spectrum needs only the tilt gone; detrend's default is 2).",
)
@click.option(
    "--sampling",
    type=RegistryChoice(lambda: fractal.SAMPLINGS),
    help="Point samples (power above Nyquist folds back) or band-limited data; by default band-limited "
    "when rough synthesised or resampled the surface, point samples otherwise.",
)
@click.option("--fill", is_flag=True, help="Fill invalid points first (linear along profiles, biharmonic in maps).")
@model_options
@click.option(
    "--psd",
    "psd_file",
    callback=side_file(TABLE),
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
    direction,
    gaps,
    estimator,
    replicates,
    seed,
    order,
    sampling,
    fill,
    noise,
    rolloff,
    level,
    tip_radius,
    psd_file,
    plot,
    work,
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
    decade over which the spectrum's local exponent stays within 0.1 in H of the
    band's (the χ² test's p-value is reported as a diagnostic). Where no band
    qualifies, the verdict is "no power-law range" and the RMS height, slope and
    curvature against scale are printed instead; a D on the edge of the range is a
    bound, printed without "±". Every result names its band, noise floor, sampling
    model and method.

    --profiles fits the profiles of a map along a direction instead (H, D = 2 - H
    and C of the profiles, as the fault literature measures them), with errors from
    a jackknife over blocks of neighbouring profiles. --estimator measures H by
    another estimator (or all five side by side), calibrated on exact fBm of the
    data's own size, sampling and noise: the bias-corrected H with a 95 % interval,
    and the raw value.

    \b
    Examples:
        rough fit-fractal rock.x3p
        rough synth --length 80mm --dimension 1.3 --rq 0.3mm | rough fit-fractal --json
        rough fit-fractal --profiles x --estimator all fault.npz
        rough fit-fractal --band 0.05/mm:5/mm --resolution 0.0309mm --psd psd.tsv --plot psd.png scan.x3p
    """
    report = not on_stdout(psd=psd_file, plot=plot)
    model = {"band": band, "resolution": resolution, "sampling": sampling, "noise": noise, "rolloff": rolloff}
    model.update(level=level, order=order, tip_radius=tip_radius)
    if isinstance(surface, io.TiledSurface):
        options = dict(gaps=gaps, estimator=estimator, fill=fill, tip_radius=tip_radius, psd_file=psd_file, plot=plot)
        return _tiled_report(surface, input, direction, options, report, work, **model)
    if fill:
        surface = fractal.fill_invalid(surface)
    if estimator or direction is not None:
        if estimator and (psd_file or plot):
            raise InputError("--psd and --plot draw a spectrum and its fit: leave out --estimator")
        if estimator:
            return _estimators_report(surface, direction, gaps, estimator, replicates, seed, model)
        return _profiles_report(surface, input, direction, gaps, model, psd_file, plot, report)
    result = fractal.fit_fractal(surface, **model)
    spectrum = fractal.binned_spectrum(surface, order) if (psd_file or plot or surface.is_profile) else None
    document = {**result.as_dict(), "points": surface.heights.size}
    if spectrum and "parseval" in spectrum:
        document["parseval"] = spectrum["parseval"]
    if psd_file:
        what, unit = ("Hann periodogram G", "m3") if surface.is_profile else ("ring-averaged P2", "m4")
        _write_psd(psd_file, spectrum, what, unit)
    if plot and result.scale_dependent:
        title = f"{_title(input, surface)}: no power-law band"
        figures.save(figures.scale_dependent_figure(result.scale_dependent, title, result.reliability_cutoff), plot)
    elif plot:
        _plot_spectrum(plot, spectrum, result, surface.spacing, _title(input, surface))
    return Report(_rows(result, surface.is_profile, document), document) if report else None


def _tiled_report(surface, input, direction, options, report, work, tip_radius, **model):
    """The fit of a map read in tiles (:mod:`rough.fractal.tiled`): the 2-D spectrum's,
    a stated estimator, or the profiles', exact; the options tiles cannot honour are refused."""
    refused = {"estimator": "--estimator", "tip_radius": "--tip-radius"}
    if direction is not None:
        refused.update(fill="--fill with --profiles (--gaps fill fills each profile)", psd_file="--psd with --profiles")
        refused.update(plot="--plot with --profiles")
    for name, flag in refused.items():
        if options[name]:
            raise InputError(f"{flag} is not available for a map read in tiles (raise --memory to read it whole)")
    if direction is not None:
        result = fractal.fit_profiles_tiles(surface, direction, options["gaps"], **model, **work)
        document = {**result.as_dict(), "tiled": result.tiled}
        rows = _rows(result.fit, True, document) + _profile_rows(result)
        return Report(rows + [_tiled_row(result.tiled)], document) if report else None
    wanted = bool(options["psd_file"] or options["plot"])
    result = fractal.fit_fractal_tiles(surface, fill=options["fill"], spectrum=wanted, **model, **work)
    document = {**result.as_dict(), "points": surface.point_count}
    if options["psd_file"]:
        _write_psd(options["psd_file"], result.spectrum, "ring-averaged P2, tiles' Welch average + coarse level", "m4")
    if options["plot"]:
        if result.verdict == "no power-law range":
            raise InputError("--plot: no power-law range, and the roughness against scale is not measured on tiles")
        _plot_spectrum(options["plot"], result.spectrum, result, surface.spacing, _title(input, surface))
    return Report(_rows(result, False, document) + [_tiled_row(result.tiled)], document) if report else None


def _tiled_row(tiled):
    estimated = "; ".join(f"{name}: {how}" for name, how in tiled["estimated"].items())
    exact = ", ".join(tiled["exact"]) or "nothing"
    units = {"join": "1/m"} if "join" in tiled else ""
    return ("tiled", tiled, units, f"read in tiles: exact: {exact}; estimated: {estimated or 'nothing'}")


def _profiles_report(surface, input, direction, gaps, model, psd_file, plot, report):
    """The pooled Whittle fit of the profiles along ``direction``; ``--psd`` writes and
    ``--plot`` draws their mean spectrum with the per-profile spread."""
    result = fractal.fit_profiles(surface, direction, gaps, **model)
    document = result.as_dict()
    if psd_file or plot:
        profiles = result.profile_set
        spectrum = fractal.profile_spectrum(profiles.heights, profiles.spacing)
        if psd_file:
            _write_psd(
                psd_file,
                spectrum,
                f"mean Hann periodogram G of {result.profiles} profiles along {result.direction}",
                extra=("profiles", "log10_spread"),
            )
        if plot:
            _plot_spectrum(
                plot,
                spectrum,
                result.fit,
                (profiles.spacing,),
                f"{_title(input, surface)}, profiles along {result.direction}",
            )
    return Report(_rows(result.fit, True, document) + _profile_rows(result), document) if report else None


def _estimators_report(surface, direction, gaps, estimator, replicates, seed, model):
    """The calibrated H of the profiles along ``direction`` by one estimator or all."""
    if direction is None and not surface.is_profile:
        raise InputError("--estimator measures H of profiles: give --profiles x, y or an angle for a map")
    direction = "x" if direction is None else direction
    names = None if estimator == "all" else [estimator]
    table = fractal.hurst_exponents(surface, direction, names, gaps, replicates=replicates, seed=seed, **model)
    document = table.as_dict()
    replaced = {"fractal_dimension", "fractal_dimension_stderr", "hurst"}
    whittle = [row for row in _rows(table.profile_fit.fit, True, document) if row[0] not in replaced]
    return Report(_estimator_rows(table, document) + whittle + _profile_rows(table.profile_fit), document)


def _write_psd(path, spectrum, what, unit="m3", extra=()):
    """The log-binned spectrum as TSV: frequency (1/m), density (``unit``), count, and
    ``extra`` columns."""
    columns = ["frequency_per_m", f"density_{unit}", "count", *extra]
    keys = ["frequency", "density", "count", *("log_spread" if name == "log10_spread" else name for name in extra)]
    lines = [f"# rough fit-fractal: log-binned spectrum ({what})", "\t".join(columns)]
    lines += ["\t".join(repr(value) for value in row) for row in zip(*(spectrum[key] for key in keys))]
    with io.atomic_output(path) as stream:
        stream.write(("\n".join(lines) + "\n").encode())


def _plot_spectrum(plot, spectrum, fit, spacing, title):
    figure = figures.spectrum_figure(spectrum["frequency"], spectrum["density"], fit, spacing, title)
    figures.save(figure, plot)


def _title(input, surface):
    """A figure's title: the input's name, and the surface's own title if it has one."""
    title = surface.metadata.get("title")
    return f"{shown(input)}: {title}" if title else shown(input)


def _rows(result, is_profile, document):
    key = "D" if is_profile else "Ds"
    if result.verdict == "no power-law range":
        return [
            ("verdict", result.verdict, "", f"no power-law range: {result.hint}"),
            (
                "fractal_dimension",
                None,
                "1",
                "none: no band of a decade keeps its local exponent; roughness against scale instead:",
            ),
            *_scale_rows(result.scale_dependent),
            *_cutoff_rows(result),
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
    amplitude = units.format_length(result.amplitude_coefficient)
    if not result.at_bound:
        amplitude += f" ± {units.format_length(result.amplitude_coefficient_stderr)}"
    rows += [
        (
            "amplitude_coefficient",
            result.amplitude_coefficient,
            "m",
            f"C = {amplitude} at η = {units.format_length(result.resolution)}",
        ),
        (
            "amplitude_coefficient_stderr",
            result.amplitude_coefficient_stderr,
            "m",
            "none: a bound has no standard error"
            if result.amplitude_coefficient_stderr is None
            else f"{units.format_length(result.amplitude_coefficient_stderr)} (standard error of C)",
        ),
        ("resolution", result.resolution, "m", f"η = {units.format_length(result.resolution)} (C is stated at it)"),
        (
            "psd_prefactor",
            result.psd_prefactor,
            "m^(3-β)" if is_profile else "m^(4-α)",
            f"{result.psd_prefactor:.5g} (the spectrum at f = 1/m, SI units)",
        ),
        ("hurst", result.hurst, "1", f"H = {result.hurst:.4f}"),
        (
            "structure_function_coefficient",
            result.structure_function_coefficient,
            "m",
            f"{units.format_length(result.structure_function_coefficient)} (Ganti & Bhushan's C_S at η)",
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
            (
                "rolloff_wavelength",
                result.rolloff_wavelength,
                "m",
                f"{units.format_length(result.rolloff_wavelength)} (1/fc)",
            )
        )
    rows += _cutoff_rows(result)
    rows.append(_method_row(result))
    if "parseval" in document:
        rows.append(
            ("parseval", document["parseval"], "1", f"{document['parseval']:.12f} (Σ G Δf over the windowed variance)")
        )
    return rows


SCALE_UNITS = {"scale": "m", "rms_height": "m", "rms_slope": "1", "rms_curvature": "1/m", "direction": ""}


def _scale_rows(table):
    """The scale-dependent roughness: one row holding the table, then a line per scale."""
    rows = [
        (
            "scale_dependent",
            table,
            SCALE_UNITS,
            f"{len(table['scale'])} scales along {table['direction']}: scale, RMS height, RMS slope, RMS curvature",
        )
    ]
    for scale, height, slope, curvature in zip(
        table["scale"], table["rms_height"], table["rms_slope"], table["rms_curvature"]
    ):
        text = f"{units.format_length(height):>12}  {slope:10.4g}  {units.format_quantity(curvature, '1/m'):>14}"
        rows.append((None, None, None, text, f"λ = {units.format_length(scale)}"))
    return rows


def _cutoff_rows(result):
    if result.reliability_cutoff is None:
        return []
    text = f"{units.format_length(result.reliability_cutoff)}: shorter wavelengths left out (the tip cannot follow)"
    return [("reliability_cutoff", result.reliability_cutoff, "m", text)]


def _dimension_text(result, key):
    if result.at_bound:
        return f"{key} = {result.fractal_dimension:.4f}: at the edge of the fractal range, a bound ({result.hint})"
    return f"{key} = {result.fractal_dimension:.4f} ± {result.fractal_dimension_stderr:.4f} (standard error)"


def _band_text(band, what):
    low, high = band
    return f"{units.format_range(low, high, '1/m')} (wavelengths {units.format_range(1 / high, 1 / low, 'm')}), {what}"


def _noise_text(result):
    if result.noise_rms is None:
        return "no white noise floor found"
    crossing = (
        f", above the power law from {units.format_quantity(result.noise_crossover, '1/m', 4)}"
        if result.noise_crossover
        else ", below the power law throughout the band"
    )
    return f"{units.format_length(result.noise_rms)} RMS white noise floor{crossing}"


def _method_row(result):
    return (
        "method",
        result.method,
        "",
        f"{result.method}; window {result.window}; sampling {result.sampling} ({result.sampling_source})",
    )


def _profile_rows(result):
    """What a profiles fit adds: the direction, how the profiles were taken, the spread."""
    spread = result.hurst_spread
    rows = [
        ("kind", result.kind, "", "H of 1-D profiles along a direction (not the map's 2-D spectrum)"),
        (
            "direction",
            result.direction,
            "",
            "the profile itself" if result.direction == "profile" else f"profiles along {result.direction}",
        ),
        ("angle", None if result.angle != result.angle else result.angle, "deg", _angle_text(result.angle)),
        (
            "profiles",
            result.profiles,
            "1",
            f"{result.profiles} profiles, {result.points} points; gaps: {result.gaps}; heights: {result.interpolation}",
        ),
        (
            "hurst_stderr",
            result.hurst_stderr,
            "1",
            "none: a bound has no standard error"
            if result.hurst_stderr is None
            else f"{result.hurst_stderr:.4f} (standard error of H: {result.stderr_method})",
        ),
        (
            "hurst_spread",
            spread,
            "1",
            "not measured (fewer than two profiles in the band)"
            if spread != spread
            else f"{spread:.4f} (SD of the profiles' own H over the band)",
        ),
        (
            "design_effect",
            result.design_effect,
            "1",
            f"{result.design_effect:.3g} (neighbouring profiles' correlation: the likelihood's weights divided by it)",
        ),
    ]
    return rows


def _angle_text(angle):
    return "none (a profile)" if angle != angle else f"{angle:.1f}° counter-clockwise from +x"


def _estimator_rows(table, document):
    """One row per estimator: the calibrated H, its 95 % interval, the raw value, the bias."""
    rows = [(None, None, None, "H (calibrated)  95 % interval   raw H    bias", "estimators")]
    for index, (estimate, record) in enumerate(zip(table.estimates, document["estimators"])):
        low, high = estimate.interval
        bound = f" (at the {estimate.at_bound} bound)" if estimate.at_bound else ""
        if estimate.hurst != estimate.hurst:
            rows.append(
                (f"estimators.{index}", record, ESTIMATE_UNITS, estimate.method, f"estimator {estimate.estimator}")
            )
            continue
        rows.append(
            (
                f"estimators.{index}",
                record,
                ESTIMATE_UNITS,
                f"{estimate.hurst:14.3f}  {low:6.3f} to {high:5.3f}  {estimate.raw:6.3f}  {estimate.bias:+6.3f}{bound}",
                f"estimator {estimate.estimator}",
            )
        )
    scales = table.scales
    whittle = (
        "the Whittle fit found no power-law band"
        if scales is None
        else f"the Whittle fit's band: wavelengths {units.format_length(scales[0])} to {units.format_length(scales[1])}"
    )
    rows.append(
        (
            "scales",
            None if scales is None else list(scales),
            "m",
            f"{whittle}; the others over their own ranges from its short end (estimators.N.scales) unless "
            f"--band or --tip-radius sets the band; calibrated on exact fBm (replicates per point: "
            f"estimators.N.replicates)",
        )
    )
    first = table.first
    stderr = document["fractal_dimension_stderr"]
    rows += [
        (
            "hurst",
            document["hurst"],
            "1",
            f"H = {first.hurst:.4f} ({first.estimator}, calibrated; 95 %: {first.interval[0]:.3f} to "
            f"{first.interval[1]:.3f})",
        ),
        ("fractal_dimension", document["fractal_dimension"], "1", f"D = 2 - H = {2 - first.hurst:.4f}"),
        (
            "fractal_dimension_stderr",
            stderr,
            "1",
            "none: a bound has no standard error"
            if stderr is None
            else f"{stderr:.4f} (the interval's half-width / 1.96)",
        ),
        (
            "whittle_fit_hurst",
            document["whittle_fit_hurst"],
            "1",
            f"{document['whittle_fit_hurst']:.4f} (H of the pooled Whittle fit, uncalibrated)",
        ),
    ]
    return rows


ESTIMATE_UNITS = {
    "estimator": "",
    "raw": "1",
    "hurst": "1",
    "interval": "1",
    "bias": "1",
    "replicates": "1",
    "method": "",
    "scales": "m",
    "at_bound": "",
}
