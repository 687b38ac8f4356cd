"""NPY: a bare NumPy array of heights in metres, read and written.

NPY carries no spacing, units, metadata or history: reading needs ``spacing``
(``--spacing`` on the command line), and writing keeps the float64 heights only.
"""

import io

import numpy as np

from ..errors import FormatError
from ..surface import Surface


def read(data, options):
    try:
        heights = np.load(io.BytesIO(bytes(data)), allow_pickle=False)
    except ValueError as error:
        raise FormatError(f"not a readable NPY array ({error})") from None
    if not (np.issubdtype(heights.dtype, np.floating) or np.issubdtype(heights.dtype, np.integer)):
        raise FormatError(f"NPY array holds {heights.dtype}, not numbers")
    if heights.ndim not in (1, 2):
        raise FormatError(f"NPY array is {heights.ndim}-D; a surface is 1-D (profile) or 2-D (map)")
    if options.spacing is None:
        raise FormatError("NPY files carry no spacing; give it with --spacing (e.g. --spacing 1um)")
    return Surface(heights, options.spacing[: heights.ndim])


def write(surface, stream):
    np.save(stream, np.asarray(surface.heights, dtype=np.float64), allow_pickle=False)
