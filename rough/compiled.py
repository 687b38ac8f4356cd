"""Functions compiled by numba, which is imported only when one is first needed
(``rough`` starts without it)."""

import functools
import threading

WAIT = 0.1  # seconds between the caller's chances to be interrupted


@functools.cache
def compiled(function):
    """``function`` compiled by numba (no GIL held, NumPy's error model), once per
    process, or loaded from numba's cache on disk when it finds a writable place for
    one (beside the function's module or in the user's cache directory).

    A call from the main thread runs in a worker thread while the caller waits in
    steps of :data:`WAIT`, so that Ctrl-C stops the caller at once, even during the
    first call's compilation (numba's compiler would otherwise swallow the interrupt
    in one of its ctypes callbacks and carry on). An interrupted call finishes in the
    background and its result is dropped. A call from another thread, which Ctrl-C
    never interrupts, runs where it is.

    Parameters
    ----------
    function : callable
        A function numba can compile in nopython mode.

    Returns
    -------
    callable
        Calls the compiled function; its first call compiles (a second or two) or
        loads the cached machine code.

    Examples
    --------
    >>> from rough.compiled import compiled
    >>> def twice(x):
    ...     return 2 * x
    >>> compiled(twice)(21)
    42
    """
    import numba  # numba: only when compiled

    try:
        dispatcher = numba.njit(nogil=True, cache=True, error_model="numpy")(function)
    except RuntimeError:  # no writable cache directory: compile in every process
        dispatcher = numba.njit(nogil=True, error_model="numpy")(function)
    return functools.partial(_waited, dispatcher)


def _waited(dispatcher, *args):
    if threading.current_thread() is not threading.main_thread():
        return dispatcher(*args)
    outcome = []

    def work():
        try:
            outcome.append((dispatcher(*args), None))
        except BaseException as error:  # handed to the caller
            outcome.append((None, error))

    worker = threading.Thread(target=work, name=f"rough: {dispatcher.__name__}", daemon=True)
    worker.start()
    while worker.is_alive():
        worker.join(WAIT)
    result, error = outcome[0]
    if error is not None:
        raise error
    return result
