"""The device side of a HID PID force-feedback joystick, for tests.

:class:`PidJoystick` decodes every report the host sends with hid-tools (not with
rough's own encoder, so the two check each other), keeps the effects the host creates,
answers the Create New Effect / PID Block Load feature exchange, and makes input
reports for a stick position. It knows nothing of how it is reached: :class:`FakeHandle`
puts it behind the hidapi device interface in-process, and ``vhid_guest.py`` behind a
real kernel uhid device in a QEMU guest.
"""

import time

import hidtools.hid
from pid_descriptor import CONTROLS, EFFECT_TYPES, OPERATIONS, Layout, descriptor

PAGE = 0xF0000


class PidJoystick:
    def __init__(self, layout=None):
        self.layout = layout = layout or Layout()
        self.descriptor = descriptor(layout)
        self.parsed = hidtools.hid.ReportDescriptor.from_bytes(list(self.descriptor))
        self.effects = {}
        self.next_block = 1
        self.pending = None
        self.actuators = False
        self.log = []  # (time, report name, {usage: value})
        self.stick = (0.5, 0.5, 0)

    # -- host to device --------------------------------------------------------------------

    def output(self, data):
        name, values = self._decode(self.parsed.output_reports, data)
        self.log.append((time.monotonic(), name, values))
        block = values.get(PAGE | 0x22)
        if name == "control":
            action = CONTROLS[values[PAGE | 0x96] - 1]
            if action == 0x97:
                self.actuators = True
            elif action == 0x98:
                self.actuators = False
            elif action in (0x99, 0x9A):
                for effect in self.effects.values():
                    effect["playing"] = False
        elif name == "set_effect":
            effect = self.effects[block]
            effect.update(
                type=EFFECT_TYPES[values[PAGE | 0x25] - 1],
                axes=(values[0x10030], values[0x10031]),
                duration=values[PAGE | 0x50],
                gain=values[PAGE | 0x52],
            )
        elif name == "constant":
            self.effects[block]["magnitude"] = values[PAGE | 0x70]
        elif name == "operation":
            self.effects[block]["playing"] = OPERATIONS[values[PAGE | 0x78] - 1] != 0x7B
        elif name == "free":
            del self.effects[block]

    def set_feature(self, data):
        name, values = self._decode(self.parsed.feature_reports, data)
        self.log.append((time.monotonic(), name, values))
        if name != "create" or EFFECT_TYPES[values[PAGE | 0x25] - 1] != 0x26:
            self.pending = ("error", 0)
            return
        block = self.next_block
        self.next_block += 1
        self.effects[block] = {"magnitude": 0, "playing": False, "axes": (0, 0), "type": 0x26}
        self.pending = ("success", block)

    def get_feature(self, report_id):
        report = self.parsed.feature_reports[report_id]
        status, block = self.pending or ("error", 0)
        values = {PAGE | 0x22: block, PAGE | 0x8B: ("success", "full", "error").index(status) + 1, PAGE | 0xAC: 1000}
        return self._encode(report, values)

    # -- device to host --------------------------------------------------------------------

    def input_report(self, x=None, y=None, buttons=None):
        """An input report for the stick at fractions ``x``, ``y`` of its travel."""
        old = self.stick
        self.stick = (old[0] if x is None else x, old[1] if y is None else y, old[2] if buttons is None else buttons)
        report = self.parsed.input_reports[self.layout.ids["input"]]
        low, high = self.layout.axis_range
        values = {
            0x10030: round(low + self.stick[0] * (high - low)),
            0x10031: round(low + self.stick[1] * (high - low)),
        }
        for i in range(self.layout.buttons):
            values[0x90001 + i] = self.stick[2] >> i & 1
        return self._encode(report, values)

    # -- what the host has done --------------------------------------------------------------

    def force(self):
        """The force the motors would make now, per axis, as fractions of the
        magnitude's logical maximum."""
        total = [0.0, 0.0]
        if not self.actuators:
            return tuple(total)
        for effect in self.effects.values():
            if effect["playing"] and effect["type"] == 0x26:
                for axis in (0, 1):
                    total[axis] += effect["axes"][axis] * effect["magnitude"] / self.layout.magnitude_range[1]
        return tuple(total)

    def names(self):
        return [name for _, name, _ in self.log]

    # -- hid-tools does the bit work ---------------------------------------------------------

    def _decode(self, reports, data):
        data = list(data)
        report = reports[data[0]]
        values = {}
        for field in report.fields:
            if not field.is_const:
                values[field.usage] = field.get_values(data)[0]
        return self._kind(report, reports), values

    def _kind(self, report, reports):
        usages = {f.usage for f in report.fields} | {u for f in report.fields if f.usages for u in f.usages}
        if reports is self.parsed.feature_reports:
            return "create" if PAGE | 0x26 in usages else "load"
        for key, test in (
            ("set_effect", PAGE | 0x50),
            ("constant", PAGE | 0x70),
            ("operation", PAGE | 0x79),
            ("control", PAGE | 0x97),
            ("gain", PAGE | 0x7E),
        ):
            if test in usages:
                return key
        return "free"

    @staticmethod
    def _encode(report, values):
        data = [0] * report.size
        data[0] = report.report_ID
        for field in report.fields:
            if field.usage in values and not field.is_const:
                field.fill_values(data, [values[field.usage]])
        return bytes(data)


class FakeHandle:
    """hidapi's device interface in front of a :class:`PidJoystick`, in-process."""

    def __init__(self, device):
        self.device = device
        self.inputs = []
        self.gone = False
        self.closed = False
        self.nonblocking = False
        self.origin = None
        self.scheduled = 0.0  # the delay of the scheduled report read last

    def set_nonblocking(self, value):
        self.nonblocking = bool(value)

    def write(self, data):
        self._check()
        self.device.output(bytes(data))
        return len(data)

    def read(self, size, timeout=0):
        self._check()
        if not self.inputs:
            return []
        delay, report = self.inputs[0]
        if delay is not None:
            now = time.monotonic()
            self.origin = self.origin or now
            if self.origin + delay - self.scheduled > now:
                return []
            # the next report's delay counts from now: a host that reads late still sees
            # every report in a read of its own, as on an idle machine
            self.origin, self.scheduled = now, delay
        self.inputs.pop(0)
        return list(report)

    def send_feature_report(self, data):
        self._check()
        self.device.set_feature(bytes(data))
        return len(data)

    def get_feature_report(self, report_id, size):
        self._check()
        return list(self.device.get_feature(report_id))

    def error(self):
        return "gone" if self.gone else ""

    def close(self):
        self.closed = True

    def move(self, x=None, y=None, buttons=None):
        """Queue an input report for the host's next read."""
        self.inputs.append((None, self.device.input_report(x, y, buttons)))

    def schedule(self, delay, x=None, y=None, buttons=None):
        """Queue an input report that becomes readable ``delay`` seconds after the
        host's first read of a scheduled report, measured as the gap to the previous
        scheduled report from the moment the host read that one."""
        self.inputs.append((delay, self.device.input_report(x, y, buttons)))

    def _check(self):
        if self.gone:
            raise OSError("read error")
