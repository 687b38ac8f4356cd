"""HID report descriptors of force-feedback joysticks, written item by item after the
USB "Device Class Definition for Physical Interface Devices" 1.0 (the PID page 0x0F):
a joystick input report (X, Y, buttons), the PID state, and the output and feature
reports a host needs to create, play and stream a constant-force effect. ``layout``
changes report IDs, field sizes and logical ranges, so tests can show that the
driver reads them from the descriptor instead of assuming one model's constants."""

import dataclasses

GENERIC_DESKTOP, BUTTON, PID, ORDINALS = 0x01, 0x09, 0x0F, 0x0A
EFFECT_TYPES = (
    0x26,
    0x27,
    0x30,
    0x31,
    0x32,
    0x40,
    0x41,
    0x42,
    0x43,
)  # constant, ramp, square, sine, triangle, spring, damper, inertia, friction
OPERATIONS = (0x79, 0x7A, 0x7B)  # start, start solo, stop
CONTROLS = (0x97, 0x98, 0x99, 0x9A, 0x9B, 0x9C)  # enable/disable actuators, stop all, reset, pause, continue
LOAD_STATUS = (0x8C, 0x8D, 0x8E)  # success, full, error


@dataclasses.dataclass(frozen=True)
class Layout:
    """What differs between joysticks."""

    axis_bits: int = 16
    axis_range: tuple = (-32767, 32767)
    buttons: int = 8
    magnitude_bits: int = 16
    magnitude_range: tuple = (-10000, 10000)
    block_bits: int = 8
    max_effects: int = 40
    ids: dict = dataclasses.field(
        default_factory=lambda: {
            "input": 1,
            "state": 2,
            "set_effect": 1,
            "constant": 5,
            "operation": 10,
            "free": 11,
            "control": 12,
            "gain": 13,
            "create": 1,
            "load": 2,
            "pool": 3,
        }
    )


def _item(prefix, value=None, size=None):
    if value is None:
        return bytes([prefix])
    if size is None:
        size = 1 if -128 <= value <= 255 else 2 if -32768 <= value <= 65535 else 4
    code = {1: 1, 2: 2, 4: 3}[size]
    return bytes([prefix | code]) + (value & ((1 << (8 * size)) - 1)).to_bytes(size, "little")


def _signed(prefix, value):
    size = 1 if -128 <= value <= 127 else 2 if -32768 <= value <= 32767 else 4
    return _item(prefix, value, size)


def usage_page(page):
    return _item(0x04, page)


def usage(value, page=None):
    if page is not None:
        return _item(0x08, (page << 16) | value, 4)
    return _item(0x08, value)


def logical(low, high):
    return _signed(0x14, low) + _signed(0x24, high)


def size_count(size, count):
    return _item(0x74, size) + _item(0x94, count)


def report_id(number):
    return _item(0x84, number)


def collection(kind, *content):
    return _item(0xA0, kind) + b"".join(content) + _item(0xC0)


def field(main, size, count, low, high, *usages, flags=0x02):
    return b"".join(usages) + logical(low, high) + size_count(size, count) + _item(main, flags)


INPUT, OUTPUT, FEATURE = 0x80, 0x90, 0xB0
APPLICATION, LOGICAL, PHYSICAL = 0x01, 0x02, 0x00


def _array(main, collection_usage, usages, bits=8):
    """A logical collection holding an array of ``usages`` (1-based selectors)."""
    return usage(collection_usage) + collection(
        LOGICAL, field(main, bits, 1, 1, len(usages), *(usage(u) for u in usages), flags=0x00)
    )


def descriptor(layout=None):
    layout = layout or Layout()
    ids = layout.ids

    def block(main):
        return field(main, layout.block_bits, 1, 1, layout.max_effects, usage(0x22))

    low, high = layout.axis_range
    joystick = usage(0x01) + collection(
        PHYSICAL,
        report_id(ids["input"]),
        field(INPUT, layout.axis_bits, 2, low, high, usage(0x30), usage(0x31)),
        usage_page(BUTTON),
        _item(0x18, 1),
        _item(0x28, layout.buttons),
        logical(0, 1),
        size_count(1, layout.buttons),
        _item(INPUT, 0x02),
        usage_page(GENERIC_DESKTOP),
    )
    magnitude_low, magnitude_high = layout.magnitude_range
    pid = usage_page(PID) + b"".join(
        [
            usage(0x92)
            + collection(
                LOGICAL,
                report_id(ids["state"]),
                field(INPUT, 1, 5, 0, 1, usage(0x9F), usage(0xA0), usage(0xA4), usage(0xA5), usage(0xA6)),
                size_count(3, 1),
                _item(INPUT, 0x03),
                field(INPUT, 8, 1, 1, layout.max_effects, usage(0x22)),
            ),
            usage(0x21)
            + collection(
                LOGICAL,
                report_id(ids["set_effect"]),
                block(OUTPUT),
                _array(OUTPUT, 0x25, EFFECT_TYPES),
                field(OUTPUT, 16, 4, 0, 32767, usage(0x50), usage(0x54), usage(0x51), usage(0xA7)),
                field(OUTPUT, 8, 1, 0, 255, usage(0x52)),
                field(OUTPUT, 8, 1, 1, 8, usage(0x53)),
                usage(0x55)
                + collection(LOGICAL, usage_page(GENERIC_DESKTOP), field(OUTPUT, 1, 2, 0, 1, usage(0x30), usage(0x31))),
                usage_page(PID),
                field(OUTPUT, 1, 1, 0, 1, usage(0x56)),
                size_count(5, 1),
                _item(OUTPUT, 0x03),
                usage(0x57)
                + collection(LOGICAL, field(OUTPUT, 16, 2, 0, 35999, usage(1, ORDINALS), usage(2, ORDINALS))),
            ),
            usage(0x73)
            + collection(
                LOGICAL,
                report_id(ids["constant"]),
                block(OUTPUT),
                field(OUTPUT, layout.magnitude_bits, 1, magnitude_low, magnitude_high, usage(0x70)),
            ),
            usage(0x77)
            + collection(
                LOGICAL,
                report_id(ids["operation"]),
                block(OUTPUT),
                _array(OUTPUT, 0x78, OPERATIONS),
                field(OUTPUT, 8, 1, 0, 255, usage(0x7C)),
            ),
            usage(0x90) + collection(LOGICAL, report_id(ids["free"]), block(OUTPUT)),
            usage(0x95) + collection(LOGICAL, report_id(ids["control"]), _array(OUTPUT, 0x96, CONTROLS)),
            usage(0x7D) + collection(LOGICAL, report_id(ids["gain"]), field(OUTPUT, 8, 1, 0, 255, usage(0x7E))),
            usage(0xAB)
            + collection(
                LOGICAL,
                report_id(ids["create"]),
                _array(FEATURE, 0x25, EFFECT_TYPES),
                field(FEATURE, 16, 1, 0, 65535, usage(0xAC)),
            ),
            usage(0x89)
            + collection(
                LOGICAL,
                report_id(ids["load"]),
                block(FEATURE),
                _array(FEATURE, 0x8B, LOAD_STATUS),
                field(FEATURE, 16, 1, 0, 65535, usage(0xAC)),
            ),
            usage(0x7F)
            + collection(
                LOGICAL,
                report_id(ids["pool"]),
                field(FEATURE, 16, 1, 0, 65535, usage(0x80)),
                field(FEATURE, 8, 1, 0, 255, usage(0x83)),
                field(FEATURE, 1, 2, 0, 1, usage(0xA9), usage(0xAA)),
                size_count(6, 1),
                _item(FEATURE, 0x03),
            ),
        ]
    )
    return usage_page(GENERIC_DESKTOP) + usage(0x04) + collection(APPLICATION, joystick, pid)
