"""rough report: one HTML or PDF report of several surfaces, a lab can hand on
(:func:`rough.reports.write_report`)."""

import click

from .. import reports
from .features import features
from .fit_fractal import fit_fractal
from .options import Command, crop_option, surface_input
from .report import shown
from .show import show
from .targets import check_target


class SetsType(click.ParamType):
    """A comma-separated list of parameter sets (:data:`rough.reports.SETS`)."""

    name = "SET,..."

    def convert(self, value, param, ctx):
        if isinstance(value, tuple):
            return value
        chosen = tuple(part.strip() for part in value.split(",") if part.strip())
        unknown = [name for name in chosen if name not in reports.SETS]
        if unknown or not chosen:
            self.fail(f"{', '.join(unknown) or 'none'}: choose from {', '.join(reports.SETS)}", param, ctx)
        return chosen


def _one_file(ctx, param, value):
    """The report's file, checked as every output is; one file, so no ``{stem}``."""
    if "{" in value:
        raise click.BadParameter(
            f"{value}: the report is one file: name it without {{…}} placeholders", param_hint=f"'{param.opts[-1]}'"
        )
    return check_target(value, param)


def _add_section(surface, input, sections, settings):
    """The section of one input, kept for the report (run by :func:`surface_input` per input)."""
    anchor = f"surface-{len(sections) + 1}"
    sections.append(reports.surface_section(surface, shown(input), anchor=anchor, **settings))


_each_input = surface_input(_add_section)


def _input_options(command):
    """INPUT... and the read options of :func:`surface_input`, on the report command."""
    command.__click_params__ = [*getattr(command, "__click_params__", []), *_each_input.__click_params__]
    return command


def _options_of(other, *names):
    """The options ``names`` of the command ``other``, the same on this one: the
    filter of ``features``, the form of ``show``."""

    def decorate(command):
        taken = [param for param in other.params if param.name in names]
        command.__click_params__ = [*getattr(command, "__click_params__", []), *reversed(taken)]
        return command

    return decorate


@click.command(cls=Command, short_help="A report of surfaces as one HTML page or PDF: figures, parameters, fits.")
@_input_options
@click.option(
    "-o",
    "--output",
    required=True,
    type=click.Path(allow_dash=True),
    metavar="FILE",
    callback=_one_file,
    help="The report: .html or .pdf (written atomically); - is standard output (HTML).",
)
@click.option(
    "-f", "--format", "report_format", type=click.Choice(reports.FORMATS), help="Force the format (default: from -o)."
)
@click.option(
    "--parameters",
    type=SetsType(),
    default=",".join(reports.SETS),
    show_default=True,
    help="The parameter sets to list (ISO 25178-2's classes; functional: ISO 13565 material ratio; other: "
    "peak density, Z2, JRC).",
)
@_options_of(features, "cutoff", "ends")
@_options_of(show, "order")
@_options_of(fit_fractal, "band")
@click.option("--fill", is_flag=True, help="Fill a map's invalid points for its spectrum and rose (as fit-fractal).")
@click.option(
    "--template",
    type=click.Path(dir_okay=False),
    metavar="FILE",
    help="A Jinja2 template for the lab's own layout (docs/report.rst lists its variables).",
)
@click.option("--title", help="The report's title (default: Surface report).")
@crop_option
def report(output, report_format, parameters, cutoff, ends, order, band, fill, template, title, **read):
    """Write one report of the surfaces in INPUT... : a summary table of every
    surface's parameters (sortable, with units, each file linked to its section),
    then a section per surface with the surface as `rough show` draws it, the form
    removed and the filter used, every parameter with its value, unit and standard
    (ISO 25178-2, ISO 21920-2), the Abbott–Firestone curve, the spectrum with the
    fitted power law over its band (--band as fit-fractal's, else the scaling
    range), the rose of a map, the verdicts and warnings, and the file's history
    and metadata. The parameters are those of `rough features`
    with the same options. A part that cannot be computed for a surface says why in
    its section. An unreadable input is reported in one line and left out (exit
    status 2).

    The HTML is one file with the figures embedded and nothing to fetch; the PDF
    (WeasyPrint) prints the same page, each surface from a new page. With
    SOURCE_DATE_EPOCH set the HTML is the same to the byte on every run.

    \b
    Examples:
        rough report scan.x3p rock.tsv -o report.html
        rough report --cutoff 0.8mm --parameters height,functional -o report.pdf a.x3p b.x3p
        rough report --order 1 --fill --title "Batch 12" map.x3p -o - > report.html
        rough report --template lab.html.j2 -o lab.html scan.x3p
    """
    format = reports.format_of(output, report_format)
    layout = reports.load_template(template)
    settings = dict(parameters=parameters, cutoff=cutoff, ends=ends, order=order, fill=fill, band=band)
    sections = []
    status = _each_input(**read, sections=sections, settings=settings)
    if sections:
        reports.write_sections(
            sections,
            output,
            template=layout,
            format=format,
            title=title,
            settings=reports.settings_text(**settings),
        )
    return status
