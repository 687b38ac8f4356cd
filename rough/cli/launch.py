"""The ``rough`` entry point: a bare ``rough --help`` answered from the stored overview
(:mod:`rough.cli.overview_cache`) without importing click, everything else handed to
:func:`rough.cli.main.main`."""

import os
import sys

from .overview_cache import stored_overview


def main():
    """Run the ``rough`` command: the stored overview when that is all that is asked,
    else the command line (:func:`rough.cli.main.main`)."""
    args = sys.argv[1:]
    if args in ([], ["-h"], ["--help"]) and "_ROUGH_COMPLETE" not in os.environ:
        text = stored_overview()
        if text is not None:
            _print(text)
    from .main import main as run  # deferred: click and the commands, when the cache cannot answer

    run(args)


def _print(text):
    try:
        sys.stdout.write(text)
        sys.stdout.flush()
    except BrokenPipeError:  # `rough --help | head -1`: quietly, as the commands do
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        sys.exit(141)
    sys.exit(0)
