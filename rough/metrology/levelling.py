"""Levelling: remove a surface's polynomial form and, with a cut-off, split off its
waviness (:func:`detrend`, what ``rough detrend`` does)."""

import numpy as np

from .. import metrology
from ..errors import InputError
from .form import polynomial_form, remove_form

KEEP = ("roughness", "waviness", "form")


def detrend(surface, order=2, cutoff=None, keep="roughness", ends="trim"):
    """Remove the polynomial form and, with a cut-off, split off the waviness.

    Removes the least-squares polynomial form of degree ``order`` and, with a
    ``cutoff``, splits what is left with the ISO 16610-21 (profiles) or ISO 16610-61
    (maps) Gaussian filter.

    Parameters
    ----------
    surface : Surface
        A profile or map; NaN points are left out of the fit and the filter.
    order : int, default 2
        Degree of the polynomial form (maps: total degree in x and y), as the source
        slides remove ``a0 + a1 x + a2 x²``; 0 removes the mean, 1 a line or plane.
    cutoff : float, optional
        The filter's cut-off wavelength λc in metres; None (the default) removes only
        the form.
    keep : {"roughness", "waviness", "form"}, default "roughness"
        ``roughness``: the form-free surface, or its roughness with a cut-off;
        ``waviness``: the Gaussian mean line of the form-free surface (needs a
        cut-off); ``form``: the fitted polynomial.
    ends : {"trim", "correct"}, default "trim"
        With a cut-off: ``trim`` drops λc/2 at each end, where ISO 16610-21 calls the
        filter unreliable; ``correct`` keeps the full length with the kernel
        renormalised over the data present (ISO 16610-28's end correction).

    Returns
    -------
    Surface
        Heights in metres, with a ``detrend`` (and, with a cut-off, a ``filter``)
        history entry. NaN stays NaN.

    Raises
    ------
    rough.InputError
        For an unknown ``keep``, ``waviness`` without a cut-off, too few valid points
        for the polynomial, or a cut-off longer than the data (or, with
        ``ends="trim"``, too long to leave two points).

    See Also
    --------
    remove_form, split, polynomial_form

    Notes
    -----
    The polynomial is fitted on the valid points only, in a Legendre basis on
    centred, scaled coordinates (docs/conventions.rst ("Metrology conventions")).
    The filter is a normalised convolution, so NaN points neither spread nor bias the
    mean line.

    Examples
    --------
    >>> import rough
    >>> from rough.metrology import detrend
    >>> scan = rough.read(rough.sample("rock-profile.tsv"))
    >>> levelled = detrend(scan)  # the quadratic form removed
    >>> [entry["command"] for entry in levelled.history]
    ['synth', 'detrend']

    With a cut-off of 0.8 mm, λc/2 = 0.4 mm is trimmed at each end (13 points of
    30.9 µm), unless the ends are corrected:

    >>> roughness = detrend(scan, order=2, cutoff=0.8e-3)
    >>> roughness.points, f"{roughness.origin[0] * 1e3:.4f} mm"
    ((2022,), '0.4017 mm')
    >>> detrend(scan, order=2, cutoff=0.8e-3, ends="correct").points
    (2048,)

    Invalid points stay invalid:

    >>> import numpy as np
    >>> scan = rough.read(rough.sample("rock-map.x3p"))
    >>> int(np.isnan(detrend(scan, order=1).heights).sum())
    6
    """
    if keep not in KEEP:
        raise InputError(f"keep must be one of {', '.join(KEEP)}, not {keep!r}")
    if keep == "waviness" and cutoff is None:
        raise InputError("the waviness needs a cut-off (--cutoff)")
    if keep == "form":
        form = polynomial_form(surface, order)
        return surface.derive(
            "detrend", {"order": order, "keep": "form"}, heights=np.where(np.isnan(surface.heights), np.nan, form)
        )
    levelled = remove_form(surface, order)
    return levelled if cutoff is None else metrology.split(levelled, cutoff, keep, ends)
