"""rough features: ISO profile and areal parameters, the amplitude density, the
slides' feature detection and Rq against evaluation length."""

import click

from .options import LENGTH, crop_option, plot_option, report_format, surface_input
from .report import Report, on_stdout, shown


@click.command(short_help="ISO parameters (Ra…JRC, Sa…Std), amplitude density, feature detection.")
@surface_input
@crop_option
@click.option(
    "--cutoff", type=LENGTH, help="Evaluate the roughness at this Gaussian cut-off λc instead of the data as given."
)
@click.option(
    "--ends",
    type=click.Choice(["trim", "correct"]),
    default="trim",
    show_default=True,
    help="With --cutoff: trim λc/2 at each end, or keep the full length.",
)
@click.option(
    "--sampling-lengths",
    type=click.IntRange(1, 1000),
    default=5,
    show_default=True,
    help="Sampling lengths that Rp, Rv and Rz are averaged over.",
)
@click.option(
    "--slope",
    type=click.Choice(["2point", "7point"]),
    default="2point",
    show_default=True,
    help="Slope for Rdq/Sdq/Sdr: forward differences, or ISO 4287's seven-point derivative.",
)
@click.option(
    "--jrc-spacing",
    type=LENGTH,
    default="0.5mm",
    show_default=True,
    help="Sampling interval at which Z2 and the Tse–Cruden JRC are evaluated.",
)
@click.option(
    "--along", type=click.Choice(["x", "y"]), help="Maps: profile parameters of the map's profiles along x or y."
)
@click.option(
    "--detect-cutoff",
    type=LENGTH,
    default="2.5mm",
    show_default=True,
    help="Feature detection: cut-off of the low-pass (mean line) profile.",
)
@click.option(
    "--detect-mode",
    type=click.Choice(["A", "B"]),
    default="B",
    show_default=True,
    help="Feature detection: B widens runs over 2·Rq_hf by 30 %; A makes the threshold grow with width.",
)
@click.option(
    "--polarity",
    type=click.Choice(["peaks", "pits", "both"]),
    default="both",
    show_default=True,
    help="Feature detection: which features to find.",
)
@click.option(
    "--list",
    "feature_list",
    metavar="FILE",
    help="Write one TSV row per detected feature (SI units); - is standard output, instead of the report.",
)
@click.option(
    "--vs-length", is_flag=True, help="Also report Rq against evaluation length and the slope of log Rq on log L."
)
@plot_option(
    "Draw the profile (features shaded) or map, and the amplitude density; - is standard output, instead of the report."
)
@report_format
def features(
    surface,
    input,
    cutoff,
    ends,
    sampling_lengths,
    slope,
    jrc_spacing,
    along,
    detect_cutoff,
    detect_mode,
    polarity,
    feature_list,
    vs_length,
    plot,
):
    """Parameters of INPUT (default: standard input) computed on the data as given,
    with only the mean of the valid points removed (pipe through `rough detrend`
    first to remove form, or give --cutoff for the roughness). Profiles: Ra, Rq,
    Rsk, Rku, Rdq, Rt over the evaluation length; Rp, Rv, Rz per sampling length,
    averaged; RSm; peak density (peaks crossing ±5 % of Rz about the mean line, per
    mm); Z2 and the Tse–Cruden JRC at --jrc-spacing; and the slides' feature
    detection. Maps: Sa, Sq, Ssk, Sku, Sp, Sv, Sz, Sdq, Sdr, Sal, Str, Std (ISO
    25178-2; Std is the lay direction). NaN points are left out.

    \b
    Examples:
        rough detrend --order 1 --crop 468um:733um dektak.csv | rough features
        rough features --cutoff 0.8mm --json scan.x3p
        rough features --list features.tsv --plot profile.png rock.tsv
        rough features --vs-length rock.tsv
    """
    from .. import metrology
    from ..io.atomic import atomic_output

    report = not on_stdout(list=feature_list, plot=plot)
    evaluated = surface if cutoff is None else metrology.split(surface, cutoff, "roughness", ends)
    values = metrology.parameters(
        evaluated, sampling_lengths=sampling_lengths, slope=slope, along=along, jrc_spacing=jrc_spacing
    )
    table = metrology.PROFILE if surface.is_profile or along else metrology.AREAL
    rows, document = _parameter_rows(evaluated, values, table, cutoff, sampling_lengths, slope, jrc_spacing, along)
    found = []
    if surface.is_profile:
        found, detection = _detect(evaluated, detect_cutoff, detect_mode, polarity)
        rows.append(("feature_count", len(found), "1", detection["text"]))
        document["feature_count"] = len(found)
        document["features"] = [
            {
                "kind": f.kind,
                "position": f.position,
                "start": f.start,
                "end": f.end,
                "height": f.height,
                "prominence": f.prominence,
                "width": f.width,
            }
            for f in found
        ]
        document["feature_detection"] = detection["settings"]
    centres, density = metrology.amplitude_density(evaluated)
    document["amplitude_density"] = {"height": centres.tolist(), "density": density.tolist()}
    if vs_length:
        scaling = metrology.rq_versus_length(evaluated)
        document["rq_vs_length"] = scaling
        rows += _scaling_rows(scaling)
    if feature_list:
        with atomic_output(feature_list) as stream:
            stream.write(_feature_table(found).encode())
    if plot:
        from .. import plots

        plots.save(plots.features_figure(evaluated, found, (centres, density), title=shown(input)), plot)
    return Report(rows, document) if report else None


def _parameter_rows(surface, values, table, cutoff, sampling_lengths, slope, jrc_spacing, along):
    import logging

    import numpy as np

    from ..units import format_length, format_quantity

    valid = int(np.count_nonzero(~np.isnan(surface.heights)))
    extent = " × ".join(format_length(s) for s in surface.size)
    basis = f"roughness at λc = {format_length(cutoff)}" if cutoff else "data as given, mean removed"
    if along:
        basis += f", profiles along {along}"
    evaluation = {
        "points": surface.heights.size,
        "valid_points": valid,
        "size": list(surface.size),
        "basis": basis,
        "sampling_lengths": sampling_lengths,
        "slope": slope,
        "jrc_spacing": jrc_spacing,
        "cutoff": cutoff,
    }
    units = {"points": "points", "valid_points": "points", "size": "m", "jrc_spacing": "m", "cutoff": "m"}
    rows = [("evaluation", evaluation, units, f"{extent}, {valid} of {surface.heights.size} points valid; {basis}")]
    for key, (unit, meaning) in table.items():
        rows.append((key, values[key], unit, f"{format_quantity(values[key], unit):<14} {meaning}"))
    notes = {
        "Rz": f"{sampling_lengths} sampling lengths",
        "Rdq": f"{slope} slope",
        "Sdq": f"{slope} slope",
        "JRC": f"Z2 at {format_length(max(jrc_spacing, surface.spacing[0]))} spacing",
    }
    if "JRC" in values and not 0 <= values["JRC"] <= 20:
        notes["JRC"] += "; outside the 0–20 range the relation was calibrated on"
        logging.getLogger("rough").warning(
            "JRC = %.4g is outside the 0–20 range the Tse–Cruden relation was calibrated on", values["JRC"]
        )
    rows = [(k, v, u, f"{t} ({notes[k]})" if k in notes else t) for k, v, u, t in rows]
    return rows, {**values, "evaluation": evaluation}


def _detect(surface, cutoff, mode, polarity):
    from ..errors import InputError
    from ..metrology import detect_features
    from ..units import format_length

    settings = {"cutoff": cutoff, "mode": mode, "polarity": polarity, "k": 2.0, "extension": 0.3}
    try:
        found, info = detect_features(surface, cutoff=cutoff, mode=mode, polarity=polarity)
    except InputError as error:
        return [], {"text": f"not detected ({error})", "settings": {**settings, "skipped": str(error)}}
    text = (
        f"{len(found)} (mode {mode}, λc {format_length(cutoff)}, threshold 2·Rq_hf = "
        f"{format_length(info['threshold'])}, +30 % lateral)"
    )
    return found, {"text": text, "settings": {**settings, **info}}


def _scaling_rows(scaling):
    from ..units import format_length

    key = "Rq" if "Rq" in scaling else "Sq"
    rows = [
        (
            f"rq_vs_length.{key}.{index}",
            value,
            "m",
            f"{format_length(value)} over {count} windows",
            f"{key}(L={format_length(length)})",
        )
        for index, (length, value, count) in enumerate(zip(scaling["length"], scaling[key], scaling["windows"]))
    ]
    rows.append(
        (
            "rq_vs_length.hurst",
            scaling["hurst"],
            "1",
            f"{key} ∝ L^{scaling['hurst']:.3f}: H = {scaling['hurst']:.3f}, D = "
            f"{scaling['fractal_dimension']:.3f} (window means removed)",
            "scaling",
        )
    )
    return rows


def _feature_table(found):
    lines = [
        "# rough features: one row per feature; positions and heights in metres",
        "kind\tposition\tstart\tend\theight\tprominence\twidth",
    ]
    lines += [
        f"{f.kind}\t{f.position!r}\t{f.start!r}\t{f.end!r}\t{f.height!r}\t{f.prominence!r}\t{f.width!r}" for f in found
    ]
    return "\n".join(lines) + "\n"
