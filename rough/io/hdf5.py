"""HDF5 height maps (bare 2-D datasets), read only, with h5py.

HDF5 has no convention for surface data. rough offers every 2-D numeric dataset in the file (groups searched in
HDF5's visiting order) as a channel named by its path; the default is the first whose name says height, topography
or surface, else the first. The dataset's rows are y and its columns x, as numpy and h5py store a C-order array
(row 0 is the first row stored). SurfaceTopography writes its arrays as ``(nx, ny)``, so its files appear
transposed here (``multiple_data_sets.h5``'s 640 × 480 dataset has 480 columns).

The numbers are bare: the file carries no spacing, so ``--spacing`` is required, and heights are taken in
``--unit`` (default metres), unless the dataset has a ``units`` or ``unit`` attribute naming a length unit (the CF
convention). 1-D datasets (coordinates, curves) are not offered. Datasets stored in external files or as virtual
datasets are refused, so a file cannot make rough read other files. A dataset that would take more than
``MAX_RATIO`` (:mod:`rough.io.limits`) times the file's size, such as a chunked dataset left unwritten or compressed
constant data, is refused as a bomb. NetCDF-4 files are HDF5 files and are read here in the same way.
"""

import io

import numpy as np

from ..errors import FormatError, InputError
from ..extras import require
from ..surface import Surface, Units, check_size
from ..units import metres_per
from . import limits
from .registry import Format, channel_metadata, choose_channel, names_height

FORMAT = Format(
    "hdf5",
    "HDF5",
    (".h5", ".hdf5", ".hdf"),
    magic=(b"\x89HDF\r\n\x1a\n",),
    carries=("units", "channels"),
    read_library="h5py",
)


def read(data, options):
    h5py = require("h5py")
    try:
        with h5py.File(io.BytesIO(bytes(data)), "r") as handle:
            return _surface(h5py, handle, options, len(data))
    except (OSError, RuntimeError, KeyError, ValueError, TypeError) as error:  # what the HDF5 library raises
        raise FormatError(f"malformed HDF5 file ({error})") from None


def _surface(h5py, handle, options, file_bytes):
    datasets = _datasets(h5py, handle)
    if not datasets:
        raise FormatError("HDF5 file holds no 2-D numeric dataset to read as a height map")
    names = list(datasets)
    index = choose_channel(names, options.channel, _default(names))
    dataset = datasets[names[index]]
    if dataset.external or dataset.is_virtual:
        raise FormatError(f"HDF5 dataset {names[index]!r} is stored outside the file; rough reads only its own data")
    check_size(dataset.shape, f"HDF5 dataset {names[index]!r}")
    _check_bytes(dataset, names[index], file_bytes)
    if options.spacing is None:
        rows, cols = dataset.shape
        raise FormatError(
            f"HDF5 dataset {names[index]!r} ({cols}×{rows} points) carries no spacing; give --spacing DX or DX,DY "
            "(and --unit for the heights' unit, default m)"
        )
    stated = _unit(dataset)
    unit = stated or options.unit or "m"
    heights = np.asarray(dataset[()], dtype=np.float64) * metres_per(unit)
    metadata = channel_metadata(names, index)
    units = Units("m", unit, () if stated else ("z",))  # the spacing is --spacing's, a length with its unit
    return Surface(heights, options.spacing, units=units, metadata=metadata)


def _check_bytes(dataset, name, file_bytes):
    """Refuse a dataset whose values would take more than ``MAX_RATIO`` times the file: a chunked dataset
    left unwritten (all fill value) or compressed constant data, a bomb (HDF5 unpacks it unbounded)."""
    unpacked = dataset.size * dataset.dtype.itemsize
    ratio = limits.cap("MAX_RATIO")
    if unpacked > limits.RATIO_FLOOR and unpacked > ratio * file_bytes:
        raise FormatError(
            f"HDF5 dataset {name!r} of {limits.human(unpacked)} in a file of {limits.human(file_bytes)} is more "
            f"than {ratio}× its file (a compression bomb?); refusing (set ROUGH_MAX_RATIO to raise the cap)"
        )


def _datasets(h5py, handle):
    found = {}

    def visit(name, item):
        if isinstance(item, h5py.Dataset) and item.ndim == 2 and item.dtype.kind in "iuf":
            found[name] = item

    handle.visititems(visit)
    return found


def _default(names):
    for index, name in enumerate(names):
        if names_height(name.rsplit("/", 1)[-1]):
            return index
    return 0


def _unit(dataset):
    for key in ("units", "unit"):
        value = dataset.attrs.get(key)
        if isinstance(value, bytes):
            value = value.decode("latin-1")
        if isinstance(value, str) and value.strip():
            try:
                metres_per(value)
            except InputError:
                return None
            return value.strip()
    return None
