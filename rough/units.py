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
    "fm": 1e-15,
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


#: SI prefixes rough prints, as powers of a thousand: k (10³) down to f (10⁻¹⁵), for
#: the amplitude coefficient C of a nanometre scan.
_PREFIXES = {1: "k", 0: "", -1: "m", -2: "µ", -3: "n", -4: "p", -5: "f"}

#: A number smaller than this fraction of the scale of its quantity is rounding
#: noise (an origin of 6.4e-17 m on a 1 µm grid): it prints as 0.
NOISE = 1e-9

#: Each SI unit of a report row (docs/output.rst) → (power of the metre it scales
#: with, how its label is written from a length symbol). A length power of 2 or 3 is
#: written as a product of lengths, ``m3/m2`` (a volume per area) as ``µm³/µm²``.
LENGTH_POWERS = {"m": 1, "m2": 2, "m3": 3, "m4": 4, "1/m": -1, "1/m2": -2, "m3/m2": 1, "m·%": 1}

_SUPERSCRIPTS = {1: "", 2: "²", 3: "³", 4: "⁴"}


def scale_for(magnitude, unit):
    """``(factor, label)``: multiply a value of about ``magnitude`` (in the SI ``unit``)
    by ``factor`` to print it in ``label``, the prefixed unit in which the number
    lies in [1, 1000) — one place for the text table, a column that shares one prefix
    and a plot's axis.

    ``unit`` is a report unit (``m``, ``m2``, ``m3``, ``1/m``, ``1/m2``, ``m3/m2``,
    ``m·%``; see :data:`LENGTH_POWERS`) or any other SI symbol (``N``, ``Hz``), which
    takes a plain prefix. A length is prefixed fm to km; an area or volume no single
    prefix fits in [0.1, 1000) is a product of neighbouring ones (1e-9 m² is 1 mm·µm,
    1000 µm², 0.001 mm²); a
    frequency is per length (``/mm``), a density per area (``/mm²``). Zero, NaN and
    infinities give the plain unit.

    Examples
    --------
    >>> scale_for(2.5e-5, "m"), scale_for(4.3e-3, "1/m"), scale_for(1.48e-8, "m3/m2")
    ((1000000.0, 'µm'), (1000.0, '/km'), (1000000000.0, 'nm³/nm²'))
    >>> scale_for(2.5e-9, "m2"), scale_for(3.6e6, "1/m2"), scale_for(float("nan"), "m")
    ((1000000000.0, 'mm·µm'), (1e-06, '/mm²'), (1.0, 'm'))
    """
    power = LENGTH_POWERS.get(unit, 1)
    if not (magnitude and math.isfinite(magnitude)):
        return 1.0, _label(unit, 0, power)
    low, high = (-5 * power, power) if power > 0 else (power, -5 * power)
    thousands = min(max(math.floor(math.log10(abs(magnitude)) / 3 + 1e-9), low), high)
    thousands = _whole_power(thousands, magnitude, power, low, high)
    return 10.0 ** (-3 * thousands), _label(unit, thousands, power)


def _whole_power(thousands, magnitude, power, low, high):
    """``thousands``, or a neighbour within ``low``…``high`` that is a whole number of
    prefixes per length when the number stays in [0.1, 1000) with it: 0.42 /mm², not
    420 /(m·mm)."""
    for whole in (thousands, thousands + 1, thousands - 1):
        if low <= whole <= high and whole % power == 0 and 0.1 <= abs(magnitude) / 10.0 ** (3 * whole) < 1000:
            return whole
    return thousands


def _label(unit, thousands, power):
    """The unit ``unit`` scaled by 1000**``thousands``, written with prefixes."""
    if unit == "m3/m2":
        symbol = _PREFIXES[thousands] + "m"
        return f"{symbol}³/{symbol}²"
    if unit == "m·%":
        return _PREFIXES[thousands] + "m·%"
    if unit not in LENGTH_POWERS:
        return _PREFIXES.get(thousands, "") + unit
    if power < 0:
        denominator = _length_product(-thousands, -power)
        return f"/({denominator})" if "·" in denominator else f"/{denominator}"
    return _length_product(thousands, power)


def _length_product(thousands, power):
    """``power`` lengths whose prefixes add up to ``thousands``, as evenly as can be:
    (-3, 2) → ``mm·µm``, (-4, 2) → ``µm²``, (-5, 3) → ``mm·µm²``."""
    smaller, larger = divmod(thousands, power)
    factors = [(smaller + 1, larger), (smaller, power - larger)]
    return "·".join(f"{_PREFIXES[p]}m{_SUPERSCRIPTS[n]}" for p, n in factors if n)


def format_length(metres, digits=5, scale=None):
    """A length with an SI-prefixed unit chosen so the number reads naturally:
    ``format_length(7.728e-08)`` → ``'77.28 nm'``. NaN prints as ``'nan m'``; see
    :func:`format_quantity` for ``scale``.

    >>> format_length(7.728e-08), format_length(1e6), format_length(6.4e-17, scale=1e-6)
    ('77.28 nm', '1000 km', '0 µm')
    """
    return _format(metres, "m", digits, scale)


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
    → ``'25 µm'``. Zero, NaN and infinities print in the plain unit.

    >>> format_si(2.5e-5, "m"), format_si(1234.5, "N"), format_si(0, "Hz")
    ('25 µm', '1.2345 kN', '0 Hz')
    """
    return _format(value, unit, digits)


def format_quantity(value, unit, digits=5, scale=None):
    """A number with its unit for people, the number in [1, 1000) where a prefix can
    make it so: ``unit`` is ``m``, ``m2``, ``m3``, ``1/m`` (printed per length,
    ``/mm``), ``1/m2`` (per area), ``m3/m2`` (a volume per area: ``µm³/µm²``, the
    prefix that fits), ``m·%`` (a height times a material ratio), ``1`` (a pure
    number), ``%`` or ``deg``; :func:`scale_for` chooses the prefix. NaN and None
    print as ``undefined``.

    ``scale`` is the size of the quantity in its context (a grid's spacing for an
    origin): a value below :data:`NOISE` times it is rounding noise, printed as 0 in
    the prefix of ``scale``.

    >>> format_quantity(2.5e-9, "m2"), format_quantity(3.6e6, "1/m2"), format_quantity(1.48e-7, "m3/m2")
    ('2.5 mm·µm', '3.6 /mm²', '148 nm³/nm²')
    >>> format_quantity(4.3e-3, "1/m"), format_quantity(0.37, "1"), format_quantity(6.4e-17, "m", scale=1e-3)
    ('4.3 /km', '0.37', '0 mm')
    """
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "undefined"
    if unit == "%":
        return f"{value:.{digits}g} %"
    if unit == "deg":
        return f"{value:.{digits}g}°"
    if unit not in LENGTH_POWERS:
        return f"{value:.{digits}g}"
    return _format(value, unit, digits, scale)


def format_range(low, high, unit, digits=4):
    """``low to high`` in ``unit`` (as :func:`format_quantity`), in one prefix when it
    fits both (the smaller at least 0.1), else each in its own.

    >>> format_range(100.0, 2e4, "1/m"), format_range(4.3e-3, 2e4, "1/m")
    ('0.1 to 20 /mm', '4.3 /km to 20 /mm')
    """
    largest = max(abs(low), abs(high))
    factor, label = scale_for(largest, unit)
    if abs(float(f"{largest * factor:.{digits}g}")) >= 1000:  # rounds up to the next prefix
        factor, label = scale_for(largest * 1.001, unit)
    if unit in LENGTH_POWERS and all(math.isfinite(v) and (v == 0 or abs(v * factor) >= 0.1) for v in (low, high)):
        return f"{low * factor:.{digits}g} to {high * factor:.{digits}g} {label}"
    return f"{format_quantity(low, unit, digits)} to {format_quantity(high, unit, digits)}"


def _format(value, unit, digits, scale=None):
    """``value`` in ``unit`` with the prefix :func:`scale_for` gives for it (for
    ``scale`` when it is noise, or zero): one prefix up when rounding makes it 1000."""
    if scale is not None and abs(value) < NOISE * abs(scale):
        value = 0.0
    magnitude = abs(value) if value or scale is None else abs(scale)
    factor, label = scale_for(magnitude, unit)
    if abs(float(f"{value * factor:.{digits}g}")) >= 1000:
        factor, label = scale_for(magnitude * 1.001, unit)
    return f"{value * factor:.{digits}g} {label}"


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
