"""Printing results: one output contract for every command (docs/output.rst).

A command's result is a :class:`Report`: ``rows`` for the text table and TSV, and
``document``, the JSON object. A row is ``(key, value, unit, text)`` or ``(key, value,
unit, text, label)``: ``key`` is a dotted path into the document whose value is
``value`` (SI units); ``text`` is the value written for reading; ``label`` replaces
the key in the text table (rows of per-angle and per-run tables); a row whose key
is None is text only (a table's header). ``unit`` is a string, or for a dict value
a dict of units by name.

- text: one aligned ``key  text`` line per row; several inputs: one block each.
- ``--json``: the document with ``file`` (the input as given, ``-`` for standard
  input) first and ``warnings`` (what was flagged or undefined) last; NaN as null;
  several inputs: JSON Lines, one object per input.
- ``--tsv``: rows ``file, key, value, unit`` with no header; ``value`` only ever a
  plain number or empty, a text value (or true/false) in the last column with the
  value empty; a list value becomes the rows ``key.0``, ``key.1``…, a dict value
  ``key.name``…, so that the outputs of several runs concatenate into one table.
"""

import contextlib
import dataclasses
import json
import logging
import math

import click

from .. import io


@dataclasses.dataclass
class Report:
    """What a command found for one input: rows for people and TSV, a JSON document."""

    rows: list
    document: dict


def printable(text):
    """``text`` on one line and safe for a terminal: control characters and other
    non-printable ones escaped as Python would (``\\n``, ``\\x1b``)."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(text))


def shown(file):
    """An input's name for people (figure titles, the text table): ``-`` is standard input."""
    return "standard input" if file == "-" else file


def echo(line):
    """Print one line on standard output; a RoughError when it is closed."""
    io.standard_output()
    click.echo(line)


def on_stdout(**files):
    """Whether a side file (``--plot``, ``--psd``, ``--list``) is ``-``: standard output
    then carries it instead of the report. Two of them there is a usage error."""
    dashes = [f"--{option}" for option, path in files.items() if path == "-"]
    if len(dashes) > 1:
        raise click.UsageError(f"{' and '.join(dashes)} cannot both go to standard output")
    return bool(dashes)


def flatten(key, value, unit=""):
    """``(key, value, unit)`` for every leaf of ``value``: list items as ``key.0``,
    ``key.1``…, dict items as ``key.name``."""
    if isinstance(value, dict):
        for name, item in value.items():
            yield from flatten(f"{key}.{name}", item, unit.get(name, "") if isinstance(unit, dict) else unit)
    elif isinstance(value, (list, tuple)):
        for index, item in enumerate(value):
            yield from flatten(f"{key}.{index}", item, unit)
    else:
        yield key, value, unit


def undefined(rows):
    """The keys whose values are NaN (undefined), as warnings."""
    return [
        f"{key} is undefined (NaN)"
        for row in rows
        if row[0] is not None
        for key, value, _ in flatten(row[0], row[1])
        if isinstance(value, float) and math.isnan(value)
    ]


class Printer:
    """Prints reports in the format asked for; ``many`` when there are several inputs."""

    def __init__(self, as_json=False, as_tsv=False, many=False):
        if as_json and as_tsv:
            raise click.UsageError("give --json or --tsv, not both")
        self.as_json, self.as_tsv, self.many, self.printed = as_json, as_tsv, many, 0

    def print(self, report, file=None, warnings=()):
        warnings = list(dict.fromkeys([*warnings, *undefined(report.rows)]))
        if self.as_json:
            document = {"file": file, **report.document, "warnings": warnings}
            echo(json.dumps(finite(document), indent=None if self.many else 2, ensure_ascii=False))
        elif self.as_tsv:
            for row in [*filter(lambda row: row[0] is not None, report.rows), ("warnings", warnings, "")]:
                for key, value, unit in flatten(*row[:3]):
                    parts = ("" if file is None else file, key, *cells(value, unit))
                    echo("\t".join(printable(part) for part in parts))
        else:
            self._table(report.rows, file)
        self.printed += 1

    def _table(self, rows, file):
        if file is not None:
            rows = [("file", file, "", shown(file)), *rows]
        labels = [row[4] if len(row) > 4 else row[0] for row in rows]
        width = max(map(len, labels))
        if self.many and self.printed:
            echo("")
        for label, row in zip(labels, rows):
            echo(printable(f"{label:<{width}}  {row[3]}"))


def emit(report, as_json=False, as_tsv=False, file=None, warnings=()):
    """Print one report (commands that read no surface: formats, experiment)."""
    Printer(as_json, as_tsv).print(report, file, warnings)


def cells(value, unit):
    """The TSV's value and unit cells: a number and its unit (``nan`` for an undefined
    one: null or NaN), empty and the text for anything else (text, true, false), so
    that the value column reads as numbers and is empty only in a text row.

    >>> cells(7.2e-08, "m"), cells(float("nan"), "m"), cells(None, "1/m"), cells("m", ""), cells(True, "")
    (('7.2e-08', 'm'), ('nan', 'm'), ('nan', '1/m'), ('', 'm'), ('', 'true'))
    """
    if type(value).__module__ == "numpy":
        value = value.tolist()
    if value is None or (isinstance(value, (int, float)) and not isinstance(value, bool)):
        return plain(value), str(unit)
    return "", plain(value)


def plain(value):
    """A TSV cell: a number as Python writes it back exactly, a boolean as true or
    false, ``nan`` for None or NaN (an undefined number)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "nan"
    if isinstance(value, bool):
        return str(value).lower()
    if type(value).__module__ == "numpy":
        return plain(value.tolist())
    if isinstance(value, float):
        return repr(float(value))
    return str(value)


def finite(value):
    """JSON has no NaN: non-finite numbers become null; numpy scalars become Python's."""
    if type(value).__module__ == "numpy":
        value = value.tolist()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [finite(v) for v in value]
    return value


class _Collector(logging.Handler):
    def __init__(self, found):
        super().__init__(logging.WARNING)
        self.found = found

    def emit(self, record):
        self.found.append(record.getMessage())


@contextlib.contextmanager
def collected_warnings():
    """The messages of warnings logged by rough (and Python warnings) meanwhile."""
    logger = logging.getLogger("rough")
    found = []
    collector = _Collector(found)
    logger.addHandler(collector)
    try:
        yield found
    finally:
        logger.removeHandler(collector)
