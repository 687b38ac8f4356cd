"""How much input rough reads, for every container and codec alike.

The caps are module constants; an environment variable of the same name raises
(or lowers) each one, e.g. ``ROUGH_MAX_INPUT_BYTES=12G``. Compressed data are
counted while they are unpacked, never unpacked first and checked after.

MAX_INPUT_BYTES   bytes a file, standard input, or any unpacked stream may reach. A
                  16384² float64 map (rough's largest surface) is 2 GiB; 3 GiB
                  leaves room for its mask and header. Analysing such a map takes
                  about ten times its heights: ``rough features`` peaked at 269 MB,
                  519 MB and 1.46 GB on 1024², 2048² and 4096² maps (0.2 GB plus
                  9.3 bytes per height byte), so ~19 GiB at 16384², which a 24 GiB
                  machine just holds; ``rough info`` takes about three times.
MAX_RATIO         unpacked bytes per packed byte. Measured heights compress 2–10:1;
                  deflate's ceiling is ~1030:1, reached only by constant data, which
                  is what a bomb holds. Checked once past RATIO_FLOOR unpacked.
MAX_TEXT_BYTES    bytes of text parsed: text takes ~6 bytes of memory per byte to
                  parse (a 23.6 MB x y z map: 187 MB at its peak), so 256 MiB (a
                  2000² x y z map) needs ~1.6 GiB; larger surfaces belong in X3P or
                  NPY. Applied while text arrives, once its first 64 KiB show it is
                  text: a stream is never read past the cap.
MAX_GZIP_LAYERS   gzip inside gzip, at most this deep.
"""

import io
import os
import re
import stat

import numpy as np

from ..errors import FormatError, InputError

MAX_INPUT_BYTES = 3 << 30
MAX_RATIO = 100
MAX_TEXT_BYTES = 256 << 20
RATIO_FLOOR = 1 << 20
MAX_GZIP_LAYERS = 4
CHUNK = 1 << 20

_SIZE = re.compile(r"^\s*(\d+(?:\.\d+)?)\s*([KMGT]?)(?:i?B)?\s*$", re.IGNORECASE)


def cap(name):
    """The cap ``name`` (e.g. ``"MAX_INPUT_BYTES"``): ``ROUGH_<name>`` from the
    environment if set (``4G``, ``512M``, ``1000``), else the module constant."""
    text = os.environ.get(f"ROUGH_{name}")
    if not text:
        return globals()[name]
    match = _SIZE.match(text)
    if not match:
        raise InputError(f"ROUGH_{name}={text!r} is not a number (write e.g. 4G, 512M or 1000)")
    return int(float(match.group(1)) * 1024 ** "_KMGT".index(match.group(2).upper() or "_"))


def human(size):
    for shift, unit in ((30, "GiB"), (20, "MiB"), (10, "KiB")):
        if size >= 1 << shift:
            return f"{size / (1 << shift):.3g} {unit}"
    return f"{size} bytes"


class Budget:
    """Counts unpacked bytes against MAX_INPUT_BYTES and MAX_RATIO × ``packed``."""

    def __init__(self, packed, what):
        self.packed, self.what, self.total = max(packed, 1), what, 0
        self.limit = cap("MAX_INPUT_BYTES")
        self.ratio = cap("MAX_RATIO")
        self.text = False

    def holds_text(self):
        """From now on the bytes are text: refused past MAX_TEXT_BYTES as they unpack."""
        self.text = True
        self.limit = min(self.limit, cap("MAX_TEXT_BYTES"))

    def room(self):
        """Bytes that may still be unpacked, plus one to notice going over."""
        return int(min(self.limit, max(RATIO_FLOOR, self.ratio * self.packed)) - self.total + 1)

    def add(self, count):
        self.total += count
        if self.text and self.total > self.limit:
            raise too_much_text(None)
        if self.total > self.limit:
            raise FormatError(
                f"{self.what} unpacks to more than {human(self.limit)}; refusing "
                "(set ROUGH_MAX_INPUT_BYTES to raise the cap)"
            )
        if self.total > RATIO_FLOOR and self.total > self.ratio * self.packed:
            raise FormatError(
                f"{self.what} unpacks to more than {self.ratio}× its {human(self.packed)} (a compression bomb?); "
                "refusing (set ROUGH_MAX_RATIO to raise the cap)"
            )


def too_much_text(size):
    """The refusal of text past MAX_TEXT_BYTES (``size`` bytes, None for a stream
    refused as it arrived)."""
    text_cap = human(cap("MAX_TEXT_BYTES"))
    amount = (
        f"{human(size)} of text is more than rough parses ({text_cap})"
        if size is not None
        else (f"more than {text_cap} of text, more than rough parses")
    )
    return FormatError(f"{amount}; convert it to X3P or NPY, or set ROUGH_MAX_TEXT_BYTES to raise the cap")


def file_size(stream):
    """The size in bytes of a stream that is a regular file, else None (a pipe, a
    terminal, an in-memory stream)."""
    try:
        status = os.fstat(stream.fileno())
    except (OSError, AttributeError, ValueError, io.UnsupportedOperation):
        return None
    return status.st_size if stat.S_ISREG(status.st_mode) else None


def too_large(what, limit):
    return InputError(f"{what}: larger than {human(limit)}; refusing (set ROUGH_MAX_INPUT_BYTES to raise the cap)")


def scaled(values, factor, what, offset=0.0):
    """``values * factor + offset``, refusing a scale that turns finite values infinite."""
    result = values * factor + offset if offset else values * factor
    if not np.isfinite(result[np.isfinite(values)]).all():
        raise FormatError(f"{what} scales heights beyond the float64 range")
    return result
