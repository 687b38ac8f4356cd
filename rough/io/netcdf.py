"""NetCDF (classic ``CDF\\x01`` and 64-bit-offset ``CDF\\x02``) in SurfaceTopography's layout, read only.

The layout SurfaceTopography's ``to_netcdf`` writes (``SurfaceTopography/IO/NC.py``): a variable ``heights`` with
dimensions ``(x, y)`` for a map or ``(x,)`` for a profile, **x first**; coordinate variables ``x`` and ``y`` whose
attribute ``length`` is the physical size along that axis (n·dx) and ``unit`` the length unit of sizes and heights
alike (``heights`` may carry its own ``unit``); an optional int8 variable ``mask`` of the same shape, non-zero at
undefined points (NaN here); an optional global attribute ``json`` with SurfaceTopography's ``info`` dictionary
(``acquisition_time`` becomes ``date``). A nonuniform profile has the dimension ``n`` and variables ``x(n)`` and
``heights(n)``; it goes through :func:`rough.io.regrid.profile_from_points`.

Orientation: rough's ``z[y, x]`` is the transpose of the file's ``heights(x, y)``. Without ``length`` attributes
the data need ``--spacing``; without a ``unit`` they are taken in ``--unit`` (default metres).

NetCDF-4 files are HDF5 files (they start with HDF5's signature) and are read by the HDF5 reader, as bare
datasets. Read with ``scipy.io.netcdf_file``.
"""

import io
import json
import struct

import numpy as np

from ..errors import FormatError
from ..surface import Surface, Units, check_size
from ..units import metres_per
from . import regrid
from .registry import Format

FORMAT = Format(
    "netcdf", "NetCDF", (".nc",), magic=(b"CDF\x01", b"CDF\x02"), carries=("spacing", "units", "metadata", "mask")
)


def read(data, options):
    from scipy.io import netcdf_file  # start-up: only NetCDF loads scipy.io (the sniffer imports every format)

    try:
        with netcdf_file(io.BytesIO(bytes(data)), "r", mmap=False, maskandscale=False) as nc:
            return _surface(nc, options)
    except (TypeError, ValueError, struct.error, OverflowError, IndexError, KeyError, AttributeError) as error:
        raise FormatError(f"malformed NetCDF file ({error})") from None


def _surface(nc, options):
    variables = nc.variables
    if "heights" not in variables:
        raise FormatError(f"NetCDF file holds no 'heights' variable (it holds {', '.join(variables) or 'none'})")
    heights_var = variables["heights"]
    dims = heights_var.dimensions
    if len(dims) not in (1, 2):
        raise FormatError(f"NetCDF 'heights' has {len(dims)} dimensions; rough reads 1 (profile) or 2 (map)")
    heights = np.array(heights_var.data, dtype=np.float64)
    check_size(heights.shape, "the NetCDF heights")
    if not heights.size:
        raise FormatError(f"NetCDF 'heights' holds no points (shape {heights.shape})")
    if "mask" in variables:
        mask = np.asarray(variables["mask"].data)
        if mask.shape != heights.shape:
            raise FormatError("NetCDF 'mask' is not shaped like 'heights'")
        heights[mask != 0] = np.nan
    x_var = variables.get("x")
    unit = _unit(x_var) or _unit(heights_var) or options.unit or "m"
    factor = metres_per(unit)
    z_unit = _unit(heights_var) or unit
    heights *= metres_per(z_unit)
    metadata = _metadata(nc)
    units = Units(unit, z_unit)
    if dims == ("n",):
        if x_var is None or x_var.shape != heights.shape:
            raise FormatError("NetCDF nonuniform profile lacks its 'x' positions")
        x = np.array(x_var.data, dtype=np.float64) * factor
        return regrid.profile_from_points(x, heights, options, units=units, metadata=metadata)
    lengths = [_length(variables.get(name), count) for name, count in zip(dims, heights.shape)]
    if None in lengths:
        if options.spacing is None:
            raise FormatError("NetCDF file gives no physical size ('length' attribute); give --spacing")
        spacing = options.spacing
    else:
        spacing = tuple(length * factor / count for length, count in zip(lengths, heights.shape))
    if heights.ndim == 1:
        return Surface(heights, spacing[:1], units=units, metadata=metadata)
    return Surface(heights.T, spacing, units=units, metadata=metadata)


def _unit(variable):
    value = getattr(variable, "unit", None) if variable is not None else None
    if isinstance(value, bytes):
        value = value.decode("latin-1")
    return value.strip() if value else None


def _length(variable, count):
    value = getattr(variable, "length", None) if variable is not None else None
    if value is None:
        return None
    length = float(np.asarray(value).ravel()[0])
    if not (0 < length < np.inf):
        raise FormatError(f"NetCDF length {length} is not a positive size")
    return length


def _metadata(nc):
    text = getattr(nc, "json", None)
    if not text:
        return {}
    try:
        info = json.loads(text.decode("utf-8") if isinstance(text, bytes) else text)
    except (ValueError, UnicodeError):
        raise FormatError("NetCDF 'json' attribute is not JSON") from None
    if not isinstance(info, dict):
        return {}
    metadata = {f"netcdf_{key}": str(value) for key, value in info.items() if key != "acquisition_time"}
    if "acquisition_time" in info:
        metadata["date"] = str(info["acquisition_time"])
    return metadata
