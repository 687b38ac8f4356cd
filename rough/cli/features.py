"""rough features: ISO profile and areal parameters, the amplitude density, the
slides' feature detection and Rq against evaluation length."""

import dataclasses
import logging

import click

from .. import errors, io, metrology, units
from .. import plot as figures
from .options import (
    LENGTH,
    POSITION,
    RATIO,
    RATIOS,
    TABLE,
    FloatRange,
    RegistryChoice,
    crop_option,
    plot_option,
    report_format,
    side_file,
    tiled_input,
)
from .report import Report, on_stdout, shown
from .work_options import jobs_option


@click.command(short_help="ISO parameters (Ra…JRC, Sa…Std), amplitude density, feature detection.")
@tiled_input
@jobs_option
@crop_option
@click.option(
    "--cutoff", type=LENGTH, help="Evaluate the roughness at this Gaussian cut-off λc instead of the data as given."
)
@click.option(
    "--ends",
    type=RegistryChoice(lambda: metrology.ENDS),
    default="trim",
    show_default=True,
    help="With --cutoff: trim λc/2 at each end, or keep the full length.",
)
@click.option(
    "--sampling-lengths",
    type=click.IntRange(1, 1000),
    help="Sampling lengths that Rp, Rv and Rz are averaged over: with --cutoff, lengths of λc in the middle of "
    "the profile (default: every whole one it holds, ISO 4288); without, equal sections (default 5).",
)
@click.option(
    "--slope",
    type=RegistryChoice(lambda: metrology.SLOPES),
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
    "--acf",
    type=RegistryChoice(lambda: metrology.ACFS),
    default="iso",
    show_default=True,
    help="Maps: the autocorrelation of Sal and Str: ISO 25178-2's (products summed over the overlap, over the "
    "sum of squares) or the mean product per lag (surfalize's).",
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
    type=RegistryChoice(lambda: metrology.MODES),
    default="B",
    show_default=True,
    help="Feature detection: B widens runs over 2·Rq_hf by 30 %; A makes the threshold grow with width.",
)
@click.option(
    "--polarity",
    type=RegistryChoice(lambda: metrology.POLARITIES),
    default="both",
    show_default=True,
    help="Feature detection: which features to find.",
)
@click.option(
    "--list",
    "feature_list",
    metavar="FILE",
    callback=side_file(TABLE),
    help="Write one TSV row per detected feature (SI units); - is standard output, instead of the report.",
)
@click.option(
    "--height",
    "material_height",
    type=POSITION,
    default="0",
    show_default=True,
    help="Material ratio Rmr(c)/Smr(c) at this height c about the mean.",
)
@click.option(
    "--ratio",
    "material_ratio",
    type=RATIO,
    default="10",
    show_default=True,
    help="Material ratio mr (%) of Rmc(mr)/Smc(mr) and of the volumes Vm(mr), Vv(mr).",
)
@click.option(
    "--dc-ratios",
    type=RATIOS,
    default="10:80",
    show_default=True,
    help="The two material ratios (%) of the height difference Rδc/Sdc.",
)
@click.option(
    "--volume-ratios",
    type=RATIOS,
    default="10:80",
    show_default=True,
    help="Maps: the material ratios p:q (%) that split Vmp, Vmc, Vvc and Vvv.",
)
@click.option(
    "--pruning",
    type=FloatRange(0, 100, max_open=True),
    default=5.0,
    show_default=True,
    help="Maps: Wolf pruning of hills and dales lower than this percentage of Sz.",
)
@click.option(
    "--edge-features",
    type=RegistryChoice(lambda: metrology.EDGES),
    default="exclude",
    show_default=True,
    help="Maps: leave out, or count, the hills and dales that touch the border or invalid points.",
)
@click.option(
    "--segments",
    metavar="FILE",
    callback=side_file(TABLE),
    help="Maps: write one TSV row per hill and dale (SI units); - is standard output, instead of the report.",
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
    acf,
    detect_cutoff,
    detect_mode,
    polarity,
    feature_list,
    material_height,
    material_ratio,
    dc_ratios,
    volume_ratios,
    pruning,
    edge_features,
    segments,
    vs_length,
    plot,
    work,
):
    """Parameters of INPUT (default: standard input) computed on the data as given,
    with only the mean of the valid points removed (pipe through `rough detrend`
    first to remove form, or give --cutoff for the roughness). Profiles: Ra, Rq,
    Rsk, Rku, Rdq, Rt over the evaluation length; Rp, Rv, Rz per sampling length
    (λc with --cutoff, ISO 4288), averaged; RSm; peak density (peaks crossing ±5 % of Rz about the mean line, per
    length: /m or /mm as fits); Z2 and the Tse–Cruden JRC at --jrc-spacing; the material-ratio parameters
    Rmr(c), Rmc(mr), Rδc, Rk, Rpk, Rvk, Mr1, Mr2, A1, A2 (ISO 13565-2) and Rpq, Rvq,
    Rmq (ISO 13565-3); and the slides' feature detection. Maps: Sa, Sq, Ssk, Sku,
    Sp, Sv, Sz, Sdq, Sdr, Sal, Str, Std (ISO 25178-2; Std is the lay direction); the
    functional parameters Smr(c), Smc(mr), Sdc, Sk, Spk, Svk, Smr1, Smr2, Sxp, the
    volumes Vm, Vv, Vmp, Vmc, Vvc, Vvv and Spq, Svq, Smq; and the feature parameters
    Spd, Spc, S5p, S5v, S10z, Sda, Sha, Sdv, Shv of the watershed segmentation with
    Wolf pruning (ISO 25178-2:2021). NaN points are left out.

    \b
    Examples:
        rough detrend --order 1 --crop 468um:733um dektak.csv | rough features
        rough features --cutoff 0.8mm --json scan.x3p
        rough features --list features.tsv --plot profile.png rock.tsv
        rough features --height -1um --ratio 20 --volume-ratios 5:85 scan.x3p
        rough features --pruning 10 --segments motifs.tsv scan.x3p
        rough features --vs-length rock.tsv
    """
    if isinstance(surface, io.TiledSurface):
        untiled = {
            "--cutoff": cutoff,
            "--along": along,
            "--plot": plot,
            "--segments": segments,
            "--list": feature_list,
            "--vs-length": vs_length,
        }
        settings = Settings(
            None, None, slope, jrc_spacing, None, material_height, material_ratio, dc_ratios, volume_ratios, acf
        )
        return _tiled(
            surface, settings, pruning, edge_features, [name for name, given in untiled.items() if given], work
        )
    report = not on_stdout(list=feature_list, plot=plot, segments=segments)
    evaluated = surface if cutoff is None else metrology.split(surface, cutoff, "roughness", ends)
    settings = Settings(
        cutoff,
        sampling_lengths,
        slope,
        jrc_spacing,
        along,
        material_height,
        material_ratio,
        dc_ratios,
        volume_ratios,
        acf,
    )
    if segments and (surface.is_profile or along):
        raise errors.InputError(
            "--segments needs a map evaluated as a map, without --along (a profile's features: --list)"
        )
    values = metrology.parameters(
        evaluated,
        sampling_lengths=sampling_lengths,
        slope=slope,
        along=along,
        jrc_spacing=jrc_spacing,
        sampling_length=cutoff,
        acf=acf,
        families=["field"],
    )
    functional = metrology.functional_parameters(
        evaluated,
        height=material_height,
        ratio=material_ratio,
        dc_ratios=dc_ratios,
        volume_ratios=volume_ratios,
        along=along,
    )
    rows, document = _parameter_rows(evaluated, values, functional, settings)
    metrology.announce_undefined(functional)
    if not (surface.is_profile or along):
        hills, dales = (metrology.segment(evaluated, kind, pruning) for kind in ("hills", "dales"))
        featured = metrology.motif_parameters(evaluated, hills, dales, edge_features)
        metrology.announce_undefined(featured, metrology.undefined_reasons(hills, dales, edge_features))
        segmentation = _segmentation(pruning, edge_features, values["Sz"])
        rows += _value_rows(featured, metrology.FEATURE, {"Spd": segmentation["text"]})
        document.update(featured)
        document["evaluation"]["segmentation"] = segmentation["settings"]
        if segments:
            with io.atomic_output(segments) as stream:
                stream.write(_segment_table(hills, dales, pruning).encode())
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
        with io.atomic_output(feature_list) as stream:
            stream.write(_feature_table(found).encode())
    if plot:
        curve = metrology.MaterialRatioCurve(evaluated)
        figure = figures.features_figure(evaluated, found, (centres, density), curve, title=shown(input))
        figures.save(figure, plot)
    return Report(rows, document) if report else None


@dataclasses.dataclass(frozen=True)
class Settings:
    """How the parameters were evaluated: the options that shape them."""

    cutoff: float
    sampling_lengths: int
    slope: str
    jrc_spacing: float
    along: str
    height: float
    ratio: float
    dc_ratios: tuple
    volume_ratios: tuple
    acf: str


def _parameter_rows(surface, values, functional, settings):
    valid = int(surface.valid.sum())
    extent = " × ".join(units.format_length(s) for s in surface.size)
    basis = (
        f"roughness at λc = {units.format_length(settings.cutoff)}"
        if settings.cutoff
        else "data as given, mean removed"
    )
    if settings.along:
        basis += f", profiles along {settings.along}"
    profile = surface.is_profile or settings.along
    sections = _sampling(surface, settings) if profile else None
    evaluation = {
        "points": surface.heights.size,
        "valid_points": valid,
        "size": list(surface.size),
        "basis": basis,
        "slope": settings.slope,
        "jrc_spacing": settings.jrc_spacing,
        "cutoff": settings.cutoff,
        "material_ratio": {
            "height": settings.height,
            "ratio": settings.ratio,
            "dc_ratios": list(settings.dc_ratios),
            "volume_ratios": list(settings.volume_ratios),
        },
    }
    if profile:
        evaluation["sampling_lengths"] = len(sections)
        evaluation["sampling_length"] = _sampling_length(surface, settings, sections)
    else:
        evaluation["acf"] = settings.acf
    ratio_units = {"height": "m", "ratio": "%", "dc_ratios": "%", "volume_ratios": "%"}
    unit = {"points": "points", "valid_points": "points", "size": "m", "jrc_spacing": "m", "cutoff": "m"}
    unit["sampling_length"] = "m"
    unit |= {"material_ratio": ratio_units, "segmentation": {"pruning": "%", "threshold": "m"}}
    rows = [("evaluation", evaluation, unit, f"{extent}, {valid} of {surface.heights.size} points valid; {basis}")]
    notes = _notes(surface, values, settings, sections)
    rows += _value_rows(values, metrology.PROFILE if profile else metrology.AREAL, notes)
    rows += _value_rows(functional, metrology.PROFILE_FUNCTIONAL if profile else metrology.AREAL_FUNCTIONAL, notes)
    if "JRC" in values and not 0 <= values["JRC"] <= 20:
        logging.getLogger("rough").warning(
            "JRC = %.4g is outside the 0–20 range the Tse–Cruden relation was calibrated on", values["JRC"]
        )
    return rows, {**values, **functional, "evaluation": evaluation}


def _tiled(surface, settings, pruning, edges, untiled, work):
    """The report of a map read in tiles (:func:`rough.metrology.tiled_evaluation`)."""
    if untiled:
        raise errors.InputError(
            f"{', '.join(untiled)} cannot be had on a map read in tiles; crop it, or give a larger --memory"
        )
    found = metrology.tiled_evaluation(
        surface,
        slope=settings.slope,
        acf=settings.acf,
        height=settings.height,
        ratio=settings.ratio,
        dc_ratios=settings.dc_ratios,
        volume_ratios=settings.volume_ratios,
        pruning=pruning,
        edges=edges,
        **work,
    )
    values, section = found.values, found.section
    extent = " × ".join(units.format_length(s) for s in surface.size)
    basis = "data as given, mean removed"
    evaluation = {
        "points": surface.point_count,
        "valid_points": found.count,
        "size": list(surface.size),
        "basis": basis,
        "slope": settings.slope,
        "jrc_spacing": settings.jrc_spacing,
        "cutoff": None,
        "acf": settings.acf,
        "material_ratio": {
            "height": settings.height,
            "ratio": settings.ratio,
            "dc_ratios": list(settings.dc_ratios),
            "volume_ratios": list(settings.volume_ratios),
        },
        "segmentation": _segmentation(pruning, edges, values["Sz"])["settings"],
    }
    unit = {"points": "points", "valid_points": "points", "size": "m", "jrc_spacing": "m", "cutoff": "m"}
    unit |= {"material_ratio": {"height": "m", "ratio": "%", "dc_ratios": "%", "volume_ratios": "%"}}
    unit["segmentation"] = {"pruning": "%", "threshold": "m"}
    text = f"{extent}, {found.count} of {surface.point_count} points valid; {basis}"
    rows = [("evaluation", evaluation, unit, text)]
    estimated = ", ".join(section["estimated"])
    tiles = f"read in {section['tiles']} strips of {section['tile_rows']} rows; estimated: {estimated}"
    if section["undefined"]:
        tiles += f"; undefined on tiles: {', '.join(section['undefined'])}"
    rows.append(("tiled", section, {"tile_rows": "rows", "spectrum_tile": "points", "pruning": "%"}, tiles))
    notes = _notes(surface, values, settings, None)
    notes |= {key: "; ".join(filter(None, (notes.get(key), "estimated"))) for key in section["estimated"]}
    for table in (metrology.AREAL, metrology.AREAL_FUNCTIONAL, metrology.FEATURE):
        rows += _value_rows(values, table, notes)
    centres, density = found.density
    document = {**values, "evaluation": evaluation, "tiled": section}
    document["amplitude_density"] = {"height": centres.tolist(), "density": density.tolist()}
    return Report(rows, document)


def _value_rows(values, table, notes=None):
    """A row per parameter of ``table`` (key: (unit, meaning)), its note in brackets."""
    notes = notes or {}
    return [
        (key, values[key], unit, f"{units.format_quantity(values[key], unit):<14} {meaning}" + _bracket(notes.get(key)))
        for key, (unit, meaning) in table.items()
    ]


def _bracket(note):
    return f" ({note})" if note else ""


def _sampling(surface, settings):
    """The sampling lengths of the profiles evaluated, as index ranges."""
    axis = 1 if settings.along == "y" else 0
    return metrology.sampling_sections(
        surface.points[axis], surface.spacing[axis], settings.cutoff, settings.sampling_lengths
    )


def _notes(surface, values, settings, sections):
    c = f"c = {units.format_length(settings.height)} about the mean"
    mr = f"mr = {settings.ratio:g} %"
    dc = f"between {settings.dc_ratios[0]:g} % and {settings.dc_ratios[1]:g} %"
    pq = f"p = {settings.volume_ratios[0]:g} %, q = {settings.volume_ratios[1]:g} %"
    notes = {
        "Rz": _sampling_note(surface, settings, sections),
        "Rdq": f"{settings.slope} slope",
        "Sdq": f"{settings.slope} slope",
        "Sal": f"{settings.acf} autocorrelation",
        "JRC": f"Z2 at {units.format_length(max(settings.jrc_spacing, surface.spacing[0]))} spacing",
        "Rmr": c,
        "Smr": c,
        "Rmc": mr,
        "Smc": mr,
        "Vm": mr,
        "Vv": mr,
        "Rdc": dc,
        "Sdc": dc,
        **dict.fromkeys(("Vmp", "Vmc", "Vvc", "Vvv"), pq),
    }
    if "JRC" in values and not 0 <= values["JRC"] <= 20:
        notes["JRC"] += "; outside the 0–20 range the relation was calibrated on"
    return notes


def _sampling_length(surface, settings, sections):
    """The sampling length in metres: λc, or the length of the equal sections."""
    if settings.cutoff is not None:
        return settings.cutoff
    axis = 1 if settings.along == "y" else 0
    return surface.points[axis] / len(sections) * surface.spacing[axis]


def _sampling_note(surface, settings, sections):
    if sections is None:
        return None
    if settings.cutoff is None:
        return f"{len(sections)} sampling lengths"
    return f"{len(sections)} sampling lengths of λc = {units.format_length(settings.cutoff)}"


def _segmentation(pruning, edges, sz):
    threshold = pruning / 100 * sz
    settings = {"pruning": pruning, "threshold": threshold, "edges": edges}
    text = (
        f"Wolf pruning at {pruning:g} % of Sz = {units.format_length(threshold)}; hills and dales at the edge {edges}d"
    )
    return {"text": text, "settings": settings}


def _segment_table(hills, dales, pruning):
    lines = [
        f"# rough features: one row per hill and dale (watershed, Wolf pruning at {pruning:g} % of Sz); "
        "x, y, heights about the mean in m, area in m², volume in m³, curvature in 1/m; edge 1 = touches the "
        "border or invalid points",
        "kind\tx\ty\theight\tsaddle\tarea\tvolume\tcurvature\tedge",
    ]
    for segmentation in (hills, dales):
        lines += [
            "\t".join(
                [m.kind, *(repr(float(v)) for v in (m.x, m.y, m.height, m.saddle, m.area, m.volume, m.curvature))]
                + [str(int(m.edge))]
            )
            for m in segmentation.motifs
        ]
    return "\n".join(lines) + "\n"


def _detect(surface, cutoff, mode, polarity):
    settings = {"cutoff": cutoff, "mode": mode, "polarity": polarity, "k": 2.0, "extension": 0.3}
    try:
        found, info = metrology.detect_features(surface, cutoff=cutoff, mode=mode, polarity=polarity)
    except errors.InputError as error:
        return [], {"text": f"not detected ({error})", "settings": {**settings, "skipped": str(error)}}
    text = (
        f"{len(found)} (mode {mode}, λc {units.format_length(cutoff)}, threshold 2·Rq_hf = "
        f"{units.format_length(info['threshold'])}, +30 % lateral)"
    )
    return found, {"text": text, "settings": {**settings, **info}}


def _scaling_rows(scaling):
    key = "Rq" if "Rq" in scaling else "Sq"
    rows = [
        (
            f"rq_vs_length.{key}.{index}",
            value,
            "m",
            f"{units.format_length(value)} over {count} windows",
            f"{key}(L={units.format_length(length)})",
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
