"""Several inputs in one call: each is read and worked on in turn, a bad one is
reported in one line and skipped, and the exit status at the end is the worst seen.

Side files (``--plot``, ``--psd``, ``--list``, ``--segments``) then need ``{stem}`` (the
input's name without directory and extension) or ``{name}`` in their names, and a
surface output ``-o`` names a directory (``out/``).

With ``--jobs N`` (N > 1) the inputs are worked on by N forked processes, and with
``--scheduler ADDRESS`` by the workers of a Dask cluster, each input a task
(:func:`rough.tasks.outcomes`); everything is printed by this process in input order,
as with one: each worker keeps its input's log lines, warnings, report and error line
and sends them back, so that standard output and standard error read as they would
one input after another. Side files and ``-o`` outputs are written by the workers
(on a cluster, to the file system they share with this machine).

A warning that an earlier input gave already (:func:`warning_template`: the same text
but for the input's name and the numbers) is printed once and counted: at the end one
line per such warning says for how many more files it came, naming the first three,
with ``…`` for each number that differs between them (:func:`shared_text`). Each input's ``--json``
document keeps all of its warnings.
"""

import contextlib
import dataclasses
import functools
import logging
import os
import re
import sys
import warnings

import click

from .. import errors, io, progress, tasks
from .main import _warn_in_one_line, current_input, failure, note, say
from .report import Printer, collected_warnings

log = logging.getLogger("rough")

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
    jobs = options.pop("jobs", 1)
    scheduler = options.pop("scheduler", None)
    printer = Printer(options.pop("as_json", False), options.pop("as_tsv", False), many)
    side = {key: options[key] for key in SIDE_FILES if options.get(key)}
    if many:
        _check_side_files(side)
        if "output" in options:
            options["output"].check_directory(names)
    elif "output" in options:
        options["output"].check()
    if scheduler is not None:
        if "-" in names:
            raise click.UsageError("standard input (-) cannot be sent to a cluster: give files (--scheduler)")
        return _in_parallel(work, names, options, side, printer, scheduler=scheduler)
    if many:
        jobs, note = tasks.usable_jobs(jobs, len(names))
        if note:
            log.warning(note)
        if jobs > 1:
            return _in_parallel(work, names, options, side, printer, jobs=jobs)
    status = 0
    with _repeats_counted(many):
        for name in _progress(names, many):
            report, warnings, failed = _one(work, name, _named(options, side, name), many)
            status = max(status, failed)
            if report is not None:
                printer.print(report, name, warnings)
    return status


#: Numbers in a warning's text (counts, sizes, positions), which :func:`warning_template` leaves out.
NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")


def warning_template(message, name):
    """What makes two inputs' warnings "the same": ``message`` without the input's
    ``name`` and with every number written ``#``.

    >>> warning_template("a.x3p: 12 of 4096 points are NaN (0.29 %)", "a.x3p")
    ': # of # points are NaN (# %)'
    """
    return NUMBER.sub("#", message.replace(name, "") if name else message)


class _Repeats(logging.Filter):
    """Lets through a warning the first time it comes (:func:`warning_template`) and
    the warnings of that same input; counts the later inputs that repeat it."""

    def __init__(self):
        super().__init__()
        self.first = {}  # template -> (the first input's message, that input)
        self.later = {}  # template -> {later input: its message without its name}, in order

    def filter(self, record):
        if record.levelno != logging.WARNING or not current_input:
            return True
        name, message = current_input[0], record.getMessage()
        template = warning_template(message, name)
        if self.first.setdefault(template, (message, name))[1] == name:
            return True
        self.later.setdefault(template, {})[name] = message.replace(name, "")
        return False

    def summary(self):
        """One line per repeated warning: how many more files gave it (the first three
        named), and its text with ``…`` for each number that differs between them."""
        for template, later in self.later.items():
            message, name = self.first[template]
            files = [str(file) for file in later]
            named = ", ".join(files[:3]) + (", …" if len(files) > 3 else "")
            text = shared_text([message.replace(name, ""), *later.values()]).lstrip(": ")
            yield f"the same warning for {len(files)} more file{'s' if len(files) > 1 else ''} ({named}): {text}"


def shared_text(messages):
    """The text of ``messages`` that share a :func:`warning_template`, with ``…`` for
    each number that is not the same in all of them.

    >>> shared_text(["Str < 0.673 at 10 %", "Str < 0.783 at 10 %"])
    'Str < … at 10 %'
    """
    numbers = [[match.group() for match in NUMBER.finditer(message)] for message in messages]
    shown = iter(values[0] if len(set(values)) == 1 else "…" for values in zip(*numbers))
    return NUMBER.sub(lambda match: next(shown), messages[0])


@contextlib.contextmanager
def _repeats_counted(many):
    """With several inputs, the handlers on standard error print a repeated warning
    once; the summary of the repeats follows the work."""
    if not many:
        yield
        return
    repeats, handlers = _Repeats(), list(log.handlers)
    for handler in handlers:
        handler.addFilter(repeats)
    try:
        yield
    finally:
        for handler in handlers:
            handler.removeFilter(repeats)
    for line in repeats.summary():
        say(line)


def read_named(name, options):
    """The surface in input ``name`` (see :func:`rough.io.read`); with a ``memory``
    option, a tiled one when it is too large for it (:func:`rough.io.open_surface`).
    Standard input on a terminal is announced first: nothing else says why the command
    waits."""
    if name == "-" and io.is_terminal(sys.stdin):
        note("reading a surface from standard input (end with Ctrl-D; give a FILE to read a file)")
    if "memory" in options:
        return io.open_surface(name, **options)
    return io.read(name, **options)


def _named(options, side, name):
    """The options for input ``name``: its side files and output."""
    named = {**options, **{key: stem_name(path, name) for key, path in side.items()}}
    if "output" in options:
        named["output"] = options["output"].for_input(name)
    return named


def _one(work, name, options, many):
    """(report, warnings, status) of one input; with several, a failure is reported
    and its status returned instead of raised."""
    report, warnings, status, message = _attempt(work, name, options, many)
    if message is not None:
        say(message)
    return report, warnings, status


def _attempt(work, name, options, many):
    """(report, warnings, status, error message or None) of one input; with several,
    a failure's message is returned instead of raised."""
    current_input[:] = [printable_name(name)] if many else []
    try:
        with collected_warnings() as warnings:
            report = work(name, **options)
        return report, warnings, 0, None
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
    return None, [], status, message


@dataclasses.dataclass
class _Outcome:
    """What a worker sends back for one input (it pickles)."""

    report: object = None
    warnings: list = dataclasses.field(default_factory=list)
    status: int = 0
    message: str = None  # the error line
    log: list = dataclasses.field(default_factory=list)  # (level, message) logged meanwhile
    stop: tuple = None  # a click error that ends the command: (usage?, message, exit status)


def _in_parallel(work, names, options, side, printer, jobs=1, scheduler=None):
    """:func:`run_each`'s loop over ``jobs`` worker processes or a cluster's workers
    (:func:`rough.tasks.outcomes`); the exit status."""
    logger = logging.getLogger("rough")
    levels = logger.level, min((handler.level for handler in logger.handlers), default=logging.WARNING)
    task = functools.partial(_in_worker, work, levels, len(names) > 1)
    items = [(name, _named(options, side, name)) for name in names]
    status = 0
    with (
        _repeats_counted(len(names) > 1),
        progress.progress(total=len(names), description="files", unit="file") as bar,
        contextlib.closing(
            tasks.outcomes(task, items, jobs=jobs, scheduler=scheduler, finished=lambda: bar.update(1))
        ) as outcomes,
    ):
        for name, outcome in zip(names, outcomes):
            report, warned, failed = _replay(name, outcome, len(names) > 1)
            status = max(status, failed)
            if report is not None:
                printer.print(report, name, warned)
    return status


class _Kept(logging.Handler):
    """Keeps a worker's log records, to be logged again by the parent in input order."""

    def __init__(self, level):
        super().__init__(level)
        self.records = []

    def emit(self, record):
        self.records.append((record.levelno, record.getMessage()))


def _in_worker(work, levels, many, item):
    """One input ``item`` = (name, options) in a worker process (forked, or a cluster's):
    an :class:`_Outcome`, nothing printed; the parent's logger and handler ``levels``."""
    name, options = item
    logger = logging.getLogger("rough")
    if not any(isinstance(handler, _Kept) for handler in logger.handlers):
        logger.handlers[:] = [_Kept(levels[1])]
        logger.setLevel(levels[0])
        logger.propagate = False
        progress.configure(False)
    kept = next(handler for handler in logger.handlers if isinstance(handler, _Kept))
    kept.records = []
    try:
        with warnings.catch_warnings():  # as the command line shows them (rough.cli.main)
            warnings.filterwarnings("ignore", category=RuntimeWarning)
            warnings.showwarning = _warn_in_one_line
            report, warned, status, message = _attempt(work, name, options, many)
    except click.ClickException as error:
        stop = (isinstance(error, click.UsageError), error.format_message(), error.exit_code)
        return _Outcome(log=kept.records, stop=stop)
    return _Outcome(report, warned, status, message, kept.records)


def _replay(name, outcome, many):
    """Print, in this process, what a worker logged for input ``name``; (report,
    warnings, status) as :func:`_one` returns them. With one input its error is raised."""
    if isinstance(outcome, tasks.Failed) and outcome.error is not None and not many:
        raise outcome.error
    if isinstance(outcome, (tasks.Died, tasks.Failed)):
        say(f"{printable_name(name)}: {outcome.message() if isinstance(outcome, tasks.Died) else outcome.message}")
        return None, [], 1
    current_input[:] = [printable_name(name)]
    try:
        for level, message in outcome.log:
            log.log(level, message)
    finally:
        current_input[:] = []
    if outcome.stop is not None:
        usage, message, status = outcome.stop
        if usage:
            raise click.UsageError(message)
        error = click.ClickException(message)
        error.exit_code = status
        raise error
    if outcome.message is not None:
        say(outcome.message)
    return outcome.report, outcome.warnings, outcome.status


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
