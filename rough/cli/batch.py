"""Several inputs in one call: each is read and worked on in turn, a bad one is
reported in one line and skipped, and the exit status at the end is the worst seen.

Side files (``--plot``, ``--psd``, ``--list``, ``--segments``) then need ``{stem}`` (the
input's name without directory and extension) or ``{name}`` in their names, and a
surface output ``-o`` names a directory (``out/``).
"""

import os
import sys

import click

from .. import errors, io, progress
from .main import current_input, failure, say
from .report import Printer, collected_warnings

#: The options that name a file written beside the report (or instead of one), and their flags.
SIDE_FILES = {
    "plot": "--plot",
    "psd_file": "--psd",
    "feature_list": "--list",
    "segments": "--segments",
}


def run_each(work, names, options):
    """Call ``work(name, **options)`` for each input in ``names`` and print the
    :class:`~rough.cli.report.Report` it returns (if any) in the format of
    ``options``' ``as_json``/``as_tsv``. Returns the exit status."""
    many = len(names) > 1
    check_inputs(names)
    printer = Printer(options.pop("as_json", False), options.pop("as_tsv", False), many)
    side = {key: options[key] for key in SIDE_FILES if options.get(key)}
    if many:
        _check_side_files(side)
        if "output" in options:
            options["output"].check_directory(names)
    elif "output" in options:
        options["output"].check()
    status = 0
    for name in _progress(names, many):
        named = {**options, **{key: stem_name(path, name) for key, path in side.items()}}
        if "output" in options:
            named["output"] = options["output"].for_input(name)
        report, warnings, failed = _one(work, name, named, many)
        status = max(status, failed)
        if report is not None:
            printer.print(report, name, warnings)
    return status


def read_named(name, options):
    """The surface in input ``name`` (see :func:`rough.io.read`)."""
    return io.read(name, **options)


def _one(work, name, options, many):
    """(report, warnings, status) of one input; with several, a failure is reported
    and its status returned instead of raised."""
    current_input[:] = [printable_name(name)] if many else []
    try:
        with collected_warnings() as warnings:
            report = work(name, **options)
        return report, warnings, 0
    except errors.InputError as error:
        failed = _named_error(error, name)
        if not many:
            raise
    except click.ClickException:
        raise
    except Exception as error:  # noqa: BLE001 -- with several inputs one failure must not stop the rest
        if not many:
            raise
        failed = error
    finally:
        current_input[:] = []
    message, status = failure(failed)
    say(message)
    return None, [], status


def _named_error(error, name):
    """The error, its message led by the input's name unless it names a file already."""
    shown = printable_name(name)
    if error.filename is None and not str(error).startswith(f"{shown}: "):
        error.args = (f"{shown}: {error}", *error.args[1:])
    return error


def printable_name(name):
    return "<stdin>" if name == "-" else name


def stem_name(template, name):
    """A side file's name for input ``name``: ``{stem}`` and ``{name}`` filled in."""
    base = "stdin" if name == "-" else os.path.basename(name)
    return template.replace("{stem}", os.path.splitext(base)[0]).replace("{name}", base)


def check_inputs(names):
    if names.count("-") > 1:
        raise click.UsageError("standard input (-) can be read only once")
    if "-" in names and sys.stdin is None:
        raise errors.InputError("<stdin>: standard input is closed")


def _check_side_files(side):
    for key, path in side.items():
        option = SIDE_FILES[key]
        if path == "-":
            raise click.UsageError(f"with several inputs, {option} cannot go to standard output")
        if "{stem}" not in path and "{name}" not in path:
            raise click.UsageError(f"with several inputs, put {{stem}} in {option}'s file name, e.g. {{stem}}.png")


def _progress(names, many):
    if not many:
        return names
    return progress.progress(names, total=len(names), description="files", unit="file")
