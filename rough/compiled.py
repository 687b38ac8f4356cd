"""Functions compiled by numba, which is imported only when one is first needed
(``rough`` starts without it)."""

import functools


@functools.cache
def compiled(function):
    """``function`` compiled by numba (no GIL held, NumPy's error model), once per
    process, or loaded from numba's cache on disk when it finds a writable place for
    one (beside the function's module or in the user's cache directory).

    Parameters
    ----------
    function : callable
        A function numba can compile in nopython mode.

    Returns
    -------
    callable
        The compiled dispatcher; its first call compiles (a second or two) or loads
        the cached machine code.

    Examples
    --------
    >>> from rough.compiled import compiled
    >>> def twice(x):
    ...     return 2 * x
    >>> compiled(twice)(21)
    42
    """
    import numba

    try:
        return numba.njit(nogil=True, cache=True, error_model="numpy")(function)
    except RuntimeError:  # no writable cache directory: compile in every process
        return numba.njit(nogil=True, error_model="numpy")(function)
