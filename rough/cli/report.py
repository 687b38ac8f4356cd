"""Printing numbers: an aligned table for people, ``--json`` and ``--tsv`` for programs.

A report is a list of rows ``(key, value, unit, text)``: ``value`` in SI units for
JSON and TSV, ``text`` (the value with a unit chosen for reading) for the table.
"""

import json
import math

import click


def emit(rows, document, as_json=False, as_tsv=False):
    """Print ``rows`` as a table or TSV, or ``document`` (a dict) as JSON."""
    if as_json:
        click.echo(json.dumps(_finite(document), indent=2, ensure_ascii=False))
    elif as_tsv:
        for key, value, unit, _ in rows:
            click.echo(f"{key}\t{_plain(value)}\t{unit}")
    else:
        width = max(len(key) for key, *_ in rows)
        for key, _, _, text in rows:
            click.echo(f"{key:<{width}}  {text}")


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
