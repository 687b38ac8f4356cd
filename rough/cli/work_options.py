"""The options of how much work runs at once, where, and in what memory: ``--jobs``
(worker processes), ``--scheduler`` (a Dask cluster), ``--memory`` (the budget that
sends a large map to tiles)."""

import click

from .. import errors, io


class JobsType(click.ParamType):
    """``--jobs``: a number of processes from 0 to :data:`MOST_JOBS`, or ``auto`` (0):
    one per core this process may use."""

    name = "N|auto"

    def convert(self, value, param, ctx):
        if isinstance(value, int):
            return value
        text = str(value).strip().lower()
        if text == "auto":
            return 0
        if not text.isdigit() or int(text) > MOST_JOBS:
            self.fail(f"{value!r}: give a number of processes from 0 to {MOST_JOBS}, or auto", param, ctx)
        return int(text)


#: The most processes ``--jobs`` starts.
MOST_JOBS = 256


def jobs_option(command):
    """``--jobs N`` and ``--scheduler ADDRESS``: with several inputs, N worker processes
    (0 or ``auto``: the cores), or each input a task on a Dask cluster; run_each
    (:mod:`rough.cli.batch`) takes them (:func:`rough.tasks.outcomes`). With one input,
    a command with ``tiled_input`` gives ``--jobs`` to its pieces instead (tiles,
    strips, bands of windows), and ``map`` (``split_input``) ``--scheduler`` too."""
    command = scheduler_option(
        "Work on the Dask cluster whose scheduler is at ADDRESS (tcp://host:8786): each input a task (rough map "
        "with one input: each band of windows); the scheduler and workers need the same rough, the workers the "
        "input files. The output is the same, in input order."
    )(command)
    return click.option(
        "--jobs",
        type=JobsType(),
        default=1,
        show_default=True,
        help="Work on N inputs at once, each in its own process (0 or auto: one per core), or, with one map read "
        "in tiles (--memory) or one roughness map, on N pieces of it; the output is the same, in input order.",
    )(command)


def scheduler_option(help, name="scheduler"):
    """``--scheduler ADDRESS``: a Dask scheduler (``tcp://host:port``) to run on."""
    return click.option("--scheduler", name, metavar="ADDRESS", help=help)


class MemoryType(click.ParamType):
    """A memory size (``4GB``, ``512MiB``, ``2G``), as bytes."""

    name = "SIZE"

    def convert(self, value, param, ctx):
        if isinstance(value, int):
            return value
        try:
            return io.memory_budget(value)
        except errors.InputError as error:
            self.fail(str(error), param, ctx)
