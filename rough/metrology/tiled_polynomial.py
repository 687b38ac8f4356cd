"""The least-squares polynomial form of a map read a strip at a time: the normal
equations of :func:`rough.metrology.polynomial_form`, summed over strips."""

import numpy as np
from numpy.polynomial import legendre

from .. import tasks
from ..errors import InputError


def tiled_form(tiled, order=2, budget=None, jobs=1, scheduler=None):
    """The least-squares polynomial form of a map read a strip at a time.

    The normal equations of :func:`~rough.metrology.polynomial_form` (Legendre
    polynomials in coordinates scaled to [-1, 1]; all terms ``x^i y^j`` with
    ``i + j <= order``) summed over strips, so the coefficients are the in-memory
    ones to rounding.

    Parameters
    ----------
    tiled : rough.io.TiledSurface
        The map; NaN points are left out of the fit.
    order : int, default 2
        The total degree.
    budget, jobs, scheduler
        As :func:`~rough.metrology.tiled_evaluation`.

    Returns
    -------
    numpy.ndarray
        The coefficients ``K`` ((order + 1) × (order + 1), K[j, i] of
        ``P_j(y) P_i(x)``, zero for ``i + j > order``): the form is ``Y @ K @ X.T``
        with ``Y = legvander(linspace(-1, 1, ny), order)`` and ``X`` likewise along x.

    Raises
    ------
    rough.InputError
        For a negative order, or valid points that do not determine the polynomial.
    """
    if order < 0:
        raise InputError(f"the polynomial order must be 0 or more, not {order}")
    ny = tiled.shape[0]
    rows = tiled.strip_rows(budget)
    items = [(tiled, first, min(rows, ny - first), order) for first in range(0, ny, rows)]
    gram, right, count = 0.0, 0.0, 0
    for part_gram, part_right, part_count in tasks.map_ordered(form_sums, items, jobs=jobs, scheduler=scheduler):
        gram, right, count = gram + part_gram, right + part_right, count + part_count
    terms = _terms(order)
    scale = np.abs(np.diag(gram)).max() if count else 0.0
    if not count or np.linalg.eigvalsh(gram).min() <= 1e-12 * scale:
        raise InputError(
            f"a polynomial of order {order} needs valid points spread over enough rows and columns; the {count} "
            "valid points do not determine it (use a lower --order)"
        )
    coefficients = np.zeros((order + 1, order + 1))
    for (i, j), value in zip(terms, np.linalg.solve(gram, right)):
        coefficients[j, i] = value
    return coefficients


def _terms(order):
    return [(i, j) for j in range(order + 1) for i in range(order + 1 - j)]


def form_sums(item):
    """One strip's share of the normal equations of :func:`tiled_form`."""
    tiled, first, rows, order = item
    ny, nx = tiled.shape
    heights = tiled.read(slice(first, first + rows))
    valid = ~np.isnan(heights)
    along_x = legendre.legvander(np.linspace(-1.0, 1.0, nx) if nx > 1 else np.zeros(1), order)
    along_y = legendre.legvander(np.linspace(-1.0, 1.0, ny) if ny > 1 else np.zeros(1), order)[first : first + rows]
    products = np.einsum("ci,ck->cik", along_x, along_x).reshape(nx, -1)
    weighted = (valid.astype(np.float64) @ products).reshape(rows, order + 1, order + 1)
    projected = np.where(valid, heights, 0.0) @ along_x
    terms = _terms(order)
    i, j = (np.array([term[axis] for term in terms]) for axis in (0, 1))
    gram = np.einsum("ra,rb,rab->ab", along_y[:, j], along_y[:, j], weighted[:, i][:, :, i])
    right = np.einsum("ra,ra->a", along_y[:, j], projected[:, i])
    return gram, right, int(valid.sum())
