"""How the heavy loops run: functions compiled by numba, which is imported only when
one is first needed (``rough`` starts without it), and BLAS kept to one thread
around the many tiny numerical fits (:func:`one_blas_thread`)."""

import contextlib
import functools
import threading
import types

import threadpoolctl

WAIT = 0.1  # seconds between the caller's chances to be interrupted


@functools.cache
def compiled(function, *helpers):
    """``function`` compiled by numba (no GIL held, NumPy's error model), once per
    process, or loaded from numba's cache on disk when it finds a writable place for
    one (beside the function's module or in the user's cache directory). The plain
    functions of its module it calls are given as ``helpers`` (those they call
    before them): they are compiled with it, and stay plain Python elsewhere.

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
    *helpers : callable
        Functions of the same module that ``function`` calls by their names.

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
    if not helpers:
        return functools.partial(_waited, _jit(function))
    names = dict(function.__globals__)  # the module's names, the helpers' compiled in place of theirs
    for helper in (*helpers, function):
        names[helper.__name__] = _jit(types.FunctionType(helper.__code__, names, helper.__name__, helper.__defaults__))
    return functools.partial(_waited, names[function.__name__])


def _jit(function):
    import numba  # numba: only when compiled

    try:
        return numba.njit(nogil=True, cache=True, error_model="numpy")(function)
    except RuntimeError:  # no writable cache directory: compile in every process
        return numba.njit(nogil=True, error_model="numpy")(function)


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


_BLAS = threading.local()  # per thread: how deep inside one_blas_thread it is


@functools.cache
def _controller():
    """threadpoolctl's view of the thread pools of the libraries loaded, taken once
    (at the first fit, when numpy's and scipy's BLAS are both loaded)."""
    return threadpoolctl.ThreadpoolController()


@contextlib.contextmanager
def _blas_limited():
    depth = getattr(_BLAS, "depth", 0)
    _BLAS.depth = depth + 1
    try:
        if depth:  # already limited by an outer call
            yield
        else:
            with _controller().limit(limits=1, user_api="blas"):
                yield
    finally:
        _BLAS.depth = depth


def one_blas_thread(function):
    """``function`` run with BLAS limited to one thread (threadpoolctl), the limit
    lifted when it returns; calls inside one already limited cost nothing more.

    scipy's L-BFGS-B and the other optimisers work on vectors of a few elements,
    where OpenBLAS's thread pool only adds hand-offs between threads: every spectral
    fit runs 1.5-3.3 times faster on one thread, with bit-identical results (scipy
    issues 22438 and 23161). Whatever else runs in parallel (scipy.fft's workers,
    numba) is left alone.

    Parameters
    ----------
    function : callable
        A function whose work is numerical fits.

    Returns
    -------
    callable
        ``function`` wrapped; it returns what ``function`` returns.

    Examples
    --------
    >>> import threadpoolctl
    >>> from rough.compiled import one_blas_thread
    >>> @one_blas_thread
    ... def threads():
    ...     return {pool["num_threads"] for pool in threadpoolctl.threadpool_info() if pool["user_api"] == "blas"}
    >>> threads() <= {1}
    True
    """

    @functools.wraps(function)
    def limited(*args, **keywords):
        with _blas_limited():
            return function(*args, **keywords)

    return limited
