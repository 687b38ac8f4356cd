"""Lengths with units: parsing what people type and what files say, printing with a unit.

Inside rough every length is in metres. On the command line a length takes a unit
(``0.1545mm``, ``30.9um``, ``2e-3m``); a bare number is in millimetres.
"""

import math
import re

from .errors import InputError

METRES_PER_UNIT = {
    "km": 1e3,
    "m": 1.0,
    "cm": 1e-2,
    "mm": 1e-3,
    "um": 1e-6,
    "µm": 1e-6,  # micro sign U+00B5
    "μm": 1e-6,  # Greek mu U+03BC
    "nm": 1e-9,
    "pm": 1e-12,
    "Å": 1e-10,
    "A": 1e-10,
    "in": 0.0254,
}

_WORDS = {
    "metre": "m", "meter": "m", "metres": "m", "meters": "m",
    "millimetre": "mm", "millimeter": "mm", "millimetres": "mm", "millimeters": "mm",
    "micrometre": "um", "micrometer": "um", "micrometres": "um", "micrometers": "um",
    "micron": "um", "microns": "um",
    "nanometre": "nm", "nanometer": "nm", "nanometres": "nm", "nanometers": "nm",
    "angstrom": "A", "angstroms": "A", "ångström": "A",
    "inch": "in", "inches": "in",
}

_NUMBER_AND_UNIT = re.compile(
    r"^\s*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*([^\s\d.+-][^\s]*)?\s*$"
)


def metres_per(unit):
    """Metres in one ``unit``: a symbol (``mm``, ``µm``, ``um``, ``Å``) or a word
    (``Micrometer``, ``microns``). Raises InputError for anything else."""
    name = unit.strip().strip("[]()").strip()
    if name in METRES_PER_UNIT:
        return METRES_PER_UNIT[name]
    word = _WORDS.get(name.lower())
    if word is None:
        raise InputError(f"unknown length unit {unit!r} (use m, mm, um, nm, ...)")
    return METRES_PER_UNIT[word]


def parse_length(text, default_unit="mm"):
    """``'30.9um'`` → 3.09e-05 (metres). A bare number is in ``default_unit``.

    Raises InputError for text that is not a finite number with a length unit.
    """
    match = _NUMBER_AND_UNIT.match(str(text))
    if not match:
        raise InputError(f"{text!r} is not a length (write e.g. 0.1545mm, 30.9um, 2e-3m)")
    value = float(match.group(1)) * metres_per(match.group(2) or default_unit)
    if not math.isfinite(value):
        raise InputError(f"{text!r} is not a finite length")
    return value


_PREFIXES = [(1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n"), (1e-12, "p")]


def format_length(metres, digits=5):
    """A length with an SI-prefixed unit chosen so the number reads naturally:
    ``format_length(7.728e-08)`` → ``'77.28 nm'``. NaN prints as ``'nan m'``."""
    return format_si(metres, "m", digits)


def format_si(value, unit, digits=5):
    """``value`` (in the SI ``unit``) printed with a prefix: ``format_si(2.5e-5, 'm')``
    → ``'25 µm'``. Zero, NaN and infinities print in the plain unit."""
    if value == 0 or not math.isfinite(value):
        return f"{value:.{digits}g} {unit}"
    magnitude = abs(value)
    scale, prefix = next(((s, p) for s, p in _PREFIXES if magnitude >= s * 0.9999995), _PREFIXES[-1])
    return f"{value / scale:.{digits}g} {prefix}{unit}"


def format_quantity(value, unit, digits=5):
    """A number with its unit for people: ``unit`` is ``m`` (SI prefix chosen),
    ``1/m`` (printed per mm), ``1`` (a pure number), ``%`` or ``deg``."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "undefined"
    if unit == "m":
        return format_length(value, digits)
    if unit == "1/m":
        return f"{value * 1e-3:.{digits}g} /mm"
    if unit == "%":
        return f"{value:.{digits}g} %"
    if unit == "deg":
        return f"{value:.{digits}g}°"
    return f"{value:.{digits}g}"


_FREQUENCY = re.compile(r"^\s*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*(?:(?:1?/|per\s*)\s*([^\s\d.+-][^\s]*))?\s*$")


def parse_frequency(text, default_unit="mm"):
    """A spatial frequency in cycles per length: ``'0.2/mm'``, ``'200/m'``, ``'5 per um'``
    → 1/m. A bare number is per ``default_unit``."""
    match = _FREQUENCY.match(str(text))
    if not match:
        raise InputError(f"{text!r} is not a spatial frequency (write e.g. 0.2/mm or 200/m)")
    value = float(match.group(1)) / metres_per(match.group(2) or default_unit)
    if not math.isfinite(value) or value < 0:
        raise InputError(f"{text!r} is not a usable spatial frequency")
    return value
