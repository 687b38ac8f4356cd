"""The command line: ``rough.cli.main`` holds the group, one module per subcommand.

:func:`main` (the ``rough`` entry point) answers ``rough``, ``rough -h`` and ``rough
--help`` with the overview stored in :mod:`.overview` (click's own text, checked by the
tests) without importing click, so that asking for help costs little more than
starting Python; everything else goes to :func:`rough.cli.main.main`.
"""

import os
import sys


def main():
    """Entry point of the ``rough`` command."""
    args = sys.argv[1:]
    if args in ([], ["-h"], ["--help"]) and "_ROUGH_COMPLETE" not in os.environ and _columns() >= 80:
        from .overview import TEXT

        try:
            sys.stdout.write(TEXT)
            sys.stdout.flush()
        except BrokenPipeError:  # `rough --help | head -1`: quietly, as the commands do
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            sys.exit(141)
        sys.exit(0)
    from .main import main as run

    run(args)


def _columns():
    """The terminal width as click sees it (shutil.get_terminal_size, without shutil):
    its help is 78 columns wide on any terminal of 80 or more."""
    try:
        columns = int(os.environ.get("COLUMNS", 0))
        return columns if columns > 0 else os.get_terminal_size(sys.__stdout__.fileno()).columns or 80
    except (AttributeError, ValueError, OSError):
        return 80
