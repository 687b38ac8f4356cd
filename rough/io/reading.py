"""Reading a surface: from a path, standard input, a stream or bytes, whatever the format.

:func:`read` sniffs the format from the content (:func:`rough.io.registry.sniff`),
unpacks gzip first, hands the bytes to the format's module and applies the checks
and options every format shares (:func:`read_bytes` does the same for bytes in
memory). Input arrives through :mod:`rough.io.receiving`, within the caps of
:mod:`rough.io.limits`.
"""

import contextlib
import dataclasses
import io
import logging
import math
import os
import struct
import sys
import threading
import tokenize
import xml.etree.ElementTree
import zipfile
import zlib

import numpy as np

from ..errors import FormatError, InputError
from ..surface import HEIGHT_LIMIT, RELIEF_LIMIT
from ..units import format_length
from . import limits, receiving, registry
from .regrid import option as regrid_option

GZIP_MAGIC = b"\x1f\x8b"
log = logging.getLogger("rough")

# What a malformed file makes the parsers raise; read() turns these into FormatError.
_PARSE_ERRORS = (
    ValueError,
    TypeError,
    KeyError,
    IndexError,
    struct.error,
    zipfile.BadZipFile,
    xml.etree.ElementTree.ParseError,
    UnicodeError,
    EOFError,
    OverflowError,
    zlib.error,
    SyntaxError,
    tokenize.TokenError,
)


@dataclasses.dataclass(frozen=True)
class ReadOptions:
    """What a file may not say for itself.

    spacing: ``(dx,)`` or ``(dx, dy)`` in metres, for data without one (NPY, a text
        column of heights); it also overrides a file's own spacing.
    unit: the length unit of text values that name none (default metres).
    verify: check X3P checksums; False reads a file whose checksums fail, with a warning.
    channel: the channel of a multi-channel file, a name or a number from 0 (default:
        the height channel).
    layer: the layer of a multi-layer X3P file, from 0 (default 0).
    window: ``((x0, x1), (y0, y1) or None)`` in metres, an ``--crop`` range that
        formats able to read part of a file (GeoTIFF) read alone; None ends are open.
    regrid: ``(spacing, method)`` for unevenly spaced profiles (see
        :mod:`rough.io.regrid`); without it they are refused.
    """

    spacing: tuple = None
    unit: str = None
    verify: bool = True
    channel: object = None
    layer: int = None
    window: tuple = None
    regrid: tuple = None

    def __post_init__(self):
        if self.regrid is not None:
            object.__setattr__(self, "regrid", regrid_option(self.regrid))


def read(source, *, spacing=None, unit=None, verify=True, channel=None, layer=None, crop=None, regrid=None):
    """Read a surface from a path, ``'-'`` (standard input), a binary stream or bytes.

    The format is sniffed from the content, not the name; gzip-compressed data are
    unpacked first.

    Parameters
    ----------
    source : str, os.PathLike, bytes or binary file object
        A path, ``'-'`` for standard input, an open binary stream, or the file's bytes.
    spacing : float or tuple of float, optional
        ``dx`` or ``(dx, dy)`` in metres (one value serves both axes), for data that
        carry none (NPY, a text column of heights, a plain matrix); it also overrides
        a file's own spacing.
    unit : str, optional
        The length unit of text values that name none (``mm``, ``um``, ...); default
        metres.
    verify : bool, default True
        Check X3P checksums; False reads a file whose checksums fail or are missing,
        with a warning.
    channel : str or int, optional
        The channel of a multi-channel file (AFM files, HDF5, ...): its name (any
        case) or its number from 0. Default: the height channel. ``rough info``
        lists a file's channels.
    layer : int, optional
        The layer of a multi-layer X3P file, from 0 (default 0).
    crop : tuple, optional
        ``((x0, x1), (y0, y1))`` or ``((x0, x1), None)``, metres, None for an open end:
        read only this range. GeoTIFF reads only that window from disk, so an
        elevation model larger than memory can be analysed piece by piece; other
        formats are read whole and cropped.
    regrid : float or (float, str), optional
        A spacing in metres, and optionally the method (``"linear"``, the default,
        which cannot ring, or ``"bandlimited"`` for coarsening), for unevenly spaced
        profiles (stylus exports,
        x z text): they are interpolated onto that grid and the step is recorded in
        the history. Without it such data are refused.

    Returns
    -------
    Surface
        Heights in metres (float64), with the file's spacing, origin, units, metadata
        and history; ``metadata["source"]`` names the source and ``source_format`` the
        format read.

    Raises
    ------
    rough.InputError
        For a file that cannot be read or used, with a message that starts with the
        file name; a :class:`~rough.errors.FormatError` for malformed files, and for
        files holding fewer than two points or no valid point.

    Notes
    -----
    Invalid points become NaN: X3P's valid-point mask, ``nan`` and ``BAD`` in text,
    ``BAD`` points of SDF files, and infinite heights (Alicona writes ``+inf``).

    Examples
    --------
    >>> import rough
    >>> scan = rough.read(rough.sample("rock-profile.tsv"))
    >>> scan.source_format, scan.heights.shape, scan.spacing  # spacing in metres
    ('tsv', (2048,), (3.09e-05,))

    Bytes work too; text names its units in the column names or a ``# unit:`` line,
    and ``nan`` or ``BAD`` mark invalid points:

    >>> text = b"x[mm]\\tz[um]\\n0\\t1.5\\n0.5\\tnan\\n1.0\\t-2\\n1.5\\tBAD\\n"
    >>> (rough.read(text).heights * 1e6).round(6).tolist()  # µm
    [1.5, nan, -2.0, nan]

    A bare column of heights needs a spacing:

    >>> column = rough.read(b"0.1\\n0.2\\n0.4\\n", spacing=1e-3, unit="um")
    >>> column.spacing, (column.heights * 1e9).round(6).tolist()  # m, nm
    ((0.001,), [100.0, 200.0, 400.0])
    """
    options = read_options(
        spacing=spacing, unit=unit, verify=verify, channel=channel, layer=layer, crop=crop, regrid=regrid
    )
    name = _name(source)
    with _warnings_held():
        with _named(name):
            surface = _read_path(name, options) if _is_path(source) else None
        if surface is None:
            name, data = _slurp(source)
            with _named(name):
                surface = read_bytes(data, options, name=name)
    surface.metadata.setdefault("source", name)
    log.info(
        "read %s: %s, %s points", name, registry.describe(surface.source_format), " × ".join(map(str, surface.points))
    )
    return surface


def read_options(spacing=None, unit=None, verify=True, channel=None, layer=None, crop=None, regrid=None):
    """The :class:`ReadOptions` of :func:`read`'s keywords."""
    return ReadOptions(
        spacing=_spacing_tuple(spacing),
        unit=unit,
        verify=verify,
        channel=channel,
        layer=layer,
        window=_window(crop),
        regrid=regrid,
    )


@contextlib.contextmanager
def _warnings_held():
    """Hold this thread's log records while a file is read: given out once it is read,
    dropped when it is refused, whose one line says what matters."""
    with held_warnings() as held:
        yield
    for record in held:
        log.handle(record)


@contextlib.contextmanager
def held_warnings():
    """Hold this thread's log records meanwhile, in the list it yields (for the caller
    to give out with ``log.handle`` or drop); other threads' records pass."""
    held, thread = [], threading.get_ident()

    def hold(record):
        if record.thread != thread:
            return True
        held.append(record)
        return False

    log.addFilter(hold)
    try:
        yield held
    finally:
        log.removeFilter(hold)


@contextlib.contextmanager
def _named(name):
    """Prefix the file's name to the message of an InputError raised inside."""
    try:
        yield
    except InputError as error:
        raise type(error)(f"{name}: {error}") from error


def read_bytes(data, options=ReadOptions(), name=None):
    """Parse a whole file's bytes (sniffing the format; ``name``'s extension decides
    for formats without a magic number) into a Surface, cropped to ``options.window``.
    Raises InputError (FormatError for malformed data) and nothing else for bad input."""
    with _malformed(lambda: registry.describe(registry.sniff(data, name))):
        return _parse(data, options, name)


@contextlib.contextmanager
def _malformed(title):
    """What a parser raises on a damaged file, as one InputError: FormatError naming
    the format (``title()`` gives its name, asked only then), or "too large"."""
    try:
        yield
    except MemoryError:
        raise InputError("too large to read into memory") from None
    except RecursionError:
        raise FormatError(f"malformed {title()} file (nested too deeply to read)") from None
    except _PARSE_ERRORS as error:
        raise FormatError(f"malformed {title()} file ({error})") from error


def _read_path(path, options):
    """A surface read straight from disk by a format that reads part of a file
    (``read_path``), or None for formats read from their bytes."""
    if not os.path.isfile(path):
        return None  # _slurp reads devices and pipes, and gives the messages
    try:
        with open(path, "rb") as stream:
            head = stream.read(registry.HEAD)
        format_module = registry.module_of(registry.sniff(head, path))
    except (OSError, InputError):
        return None
    if not hasattr(format_module, "read_path"):
        return None
    with _malformed(lambda: format_module.FORMAT.title), np.errstate(all="ignore"):
        surface = format_module.read_path(path, options)
    return _checked(surface, format_module.FORMAT.name, options, windowed=True)


def _parse(data, options, name=None):
    if not data:
        raise FormatError("empty file, no surface to read")
    packed, layers = len(data), 0
    while bytes(data[:2]) == GZIP_MAGIC:
        layers += 1
        if layers > limits.MAX_GZIP_LAYERS:
            raise FormatError(f"gzip nested more than {limits.MAX_GZIP_LAYERS} deep; refusing")
        data = gunzip(data, packed)
    format_name = registry.sniff(data, name)
    if format_name == "tsv" and len(data) > limits.cap("MAX_TEXT_BYTES"):
        raise limits.too_much_text(len(data))
    with np.errstate(all="ignore"):
        surface = registry.module_of(format_name).read(data, options)
    return _checked(surface, format_name, options)


def _checked(surface, format_name, options, windowed=False):
    """The checks and options every format shares: infinite heights → NaN, at least
    two points and one valid, heights within ±:data:`~rough.surface.HEIGHT_LIMIT`,
    ``options.spacing`` and ``options.window``."""
    surface.source_format = format_name
    squares = _sum_of_squares(surface.heights)  # one pass: NaN, infinity or a huge height all show in it
    clean = squares <= HEIGHT_LIMIT**2
    if not clean and not np.isfinite(surface.heights).all():
        infinite = np.isinf(surface.heights)
        if infinite.any():
            first = np.unravel_index(np.argmax(infinite), infinite.shape)[::-1]
            log.warning(
                "%d infinite heights marked invalid (NaN), the first at point %s",
                infinite.sum(),
                ", ".join(map(str, first)),
            )
            surface.heights = np.where(infinite, np.nan, surface.heights)
    if surface.heights.size < 2:
        raise FormatError(f"holds {surface.heights.size} point; a surface needs at least two points")
    if not clean and np.isnan(surface.heights).all():
        raise FormatError(f"holds no valid points (all {surface.heights.size} heights are invalid)")
    given = None if options.spacing is None else options.spacing[: surface.heights.ndim]
    if given is not None and tuple(surface.spacing) != tuple(given):
        log.warning(
            "the spacing given, %s, overrides the file's own, %s",
            " × ".join(map(format_length, given)),
            " × ".join(map(format_length, surface.spacing)),
        )
        surface = dataclasses.replace(surface, spacing=given)
    _plausible(surface, None if np.isnan(squares) else squares)
    if options.window is not None and not windowed:
        x, y = options.window
        if y is not None and surface.is_profile:
            raise InputError("a profile has no y range; crop it with X0:X1")
        surface = dataclasses.replace(surface.crop(x, y), source_format=surface.source_format)
    return surface


def _sum_of_squares(heights):
    """Σ z² in one pass without a temporary: NaN when a height is NaN, infinite when
    one is infinite or beyond 1e154 m."""
    with np.errstate(over="ignore", invalid="ignore"):
        if heights.flags.c_contiguous:
            flat = heights.reshape(-1)
            return float(np.dot(flat, flat))
        return float(sum(np.dot(row, row) for row in np.atleast_2d(heights)))


def _plausible(surface, squares):
    """Refuse heights beyond ±HEIGHT_LIMIT (no surface reaches them: the data are
    damaged, or their unit is wrong) and warn of heights spanning more than
    RELIEF_LIMIT times the surface's width. ``squares`` is Σ z² (None with NaN
    heights), which spares a look at every height when it is small enough."""
    heights, unit = surface.heights, surface.units.z
    width = max(surface.size)
    if squares is not None and squares <= HEIGHT_LIMIT**2 and 2 * math.sqrt(squares) <= RELIEF_LIMIT * width:
        return  # every |z| is at most √Σz²: within the limit, and the span within twice that
    low, high = np.nanmin(heights), np.nanmax(heights)
    if max(-low, high) > HEIGHT_LIMIT:
        worst = low if -low > high else high
        point = np.unravel_index(np.argmax(heights == worst), heights.shape)[::-1]
        raise FormatError(
            f"a height of {worst:.6g} m (at point {', '.join(map(str, point))}) is beyond "
            f"±{format_length(HEIGHT_LIMIT)}, which no surface reaches: the data are damaged, "
            f"or their unit ({unit}) is wrong"
        )
    if high - low > RELIEF_LIMIT * width:
        log.warning(
            "the heights span %s, %.3g times the surface's %s width: is their unit (%s) right?",
            format_length(high - low),
            (high - low) / width,
            format_length(width),
            unit,
        )


def gunzip(data, packed=None):
    """Unpack gzip data, every member of it (``cat a.gz b.gz``), in chunks: refused
    past the caps of :mod:`rough.io.limits` (MAX_TEXT_BYTES once the first bytes
    show text), counted against ``packed`` bytes (the size of the file as given, for
    nested gzip)."""
    budget = limits.Budget(packed or len(data), "gzip data")
    parts, pending, looked = [], bytes(data), False
    while pending:
        unpacker = zlib.decompressobj(wbits=31)
        while pending and not unpacker.eof:
            part = unpacker.decompress(pending, min(limits.CHUNK << 4, budget.room()))
            pending = unpacker.unconsumed_tail
            parts.append(part)
            if not looked and (budget.total + len(part) >= registry.HEAD or not pending):
                looked = True
                if _is_text(b"".join(parts)[: registry.HEAD]):
                    budget.holds_text()  # text is capped as it unpacks, not once unpacked
            budget.add(len(part))
        if not unpacker.eof:
            raise FormatError("truncated gzip data")
        pending = unpacker.unused_data
        if pending and pending[:2] != GZIP_MAGIC:
            if pending.strip(b"\0"):
                raise FormatError(f"{len(pending)} bytes of junk after the gzip data")
            pending = b""
    return b"".join(parts)


def _slurp(source):
    """``(name for messages, bytes)`` of a path, ``'-'``, a stream or bytes."""
    if isinstance(source, (bytes, bytearray, memoryview)):
        if len(source) > limits.cap("MAX_INPUT_BYTES"):
            raise InputError(f"<bytes>: more than {limits.human(limits.cap('MAX_INPUT_BYTES'))}; refusing")
        return "<bytes>", source
    if source == "-" or source is sys.stdin:
        receiving.widen_pipe(sys.stdin)
        return "<stdin>", receiving.read_capped(sys.stdin.buffer, "<stdin>", _is_text)
    if isinstance(source, (str, os.PathLike)):
        name = os.fspath(source)
        try:
            with open(name, "rb") as stream:
                return name, receiving.read_capped(stream, name, lambda head: _is_text(head, name))
        except FileNotFoundError:
            raise InputError(f"{name}: no such file") from None
        except IsADirectoryError:
            raise InputError(f"{name}: is a folder, not a surface file") from None
        except PermissionError:
            raise InputError(f"{name}: permission denied") from None
    if isinstance(source, io.IOBase) or hasattr(source, "read"):
        name = getattr(source, "name", "<stream>")
        return name, receiving.read_capped(source, name, _is_text)
    raise InputError(f"cannot read a surface from {type(source).__name__}")


def _is_text(head, name=None):
    """Whether input starting with ``head`` is read as text (and so capped at
    MAX_TEXT_BYTES while it arrives); gzip data are capped once unpacked."""
    try:
        return bytes(head[:2]) != GZIP_MAGIC and registry.sniff(head, name) == "tsv"
    except InputError:
        return False


def _is_path(source):
    return isinstance(source, (str, os.PathLike)) and os.fspath(source) != "-"


def _name(source):
    if _is_path(source):
        return os.fspath(source)
    if source == "-" or source is sys.stdin:
        return "<stdin>"
    if isinstance(source, (bytes, bytearray, memoryview)):
        return "<bytes>"
    return getattr(source, "name", "<stream>")


def _window(crop):
    if crop is None:
        return None
    x, y = (tuple(crop) + (None,))[:2]
    return (tuple(x) if x is not None else (None, None)), (tuple(y) if y is not None else None)


def _spacing_tuple(spacing):
    if spacing is None:
        return None
    values = tuple(float(s) for s in (spacing if isinstance(spacing, (tuple, list)) else (spacing,)))
    if len(values) == 1:
        values = values * 2
    if len(values) != 2 or not all(0 < v < float("inf") for v in values):
        raise InputError(f"spacing must be one or two positive lengths, got {spacing!r}")
    return values
