"""rough info: what a surface file holds."""

import click

from .. import io, metrology, units
from .options import crop_option, report_format, tiled_input
from .report import Report
from .work_options import jobs_option


@click.command(short_help="Shape, spacing, size, valid points, z range, Rq/Sq and history.")
@tiled_input
@jobs_option
@crop_option
@report_format
def info(surface, input, work):
    """Describe the surface in INPUT (default: standard input).

    Reports the number of points and spacing (x first), the physical size, the
    valid (non-NaN) points, the height range and the RMS height (Rq for a profile,
    Sq for a map) of the valid points about their mean, with no levelling; then the
    file's metadata and history.

    \b
    Examples:
        rough info scan.x3p
        rough synth --length 20mm --dimension 1.3 --rq 10um | rough info
        rough info --json scan.x3p | jq .spacing
        rough info --tsv a.x3p b.x3p c.x3p > inventory.tsv
    """
    facts = metrology.summary(surface, **work)
    document = {"format": surface.source_format, **facts}
    document["units"] = {**facts["units"], "assumed": list(surface.units.assumed)}
    x_by_y = " × ".join
    rms_key = "Rq" if surface.is_profile else "Sq"
    digits = _digits(facts["z_min"], facts["z_max"])
    rows = [
        ("format", surface.source_format, "", io.describe(surface.source_format)),
        ("kind", facts["kind"], "", facts["kind"]),
        (
            "shape",
            facts["shape"],
            "points",
            f"{x_by_y(map(str, facts['shape']))} points" + ("" if surface.is_profile else " (x × y)"),
        ),
        ("spacing", facts["spacing"], "m", x_by_y(units.format_length(d) for d in facts["spacing"])),
        ("size", facts["size"], "m", x_by_y(units.format_length(s) for s in facts["size"])),
        (
            "origin",
            facts["origin"],
            "m",
            ", ".join(
                units.format_length(o, units.digits_for(o, d), scale=d)
                for o, d in zip(facts["origin"], facts["spacing"])
            ),
        ),
        (
            "valid_points",
            facts["valid_points"],
            "points",
            f"{facts['valid_points']} of {facts['points']} ({100 * facts['valid_points'] / facts['points']:.2f} %)",
        ),
        ("z_min", facts["z_min"], "m", _length(facts["z_min"], digits)),
        ("z_max", facts["z_max"], "m", _length(facts["z_max"], digits)),
        (rms_key, facts[rms_key], "m", f"{_length(facts[rms_key])} (valid points about their mean, not levelled)"),
        ("units", document["units"], "", surface.units.description()),
    ]
    if isinstance(surface, io.TiledSurface):
        rows.append(("tiled", True, "", "read a strip at a time: larger than the memory budget (--memory)"))
        document["tiled"] = True
    rows += [(f"metadata.{key}", value, "", value) for key, value in sorted(facts["metadata"].items())]
    rows += [(f"history.{number}", entry, "", _history_line(entry)) for number, entry in enumerate(facts["history"])]
    return Report(rows, document)


def _length(value, digits=5):
    return "none (no valid points)" if value is None else units.format_length(value, digits)


def _digits(low, high):
    """Significant digits that tell ``low`` from ``high`` (a 4 µm range at 106 mm
    needs eight)."""
    if low is None or high is None:
        return 5
    return units.digits_for(max(abs(low), abs(high)), (high - low) / 100)


def _history_line(entry):
    parameters = " ".join(f"{key}={value}" for key, value in entry.get("parameters", {}).items())
    return (
        f"{entry.get('time', '?')}  rough {entry.get('version', '?')} {entry.get('command', '?')} {parameters}".rstrip()
    )
