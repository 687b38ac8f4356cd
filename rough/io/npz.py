"""NPZ: a NumPy archive of named arrays (``numpy.savez``, ``numpy.savez_compressed``), read only.

An NPZ file is a zip archive of NPY members. Each member's NPY header is checked as
an NPY file's is (numbers, 0-D to 2-D, exactly as many bytes as it declares: fewer
mean a damaged file), and the archive's sizes and CRCs as an X3P's are; a member
holding Python objects (a pickled string such as ``meta_str``) is skipped, never
unpickled.

Channels: the 2-D numeric members, in the archive's order. An archive without one
is a profile, its channels the 1-D numeric members (a member named ``x…`` of the
profile's length is its x axis, not a channel). ``--channel`` takes a name (without
``.npy``, any case) or a number from 0. The default is the raw height array: the
first member whose name says height (:data:`rough.io.registry.HEIGHT_NAME`: ``z``
as a word, ``height``, ``topography``, ``surface``, ``elevation``, ...) and, split at
anything not a letter, holds no word of processing (``detrended``, ``levelled``,
``filtered``, ``residual``, …); else the first that says height; else the first.
rough removes form itself, so the raw heights are the honest default (``Z_grid`` before ``Z_detrended``).

Spacing and origin, per axis: a scalar member ``dx`` (``dy``), else a 1-D axis
member named ``x…`` (``y…``: ``x``, ``xg``, ``x_axis``) as long as the columns
(rows), equally spaced to 1e-6 of its step, its first value the origin. A lone
``dx`` serves both axes of a map, as ``--spacing DX`` does. A scalar and an axis
that disagree are refused. NPZ carries no units: spacing, axes and heights are taken
in metres. Without any of these, ``--spacing`` is required, as for NPY. Rows are y:
row 0 lies at the y axis's first value; a decreasing axis is reversed (with its
rows or columns) so that positions increase with the index.
"""

import io
import re
import zipfile

import numpy as np

from ..errors import FormatError
from ..surface import Surface, Units, check_size
from . import ziparchive
from .header import zip_names
from .registry import Format, channel_metadata, choose_channel, names_height

FORMAT = Format(
    "npz",
    "NumPy NPZ",
    (".npz",),
    magic=(b"PK\x03\x04",),
    probe=lambda head: _holds_npy(zip_names(head)),
    carries=("spacing", "channels"),
)

PROCESSED_WORDS = {"detrended", "levelled", "leveled", "filtered", "flattened", "residual", "residuals", "fitted"}
HEADER_BYTES = 1 << 16  # an NPY header is at most this long here
AXIS_TOLERANCE = 1e-6  # of the step: how far an axis may stray from equal spacing


def _holds_npy(names):
    return any(name.endswith(".npy") for name in names) and not any(name.endswith("main.xml") for name in names)


def read(data, options):
    try:
        archive = zipfile.ZipFile(ziparchive.ViewFile(data))
        headers = {info.filename[: -len(".npy")]: (info, _header(archive, info)) for info in _members(archive)}
    except (*ziparchive.ZIP_ERRORS, ValueError) as error:
        raise FormatError(f"not a readable NPZ archive ({error})") from None
    numeric = {name: found for name, found in headers.items() if found[1] is not None}
    maps = [name for name, (_, header) in numeric.items() if len(header[0]) == 2]
    names = maps or [name for name, (_, header) in numeric.items() if len(header[0]) == 1 and header[0][0] >= 2]
    if not maps:
        names = [name for name in names if not name.casefold().startswith("x")] or names
    if not names:
        raise FormatError("NPZ archive holds no numeric 1-D or 2-D array to read as heights")
    index = choose_channel(names, options.channel, default_channel(names))
    heights = _array(archive, data, numeric[names[index]])
    check_size(heights.shape, f"NPZ array {names[index]!r}")
    values = {name: found for name, found in numeric.items() if name != names[index]}
    spacing, origin, flips = _geometry(archive, data, values, heights.shape[::-1], options)
    for axis in flips:
        heights = np.flip(heights, axis=heights.ndim - 1 - axis)
    metadata = channel_metadata(names, index)
    units = Units("m", "m", assumed=("xy", "z"))  # NPZ states no unit: metres
    return Surface(np.asarray(heights, np.float64), spacing, origin, units=units, metadata=metadata)


def default_channel(names):
    """The index of the raw height array among ``names``: a height word and no word of
    processing, else a height word, else the first (see the module's notes).

    >>> default_channel(["xg", "Z_detrended", "Z_grid"])
    2
    >>> default_channel(["a", "b"])
    0
    """

    def rank(index):
        if not names_height(names[index]):
            return 2, index
        return (1 if set(re.split(r"[^a-z]+", names[index].casefold())) & PROCESSED_WORDS else 0), index

    return min(range(len(names)), key=rank)


def _members(archive):
    for info in archive.infolist():
        if info.filename.endswith(".npy") and not info.is_dir():
            yield info


def _header(archive, info):
    """``(shape, fortran, dtype, header length)`` of a numeric member of at most two
    dimensions; None for any other member (objects are skipped, never unpickled)."""
    with archive.open(info) as member:
        head = member.read(HEADER_BYTES)
    stream = io.BytesIO(head)
    version = np.lib.format.read_magic(stream)
    reader = {(1, 0): np.lib.format.read_array_header_1_0, (2, 0): np.lib.format.read_array_header_2_0}.get(version)
    if reader is None:
        raise FormatError(f"{info.filename}: NPY format version {version[0]}.{version[1]} is not supported")
    shape, fortran, dtype = reader(stream)
    if dtype.kind not in "iuf" or len(shape) > 2:
        return None
    if not all(isinstance(n, int) and n >= 0 for n in shape):
        raise FormatError(f"{info.filename}: NPY shape {shape} is not a list of sizes")
    return shape, fortran, dtype, stream.tell()


def _array(archive, data, found):
    """A member's numbers, after checking it holds exactly what its NPY header declares."""
    info, (shape, fortran, dtype, offset) = found
    content = ziparchive.member(archive, info.filename, data)
    count = int(np.prod(shape, dtype=object))
    if count * dtype.itemsize != len(content) - offset:
        raise FormatError(
            f"{info.filename}: its NPY header declares {'×'.join(map(str, shape)) or 'one'} values of "
            f"{dtype.itemsize} bytes; the member holds {len(content) - offset} bytes"
        )
    values = np.frombuffer(content, dtype, count=count, offset=offset)
    return values.reshape(shape[::-1]).T if fortran else values.reshape(shape)


def _geometry(archive, data, values, points, options):
    """``(spacing, origin, flipped axes)`` from the members ``dx``, ``dy`` and the axes,
    or ``options.spacing``; the x axis first."""
    spacing, origin, flips = [], [], []
    for axis, count in enumerate(points):
        letter = "xy"[axis]
        step = _scalar(archive, data, values, f"d{letter}")
        line = _axis(archive, data, values, letter, count)
        if line is not None:
            first, line_step = line
            if step is not None and not np.isclose(step, abs(line_step), rtol=AXIS_TOLERANCE, atol=0):
                raise FormatError(f"NPZ member d{letter} = {step:g} m disagrees with the {letter} axis's step")
            if line_step < 0:
                flips.append(axis)
                first, line_step = first + line_step * (count - 1), -line_step
            step = line_step
            origin.append(first)
        else:
            origin.append(0.0)
        if step is None and axis == 1 and _scalar(archive, data, values, "dx") is not None:
            step = spacing[0]
        spacing.append(step)
    if None in spacing:
        if options.spacing is None:
            raise FormatError("NPZ archive carries no spacing (no dx, dy or x, y axes); give it with --spacing")
        return options.spacing[: len(points)], None, []
    return tuple(spacing), tuple(origin), flips


def _scalar(archive, data, values, name):
    found = _named(values, lambda key: key == name, lambda shape: int(np.prod(shape)) == 1)
    if found is None:
        return None
    value = float(_array(archive, data, found).reshape(-1)[0])
    if not (np.isfinite(value) and value > 0):
        raise FormatError(f"NPZ member {name} = {value:g} is not a positive length")
    return value


def _axis(archive, data, values, letter, count):
    """``(first value, step)`` of the equally spaced 1-D member named ``letter…`` with
    ``count`` values; None when there is none."""
    found = _named(values, lambda key: key.startswith(letter), lambda shape: shape == (count,))
    if found is None or count < 2:
        return None
    line = _array(archive, data, found).astype(np.float64)
    step = (line[-1] - line[0]) / (count - 1)
    if not (
        np.isfinite(line).all() and step != 0 and np.all(np.abs(np.diff(line) - step) <= AXIS_TOLERANCE * abs(step))
    ):
        raise FormatError(f"NPZ axis {found[0].filename[:-4]!r} is not equally spaced; rough reads regular grids")
    return float(line[0]), float(step)


def _named(values, name_matches, shape_matches):
    for name, (info, header) in values.items():
        if name_matches(name.casefold()) and shape_matches(header[0]):
            return info, header
    return None
