"""Small valid files of every format rough reads, as bytes: the seeds that the
mutation tests (tests/test_fuzz.py) and the coverage-guided fuzzer
(bench/fuzz_readers.py) start from."""

import gzip
import io

import numpy as np

from rough import Surface

from format_files import al3d_file, sdf_binary

MAP = np.array([[1.0, 2.0, np.nan, 4.0], [5.0, 6.0, 7.0, 8.0], [9.0, 10.0, 11.0, 12.0]]) * 1e-6
PROFILE = np.array([0.0, 1.5, -2.0, 3.25, 0.5, 1.0]) * 1e-6


def _written(surface, fmt):
    buffer = io.BytesIO()
    surface.write(buffer, fmt)
    return buffer.getvalue()


def seeds():
    """``{name: bytes}`` of valid inputs, one or more per reader."""
    surface = Surface(MAP, (1e-6, 2e-6), metadata={"title": "seed"})
    profile = Surface(PROFILE, (0.5e-6,))
    result = {f"map.{fmt}": _written(surface, fmt) for fmt in ("x3p", "exr", "gsf", "tsv", "npy")}
    result.update({f"profile.{fmt}": _written(profile, fmt) for fmt in ("x3p", "tsv")})
    result["columns.csv"] = b"x [um];z [um]\n0,0;1,5\n0,5;2,25\n1,0;BAD\n1,5;3,0\n"
    result["dektak.csv"] = (
        b"Scan Parameters\r\r\nLength,0.8 um\r\nResolution,0.156 um/sample\r\n\r\r\n"
        b"Scan Data\r\r\nLateral um,Raw Micrometer,\r\n0.0,-0.00933,,\r\n0.2,-0.00760,,\r\n"
        b"0.3,-0.00644,,\r\n0.5,-0.00498,,\r\n0.6,-0.00345,,\r\n0.8,-0.00200,,\r\n"
    )
    result["gwyddion.txt"] = (
        b"# Channel: Height\n# Width: 12.34 um\n# Height: 5.6789 um\n# Value units: m\n"
        b"1e-9 2e-9 3e-9\n4e-9 5e-9 6e-9\n7e-9 8e-9 9e-9\n1e-9 1e-9 1e-9\n"
    )
    result["grid.xyz"] = b"0 0 1\n1 0 2\n0 1 3\n1 1 4\n0 2 5\n1 2 6\n"
    result["ascii.sdf"] = (
        b"aISO-1.0\nManufacID = seed\nNumPoints = 3\nNumProfiles = 2\nXscale = 1e-6\nYscale = 1e-6\n"
        b"Zscale = 1e-6\nDataType = 7\n*\n1 2 BAD\n4 5 6\n*\n"
    )
    result["binary.sdf"] = sdf_binary(
        3, 2, 1e-6, 2e-6, datatype=5, body=np.arange(6, dtype="<i2").tobytes(), manufacturer=b"seed"
    )
    result["depth.al3d"] = al3d_file(
        np.arange(15, dtype="<f4").reshape(3, 5) * np.float32(1e-6), tags={"CreatingApplication": "seed"}
    )
    result["map.tsv.gz"] = gzip.compress(result["map.tsv"])
    return result
