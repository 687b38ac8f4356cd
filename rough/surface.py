"""The data model: a measured or synthesised profile (1-D) or height map (2-D).

Conventions (docs/conventions.rst ("Data model")): heights are float64 metres, a profile is ``z[x]`` and a map
``z[y, x]`` (row-major, x fastest, as in X3P). ``spacing`` is ``(dx,)`` or
``(dx, dy)`` in metres; the physical length is ``n * dx``. NaN marks invalid points.
"""

import dataclasses
import datetime
import math
import os
from dataclasses import dataclass, field

import numpy as np

import rough  # the package: rough.io (which builds Surfaces) loads only when write() needs it

from . import __version__
from .errors import InputError
from .units import digits_for, format_length

MAX_POINTS = 1 << 28  # 16384 × 16384: 2 GiB of heights; `features` takes ~10× that (rough.io.limits)
SPACING_RANGE = (1e-12, 1e6)  # metres: below atomic resolution or beyond a continent, a unit is wrong
HEIGHT_LIMIT = 1e5  # metres: no surface on Earth reaches 100 km above or below its mean (Everest 8.8 km)
RELIEF_LIMIT = 1e3  # heights spanning more than this many times a surface's width: a unit is likely wrong


def check_size(shape, what):
    """Refuse to make a surface of ``shape`` past :data:`MAX_POINTS` (before allocating it)."""
    points = math.prod(shape)
    if points > MAX_POINTS:
        raise InputError(
            f"{what} would hold {points:,} points, more than rough's limit of {MAX_POINTS:,} "
            "(16384 × 16384); choose a coarser spacing or a smaller size"
        )


@dataclass(frozen=True, repr=False)
class Units:
    """The units a surface's source file used for lateral and height values.

    Informational only: rough always holds metres, whatever the file used. Readers
    record the units they found; writers whose format carries them (``rough formats``
    lists what each carries) pass them on. A file that states no unit (NPY, a bare
    column of numbers) is read in metres, or the unit given to the reader, and its
    reader lists the axes in ``assumed``: ``rough info`` says so.

    Attributes
    ----------
    xy : str, default "m"
        The unit of lateral positions in the source file (``m``, ``mm``, ``um``, ...).
    z : str, default "m"
        The unit of heights in the source file.
    assumed : tuple of str, default ()
        The axes (``"xy"``, ``"z"``) whose unit the file does not state: the unit above
        is the one rough was told or assumed (metres).

    Examples
    --------
    >>> import rough
    >>> rough.Units()
    Units(xy='m', z='m')
    >>> scan = rough.read(b"x[mm] z[um]\\n0 1.5\\n0.5 -2\\n1.0 0.5\\n")
    >>> scan.units                             # as the file said; heights are in metres
    Units(xy='mm', z='um')
    >>> round(float(scan.heights[0]) * 1e6, 6)  # µm
    1.5
    >>> rough.read(b"0 1.5e-6\\n5e-4 -2e-6\\n1e-3 0.5e-6\\n").units
    Units(xy='m', z='m', assumed=('xy', 'z'))
    """

    xy: str = "m"
    z: str = "m"
    assumed: tuple = ()

    def __repr__(self):
        assumed = f", assumed={tuple(self.assumed)!r}" if self.assumed else ""
        return f"Units(xy={self.xy!r}, z={self.z!r}{assumed})"

    def description(self):
        """The units as ``rough info`` and reports print them, saying which the file
        did not state and in which unit its numbers were read.

        >>> Units("mm", "um").description()
        'xy mm, z um (as the file states)'
        >>> Units(assumed=("z",)).description()
        'xy m, z m (assumed: the source file stated no unit for z; numbers read z in m)'
        """
        line = f"xy {self.xy}, z {self.z}"
        if not self.assumed:
            return f"{line} (as the file states)"
        read = ", ".join(f"{axis} in {getattr(self, axis)}" for axis in self.assumed)
        return f"{line} (assumed: the source file stated no unit for {' or '.join(self.assumed)}; numbers read {read})"


@dataclass(eq=False)
class Surface:
    """A profile or height map: heights on a regular grid, with provenance.

    ``Surface(heights, spacing, origin=None, units=Units(), metadata={}, history=[])``
    makes one from an array; :func:`rough.read` and the synthesis functions return
    one. Integer and float32 heights are converted to float64; a single spacing for a
    map is used for both axes.

    Attributes
    ----------
    heights : numpy.ndarray of float64
        Heights in metres, shape ``(nx,)`` for a profile (``z[x]``) or ``(ny, nx)`` for
        a map (``z[y, x]``, x fastest, as in X3P). NaN marks invalid points.
    spacing : tuple of float
        ``(dx,)`` or ``(dx, dy)``, metres, finite and positive.
    origin : tuple of float
        Position of the first point, ``(x0,)`` or ``(x0, y0)``, metres (default zeros).
    units : Units
        The units the data came in (see :class:`Units`); informational.
    metadata : dict of str
        Strings such as ``title``, ``instrument``, ``date``, ``source``.
    history : list of dict
        One entry per command that made or changed the surface, oldest first:
        ``{"command", "parameters", "version", "time"}``.
    source_format : str or None
        The format the surface was read from (a key of ``rough.io.FORMATS``), or None
        for a surface made or changed in memory.
    is_profile : bool
        True for a profile (1-D heights), False for a map.
    kind : str
        ``"profile"`` or ``"map"``.
    points : tuple of int
        Points along each axis, x first: ``(nx,)`` or ``(nx, ny)``.
    size : tuple of float
        Physical size along each axis, x first, in metres (``n * spacing``).
    valid : numpy.ndarray of bool
        Mask of the valid (non-NaN) points, shaped like ``heights``.

    Raises
    ------
    rough.InputError
        For heights that are not numbers, not 1-D or 2-D, or empty, and for a spacing
        or origin of the wrong length, not finite, or (spacing) outside 1 pm to 1000 km.

    See Also
    --------
    rough.read : Read a surface from a file, standard input or bytes.

    Notes
    -----
    ``shape``-like tuples (``points``, ``spacing``, ``size``, ``origin``) list x first,
    while ``heights.shape`` is row-major (y first). Methods: ``positions(axis)`` (sample
    positions, m), ``crop(x=(x0, x1), y=(y0, y1))`` (an evaluation range that includes
    the samples nearest to its ends), ``derive(command, parameters, **changes)`` (a
    changed copy with a history entry) and ``write(target, format=None)``.

    Examples
    --------
    A profile of four points 0.5 mm apart, one of them invalid:

    >>> import numpy as np
    >>> import rough
    >>> profile = rough.Surface(np.array([0.0, 1e-6, np.nan, 3e-6]), spacing=0.5e-3)
    >>> profile
    <Surface profile 4 points, spacing (0.0005) m, 0 history entries>
    >>> profile.kind, profile.points, profile.size  # size in metres
    ('profile', (4,), (0.002,))
    >>> profile.valid.tolist()
    [True, True, False, True]
    >>> profile.positions().tolist()  # m
    [0.0, 0.0005, 0.001, 0.0015]

    A map: ``heights`` is ``z[y, x]``, the tuples list x first.

    >>> scan = rough.read(rough.sample("rock-map.x3p"))
    >>> scan.heights.shape, scan.points
    ((96, 128), (128, 96))
    >>> [f"{length * 1e3:.1f} mm" for length in scan.size]
    ['6.4 mm', '4.8 mm']
    >>> int(scan.valid.sum()), scan.heights.size  # a 3 × 2 patch of invalid points
    (12282, 12288)
    >>> part = scan.crop(x=(1e-3, 2e-3))  # from x = 1 mm to 2 mm, every row
    >>> part.points, part.origin, part.history[-1]["command"]
    ((21, 96), (0.001, 0.0), 'crop')
    """

    heights: np.ndarray
    spacing: tuple
    origin: tuple = None
    units: Units = field(default_factory=Units)
    metadata: dict = field(default_factory=dict)
    history: list = field(default_factory=list)
    source_format: str = field(default=None, compare=False)

    def __post_init__(self):
        heights = np.asarray(self.heights)
        if heights.dtype != np.float64:
            if not (np.issubdtype(heights.dtype, np.floating) or np.issubdtype(heights.dtype, np.integer)):
                raise InputError(f"heights must be numbers, not {heights.dtype}")
            heights = heights.astype(np.float64)
        if heights.ndim not in (1, 2):
            raise InputError(f"a surface is a profile (1-D) or a map (2-D), not {heights.ndim}-D")
        if heights.size == 0:
            raise InputError("a surface needs at least one point")
        self.heights = heights
        self.spacing = _lengths(self.spacing, heights.ndim, "spacing", positive=True)
        _check_spacing(self.spacing)
        self.origin = _lengths(self.origin or (0.0,) * heights.ndim, heights.ndim, "origin")

    @property
    def is_profile(self):
        """True for a profile (1-D heights), False for a map."""
        return self.heights.ndim == 1

    @property
    def kind(self):
        """``"profile"`` or ``"map"``."""
        return "profile" if self.is_profile else "map"

    @property
    def points(self):
        """Points along each axis, x first: ``(nx,)`` or ``(nx, ny)``."""
        return tuple(reversed(self.heights.shape))

    @property
    def size(self):
        """Physical size along each axis, x first, in metres (``n * spacing``)."""
        return tuple(n * d for n, d in zip(self.points, self.spacing))

    @property
    def valid(self):
        """Boolean mask of the valid (non-NaN) points."""
        return ~np.isnan(self.heights)

    def derive(self, command, parameters, **changes):
        """A new surface with ``changes`` applied (e.g. ``heights=...``) and one history
        entry appended for ``command`` with its ``parameters`` (JSON-able values)."""
        entry = history_entry(command, parameters)
        return dataclasses.replace(
            self, history=[*self.history, entry], metadata=dict(self.metadata), source_format=None, **changes
        )

    def positions(self, axis=0):
        """Sample positions along ``axis`` (0 = x, 1 = y), metres."""
        return self.origin[axis] + self.spacing[axis] * np.arange(self.points[axis])

    def crop(self, x=None, y=None):
        """The part of the surface between two positions on each axis (metres; None
        keeps that end). A range includes the samples nearest to its ends, as an
        instrument's cursors do: ``crop(x=(468e-6, 733e-6))`` keeps the sample at
        467.97 µm when the spacing is 0.15625 µm. Raises InputError for a range that
        holds fewer than two samples."""
        bounds = [x, y][: self.heights.ndim]
        slices, origin = [], []
        for axis, bound in enumerate(bounds):
            start, stop = index_range(bound, self.origin[axis], self.spacing[axis], self.points[axis], "xy"[axis])
            slices.append(slice(start, stop))
            origin.append(self.origin[axis] + start * self.spacing[axis])
        index = tuple(reversed(slices))
        parameters = {"x": list(x) if x else None, "y": list(y) if y else None}
        return self.derive("crop", parameters, heights=self.heights[index], origin=tuple(origin))

    def write(self, target, format=None):
        """Write to a path or binary stream, atomically for paths, as
        :func:`rough.io.write` does. ``format`` is a key of ``rough.io.WRITABLE`` (``rough
        formats`` lists them); by default it follows the file extension, and a stream
        gets X3P."""
        rough.io.write(self, target, format=format)

    def __repr__(self):
        dims = " × ".join(str(n) for n in self.points)
        steps = ", ".join(f"{d:g}" for d in self.spacing)
        return f"<Surface {self.kind} {dims} points, spacing ({steps}) m, {len(self.history)} history entries>"


def history_entry(command, parameters):
    """One history entry stamped with rough's version and the time (UTC). The time is
    ``SOURCE_DATE_EPOCH`` when that is set, so that seeded output can be bit-identical."""
    return {"command": command, "parameters": dict(parameters), "version": __version__, "time": timestamp()}


def timestamp():
    """Now (or ``SOURCE_DATE_EPOCH``, whole seconds since 1970 UTC) as an ISO 8601 UTC
    string to the second; an InputError when ``SOURCE_DATE_EPOCH`` is set but is not
    such a number."""
    epoch = os.environ.get("SOURCE_DATE_EPOCH")
    if not epoch:
        return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    try:
        if not epoch.strip().isdigit():
            raise ValueError(epoch)
        moment = datetime.datetime.fromtimestamp(int(epoch), datetime.timezone.utc)
    except (ValueError, OverflowError, OSError):
        raise InputError(
            f"SOURCE_DATE_EPOCH={epoch!r}: not a time (whole seconds since 1970-01-01 UTC, e.g. 1767225600)"
        ) from None
    return moment.strftime("%Y-%m-%dT%H:%M:%SZ")


def _lengths(values, ndim, name, positive=False):
    try:
        values = tuple(float(v) for v in np.atleast_1d(values))
    except (TypeError, ValueError):
        raise InputError(f"{name} must be numbers (metres), not {values!r}") from None
    if len(values) == 1 and ndim == 2:
        values = values * 2
    if len(values) != ndim:
        raise InputError(f"a {ndim}-D surface needs {ndim} {name} values, got {len(values)}")
    if not all(np.isfinite(values)) or (positive and min(values) <= 0):
        raise InputError(f"{name} must be finite{' and positive' if positive else ''}, got {values}")
    return values


def _check_spacing(spacing):
    low, high = SPACING_RANGE
    outside = [d for d in spacing if not low <= d <= high]
    if outside:
        raise InputError(
            f"a spacing of {outside[0]:g} m is outside what any instrument samples at "
            f"({low:g} m to {high:g} m); check the file's units or --spacing"
        )


def index_range(bound, origin, spacing, count, name):
    """``(start, stop)`` sample indices of the positions between ``bound = (low, high)``
    (metres, either may be None) on the axis ``name`` of ``count`` samples from
    ``origin``, ends rounded to the nearest sample, as :meth:`Surface.crop` keeps them
    (readers of windows use it too). Raises InputError for fewer than two samples."""
    if bound is None:
        return 0, count
    low, high = bound
    start = 0 if low is None else max(0, int(np.floor((low - origin) / spacing + 0.5)))
    stop = count if high is None else min(count, int(np.floor((high - origin) / spacing + 0.5)) + 1)
    if stop - start < 2:
        last = origin + spacing * (count - 1)
        digits = digits_for(max(abs(origin), abs(last)), spacing)
        ends = ":".join("" if end is None else format_length(end, digits).replace(" ", "") for end in bound)
        raise InputError(
            f"the {name} range {ends} holds fewer than two samples "
            f"(the data span {format_length(origin, digits)} to {format_length(last, digits)})"
        )
    return start, stop
