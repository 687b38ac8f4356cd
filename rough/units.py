"""Lengths with units: parsing what people type and what files say, printing with a unit.

Inside rough every length is in metres. rough never guesses a unit: a number in a file
that names none is in metres (SI) unless the reader is told otherwise, and a length,
frequency or physical quantity typed on the command line names its unit (``0.1545mm``,
``30.9um``, ``0.2/mm``, ``1.28N/mm``); zero needs none. (The command line refuses a
bare number, :func:`is_bare`, in one line since rough 0.14; 0.12 and 0.13 read it in
the option's old default unit, with a warning.)
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
    "metre": "m",
    "meter": "m",
    "metres": "m",
    "meters": "m",
    "millimetre": "mm",
    "millimeter": "mm",
    "millimetres": "mm",
    "millimeters": "mm",
    "micrometre": "um",
    "micrometer": "um",
    "micrometres": "um",
    "micrometers": "um",
    "micron": "um",
    "microns": "um",
    "nanometre": "nm",
    "nanometer": "nm",
    "nanometres": "nm",
    "nanometers": "nm",
    "angstrom": "A",
    "angstroms": "A",
    "ångström": "A",
    "inch": "in",
    "inches": "in",
}

_NUMBER_AND_UNIT = re.compile(r"^\s*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*([^\s\d.+-][^\s]*)?\s*$")


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


def is_bare(text):
    """Whether ``text`` is a number that names no unit (zero included).

    >>> is_bare("0.8"), is_bare(" -2e-3 "), is_bare("0.8mm"), is_bare("0.2/mm"), is_bare("x")
    (True, True, False, False, False)
    """
    match = _NUMBER_AND_UNIT.match(str(text))
    return bool(match) and match.group(2) is None


def _unit_named(match, text, default_unit, example):
    """The unit ``match`` names, else ``default_unit``; a bare zero needs none (``'m'``)."""
    unit = match.group(2) or default_unit
    if unit is None:
        if float(match.group(1)) != 0:
            raise InputError(f"{text!r} names no unit (write e.g. {example})")
        return "m"
    return unit


def parse_length(text, default_unit=None):
    """``'30.9um'`` → 3.09e-05 (metres). A bare number is in ``default_unit``; with
    none, only zero may be bare.

    Raises InputError for text that is not a finite number with a length unit.

    >>> parse_length("30.9um"), parse_length("0"), parse_length("2", "mm")
    (3.09e-05, 0.0, 0.002)
    """
    match = _NUMBER_AND_UNIT.match(str(text))
    if not match:
        raise InputError(f"{text!r} is not a length (write e.g. 0.1545mm, 30.9um, 2e-3m)")
    value = float(match.group(1)) * metres_per(_unit_named(match, text, default_unit, "0.1545mm or 30.9um"))
    if not math.isfinite(value):
        raise InputError(f"{text!r} is not a finite length")
    return value


_PREFIXES = [(1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n"), (1e-12, "p")]


def format_length(metres, digits=5):
    """A length with an SI-prefixed unit chosen so the number reads naturally:
    ``format_length(7.728e-08)`` → ``'77.28 nm'``. NaN prints as ``'nan m'``."""
    return format_si(metres, "m", digits)


def digits_for(magnitude, resolution):
    """Significant digits that show ``resolution`` in a number of size ``magnitude``
    (at least five, at most fifteen): a 1 m step at 564 km needs seven.

    >>> digits_for(564999.0, 1.0), digits_for(0.1, 0.1)
    (7, 5)
    """
    if not (resolution > 0 and math.isfinite(magnitude) and math.isfinite(resolution)) or magnitude == 0:
        return 5
    return max(5, min(15, 1 + math.ceil(math.log10(abs(magnitude) / resolution))))


def format_si(value, unit, digits=5):
    """``value`` (in the SI ``unit``) printed with a prefix: ``format_si(2.5e-5, 'm')``
    → ``'25 µm'``. Zero, NaN and infinities print in the plain unit."""
    if value == 0 or not math.isfinite(value):
        return f"{value:.{digits}g} {unit}"
    magnitude = abs(value)
    scale, prefix = next(((s, p) for s, p in _PREFIXES if magnitude >= s * 0.9999995), _PREFIXES[-1])
    return f"{value / scale:.{digits}g} {prefix}{unit}"


def format_quantity(value, unit, digits=5):
    """A number with its unit for people: ``unit`` is ``m``, ``m2``, ``m3`` (SI prefix
    chosen), ``1/m`` (printed per mm), ``1/m2`` (per mm²), ``m3/m2`` (a volume per
    area, µm³/µm²), ``m·%`` (a height times a material ratio), ``1`` (a pure number),
    ``%`` or ``deg``.

    >>> format_quantity(2.5e-9, "m2"), format_quantity(3.6e6, "1/m2"), format_quantity(1.48e-8, "m3/m2")
    ('0.0025 mm²', '3.6 /mm²', '0.0148 µm³/µm²')
    """
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "undefined"
    if unit == "m":
        return format_length(value, digits)
    if unit in _POWERS:
        return _format_power(value, _POWERS[unit], digits)
    if unit == "m3/m2":
        return f"{value * 1e6:.{digits}g} µm³/µm²"  # = ml/m², the unit tribologists quote
    if unit == "m·%":
        return f"{format_length(value, digits)}·%"
    if unit == "1/m":
        return f"{value * 1e-3:.{digits}g} /mm"
    if unit == "1/m2":
        return f"{value * 1e-6:.{digits}g} /mm²"
    if unit == "%":
        return f"{value:.{digits}g} %"
    if unit == "deg":
        return f"{value:.{digits}g}°"
    return f"{value:.{digits}g}"


_POWERS = {"m2": 2, "m3": 3}


def _format_power(value, power, digits):
    """An area or volume in the largest prefix that leaves at least a thousandth:
    2.5e-9 m² → 0.0025 mm², 7.8e-7 m² → 0.78 mm², 2.5e-13 m² → 0.25 µm²."""
    if value == 0 or not math.isfinite(value):
        return f"{value:.{digits}g} m{'²³'[power - 2]}"
    scale, prefix = next(((s, p) for s, p in _PREFIXES if abs(value) >= 1e-3 * s**power), _PREFIXES[-1])
    return f"{value / scale**power:.{digits}g} {prefix}m{'²³'[power - 2]}"


_FREQUENCY = re.compile(
    r"^\s*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*(?:(?:1?/|per\s*)\s*([^\s\d.+-][^\s]*))?\s*$"
)


def parse_frequency(text, default_unit=None):
    """A spatial frequency in cycles per length: ``'0.2/mm'``, ``'200/m'``, ``'5 per um'``
    → 1/m. A bare number is per ``default_unit``; with none, only zero may be bare."""
    match = _FREQUENCY.match(str(text))
    if not match:
        raise InputError(f"{text!r} is not a spatial frequency (write e.g. 0.2/mm or 200/m)")
    value = float(match.group(1)) / metres_per(_unit_named(match, text, default_unit, "0.2/mm or 200/m"))
    if not math.isfinite(value) or value < 0:
        raise InputError(f"{text!r} is not a usable spatial frequency")
    return value


# Physical quantities for the haptic renderer: SI factor of each unit a person may type.
# The sources write stiffness in N/mm, damping in N·s/mm and speeds in mm/s.
QUANTITIES = {
    "force": ("N", {"N": 1.0, "mN": 1e-3, "kN": 1e3}),
    "stiffness": ("N/m", {"N/m": 1.0, "N/mm": 1e3, "N/um": 1e6, "kN/m": 1e3}),
    "damping": ("N*s/m", {"N*s/m": 1.0, "N*s/mm": 1e3, "kg/s": 1.0}),
    "mass": ("kg", {"kg": 1.0, "g": 1e-3, "mg": 1e-6, "N*s^2/m": 1.0, "N*s^2/mm": 1e3}),
    "speed": ("m/s", {"m/s": 1.0, "mm/s": 1e-3, "um/s": 1e-6, "cm/s": 1e-2}),
    "time": ("s", {"s": 1.0, "ms": 1e-3, "us": 1e-6, "min": 60.0}),
    "rate": ("Hz", {"Hz": 1.0, "kHz": 1e3}),
}


def parse_quantity(text, kind, default_unit=None):
    """``parse_quantity('1.28N/mm', 'stiffness')`` → 1280.0 (SI). Units may be written
    with ``*``, ``·`` or a space for products (``N*s/m``, ``N·s/mm``) and ``µ``/``u``
    for micro; a bare number is in ``default_unit`` (with none, only zero may be bare)."""
    si_unit, units = QUANTITIES[kind]
    match = _NUMBER_AND_UNIT.match(str(text).replace(" ", "").replace("·", "*"))
    unit = None if not match else (match.group(2) or default_unit)
    if match and unit is None and float(match.group(1)) == 0:
        unit = si_unit
    if unit is not None:
        unit = unit.replace("µ", "u").replace("μ", "u").replace("Ns", "N*s").replace("**", "^").replace("²", "^2")
    if unit not in units:
        accepted = ", ".join(units)
        raise InputError(f"{text!r} is not a {kind} (write a number with one of the units {accepted})")
    value = float(match.group(1)) * units[unit]
    if not math.isfinite(value):
        raise InputError(f"{text!r} is not a finite {kind}")
    return value


def format_unit(value, kind, digits=4):
    """``value`` (SI) printed in the unit the sources use for ``kind``:
    N, N/mm, N·s/m, g, mm/s, s, Hz."""
    shown = {"stiffness": (1e-3, "N/mm"), "mass": (1e3, "g"), "speed": (1e3, "mm/s"), "damping": (1.0, "N·s/m")}.get(
        kind, (1.0, QUANTITIES[kind][0])
    )
    return f"{value * shown[0]:.{digits}g} {shown[1]}"
