"""NPY: a bare NumPy array of heights in metres, read and written.

NPY carries no spacing, units, metadata or history: reading needs ``spacing``
(``--spacing`` on the command line), and writing keeps the float64 heights only.
"""

import io

import numpy as np

from ..errors import FormatError
from ..surface import Surface
from .registry import Format

FORMAT = Format("npy", "NumPy NPY", (".npy",), magic=(b"\x93NUMPY",), writes=True)


def read(data, options):
    """The header is checked (numbers, 1-D or 2-D, exactly as many bytes as it
    declares: more or fewer mean a damaged file) before any array is made; object
    arrays are never unpickled."""
    stream = io.BytesIO(bytes(data))
    try:
        version = np.lib.format.read_magic(stream)
        reader = {(1, 0): np.lib.format.read_array_header_1_0, (2, 0): np.lib.format.read_array_header_2_0}.get(version)
        if reader is None:
            raise FormatError(f"NPY format version {version[0]}.{version[1]} is not supported")
        shape, fortran, dtype = reader(stream)
    except ValueError as error:
        raise FormatError(f"not a readable NPY array ({error})") from None
    if not (np.issubdtype(dtype, np.floating) or np.issubdtype(dtype, np.integer)):
        raise FormatError(f"NPY array holds {dtype}, not numbers")
    if len(shape) not in (1, 2):
        raise FormatError(f"NPY array is {len(shape)}-D; a surface is 1-D (profile) or 2-D (map)")
    if not all(isinstance(n, int) and n >= 0 for n in shape):
        raise FormatError(f"NPY shape {shape} is not a list of sizes")
    count = int(np.prod(shape, dtype=object))
    available = len(data) - stream.tell()
    if count * dtype.itemsize != available:
        raise FormatError(
            f"NPY header declares {'×'.join(map(str, shape))} values of {dtype.itemsize} bytes; the file "
            f"holds {available} bytes"
        )
    if options.spacing is None:
        raise FormatError("NPY files carry no spacing; give it with --spacing (e.g. --spacing 1um)")
    heights = np.frombuffer(data, dtype, count=count, offset=stream.tell())
    heights = heights.reshape(shape[::-1]).T if fortran else heights.reshape(shape)
    return Surface(heights.astype(np.float64), options.spacing[: len(shape)])


def write(surface, stream):
    np.save(stream, np.asarray(surface.heights, dtype=np.float64), allow_pickle=False)
