"""Printing numbers: an aligned table for people, ``--json`` and ``--tsv`` for programs.

A report is a list of rows ``(key, value, unit, text)``: ``value`` in SI units for
JSON and TSV, ``text`` (the value with a unit chosen for reading) for the table.
"""

import json
import math

import click


def printable(text):
    """``text`` on one line and safe for a terminal: control characters and other
    non-printable ones escaped as Python would (``\\n``, ``\\x1b``)."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(text))


def echo(line):
    """Print one line on standard output; a RoughError when it is closed."""
    from ..io.atomic import standard_output

    standard_output()
    click.echo(line)


def on_stdout(**files):
    """Whether a side file (``--plot``, ``--psd``, ``--list``) is ``-``: standard output
    then carries it instead of the report. Two of them there is a usage error."""
    dashes = [f"--{option}" for option, path in files.items() if path == "-"]
    if len(dashes) > 1:
        raise click.UsageError(f"{' and '.join(dashes)} cannot both go to standard output")
    return bool(dashes)


def emit(rows, document, as_json=False, as_tsv=False):
    """Print ``rows`` as a table or TSV, or ``document`` (a dict) as JSON."""
    if as_json:
        echo(json.dumps(_finite(document), indent=2, ensure_ascii=False))
    elif as_tsv:
        for key, value, unit, _ in rows:
            echo("\t".join(printable(part) for part in (key, _plain(value), unit)))
    else:
        width = max(len(key) for key, *_ in rows)
        for key, _, _, text in rows:
            echo(printable(f"{key:<{width}}  {text}"))


def _plain(value):
    if isinstance(value, (list, tuple)):
        return " ".join(_plain(v) for v in value)
    return "" if value is None else repr(value) if isinstance(value, float) else str(value)


def _finite(value):
    """JSON has no NaN: non-finite numbers become null."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    return value
