"""Form removal: the least-squares polynomial of order N (docs/conventions.rst
("Metrology conventions"); the slides remove
``Y(x) = a0 + a1 x + a2 x²``).

Profiles: a polynomial of degree N in x. Maps: all terms ``x^i y^j`` with
``i + j ≤ N``. The fit uses the valid (non-NaN) points only; invalid points stay NaN
in the result. Coordinates are centred and scaled to [-1, 1] and the basis is
Legendre polynomials, which are nearly orthogonal on a regular grid, so the normal
equations stay well conditioned at high orders. The basis is separable, so the
normal equations are assembled from one pass over the map per product of x-basis
functions, without ever forming the (points × terms) design matrix.
"""

import numpy as np
from numpy.polynomial import legendre

from ..errors import InputError


def polynomial_form(surface, order=2):
    """The least-squares polynomial form of a surface, evaluated at every point.

    Parameters
    ----------
    surface : Surface
        A profile or map. The polynomial is fitted to its valid points only; NaN
        points are left out of the fit.
    order : int, default 2
        The total degree: profiles, a polynomial of degree ``order`` in x; maps, all
        terms ``x^i y^j`` with ``i + j <= order``.

    Returns
    -------
    numpy.ndarray
        The form in metres, shaped like ``surface.heights`` and evaluated everywhere,
        at the invalid points too.

    Raises
    ------
    rough.InputError
        For a negative order, or when the valid points cannot determine that many
        terms (too few distinct x positions, or rows and columns for a map).

    See Also
    --------
    remove_form : The surface less this form.

    Notes
    -----
    Coordinates are centred and scaled to [-1, 1] and the basis is Legendre
    polynomials, so the normal equations stay well conditioned at high orders.

    Examples
    --------
    A quadratic is its own form, found from the valid points and evaluated at the
    invalid one as well:

    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology import polynomial_form
    >>> x = np.arange(11) * 0.1e-3  # 1 mm at 0.1 mm
    >>> z = 1e-6 + 2e-3 * x - 5.0 * x**2  # metres
    >>> z[4] = np.nan
    >>> form = polynomial_form(rough.Surface(z, 0.1e-3), order=2)
    >>> form.shape
    (11,)
    >>> bool(np.nanmax(np.abs(form - z)) < 1e-18)
    True
    >>> f"{form[4] * 1e6:.4f} µm"  # 1 + 0.8 - 0.8 µm at x = 0.4 mm
    '1.0000 µm'
    """
    along_y, coefficients, along_x = form_factors(surface, order)
    return (along_y @ coefficients @ along_x.T).reshape(surface.heights.shape)


def form_factors(surface, order=2):
    """The fitted form as separable factors ``(Y, K, X)`` with form = Y @ K @ X.T:
    Y (ny × terms in y) and X (nx × terms in x) are Legendre bases on the rows and
    columns, K the coefficients. For a profile Y is [[1]]. Lets callers evaluate the
    form a block of rows at a time."""
    if order < 0:
        raise InputError(f"the polynomial order must be 0 or more, not {order}")
    heights = np.atleast_2d(surface.heights)
    valid = ~np.isnan(heights)
    ny, nx = heights.shape
    along_x = legendre.legvander(_unit_interval(nx), order)
    along_y = legendre.legvander(_unit_interval(ny), order if surface.heights.ndim == 2 else 0)
    terms = [(i, j) for j in range(along_y.shape[1]) for i in range(order + 1 - j)]
    complete = bool(valid.all())
    weights = None if complete else valid.astype(np.float64)
    weighted_x = {
        (i, k): np.full(ny, along_x[:, i] @ along_x[:, k]) if complete else weights @ (along_x[:, i] * along_x[:, k])
        for i in range(order + 1)
        for k in range(i, order + 1)
    }
    projected = (heights if complete else np.where(valid, heights, 0.0)) @ along_x
    gram = np.empty((len(terms), len(terms)))
    right = np.empty(len(terms))
    for a, (i, j) in enumerate(terms):
        right[a] = along_y[:, j] @ projected[:, i]
        for b, (k, m) in enumerate(terms):
            gram[a, b] = (along_y[:, j] * along_y[:, m]) @ weighted_x[min(i, k), max(i, k)]
    _check_determined(gram, valid, order, surface.heights.ndim)
    coefficients = np.zeros((along_y.shape[1], order + 1))
    for (i, j), value in zip(terms, np.linalg.solve(gram, right)):
        coefficients[j, i] = value
    return along_y, coefficients, along_x


def remove_form(surface, order=2):
    """A surface less its least-squares polynomial form.

    Parameters
    ----------
    surface : Surface
        A profile or map; the form is fitted on its valid points only.
    order : int, default 2
        The total degree of the polynomial (see :func:`polynomial_form`).

    Returns
    -------
    Surface
        The residual heights in metres, with a ``detrend`` history entry recording
        ``order``. NaN stays NaN.

    Raises
    ------
    rough.InputError
        When the valid points cannot determine the polynomial.

    See Also
    --------
    detrend : Form removal and the Gaussian filter in one call.

    Examples
    --------
    A tilted plane with an invalid point levels to zero:

    >>> import numpy as np
    >>> import rough
    >>> from rough.metrology import remove_form
    >>> y, x = np.mgrid[0:4, 0:5] * 1e-3  # a 5 × 4 grid at 1 mm
    >>> heights = 3e-6 + 0.01 * x - 0.02 * y
    >>> heights[1, 2] = np.nan
    >>> levelled = remove_form(rough.Surface(heights, 1e-3), order=1)
    >>> int(np.isnan(levelled.heights).sum()), bool(np.nanmax(np.abs(levelled.heights)) < 1e-15)
    (1, True)
    >>> levelled.history[-1]["command"], levelled.history[-1]["parameters"]
    ('detrend', {'order': 1})
    """
    residual = surface.heights - polynomial_form(surface, order)
    return surface.derive("detrend", {"order": order}, heights=residual)


def _unit_interval(n):
    """n equally spaced coordinates mapped onto [-1, 1]."""
    return np.linspace(-1.0, 1.0, n) if n > 1 else np.zeros(1)


def _check_determined(gram, valid, order, ndim):
    count = int(valid.sum())
    if count == 0:
        raise InputError("no valid points: nothing to fit")
    scale = np.abs(np.diag(gram)).max()
    smallest = np.linalg.eigvalsh(gram).min() if scale > 0 else 0.0
    if smallest <= 1e-12 * scale:
        shape = "distinct x positions" if ndim == 1 else "valid points spread over enough rows and columns"
        raise InputError(
            f"a polynomial of order {order} needs {order + 1} {shape}; the {count} valid points do not determine it "
            "(use a lower --order)"
        )
