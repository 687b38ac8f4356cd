"""Progress bars on standard error for long work, over tqdm.

A bar appears only once the work has taken :data:`DELAY` seconds, only when progress
is enabled (the command line's ``-q`` disables it) and standard error is a terminal,
and it disappears when the work is done: pipes, files and logs never receive one.
"""

import functools
import logging
import sys

DELAY = 2.0  # seconds of work before a bar is drawn
_state = {"enabled": True}


def configure(enabled):
    """Enable or disable progress bars for the rest of the process.

    Parameters
    ----------
    enabled : bool
        False (the command line's ``-q``) draws no bar anywhere; True (the default)
        draws one on standard error when it is a terminal.

    Examples
    --------
    >>> from rough import progress
    >>> progress.configure(False)
    >>> progress.progress(range(3)).disable
    True
    >>> progress.configure(True)
    """
    _state["enabled"] = bool(enabled)


def progress(iterable=None, *, total=None, description="", unit="step"):
    """A progress bar on standard error: iterate it, or call its ``update(n)``.

    Parameters
    ----------
    iterable : iterable, optional
        The work items; iterating the bar yields them. Without it, call
        ``update(n)`` as the work goes.
    total : int, optional
        The number of steps (default ``len(iterable)`` when it has one). From
        100000 steps on, counts are shown with SI prefixes (1.2M).
    description : str, optional
        A few words put before the bar.
    unit : str, default "step"
        What one step is, as in "12 rows/s".

    Returns
    -------
    tqdm.tqdm
        A tqdm bar (also a context manager; closing it erases it), drawn only when
        progress is enabled, standard error is a terminal and the work has taken
        :data:`DELAY` seconds; otherwise silent, with the same methods.

    Examples
    --------
    >>> from rough.progress import progress
    >>> with progress(total=4, description="bands", unit="band") as bar:
    ...     for _ in range(4):
    ...         bar.update(1)
    >>> [row for row in progress(range(3), description="rows")]  # silent here: no terminal
    [0, 1, 2]
    """
    stream = sys.stderr
    if total is None and iterable is not None and hasattr(iterable, "__len__"):
        total = len(iterable)
    return _bar_class()(
        iterable,
        total=total,
        desc=description or None,
        unit=unit,
        unit_scale=bool(total and total >= 100_000),
        file=stream,
        disable=not (_state["enabled"] and _is_terminal(stream)),
        delay=DELAY,
        leave=False,
        dynamic_ncols=True,
    )


@functools.cache
def _bar_class():
    """The bar class, made on first use so that starting a command does not import
    tqdm (about 75 ms) when no long work comes."""
    from tqdm import tqdm  # deferred: every command loads this module, few draw a bar (75 ms)

    class Bar(tqdm):
        """A tqdm bar that, while drawn, sends rough's log lines through ``tqdm.write``,
        so that a warning in the middle of the work does not land on the bar's line."""

        def __init__(self, *args, **kwargs):
            self._redirect = None
            super().__init__(*args, **kwargs)
            logger = logging.getLogger("rough")
            if not self.disable and any(isinstance(h, logging.StreamHandler) for h in logger.handlers):
                from tqdm.contrib.logging import logging_redirect_tqdm  # deferred with tqdm

                self._redirect = logging_redirect_tqdm([logger], tqdm_class=tqdm)
                self._redirect.__enter__()

        def close(self):
            try:
                super().close()
            finally:
                redirect, self._redirect = getattr(self, "_redirect", None), None
                if redirect is not None:
                    redirect.__exit__(None, None, None)

    return Bar


def _is_terminal(stream):
    try:
        return stream is not None and stream.isatty()
    except (AttributeError, OSError, ValueError):  # a closed or unusual stream: no bar
        return False
