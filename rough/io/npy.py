"""NPY: a bare NumPy array of heights in metres, read and written.

NPY carries no spacing, units, metadata or history: reading needs ``spacing``
(``--spacing`` on the command line), and writing keeps the float64 heights only.
A map is read a window at a time through a memory map (:func:`open_tiles`).
"""

import io
import os

import numpy as np

from ..errors import FormatError
from ..surface import Surface, Units
from .registry import Format
from .tiled import TiledSurface
from .windowed import FileSource, finite

FORMAT = Format("npy", "NumPy NPY", (".npy",), magic=(b"\x93NUMPY",), writes=True, carries=("tiles",))
#: Heights read as metres and spacing from ``--spacing``: the file states no unit.
UNITS = Units("m", "m", assumed=("xy", "z"))


def read(data, options):
    """The header is checked (numbers, 1-D or 2-D, exactly as many bytes as it
    declares: more or fewer mean a damaged file) before any array is made; object
    arrays are never unpickled."""
    shape, fortran, dtype, offset = _header(io.BytesIO(bytes(data)), len(data), options)
    count = int(np.prod(shape, dtype=object))
    heights = np.frombuffer(data, dtype, count=count, offset=offset)
    heights = heights.reshape(shape[::-1]).T if fortran else heights.reshape(shape)
    return Surface(heights.astype(np.float64), options.spacing[: len(shape)], units=UNITS)


def open_tiles(path, options):
    """A :class:`~rough.io.tiled.TiledSurface` of the map in an NPY file, read through
    a memory map with the checks of :func:`read`; None for a profile (read whole)."""
    with open(path, "rb") as stream:
        shape, _, _, _ = _header(stream, os.fstat(stream.fileno()).st_size, options)
    if len(shape) != 2 or shape[0] * shape[1] < 2:
        return None
    return TiledSurface(NpySource(path), tuple(shape), tuple(options.spacing[:2]), units=UNITS)


def _header(stream, size, options):
    """``(shape, Fortran order, dtype, offset of the data)`` of an NPY file of ``size``
    bytes, checked; FormatError for anything :func:`read` refuses."""
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
    available = size - stream.tell()
    if count * dtype.itemsize != available:
        raise FormatError(
            f"NPY header declares {'×'.join(map(str, shape))} values of {dtype.itemsize} bytes; the file "
            f"holds {available} bytes"
        )
    if options.spacing is None:
        raise FormatError("NPY files carry no spacing; give it with --spacing (e.g. --spacing 1um)")
    return shape, fortran, dtype, stream.tell()


class NpySource(FileSource):
    """Windows of an NPY map, through a read-only memory map opened in each process."""

    def opened(self):
        return np.load(self.path, mmap_mode="r", allow_pickle=False)

    def window(self, rows, cols):
        heights, _ = self.handle()
        return finite(np.array(heights[rows, cols], dtype=np.float64))


def write(surface, stream):
    np.save(stream, np.asarray(surface.heights, dtype=np.float64), allow_pickle=False)
