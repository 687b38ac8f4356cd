"""Text surfaces: read in several dialects, written as TSV.

Read (the dialect is recognised from the content):

columns
    ``z`` alone (needs ``--spacing``), ``x z``, ``x z valid`` or ``x y z`` (an x y z
    grid, points in any order, missing points NaN), separated by spaces, tabs, commas
    or semicolons (then a decimal comma is accepted); an optional line of column
    names, whose units (``x[um]``, ``z (nm)``, ``x in µm``, or a bare unit such as
    ``µm µm``) or a following line of units (``[mm];[mm];[1/0]``) say the unit; a
    ``# unit: mm`` line gives it for all columns. A first column named ``index`` (or
    ``#``, ``no``, ``n``) that counts the rows is dropped; a line holding one whole
    number between the names and the rows (a point count) is skipped. Four or more
    columns are a plain matrix of heights (rows are y; needs ``--spacing``). UTF-8,
    UTF-16 with a byte-order mark, or Latin-1.
Dektak
    the Bruker Dektak CSV export (``Scan Parameters`` … ``Scan Data``).
Gwyddion
    Gwyddion's text export (``# Width:``, ``# Height:``, ``# Value units:``,
    ``# Channel:``), also with German keywords (``Breite``, ``Höhe``, ``Kanal``).
key=value
    a matrix after ``h=… w=…``, ``pixel size=…``, ``height conversion factor``.

Units: named in the file, else ``unit`` (``--unit``), else metres. x values count as
evenly spaced when they are within their printed precision of a line (Dektak prints
0.1 µm steps for a 0.15625 µm spacing; a bare ``0`` counts as printed as finely as
the other values; x printed coarser than a tenth of a step needs at least ten points
to count); the spacing is their least-squares slope. Profiles with unevenly
spaced x go through :func:`rough.io.regrid.profile_from_points`: gridded on request
(``--regrid``), refused otherwise. ``nan`` and ``BAD`` mark invalid points.

Written (TSV): ``#`` lines with the unit, spacing, origin, point count, units, metadata
and one line per history entry, then ``x z`` (profiles) or ``x y z`` (maps, a blank line
after each row, as gnuplot expects), in metres, with every float printed to round-trip
exactly, every line ended.

A file cut short is refused where it shows (docs/formats.rst, "Damaged files"): rough's
own TSV by its point count and line ends, other text by a last line without a line end
that has fewer values than the line above or whose last number is printed unlike its
column's.
"""

import json
import logging
import re
import unicodedata

import numpy as np

from .. import __version__
from ..errors import FormatError, InputError
from ..surface import Surface, Units
from ..units import metres_per
from . import provenance, regrid
from .registry import Format

log = logging.getLogger("rough")


def _looks_like_text(head):
    return head.startswith((b"\xff\xfe", b"\xfe\xff")) or b"\0" not in head[:4096]


FORMAT = Format(
    "tsv",
    "text",
    (".tsv", ".txt"),
    probe=_looks_like_text,
    writes=True,
    carries=("spacing", "exact-grid", "units", "metadata", "mask", "history"),
    binary=False,
)

_UNIT_IN_NAME = re.compile(r"[\[(]\s*([^\])]+?)\s*[\])]|\s([A-Za-zµμÅ]+)\s*$")
_NUMERIC = re.compile(r"^[\s,;]*[+-]?(\d|\.\d|nan|inf|bad)", re.IGNORECASE)
_BAD = re.compile(r"\bBAD\b", re.IGNORECASE)
_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")
_MISTYPED_NUMBER = re.compile(r"^[+-]?[\dOoIl]*[\d.][\dOoIl.]*([eE][+-]?\d+)?$")
_PRINTED = re.compile(r"^[+-]?\d*(?:[.,](\d*))?(?:[eE][+-]?(\d*))?$")
_BLANK_LINE_AT_END = re.compile(r"(\r\n|\n|\r)[ \t]*(\r\n|\n|\r)\s*$")
_INFINITY = re.compile(r"^[+-]?inf(inity)?$", re.IGNORECASE)
_COUNT = re.compile(r"^\s*\d+\s*$")
_INDEX_NAMES = ("index", "idx", "#", "no", "no.", "nr", "n", "point")
_GWYDDION_KEYS = {"kanal": "channel", "breite": "width", "höhe": "height"}  # German export


class _BadLine(FormatError):
    """A problem in one line; read() adds the line's number."""

    def __init__(self, line, problem):
        super().__init__(problem)
        self.line = line


def read(data, options):
    text = _decode(data)
    raw = text.splitlines()
    lines = [line for line in raw if line.strip()]
    if not lines:
        raise FormatError("empty text file, no surface to read")
    try:
        _check_ending(text, lines)
        del text  # the lines hold the data from here on: a map's text is tens of MB
        return _read_lines(lines, options)
    except _BadLine as error:
        raise FormatError(f"line {_line_number(raw, error.line)}: {error}") from None


def _check_ending(text, lines):
    """Refuse a file cut short (docs/formats.rst, "Damaged files"). rough's own TSV
    ends every line, and a map's every row with a blank line. A file of any other
    kind whose last line has no line end is cut short when that line has fewer
    values than the line before it, or when its last number is printed unlike the
    numbers above it in its column (or, with none above, the numbers before it in
    its line), two or more that share one style: without their exponent, with a
    shorter exponent, or with fewer decimals. Otherwise a warning says that the last
    value may be cut."""
    if lines[0].startswith("# rough "):
        if not text.endswith(("\n", "\r")):
            raise _BadLine(lines[-1], "the last line has no line end; rough ends every line, so the file was cut short")
        if " map:" in lines[0] and not _BLANK_LINE_AT_END.search(_trailing_space(text)):
            raise _BadLine(lines[-1], "the last row of the map has no blank line after it, so the file was cut short")
        return
    if text.endswith(("\n", "\r")) or not _NUMERIC.match(lines[-1]):
        return
    numeric_above = len(lines) > 1 and _NUMERIC.match(lines[-2])
    delimiter = _delimiter(lines[-2] if numeric_above else lines[-1])
    last = [field for field in _split(lines[-1], delimiter) if field]
    above = [field for field in _split(lines[-2], delimiter) if field] if numeric_above else []
    if len(last) < len(above):
        raise _BadLine(
            lines[-1],
            f"the last line has {len(last)} values where the line before has {len(above)}, "
            "and no line end: the file was cut short",
        )
    column = [fields[len(last) - 1] for fields in _column_above(lines, delimiter, len(last))] or last[:-1]
    if _printed_unlike(last[-1], column):
        raise _BadLine(
            lines[-1],
            f"the last number, {last[-1]!r}, is printed unlike the others of its column (e.g. {column[-1]!r}) "
            "and the file has no line end: it was cut short (if not, end the file with a line end)",
        )
    log.warning("the file has no line end after its last value, %r: if it was cut short, that value is wrong", last[-1])


def _trailing_space(text):
    """The white space that ends ``text``, found without a pass over the rest."""
    end = len(text)
    while end and text[end - 1].isspace():
        end -= 1
    return text[end:]


def _column_above(lines, delimiter, count):
    """The fields of up to 100 numeric lines before the last that have ``count`` values."""
    rows = []
    for line in reversed(lines[-101:-1]):
        fields = [field for field in _split(line, delimiter) if field]
        if not _NUMERIC.match(line) or len(fields) != count:
            break
        rows.append(fields)
    return rows


def _printed_unlike(token, column):
    """Whether ``token`` reads as a cut copy of the style that the numbers of
    ``column`` (two or more) share: all with an exponent (it has none, or fewer
    exponent digits than any of them), or all without one and with the same count of
    decimals (it has fewer)."""
    styles = [_style(field) for field in column]
    mine = _style(token)
    if len(column) < 2 or mine is None or None in styles:
        return False
    exponents = {exponent for _, exponent in styles}
    if 0 not in exponents:
        return mine[1] < min(exponents)
    decimals = {decimal for decimal, _ in styles}
    return exponents == {0} and len(decimals) == 1 and mine[0] < min(decimals)


def _style(token):
    """``(decimals, exponent digits)`` of a printed number, None for other text."""
    match = _PRINTED.match(token)
    if not match:
        return None
    return len(match.group(1) or ""), len(match.group(2) or "")


def _line_number(raw, line):
    """The number of ``line`` in the file: the same string object where it was passed on
    unchanged (a repeated line has several numbers), else the first equal line."""
    same = next((i for i, candidate in enumerate(raw) if candidate is line), None)
    return (raw.index(line) if same is None else same) + 1


def _read_lines(lines, options):
    if any(line.strip() == "Scan Data" for line in lines[:200]):
        return _dektak(lines, options)
    if any(line.startswith(("# Width:", "# Breite:")) for line in lines[:20]):
        return _gwyddion_export(lines)
    if "=" in lines[0] and not _NUMERIC.match(lines[0]):
        return _key_value_matrix(lines, options)
    return _columns(lines, options)


def write(surface, stream):
    stream.write(header_lines(surface).encode("utf-8"))
    x = surface.origin[0] + surface.spacing[0] * np.arange(surface.points[0])
    x_text = [repr(position) for position in x.tolist()]  # each row of a map repeats them
    if surface.is_profile:
        stream.write(b"x\tz\n")
        _write_rows(stream, x_text, "", surface.heights)
        return
    stream.write(b"x\ty\tz\n")
    for row, heights in enumerate(surface.heights):
        y = surface.origin[1] + surface.spacing[1] * row
        _write_rows(stream, x_text, f"\t{float(y)!r}", heights)
        stream.write(b"\n")


def header_lines(surface):
    """The ``#`` lines that open rough's TSV output."""
    parts = provenance.parts(surface)
    lines = [
        f"rough {__version__} {surface.kind}: positions and heights in metres",
        "unit: m",
        "spacing: " + " ".join(repr(d) for d in surface.spacing),
        "origin: " + " ".join(repr(o) for o in surface.origin),
        "points: " + " ".join(map(str, surface.points)),
        "units: " + json.dumps(parts["units"]),
        "metadata: " + json.dumps(parts["metadata"]),
        *("history: " + json.dumps(entry) for entry in parts["history"]),
    ]
    return "".join(f"# {line}\n" for line in lines)


def _write_rows(stream, x_text, y_text, heights):
    """Lines of x, y and z: x as printed, y printed once ("" for a profile), z by repr."""
    for start in range(0, len(heights), 65536):
        z = heights[start : start + 65536].tolist()
        lines = "\n".join([f"{x}{y_text}\t{value!r}" for x, value in zip(x_text[start : start + 65536], z)])
        stream.write((lines + "\n").encode("ascii"))


# -- dialects ------------------------------------------------------------------------


def _columns(lines, options):
    """The surface in columns of numbers, checked against the point count of rough's
    own header (``# points: NX NY``) where it has one (a map one point wide reads as
    a profile)."""
    settings, surface = _read_columns(lines, options)
    stated = [count for count in _floats(settings.get("points", "")) if count != 1]
    if "points" in settings and stated != [count for count in surface.points if count != 1]:
        raise FormatError(
            f"the header says {settings['points'].strip()} points, the data hold "
            f"{' '.join(map(str, surface.points))}: the file was cut short or changed"
        )
    return surface


def _read_columns(lines, options):
    comments = [line.lstrip("#%").strip() for line in lines if line.lstrip().startswith(("#", "%"))]
    settings = _comment_settings(comments)
    body = [line for line in lines if not line.lstrip().startswith(("#", "%"))]
    names, units_row, body = _column_names(body)
    if len(body) > 1 and _COUNT.match(body[0]) and len(_split(body[1], _delimiter(body[1]))) > 1:
        body = body[1:]
    if not body:
        raise FormatError("no numeric data found")
    delimiter = _delimiter(body[0])
    table = _numbers(body, delimiter, None)
    first = 1 if table.shape[1] >= 3 and _counts_rows(names, table[:, 0]) else 0
    table, names, units_row = table[:, first:], names[first:], units_row and units_row[first:]
    count = table.shape[1]
    default_unit = settings.get("unit") or options.unit or "m"
    named = [_unit_of(name, None) for name in (units_row or names or [""] * count)]
    named += [None] * (count - len(named))
    units = [unit or default_unit for unit in named]
    stated = [unit is not None or "unit" in settings for unit in named]
    lower = [n.strip().lower() for n in names]
    if count >= 3 and any("valid" in n or "mask" in n for n in lower):
        flag = next(i for i, n in enumerate(lower) if "valid" in n or "mask" in n)
        keep = [i for i in range(count) if i != flag][:2]
        heights = np.where(table[:, flag] != 0, table[:, keep[1]], np.nan)
        x_tokens = _column_tokens(body, delimiter, first + keep[0])
        surface = _profile(table[:, keep[0]], heights, (units[keep[0]], units[keep[1]]), settings, options, x_tokens)
        return settings, _stating(surface, stated[keep[0]], stated[keep[1]])
    if count == 1:
        surface = _from_spacing(table[:, 0] * metres_per(units[0]), options, settings, Units(units[0], units[0]))
        return settings, _stating(surface, stated[0], stated[0])
    if count == 2:
        x_tokens = _column_tokens(body, delimiter, first)
        surface = _profile(table[:, 0], table[:, 1], units[:2], settings, options, x_tokens)
        return settings, _stating(surface, stated[0], stated[1])
    if count == 3:
        return settings, _stating(_grid(table, units, settings), stated[0], stated[2])
    heights = table * metres_per(default_unit)
    surface = _from_spacing(
        heights if len(heights) > 1 else heights[0], options, settings, Units(default_unit, default_unit)
    )
    return settings, _stating(surface, "unit" in settings, "unit" in settings)


def _stating(surface, xy_stated, z_stated):
    """``surface`` with the axes whose unit the file does not state in ``units.assumed``."""
    assumed = tuple(axis for axis, stated in (("xy", xy_stated), ("z", z_stated)) if not stated)
    if assumed:
        surface.units = Units(surface.units.xy, surface.units.z, assumed)
    return surface


def _dektak(lines, options):
    start = next(i for i, line in enumerate(lines) if line.strip() == "Scan Data")
    parameters = {}
    for line in lines[:start]:
        key, comma, value = line.partition(",")
        if comma and value.strip():
            parameters[key.strip()] = value.strip().rstrip(",")
    names = [name.strip() for name in lines[start + 1].split(",")]
    if len(names) < 2:
        raise FormatError("Dektak CSV: no column names after 'Scan Data'")
    body = lines[start + 2 :]
    table = _numbers(body, ",", (0, 1))
    x_unit, z_unit = _unit_of(names[0], "um"), _unit_of(names[1], "um")
    metadata = {"instrument": "Dektak stylus profiler"}
    for key in ("Stylus", "Length", "Resolution", "Force", "Scan Type", "Profile", "Duration"):
        if key in parameters:
            metadata[f"dektak_{key.lower().replace(' ', '_')}"] = parameters[key]
    surface = _profile(table[:, 0], table[:, 1], (x_unit, z_unit), {}, options, _column_tokens(body, ",", 0))
    surface.metadata.update(metadata)
    return surface


def _gwyddion_export(lines):
    header = {}
    for line in lines:
        if line.startswith("#"):
            key, colon, value = line[1:].partition(":")
            if colon:
                key = key.strip().lower()
                header[_GWYDDION_KEYS.get(key, key)] = value.strip()
    body = [line for line in lines if not line.startswith("#")]
    table = _numbers(body, None, None)
    z_unit = header.get("value units", "m")
    try:
        z_factor = metres_per(z_unit)
    except InputError:
        raise FormatError(f"Gwyddion export values are in {z_unit!r}, not a length") from None
    width, xy_unit = _length_with_unit(header.get("width"), "Width")
    height, _ = _length_with_unit(header.get("height"), "Height")
    ny, nx = table.shape
    metadata = {"title": header["channel"]} if header.get("channel") else {}
    units = Units(xy_unit, z_unit)
    if ny == 1:
        return Surface(table[0] * z_factor, (width / nx,), units=units, metadata=metadata)
    return Surface(table * z_factor, (width / nx, height / ny), units=units, metadata=metadata)


def _key_value_matrix(lines, options):
    header, position = {}, 0
    while position < len(lines) and not _NUMERIC.match(lines[position]):
        for key, value in re.findall(r"([^=]+?)\s*=\s*(\S+(?:\s+[A-Za-zµμ]+$)?)(?:\s+|$)", lines[position].strip()):
            header[key.strip().lower()] = value.strip()
        position += 1
    table = _numbers(lines[position:], None, None)
    rows, columns = header.get("h"), header.get("w")
    if rows is not None and columns is not None and (int(rows), int(columns)) != table.shape:
        raise FormatError(
            f"header says {rows} rows × {columns} columns, the data have {table.shape[0]} × {table.shape[1]}"
        )
    if "pixel size" in header:
        pixel, xy_unit = _length_with_unit(header["pixel size"], "pixel size")
        spacing = (pixel, pixel)
    elif options.spacing is not None:
        spacing, xy_unit = options.spacing, "m"
    else:
        raise FormatError("no pixel size in the header; give the spacing with --spacing")
    factor_key = next((k for k in header if k.startswith("height conversion factor")), None)
    if factor_key:
        z_factor, z_unit = float(header[factor_key]), "m"
    else:
        z_unit = options.unit or "m"
        z_factor = metres_per(z_unit)
    assumed = () if factor_key or "data unit" in header else ("z",)
    units = Units(xy_unit, header.get("data unit", z_unit), ("xy", *assumed) if "pixel size" not in header else assumed)
    if table.shape[0] == 1:
        return Surface(table[0] * z_factor, spacing[:1], units=units)
    return Surface(table * z_factor, spacing, units=units)


# -- pieces --------------------------------------------------------------------------


def _decode(data):
    raw = bytes(data)
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        return raw.decode("utf-16")
    raw = raw.removeprefix(b"\xef\xbb\xbf")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        return raw.decode("latin-1")


def _comment_settings(comments):
    """``unit``, ``spacing``, ``origin`` and rough's provenance from ``# key: value``."""
    settings, history = {}, []
    for comment in comments:
        key, colon, value = comment.partition(":")
        key = key.strip().lower()
        if not colon:
            continue
        if key == "history":
            history.append(json.loads(value))
        elif key in ("unit", "spacing", "origin", "units", "metadata", "points"):
            settings[key] = value.strip()
    settings["history"] = history
    return settings


def _column_names(body):
    """Split off a line of column names and a line of units, if the data have them."""
    names, units_row = [], None
    if body and not _NUMERIC.match(body[0]):
        names = _names(body[0])
        body = body[1:]
        if body and not _NUMERIC.match(body[0]):
            units_row = _names(body[0])
            body = body[1:]
    return names, units_row, body


def _names(line):
    """The fields of a line of column names or units. A line in which a field is a
    number, or a number with a letter for a digit (``O.5``, ``1l``), or that holds an
    invisible formatting character, is a data line with a typo, not a header."""
    fields = _split(line, _delimiter(line))
    for field in fields:
        hidden = [c for c in field if unicodedata.category(c) == "Cf"]
        if hidden:
            raise _BadLine(line, f"invisible character U+{ord(hidden[0]):04X} in {line!r}")
        if _NUMBER.match(field) or _MISTYPED_NUMBER.match(field):
            raise _BadLine(line, f"{line.strip()[:60]!r} is neither column names nor numbers (a typo in {field!r}?)")
    return fields


def _delimiter(line):
    for candidate in (";", "\t", ","):
        if candidate in line:
            return candidate
    return None


def _split(line, delimiter):
    return [part.strip() for part in (line.split(delimiter) if delimiter else line.split())]


def _numbers(body, delimiter, columns):
    """The numeric table of the data lines, rows × columns, NaN for ``BAD``/``nan``.
    ``columns`` defaults to as many as the first line has (trailing separators aside)."""
    if not any(line.strip() for line in body):
        raise FormatError("no numeric data found")
    rows, block = body, "\n".join(body)  # loadtxt takes the lines as a list: a StringIO costs 4 bytes a character
    if delimiter in (";", "\t") and any("," in line for line in body[:10]):
        block = block.replace(",", ".")
        rows = None
    if any(marker in block for marker in ("BAD", "bad", "Bad")):
        block = _BAD.sub("nan", block)
        rows = None
    rows = rows or block.split("\n")
    if columns is None:
        columns = range(len(_split(body[0].rstrip(delimiter or None), delimiter)))
    try:
        table = np.loadtxt(rows, delimiter=delimiter, usecols=tuple(columns), ndmin=2, comments=None)
    except ValueError as error:
        short = re.match(r"invalid column index \d+ at row (\d+) with (\d+) columns", str(error))
        if short and int(short.group(1)) <= len(body):  # loadtxt counts these rows from 1
            line, count = body[int(short.group(1)) - 1], int(short.group(2))
            raise _BadLine(
                line, f"{count} value{'s' * (count != 1)} where the first row has {len(columns)} (a row cut short?)"
            ) from None
        row = re.search(r",? at row (\d+)", str(error))
        if row and int(row.group(1)) < len(body):
            line = body[int(row.group(1))]
            problem = str(error)[: row.start()]
            raise _BadLine(line, f"unreadable number in {line.strip()[:60]!r} ({problem})") from None
        raise FormatError(f"unreadable number in the data ({error})") from None
    if table.size == 0:
        raise FormatError("no numeric data found")
    for row, column in np.argwhere(np.isinf(table)):
        fields = _split(body[row], delimiter)
        token = fields[columns[column]] if columns[column] < len(fields) else ""
        if not _INFINITY.match(token):
            raise _BadLine(body[row], f"the number {token[:40]!r} is beyond the float64 range")
    return table


def _unit_of(name, default):
    """The length unit named in a column name such as ``x[um]``, ``z (nm)``, ``Lateral um``
    or ``µm`` alone."""
    match = _UNIT_IN_NAME.search(name or "")
    for candidate in (match and (match.group(1) or match.group(2)), (name or "").strip()):
        try:
            if candidate:
                metres_per(candidate)
                return candidate
        except InputError:
            pass
    return default


def _counts_rows(names, values):
    """Whether the first column is a row index: named like one and counting 0, 1, 2, …
    (or from 1)."""
    named = bool(names) and names[0].strip().lower() in _INDEX_NAMES
    return named and bool(np.all(values == values[0] + np.arange(len(values)))) and values[0] in (0, 1)


def _length_with_unit(text, what):
    match = re.match(r"^\s*([-+0-9.eE]+)\s*(\S*)\s*$", text or "")
    if not match:
        raise FormatError(f"cannot read the {what} {text!r}")
    value, unit = float(match.group(1)), match.group(2) or "m"
    length = value * metres_per(unit)
    if not length > 0:
        raise FormatError(f"the {what} must be a positive length, not {text!r}")
    return length, unit


def _quanta(tokens):
    """How finely each printed number resolves its value: ``'1.25'`` → 0.01,
    ``'3e-05'`` → 1e-05, ``'7'`` → 1. A zero (often printed bare, ``0``, among
    ``1.6655563e-08``) is taken as printed as finely as the median other value."""
    quanta, zero = [], []
    for token in tokens:
        mantissa, _, exponent = token.strip().lower().partition("e")
        quanta.append(10.0 ** (int(exponent or 0) - len(mantissa.partition(".")[2])))
        zero.append(not mantissa.strip("+-0."))
    quanta, zero = np.array(quanta), np.array(zero, bool)
    if zero.any() and not zero.all():
        quanta[zero] = np.median(quanta[~zero])
    return quanta


def _regular(values, tokens, what):
    """``(step, start)`` of evenly spaced values by least squares, or None when they are
    not. Values must lie on the line exactly, or within the rounding of the digits they
    were printed with (``tokens``, a callable giving the printed text of each value, is
    asked only then); values printed coarser than a tenth of a step need ten of them."""
    n = len(values)
    if n < 2:
        raise FormatError(f"a single {what} value gives no spacing")
    index = np.arange(n)
    step, start = np.polyfit(index, values, 1)
    deviation = np.abs(values - (start + step * index))
    if step > 0 and deviation.max() <= 1e-9 * step * n:
        return float(step), float(start)
    if not step > 0:
        return None
    quanta = _quanta(tokens())
    convincing = n >= 10 or quanta.max() <= 0.1 * step  # a few coarsely printed values prove nothing
    if not (convincing and np.all(deviation <= 0.6 * quanta) and 0.6 * quanta.max() < 0.5 * step):
        return None
    return float(step), float(start)


def _level_tokens(levels):
    """The distinct grid coordinates printed back as the shortest text that gives each."""
    return lambda: [repr(float(level)) for level in levels]


def _column_tokens(body, delimiter, column):
    return lambda: [_split(line, delimiter)[column] for line in body]


def _profile(x, z, units, settings, options, x_tokens):
    """A profile from x and z columns (``units`` their units, ``x_tokens`` a callable
    giving x as printed); unevenly spaced x goes to :func:`regrid.profile_from_points`."""
    if len(x) < 2:
        raise FormatError("a profile needs at least two points to have a spacing")
    tokens = x_tokens
    if x[-1] < x[0]:
        x, z, tokens = x[::-1], z[::-1], lambda: x_tokens()[::-1]
    x_factor, z_factor = metres_per(units[0]), metres_per(units[1])
    metadata, surface_units, history = _provenance(settings, Units(*units))
    if "spacing" in settings:
        regular = _floats(settings["spacing"])[0] / x_factor, x[0]
    else:
        regular = _regular(x, tokens, "x") if np.isfinite(x).all() else None
    if regular is None:
        return regrid.profile_from_points(
            x * x_factor, z * z_factor, options, units=surface_units, metadata=metadata, history=history
        )
    step, start = regular
    return Surface(z * z_factor, (step * x_factor,), (start * x_factor,), surface_units, metadata, history)


def _grid(table, units, settings):
    x, y, z = table.T
    factors = [metres_per(u) for u in units[:3]]
    given = _floats(settings["spacing"]) if "spacing" in settings else None
    axes = []
    for column, values in enumerate((x, y)):
        levels = np.unique(values[~np.isnan(values)])
        if given:
            step, start = given[column] / factors[column], levels[0]
        else:
            regular = _regular(levels, _level_tokens(levels), "xy"[column]) if len(levels) > 1 else (1.0, levels[0])
            if regular is None:
                steps = np.diff(levels)
                raise FormatError(
                    f"irregular grid: {'xy'[column]} values are not evenly spaced (steps from {steps.min():.6g} "
                    f"to {steps.max():.6g}); rough needs a regular grid, so resample them first"
                )
            step, start = regular
        index = np.rint((values - start) / step)
        if np.max(np.abs(values - (start + index * step))) > 0.25 * step:
            raise FormatError(f"irregular grid: {'xy'[column]} values do not fall on a regular grid")
        axes.append((index.astype(np.int64), int(index.max()) + 1, step * factors[column], start * factors[column]))
    (ix, nx, dx, x0), (iy, ny, dy, y0) = axes
    if nx * ny > 4 * len(z) + 16:
        raise FormatError(f"x y z points cover only {len(z)} of the {nx}×{ny} grid they span")
    heights = np.full((ny, nx), np.nan)
    flat = iy * nx + ix
    if np.count_nonzero(np.bincount(flat, minlength=nx * ny)) != len(flat):
        raise FormatError("x y z grid has more than one height at the same point")
    heights.ravel()[flat] = z * factors[2]
    metadata, surface_units, history = _provenance(settings, Units(units[0], units[2]))
    if nx * ny == 1:
        raise FormatError("a single x y z point is not a surface")
    if ny == 1:
        return Surface(heights[0], (dx,), (x0,), surface_units, metadata, history)
    if nx == 1:
        return Surface(heights[:, 0], (dy,), (y0,), surface_units, metadata, history)
    return Surface(heights, (dx, dy), (x0, y0), surface_units, metadata, history)


def _from_spacing(heights, options, settings, units):
    if "spacing" in settings:
        spacing = tuple(_floats(settings["spacing"]))
    elif options.spacing is not None:
        spacing = options.spacing
    else:
        raise FormatError("a column of heights without x needs the spacing: give --spacing (e.g. --spacing 1um)")
    metadata, units, history = _provenance(settings, units)
    return Surface(heights, spacing[: np.ndim(heights)], units=units, metadata=metadata, history=history)


def _provenance(settings, units):
    return provenance.restore(
        {"units": settings.get("units"), "metadata": settings.get("metadata"), "history": settings.get("history")},
        units=units,
    )


def _floats(text):
    return [float(value) for value in text.split()]
