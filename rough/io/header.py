"""What the headers of instrument files share: ``[section]`` blocks of key-value
lines, numbers checked with one-line errors, length units that may not be lengths, a
file's length checked against what its header describes, the member names of a zip,
the first tags of a TIFF, and a library kept quiet while it parses a damaged file."""

import contextlib
import logging
import struct

import numpy as np

from ..errors import FormatError, InputError
from ..units import metres_per


def ini_sections(text, separator="="):
    """``{section: {key: value}}`` of ``[section]`` lines followed by ``key = value``
    lines (or ``key: value`` with ``separator=":"``); the first value of a key wins and
    lines before the first section are ignored.

    >>> ini_sections("[Scan]\\nPoints = 256\\nUnit = nm\\n")
    {'Scan': {'Points': '256', 'Unit': 'nm'}}
    """
    found, current = {}, None
    for line in text.splitlines():
        line = line.strip()
        if line.startswith("[") and line.endswith("]"):
            current = found.setdefault(line[1:-1], {})
        elif separator in line and current is not None:
            key, _, value = line.partition(separator)
            current.setdefault(key.strip(), value.strip())
    return found


def check_length(data, end, title, contents):
    """Refuse a file that is not the ``end`` bytes its header describes: shorter (the
    data run past the end of the file) or longer (a damaged or misread header).
    ``title`` names the format, ``contents`` what the header describes.

    >>> check_length(bytes(12), 10, "BCR", "header and 2×1 points")
    Traceback (most recent call last):
    ...
    rough.errors.FormatError: BCR file holds 12 bytes, its header describes 10 (header and 2×1 points)
    """
    if end > len(data):
        raise FormatError(
            f"{title} data runs past the end of the file: it holds {len(data):,} bytes, "
            f"its header describes {end:,} ({contents})"
        )
    if end < len(data):
        raise FormatError(f"{title} file holds {len(data):,} bytes, its header describes {end:,} ({contents})")


def header_number(fields, key, what, default=None):
    """The finite number ``fields[key]`` (``default`` when the key is missing and a
    default is given); FormatError naming ``what`` header otherwise."""
    text = fields.get(key)
    if text is None and default is not None:
        return default
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise FormatError(f"{what} header {key} is {text!r}, not a number") from None
    if not np.isfinite(value):
        raise FormatError(f"{what} header {key} is {text!r}, not a finite number")
    return value


def header_count(fields, key, what):
    """The positive whole number ``fields[key]``; FormatError naming ``what`` header otherwise."""
    value = header_number(fields, key, what)
    if value != int(value) or value < 1:
        raise FormatError(f"{what} header {key} is {fields[key]!r}, not a positive count")
    return int(value)


def length_unit(unit, what):
    """Metres per ``unit``; FormatError saying that ``what`` is not a length unit otherwise."""
    metres = metres_or_none(unit)
    if metres is None:
        raise FormatError(f"{what} is {unit!r}, not a length unit")
    return metres


def metres_or_none(unit):
    """Metres per ``unit``, or None when it is not a length unit (V, deg, a.u.)."""
    try:
        return metres_per(unit)
    except InputError:
        return None


@contextlib.contextmanager
def quiet(logger_name):
    """Keep a library's log messages about a damaged file off the terminal: the
    FormatError says it in one line."""
    library = logging.getLogger(logger_name)
    level = library.level
    library.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        library.setLevel(level)


def zip_names(head):
    """The member names of a zip file, from its local headers walked from the start for
    as far as ``head`` (the file's first bytes) reaches; the walk stops at a member
    whose size is left to a data descriptor. Names found by walking, not by searching,
    so that bytes in a member's data never pass for a name.

    >>> import io, zipfile
    >>> buffer = io.BytesIO()
    >>> with zipfile.ZipFile(buffer, "w") as archive:
    ...     archive.writestr("main.xml", "<x/>")
    ...     archive.writestr("bindata/data.bin", b"xl/ PK")
    >>> zip_names(buffer.getvalue())
    ['main.xml', 'bindata/data.bin']
    """
    names, position = [], 0
    while head[position : position + 4] == b"PK\x03\x04" and position + 30 <= len(head):
        flags, _, _, _, _, packed, _, name_length, extra_length = struct.unpack_from("<HHHHIIIHH", head, position + 6)
        names.append(bytes(head[position + 30 : position + 30 + name_length]).decode("latin-1"))
        if flags & 0x8:
            break
        position += 30 + name_length + extra_length + packed
    return names


def first_tiff_tags(head):
    """``(tag, type, count, value)`` of each entry of a classic TIFF's first directory
    that lies within ``head`` (the value as a 32-bit number in the file's byte order);
    none when ``head`` is not a TIFF.

    >>> head = b"II*\\0" + struct.pack("<IH", 8, 1) + struct.pack("<HHII", 256, 4, 1, 64)
    >>> list(first_tiff_tags(head))
    [(256, 4, 1, 64)]
    """
    order = {b"II": "<", b"MM": ">"}.get(bytes(head[:2]))
    if order is None or len(head) < 8:
        return
    (directory,) = struct.unpack_from(order + "I", head, 4)
    if directory + 2 > len(head):
        return
    (count,) = struct.unpack_from(order + "H", head, directory)
    for entry in range(min(count, (len(head) - directory - 2) // 12)):
        yield struct.unpack_from(order + "HHII", head, directory + 2 + 12 * entry)
