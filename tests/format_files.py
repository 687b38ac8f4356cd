"""Hand-made GSF, binary SDF and AL3D files for tests (bytes), written independently
of rough's readers, as tests/x3p_files.py does for X3P."""

import struct

import numpy as np


def gsf(header_lines, values):
    """A Gwyddion Simple Field: the header lines, NUL padding to 4 bytes, float32 values."""
    header = ("Gwyddion Simple Field 1.0\n" + "".join(f"{line}\n" for line in header_lines)).encode()
    return header + bytes(4 - len(header) % 4) + np.asarray(values, "<f4").tobytes()


def sdf_binary(points, profiles, xscale=1e-6, yscale=1e-6, zscale=1e-9, datatype=7, body=b"", manufacturer=b"TEST"):
    """A binary ISO 25178-71 SDF: the fixed header, then ``body`` as given."""
    return (
        struct.pack(
            "<8s10s12s12sHHddddBBB",
            b"bISO-1.0",
            manufacturer,
            b"010120201200",
            b"010120201200",
            points,
            profiles,
            xscale,
            yscale,
            zscale,
            1e-9,
            0,
            datatype,
            0,
        )
        + body
    )


def al3d_file(depth, pixel=(1e-6, 2e-6), invalid=3e15, tags=None, cut=0):
    """An AL3D file as MeasureSuite writes one: tags, a 256-byte comment, float32 rows
    padded to 8 bytes; ``tags`` override the header, ``cut`` drops bytes at the end."""
    rows, cols = depth.shape
    header = {
        "Cols": cols,
        "Rows": rows,
        "PixelSizeXMeter": pixel[0],
        "PixelSizeYMeter": pixel[1],
        "InvalidPixelValue": invalid,
        "NumberOfPlanes": 0,
        "CreatingApplication": "hand-made",
    }
    header.update(tags or {})
    offset = 17 + 52 * (len(header) + 3) + 256
    header["DepthImageOffset"] = header.get("DepthImageOffset", offset)

    def tag(key, value):
        return str(key).encode().ljust(20, b"\0") + str(value).encode().ljust(30, b"\0") + b"\r\n"

    blob = b"AliconaImaging\0\r\n" + tag("Version", 1) + tag("TagCount", len(header))
    blob += b"".join(tag(k, v) for k, v in header.items()) + b"\0" * 254 + b"\r\n"
    stride = (cols * 4 + 7) // 8 * 8
    blob += b"".join(row.astype("<f4").tobytes().ljust(stride, b"\xaa") for row in depth)
    return blob[: len(blob) - cut]
