"""Sections laid out as one HTML page through a Jinja2 template (the default one in
``rough/reports/templates``, or a lab's own), and that page printed as PDF by
WeasyPrint. The variables a template receives are listed in docs/report.rst."""

import dataclasses
import importlib.resources
import math
import os
import traceback

from .. import __version__, errors, units
from ..extras import require
from ..surface import timestamp

DEFAULT = "report.html.j2"
STYLE = "report.css"
SCRIPT = "sortable.js"
VARIABLES = ("title", "date", "version", "settings", "sections", "summaries", "style", "script")


@dataclasses.dataclass(frozen=True)
class Column:
    """A column of the summary: parameter ``key`` in SI ``unit``, shown in ``symbol``
    (a prefixed unit chosen for the column's values) as SI value × ``scale``."""

    key: str
    unit: str
    symbol: str
    scale: float
    meaning: str
    reference: str

    def cell(self, value):
        """The text of ``value`` (SI) in this column's unit."""
        return "undefined" if math.isnan(value) else f"{value * self.scale:.4g}"


def load_template(path=None):
    """The Jinja2 template of a report: the default one, or the file ``path`` (a lab's
    own layout; see docs/report.rst for the variables it receives).

    Parameters
    ----------
    path : str or os.PathLike, optional
        A Jinja2 template file. It may ``{% include %}`` or ``{% extends %}`` a file
        beside it or the default template, ``report.html.j2`` (its own folder is
        searched first). Checked here, before any work: its syntax and that of every
        template it names, that those exist, and that it uses no variable but those
        of docs/report.rst.

    Returns
    -------
    jinja2.Template

    Raises
    ------
    rough.InputError
        A file that cannot be read or is not a valid template, a template it names
        that is not found, a variable it is not given: one line naming the file and
        the line of the mistake.
    """
    if path is None:
        return _environment().get_template(DEFAULT)
    path = os.fspath(path)
    try:
        with open(path, encoding="utf-8") as stream:
            stream.read()
    except (OSError, UnicodeDecodeError) as error:
        raise errors.InputError(f"{path}: cannot read the template: {getattr(error, 'strerror', error)}") from None
    jinja2 = require("jinja2")  # optional: report
    environment = _environment(os.path.dirname(os.path.abspath(path)))
    try:
        template = environment.get_template(os.path.basename(path))
        _check_names(environment, template.filename, set())
    except jinja2.TemplateError as error:
        filename = getattr(error, "filename", None) or path
        raise errors.InputError(f"{filename}: {_where(error)}not a valid report template: {error.message}") from None
    return template


def _check_names(environment, filename, checked):
    """Refuse a variable not in :data:`VARIABLES` or a template not found in the
    template file ``filename`` and, in turn, in every template it names."""
    jinja2 = require("jinja2")  # optional: report
    meta = require("jinja2.meta")  # optional: report
    checked.add(filename)
    with open(filename, encoding="utf-8") as stream:
        tree = environment.parse(stream.read(), filename=filename)
    unknown = meta.find_undeclared_variables(tree) - set(VARIABLES) - set(environment.globals)
    for node in tree.find_all(jinja2.nodes.Name):
        if node.name in unknown:
            given = ", ".join(VARIABLES)
            raise _refused(filename, node.lineno, f"{node.name!r} is undefined (a report template is given {given})")
    named = (jinja2.nodes.Extends, jinja2.nodes.Include, jinja2.nodes.Import, jinja2.nodes.FromImport)
    for node in tree.find_all(named):
        name = node.template.value if isinstance(node.template, jinja2.nodes.Const) else None
        if not isinstance(name, str) or getattr(node, "ignore_missing", False):
            continue
        try:
            found = environment.get_template(name).filename
        except jinja2.TemplateNotFound:
            raise _refused(filename, node.lineno, f"{name} is found neither beside it nor among rough's") from None
        if found not in checked:
            _check_names(environment, found, checked)


def _refused(filename, line, problem):
    return errors.InputError(f"{filename}: line {line}: not a valid report template: {problem}")


def render_html(sections, *, title=None, template=None, settings=None):
    """The report of ``sections`` as one self-contained HTML page.

    Parameters
    ----------
    sections : list of Section
        From :func:`rough.reports.surface_section`, one per surface, in order.
    title : str, optional
        The report's title; default ``"Surface report"``.
    template : jinja2.Template, optional
        From :func:`load_template`; default the built-in one.
    settings : dict of str to str, optional
        How the surfaces were evaluated (shown as a list; e.g. ``{"filter": "none"}``).

    Returns
    -------
    str
        The HTML. Undefined (NaN) parameters read "undefined"; each summary cell
        carries its SI value in ``data-value`` (empty when undefined).

    Raises
    ------
    rough.InputError
        A template that uses a variable it is not given, or fails as it renders.
    """
    jinja2 = require("jinja2")  # optional: report
    template = template or load_template()
    context = {
        "title": title or "Surface report",
        "date": timestamp(),
        "version": __version__,
        "settings": settings or {},
        "sections": sections,
        "summaries": summaries(sections),
        "style": _resource(STYLE),
        "script": _resource(SCRIPT),
    }
    try:
        return template.render(context)
    except Exception as error:  # a lab's template can fail any way: said in one line if it is the template's
        where = _template_frame(error)
        if where is None and not isinstance(error, jinja2.TemplateError):
            raise
        filename, line = where or (getattr(error, "filename", None) or template.filename, error.lineno)
        message = error.message if isinstance(error, jinja2.TemplateError) else f"{error} ({type(error).__name__})"
        place = f"{filename}: line {line}: " if line else f"{filename}: "
        raise errors.InputError(f"{place}the report template failed: {message}") from None


def render_pdf(html):
    """``html`` (from :func:`render_html`) printed as PDF by WeasyPrint (the ``report``
    extra): A4 pages, each surface from a new page. Returns the PDF's bytes."""
    weasyprint = require("weasyprint")  # optional: report
    return weasyprint.HTML(string=html, base_url=None).write_pdf()


@dataclasses.dataclass(frozen=True)
class Summary:
    """A summary table of the sections of one ``kind`` (``"map"`` or ``"profile"``):
    its :class:`Column` objects and its rows, each ``{"section": Section, "cells":
    [(SI value or None, text), ...]}`` in the order of the columns."""

    kind: str
    columns: list
    rows: list


def summaries(sections):
    """One :class:`Summary` per kind of surface among ``sections`` (maps and profiles
    have different parameters), in order of first appearance."""
    tables = []
    for kind in dict.fromkeys(section.kind for section in sections):
        alike = [section for section in sections if section.kind == kind]
        columns = summary_columns(alike)
        tables.append(Summary(kind, columns, [_row(section, columns) for section in alike]))
    return tables


def summary_columns(sections):
    """The summary's :class:`Column` objects: every parameter of any section, in
    order of first appearance, each in a unit that suits its largest value."""
    columns = {}
    for section in sections:
        for parameter in section.parameters:
            columns.setdefault(parameter.key, []).append(parameter)
    return [_column(found) for found in columns.values()]


def _column(parameters):
    first = parameters[0]
    finite = [abs(p.value) for p in parameters if math.isfinite(p.value) and p.value != 0]
    scale, symbol = _unit_of(max(finite, default=0.0), first.unit)
    return Column(first.key, first.unit, symbol, scale, first.meaning, first.reference)


def _unit_of(magnitude, unit):
    """(scale, symbol) of a column whose largest value is ``magnitude`` (SI ``unit``):
    a length unit takes the prefix of :func:`rough.units.scale_for`; others are
    printed as they are (``%``, ``°``, nothing for a pure number)."""
    if unit in units.LENGTH_POWERS:
        return units.scale_for(magnitude, unit)
    return 1.0, {"%": "%", "deg": "°"}.get(unit, "")


def _row(section, columns):
    found = section.values
    return {
        "section": section,
        "cells": [(found[c.key].value, c.cell(found[c.key].value)) if c.key in found else (None, "") for c in columns],
    }


def _environment(folder=None):
    """The Jinja2 environment: templates are looked for in ``folder`` (a lab's
    template's own), then among rough's."""
    jinja2 = require("jinja2")  # optional: report
    loader = jinja2.PackageLoader("rough.reports", "templates")
    if folder is not None:
        loader = jinja2.ChoiceLoader([jinja2.FileSystemLoader(folder), loader])
    return jinja2.Environment(loader=loader, autoescape=True, undefined=jinja2.StrictUndefined)


def _template_frame(error):
    """(file, line) of the innermost frame of a template in ``error``'s traceback
    (Jinja2 rewrites those frames to name the template file and line), or None."""
    inside = [(f.filename, f.lineno) for f in traceback.extract_tb(error.__traceback__) if _is_template(f.filename)]
    return inside[-1] if inside else None


def _is_template(filename):
    return not filename.endswith(".py") and not filename.startswith("<")


def _resource(name):
    return importlib.resources.files("rough.reports").joinpath("templates", name).read_text(encoding="utf-8")


def _where(error):
    line = getattr(error, "lineno", None)
    return f"line {line}: " if line else ""
