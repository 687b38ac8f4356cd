"""Zygo MetroPro ``.dat`` (phase maps of Zygo interferometers), read only.

A big-endian header (magic ``88 1B 03 6F``, ``…70`` or ``…71`` for header formats 1, 2
and 3; 834 bytes for formats 1 and 2, 4096 for format 3, as ``header_size`` at byte 6
says) is followed by the intensity buckets (``ac_n_buckets`` × ``ac_width`` ×
``ac_height`` big-endian uint16) and then the connected phase data, ``cn_width`` ×
``cn_height`` big-endian int32, row by row as the camera delivered them (row 0 is the
first stored row; rough keeps that order), which end the file (a file of another
length is refused). Phase values of 2147483640 and above mark
invalid points (NaN here). Heights are phase × ``intf_scale_factor`` ×
``obliquity_factor`` × ``wavelength_in`` / R, where R is 4096, 32768 or 131072 for
``phase_res`` 0, 1 or 2, negated when ``sign`` is set; the pixel size is
``lateral_res`` (metres). ``time_stamp`` is in seconds since 1970 (UTC). Layout from
the MetroPro Reference Guide (0347-M) as Gwyddion's ``metropro.c`` and
SurfaceTopography's ``MetroPro.py`` read it; the intensity buckets are not read.
"""

import datetime
import struct

import numpy as np

from ..errors import FormatError
from ..surface import Surface, Units, check_size
from .header import check_length
from .registry import Format

FORMAT = Format(
    "metropro",
    "Zygo MetroPro",
    (".dat",),
    magic=(b"\x88\x1b\x03\x6f", b"\x88\x1b\x03\x70", b"\x88\x1b\x03\x71"),
    carries=("spacing", "units", "metadata", "time", "mask"),
)

HEADER_SIZES = {b"\x88\x1b\x03\x6f": (1, 834), b"\x88\x1b\x03\x70": (2, 834), b"\x88\x1b\x03\x71": (3, 4096)}
PHASE_RESOLUTION = {0: 4096, 1: 32768, 2: 131072}
INVALID_PHASE = 2147483640


def read(data, options):
    data = bytes(data)
    header = _header(data)
    nx, ny = header["cn_width"], header["cn_height"]
    if nx == 0 or ny == 0:
        raise FormatError("MetroPro file holds no phase data (connected-phase size 0)")
    check_size((ny, nx), "the MetroPro phase map")
    offset = header["header_size"] + 2 * header["ac_n_buckets"] * header["ac_width"] * header["ac_height"]
    end = offset + 4 * nx * ny
    check_length(data, end, "MetroPro", f"header, intensity, then {nx}×{ny} phase points")
    phase = np.frombuffer(data, ">i4", nx * ny, offset).reshape(ny, nx)
    heights = np.where(phase >= INVALID_PHASE, np.nan, phase * _height_scale(header))
    return Surface(heights, _spacing(header), units=Units(xy="m", z="m"), metadata=_metadata(header))


def _header(data):
    magic = data[:4]
    if magic not in HEADER_SIZES:
        raise FormatError("not a MetroPro file (unknown magic number)")
    if len(data) < 834:
        raise FormatError(f"MetroPro header is truncated ({len(data)} bytes of 834)")
    header_format, header_size = struct.unpack_from(">HI", data, 4)
    if (header_format, header_size) != HEADER_SIZES[magic]:
        raise FormatError(f"MetroPro header format {header_format} of {header_size} bytes does not match its magic")
    if header_size > len(data):
        raise FormatError(f"MetroPro header of {header_size} bytes is longer than the file")
    ac_width, ac_height, ac_n_buckets = struct.unpack_from(">HHH", data, 52)
    cn_width, cn_height = struct.unpack_from(">HH", data, 68)
    scale_factor, wavelength, _, obliquity, _, lateral_res = struct.unpack_from(">6f", data, 164)
    return {
        "header_size": header_size,
        "software_date": _text(data[12:42]),
        "ac_width": ac_width,
        "ac_height": ac_height,
        "ac_n_buckets": ac_n_buckets,
        "cn_width": cn_width,
        "cn_height": cn_height,
        "time_stamp": struct.unpack_from(">i", data, 76)[0],
        "comment": _text(data[80:162]),
        "intf_scale_factor": scale_factor,
        "wavelength_in": wavelength,
        "obliquity_factor": obliquity,
        "lateral_res": lateral_res,
        "phase_res": struct.unpack_from(">h", data, 218)[0],
        "sign": struct.unpack_from(">h", data, 232)[0],
        "sys_serial": struct.unpack_from(">H", data, 242)[0],
        "obj_name": _text(data[246:258]),
        "part_name": _text(data[258:298]),
    }


def _height_scale(header):
    if header["phase_res"] not in PHASE_RESOLUTION:
        raise FormatError(f"MetroPro phase_res {header['phase_res']} is not 0, 1 or 2")
    scale = (
        header["intf_scale_factor"]
        * header["obliquity_factor"]
        * header["wavelength_in"]
        / PHASE_RESOLUTION[header["phase_res"]]
    )
    if not (np.isfinite(scale) and scale != 0):
        raise FormatError(f"MetroPro height scale {scale!r} m is not a finite non-zero number")
    return -scale if header["sign"] else scale


def _spacing(header):
    pixel = header["lateral_res"]
    if not (0 < pixel < np.inf):
        raise FormatError(f"MetroPro lateral_res {pixel!r} m is not a pixel size")
    return (float(pixel), float(pixel))


def _metadata(header):
    metadata = {"vendor": "Zygo", "metropro_wavelength": f"{header['wavelength_in']:.6g} m"}
    if header["time_stamp"] > 0:
        when = datetime.datetime.fromtimestamp(header["time_stamp"], datetime.timezone.utc)
        metadata["date"] = when.isoformat()
    for key, name in (("comment", "comment"), ("part_name", "title"), ("obj_name", "metropro_objective")):
        if header[key]:
            metadata[name] = header[key]
    if header["sys_serial"]:
        metadata["metropro_serial"] = str(header["sys_serial"])
    if header["software_date"]:
        metadata["metropro_software_date"] = header["software_date"]
    return metadata


def _text(raw):
    return raw.split(b"\0", 1)[0].decode("latin-1").strip()
