"""The HID PID reports of a force-feedback joystick, found in its report descriptor.

A PID device (USB "Physical Interface Device" class, usage page 0x0F) describes in its
report descriptor which reports it takes and where each field sits. The descriptor is
parsed with hid-tools; each report is recognised by the usages it holds (descriptors
nest their collections differently from one model to the next), and every field's bit
offset, size and logical range comes from the descriptor, never from constants for
one model. Reports are packed here, bit by bit, little-endian as HID requires.

Reports used: the joystick's input report (X, Y, buttons); Device Control (enable
actuators, stop all effects, reset), Device Gain, Set Effect, Set Constant Force,
Effect Operation and Block Free (output); Create New Effect and PID Block Load
(feature). rough renders with two constant-force effects, one per axis (Axes Enable
holds only that axis, Direction Enable 0), each with a signed magnitude: positive
pushes the stick toward its axis's logical maximum.
"""

import dataclasses

from .. import extras
from ..errors import RoughError

PAGE = 0xF0000
X, Y = 0x10030, 0x10031
BUTTON_PAGE = 0x90000
EFFECT_BLOCK_INDEX = PAGE | 0x22
CONSTANT_FORCE = PAGE | 0x26
DURATION, SAMPLE_PERIOD, GAIN, TRIGGER_BUTTON = PAGE | 0x50, PAGE | 0x51, PAGE | 0x52, PAGE | 0x53
TRIGGER_REPEAT, START_DELAY = PAGE | 0x54, PAGE | 0xA7
DIRECTION_ENABLE, MAGNITUDE = PAGE | 0x56, PAGE | 0x70
OP_START, OP_STOP, LOOP_COUNT = PAGE | 0x79, PAGE | 0x7B, PAGE | 0x7C
ENABLE_ACTUATORS, DISABLE_ACTUATORS, STOP_ALL, RESET = PAGE | 0x97, PAGE | 0x98, PAGE | 0x99, PAGE | 0x9A
DEVICE_GAIN, BYTE_COUNT = PAGE | 0x7E, PAGE | 0xAC
LOAD_SUCCESS, LOAD_FULL = PAGE | 0x8C, PAGE | 0x8D
SET_EFFECT_REPORT, CONSTANT_FORCE_REPORT, BLOCK_FREE_REPORT = PAGE | 0x21, PAGE | 0x73, PAGE | 0x90
OTHER_EFFECT_PARAMETERS = {PAGE | 0x6F, PAGE | 0x71, PAGE | 0x72, PAGE | 0x75, PAGE | 0x76}


class PidError(RoughError):
    """The device is not a usable force-feedback joystick, or refused a request."""


@dataclasses.dataclass(frozen=True)
class Field:
    """One value in a report: bit offset (counting the report ID byte), size in bits,
    logical range, and for array fields the usages it selects among."""

    start: int
    size: int
    low: int
    high: int
    choices: tuple = ()

    def put(self, report, value):
        value = int(value)
        if not self.low <= value <= self.high and value != self.null:
            raise PidError(f"value {value} outside the field's logical range {self.low}..{self.high}")
        bits = value & ((1 << self.size) - 1)
        for bit in range(self.size):
            if bits >> bit & 1:
                position = self.start + bit
                report[position >> 3] |= 1 << (position & 7)

    def get(self, report):
        bits = 0
        for bit in range(self.size):
            position = self.start + bit
            bits |= (report[position >> 3] >> (position & 7) & 1) << bit
        if self.low < 0 and bits >> (self.size - 1):
            bits -= 1 << self.size
        return bits

    def choose(self, usage):
        """The array value that selects ``usage``."""
        if usage not in self.choices:
            raise PidError(f"the device does not offer usage {usage & 0xFFFF:#04x} here")
        return self.low + self.choices.index(usage)

    @property
    def null(self):
        """A value outside the logical range (HID's Null: "no value"), or the low end
        when the field has no room for one."""
        largest = (1 << (self.size - 1)) - 1 if self.low < 0 else (1 << self.size) - 1
        if self.low > 0:
            return 0
        return largest if self.high < largest else self.low

    def scale(self, fraction):
        """``fraction`` in [-1, 1] of the positive logical maximum, rounded and clamped."""
        return max(self.low, min(self.high, round(fraction * self.high)))


@dataclasses.dataclass
class Report:
    """A report: its ID (0 when the device numbers none), size in bytes, and its
    fields by usage (array fields by the usage of their collection)."""

    id: int
    size: int
    fields: dict

    def encode(self, values):
        """The report's bytes, with ``values`` by usage; fields not given are 0."""
        report = bytearray(self.size)
        if self.id:
            report[0] = self.id
        for usage, value in values.items():
            if usage in self.fields:
                self.fields[usage].put(report, value)
        return bytes(report)

    def wire(self, values):
        """The bytes for hidapi's write: an unnumbered report gets a leading 0."""
        encoded = self.encode(values)
        return encoded if self.id else b"\0" + encoded


class PidDescriptor:
    """The reports a constant-force joystick offers, from its report descriptor bytes."""

    def __init__(self, descriptor):
        descriptors = extras.require("hidtools.hid")

        try:
            parsed = descriptors.ReportDescriptor.from_bytes(list(descriptor))
        except Exception as error:  # noqa: BLE001 -- hid-tools raises assorted errors on bad descriptors
            raise PidError(f"unreadable HID report descriptor ({type(error).__name__}: {error})") from None
        self.joystick = _find(parsed.input_reports, lambda u, a: X in u and Y in u, "an input report with X and Y axes")
        fields = self.joystick.fields
        self.buttons = [fields[usage] for usage in sorted(u for u in fields if u & 0xFFFF0000 == BUTTON_PAGE)]
        self.set_effect = _find(
            parsed.output_reports, lambda u, a: CONSTANT_FORCE in a and DURATION in u, "a Set Effect report"
        )
        self.constant = _find(
            parsed.output_reports,
            lambda u, a: MAGNITUDE in u and not (u & OTHER_EFFECT_PARAMETERS),
            "a Set Constant Force report",
        )
        self.operation = _find(parsed.output_reports, lambda u, a: OP_START in a, "an Effect Operation report")
        self.control = _find(parsed.output_reports, lambda u, a: ENABLE_ACTUATORS in a, "a Device Control report")
        self.create = _find(
            parsed.feature_reports,
            lambda u, a: CONSTANT_FORCE in a and EFFECT_BLOCK_INDEX not in u,
            "a Create New Effect feature report",
        )
        self.load = _find(parsed.feature_reports, lambda u, a: LOAD_SUCCESS in a, "a PID Block Load feature report")
        self.gain = _find(parsed.output_reports, lambda u, a: DEVICE_GAIN in u, None)
        self.free = _find(
            parsed.output_reports, lambda u, a: BLOCK_FREE_REPORT in a or set(u) == {EFFECT_BLOCK_INDEX}, None
        )
        for name in ("x", "y"):
            if (X if name == "x" else Y) not in self.joystick.fields:
                raise PidError(f"the joystick reports no {name} axis")

    def position(self, report):
        """``(x, y, buttons)`` from an input report: x and y as fractions of their
        logical range (0 at the minimum, 1 at the maximum), buttons as a bit mask
        (button 1 the lowest bit). None for another report."""
        if not report or (self.joystick.id and report[0] != self.joystick.id) or len(report) < self.joystick.size:
            return None
        x, y = self.joystick.fields[X], self.joystick.fields[Y]
        buttons = sum(field.get(report) << i for i, field in enumerate(self.buttons))
        return (x.get(report) - x.low) / (x.high - x.low), (y.get(report) - y.low) / (y.high - y.low), buttons


def _find(reports, test, wanted):
    for number, report in sorted(reports.items()):
        fields, arrays = {}, set()
        for field in report.fields:
            if field.is_const:
                continue
            if field.is_array:
                choices = tuple(field.usages)
                arrays.update(choices)
                arrays.add(field.logical)
                fields[field.usage] = Field(field.start, field.size, field.logical_min, field.logical_max, choices)
            else:
                fields.setdefault(field.usage, Field(field.start, field.size, field.logical_min, field.logical_max))
        if test(set(fields), arrays | {report.fields[0].logical} if report.fields else arrays):
            return Report(number if report.numbered else 0, report.size, fields)
    if wanted is None:
        return None
    raise PidError(f"not a force-feedback joystick: its HID descriptor has no {wanted}")
