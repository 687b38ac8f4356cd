"""A whole report written in one call: surfaces read, sections made, the page
rendered and written atomically as HTML or PDF."""

import inspect
import os
import sys

from .. import errors, io, metrology, units
from ..extras import require
from .choices import FORMATS, SETS
from .rendering import load_template, render_html, render_pdf
from .sections import filter_text, form_text, surface_section

SUFFIXES = {".html": "html", ".htm": "html", ".pdf": "pdf"}


def format_of(target, format=None):
    """The format of a report written to ``target``: ``format`` if given, else from the
    suffix (``.html``, ``.htm``, ``.pdf``); standard output (``-``) is HTML. Checked
    here, before any work: that matplotlib is installed (and WeasyPrint for a PDF),
    that a PDF does not go to a terminal, and that the target's folder exists.

    >>> format_of("report.pdf"), format_of("-"), format_of("out.txt", "html")
    ('pdf', 'html', 'html')
    """
    if format is None:
        suffix = os.path.splitext(os.fspath(target))[1].lower()
        if target != "-" and suffix not in SUFFIXES:
            raise errors.InputError(
                f"{target}: cannot tell the report's format from {suffix or 'no suffix'}: "
                "name a .html or .pdf file, or give the format"
            )
        format = SUFFIXES.get(suffix, "html")
    if format not in FORMATS:
        raise errors.InputError(f"unknown report format {format!r} (choose from {', '.join(FORMATS)})")
    require("matplotlib")  # optional: report (the figures)
    if format == "pdf":
        require("weasyprint")  # optional: report
        if _on_terminal(os.fspath(target)):
            raise errors.InputError("refusing to write a PDF to a terminal: give -o FILE, or a pipe", filename=target)
    _check_folder(os.fspath(target))
    return format


def _check_folder(target):
    """Refuse, before any work, a report that could not be written where it is asked."""
    if target == "-" or io.names_a_terminal(target):
        return
    if os.path.isdir(target):
        raise errors.InputError(f"{target}: is a folder, not a file to write", filename=target)
    folder = os.path.dirname(os.path.abspath(target))
    if not os.path.isdir(folder):
        raise errors.InputError(f"{target}: cannot write, folder {folder} does not exist", filename=target)


def _on_terminal(target):
    return io.is_terminal(sys.stdout) if target == "-" else io.names_a_terminal(target)


def settings_text(parameters=SETS, cutoff=None, ends="trim", order=None, fill=False, band=None):
    """How the surfaces of a report were evaluated, as the report lists it."""
    return {
        "parameter sets": ", ".join(parameters),
        "form removed": form_text(order),
        "filter": filter_text(cutoff, ends),
        "fit band": "the scaling range" if band is None else _band_text(*band),
        "gaps": "filled for the spectrum and the rose" if fill else "left out (a map with gaps has no spectrum)",
        "conditions": conditions_text(),
    }


def _band_text(low, high):
    """A band given to the fits (1/m), either end open (None)."""
    if low is not None and high is not None:
        return units.format_range(low, high, "1/m")
    return " to ".join("open" if end is None else units.format_quantity(end, "1/m", 4) for end in (low, high))


def conditions_text():
    """The conditions of the parameters, which the report takes at the defaults of
    :func:`rough.metrology.parameters` (those of ``rough features``)."""
    given = {
        name: parameter.default
        for name, parameter in inspect.signature(metrology.parameters).parameters.items()
        if parameter.default is not parameter.empty
    }
    said = {
        "slope": lambda v: f"{v} slopes",
        "acf": lambda v: f"{v} autocorrelation",
        "jrc_spacing": lambda v: f"Z2 at {units.format_quantity(v, 'm')}",
        "height": lambda v: f"Rmr/Smr at c = {units.format_quantity(v, 'm')} about the mean",
        "ratio": lambda v: f"Rmc/Smc, Vm, Vv at mr = {v:g} %",
        "dc_ratios": lambda v: f"Rδc/Sdc between {v[0]:g} % and {v[1]:g} %",
        "volume_ratios": lambda v: f"volumes split at p = {v[0]:g} %, q = {v[1]:g} %",
        "pruning": lambda v: f"Wolf pruning at {v:g} % of Sz",
        "edge_features": lambda v: f"hills and dales at the edge: {v}",
    }
    return "; ".join(text(given[name]) for name, text in said.items() if name in given)


def write_sections(sections, target, *, template=None, format=None, title=None, settings=None):
    """Render ``sections`` (:func:`rough.reports.surface_section`) and write them to
    ``target`` atomically: HTML, or PDF (see :func:`write_report`)."""
    html = render_html(sections, title=title, template=template, settings=settings)
    data = render_pdf(html) if format_of(target, format) == "pdf" else html.encode("utf-8")
    with io.atomic_output(target) as stream:
        stream.write(data)


def write_report(surfaces, target, *, template=None, format=None, title=None, **evaluation):
    """Write the report of ``surfaces`` to ``target``: ``rough report``.

    One section per surface (:func:`rough.reports.surface_section`: the surface, the
    form and filter used, every parameter with its unit and standard, the
    Abbott–Firestone curve, the spectrum with its fitted power law and band, the rose
    of a map, the verdicts and warnings, the history and metadata) after a summary
    table of every surface's parameters. The HTML is one file: figures embedded as
    ``data:`` URIs, no network access; with ``SOURCE_DATE_EPOCH`` set its bytes are
    the same on every run.

    Parameters
    ----------
    surfaces : sequence of Surface or path
        The surfaces, or files to read (:func:`rough.read`); NaN points are left out
        of the parameters (see ``fill`` for the spectrum and rose).
    target : str or os.PathLike
        The report file (written atomically); ``-`` is standard output.
    template : str or os.PathLike, optional
        A Jinja2 template file to lay the report out (docs/report.rst lists its
        variables); default the built-in one.
    format : {"html", "pdf"}, optional
        Default: from ``target``'s suffix; HTML on standard output.
    title : str, optional
        The report's title.
    **evaluation
        How each surface is evaluated, the keywords of
        :func:`~rough.reports.surface_section`: ``parameters`` (the sets to list, default
        all of :data:`rough.reports.SETS`), ``cutoff`` (a Gaussian cut-off λc in metres:
        report the roughness), ``ends``, ``order`` (remove the polynomial form of this
        degree first), ``fill`` (fill a map's invalid points for its spectrum and rose)
        and ``band`` (the fits' band in 1/m, as ``rough fit-fractal --band``).

    Returns
    -------
    list of Section
        The sections written.

    Raises
    ------
    rough.InputError
        An unreadable input or template, an unknown format or parameter set.

    Examples
    --------
    >>> import rough
    >>> sections = rough.reports.write_report([rough.sample("rock-profile.tsv")], "rock-report.html")
    >>> sections[0].values["Rq"].unit
    'm'
    """
    format = format_of(target, format)
    template = load_template(template)
    sections = [
        surface_section(
            _surface(each),
            _name(each, index),
            anchor=f"surface-{index + 1}",
            **evaluation,
        )
        for index, each in enumerate(surfaces)
    ]
    settings = settings_text(**evaluation)
    write_sections(sections, target, template=template, format=format, title=title, settings=settings)
    return sections


def _surface(each):
    return io.read(each) if isinstance(each, (str, os.PathLike)) else each


def _name(each, index):
    if isinstance(each, (str, os.PathLike)):
        return os.fspath(each)
    return each.metadata.get("title") or f"surface {index + 1}"
