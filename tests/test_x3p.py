"""X3P: what the schema says, what real files hold, and what the reader refuses."""

import hashlib
import io
import struct
import zipfile
from xml.etree import ElementTree

import numpy as np
import pytest

from rough import Surface
from rough.errors import FormatError
from rough.io import read_bytes
from rough.io.x3p import NAMESPACE, VENDOR_ID

from x3p_files import GRID, written, x3p_file


def members(blob):
    with zipfile.ZipFile(io.BytesIO(blob)) as archive:
        return {info.filename: (info, archive.read(info)) for info in archive.infolist()}


# -- rough's own output follows the schema --------------------------------------------


@pytest.mark.parametrize("heights", [GRID, GRID[0], np.where(GRID > 5e-6, GRID, np.nan)])
def test_output_follows_the_schema(heights):
    blob = written(Surface(heights, (1e-6, 2e-6)[: heights.ndim]))
    parts = members(blob)
    document = parts["main.xml"][1]
    assert parts["md5checksum.hex"][1].split()[0].decode() == hashlib.md5(document).hexdigest()
    root = ElementTree.fromstring(document)
    assert root.tag == f"{{{NAMESPACE}}}ISO5436_2"
    assert [child.tag for child in root] == ["Record1", "Record2", "Record3", "Record4", "VendorSpecificID"]
    assert [child.tag for child in root.find("Record2")] == ["Date", "Instrument", "CalibrationDate", "ProbingSystem"]
    assert root.findtext("VendorSpecificID") == VENDOR_ID
    assert root.findtext("Record1/FeatureType") == ("PRF" if heights.ndim == 1 else "SUR")
    assert root.findtext("Record1/Axes/CZ/DataType") == "D"
    data = parts["bindata/data.bin"][1]
    assert root.findtext("Record3/DataLink/MD5ChecksumPointData") == hashlib.md5(data).hexdigest()
    assert np.array_equal(np.frombuffer(data, "<f8"), heights.ravel(), equal_nan=True)
    assert all(info.compress_type == zipfile.ZIP_STORED for info, _ in parts.values())
    size_y = root.findtext("Record3/MatrixDimension/SizeY")
    assert size_y == ("1" if heights.ndim == 1 else "3")
    if np.isnan(heights).any():
        mask = parts["bindata/valid.bin"][1]
        assert root.findtext("Record3/DataLink/MD5ChecksumValidPoints") == hashlib.md5(mask).hexdigest()
        bits = np.unpackbits(np.frombuffer(mask, np.uint8), count=heights.size, bitorder="little")
        assert np.array_equal(bits.astype(bool), ~np.isnan(heights.ravel()))
    else:
        assert "bindata/valid.bin" not in parts


def test_integer_types_are_signed_in_what_rough_reads():
    raw = np.array([[-32768, -1, 0, 32767]], dtype=np.int16)
    surface = read_bytes(x3p_file(raw, code="I", increment=1e-9, offset=0.0))
    assert surface.heights.tolist() == [-32768e-9, -1e-9, 0.0, 32767e-9]
    raw32 = np.array([[-(2**31), -5, 2**31 - 1]], dtype=np.int32)
    heights = read_bytes(x3p_file(raw32, code="L", increment=1e-9)).heights  # 2**31 m would be refused: > 100 km
    assert heights.tolist() == (raw32[0].astype(np.float64) * 1e-9).tolist()


def test_binary_data_start_aligned_for_zero_copy_reading():
    blob = written(Surface(GRID, (1e-6, 1e-6)))
    with zipfile.ZipFile(io.BytesIO(blob)) as archive:
        info = archive.getinfo("bindata/data.bin")
    name_length, extra_length = struct.unpack("<HH", blob[info.header_offset + 26 : info.header_offset + 30])
    assert (info.header_offset + 30 + name_length + extra_length) % 64 == 0
    surface = read_bytes(blob)
    assert surface.heights.flags.aligned and not surface.heights.flags.writeable


# -- the variations of real X3P files ------------------------------------------------------


@pytest.mark.parametrize(
    "code,increment,offset", [("I", 1e-8, -0.5e-6), ("L", 1e-9, 2e-6), ("F", None, None), ("D", None, 1e-6)]
)
@pytest.mark.parametrize("inline", [False, True])
def test_data_types_with_increment_and_offset(code, increment, offset, inline):
    rng = np.random.default_rng(3)
    raw = rng.integers(-1000, 1000, size=(3, 5)) if code in "IL" else rng.normal(size=(3, 5)) * 1e-6
    raw = raw.astype({"I": "<i2", "L": "<i4", "F": "<f4", "D": "<f8"}[code])
    surface = read_bytes(x3p_file(raw, code=code, increment=increment, offset=offset, inline=inline))
    scale = increment if code in "IL" else 1.0
    expected = raw.astype(np.float64) * scale + (offset or 0.0)
    assert surface.heights.shape == (3, 5)
    np.testing.assert_array_equal(surface.heights, expected)
    assert surface.spacing == (1e-6, 2e-6)


@pytest.mark.parametrize("inline", [False, True])
def test_invalid_points_become_nan(inline):
    valid = np.ones(GRID.shape, bool)
    valid[1, 2] = valid[0, 0] = False
    surface = read_bytes(x3p_file(GRID, valid=valid, inline=inline))
    assert np.array_equal(np.isnan(surface.heights), ~valid)
    assert np.array_equal(surface.heights[valid], GRID[valid])


def test_folder_prefix_bom_and_missing_record2():
    surface = read_bytes(x3p_file(GRID, prefix="scan-7/", bom=True, record2=False, compression=zipfile.ZIP_STORED))
    np.testing.assert_array_equal(surface.heights, GRID)
    assert "instrument_model" not in surface.metadata


def test_record2_becomes_metadata():
    metadata = read_bytes(x3p_file(GRID)).metadata
    assert metadata["instrument_manufacturer"] == "Acme"
    assert metadata["creator"] == "A. Tester"
    assert metadata["probing_type"] == "Contacting"
    assert metadata["date"] == "2020-01-02T03:04:05"


def test_profile_feature():
    surface = read_bytes(x3p_file(GRID[:1], feature="PRF"))
    assert surface.is_profile and surface.spacing == (1e-6,)
    np.testing.assert_array_equal(surface.heights, GRID[0])


@pytest.mark.parametrize("inline", [False, True])
def test_absolute_y_axis_on_a_regular_grid(inline):
    surface = read_bytes(x3p_file(GRID, absolute_y=np.array([1, 2, 3]), inline=inline))
    assert surface.spacing == (1e-6, 2.0)
    assert surface.origin == (0.0, 3.0)
    np.testing.assert_array_equal(surface.heights, GRID)


def test_irregular_absolute_axis_is_refused():
    with pytest.raises(FormatError, match="irregular grid"):
        read_bytes(x3p_file(GRID, absolute_y=np.array([1, 2, 4])))


# -- refusals --------------------------------------------------------------------------


@pytest.mark.parametrize(
    "blob,message",
    [
        (x3p_file(GRID, main_checksum="bad"), "main.xml checksum mismatch"),
        (x3p_file(GRID, main_checksum="missing"), "checksum file md5checksum.hex"),
        (x3p_file(GRID, data_checksum="bad"), "bindata/data.bin checksum mismatch"),
        (x3p_file(GRID, data_checksum="missing"), "no MD5 checksum for bindata/data.bin"),
        (x3p_file(GRID, size=(4, 3, 1000000)), "holds 96 bytes, but the header implies"),
        (x3p_file(GRID, size=(1000000, 1000000, 1)), "more than rough handles"),
        (x3p_file(GRID, inline=True, size=(5, 3, 1)), "DataList holds 12 points"),
        (x3p_file(GRID, feature="PCL"), "point clouds"),
        (x3p_file(GRID, feature="PRF"), "SizeY 1"),
        (x3p_file(GRID, doctype='<!DOCTYPE p [<!ENTITY e SYSTEM "file:///etc/passwd">]>'), "DOCTYPE"),
        (b"PK\x05\x06" + bytes(18), "without main.xml"),
    ],
)
def test_refused_with_a_reason(blob, message):
    with pytest.raises(FormatError, match=message):
        read_bytes(blob)


def test_corrupted_data_are_caught_by_the_checksum():
    blob = bytearray(written(Surface(GRID, (1e-6, 1e-6))))
    payload = bytes(GRID.astype("<f8").tobytes())
    at = blob.find(payload)
    blob[at + 5] ^= 0xFF
    with pytest.raises(FormatError, match="checksum mismatch"):
        read_bytes(bytes(blob))


@pytest.mark.parametrize("cut", [10, 100, 600, -200, -22, -1])
def test_truncated_archive_is_refused(cut):
    blob = written(Surface(GRID, (1e-6, 1e-6)))
    with pytest.raises(FormatError):
        read_bytes(blob[:cut])


def test_checksum_failures_can_be_read_with_a_warning(caplog):
    from rough.io import ReadOptions

    surface = read_bytes(x3p_file(GRID, main_checksum="bad"), ReadOptions(verify=False))
    np.testing.assert_array_equal(surface.heights, GRID)
    assert "checksum mismatch" in caplog.text


# -- the real files of ../shared/data --------------------------------------------------

REAL = {
    # path: (nx, ny, dx, dy, invalid points), from data/INDEX.md
    "x3ptools/sample-land.x3p": (918, 256, 2.58e-6, 2.58e-6, 25292),
    "x3ptools/pyramid.x3p": (5, 5, 1.0, 1.0, 0),
    "x3ptools/testing.x3p": (30, 20, 0.0275, 0.0275, 0),
    "opengps/ISO5436-sample1.x3p": (4, 4, 0.016016, 0.016016, 1),
    "opengps/ISO5436-sample1_bin.x3p": (4, 4, 0.016016, 0.016016, 1),
    "opengps/ISO5436-sample3.x3p": (4, 4, 0.016016, 2.0, 1),
    "opengps/ISO5436-sample4.x3p": (4, 4, 0.016016, 0.016016, 1),
    "opengps/ISO5436-sample4_bin.x3p": (4, 4, 0.016016, 0.016016, 1),
    "opengps/KautschukInfiniteFocus.x3p": (860, 634, 2.279984e-6, 2.279795e-6, 5296),
    "SurfaceTopography/x3p-2.x3p": (650, 650, 1.27656509837346e-7, 3.14582113527746e-7, 0),
}


@pytest.mark.parametrize("path", sorted(REAL))
def test_real_files_read_as_index_lists(shared_data, path):
    from rough.io import read

    nx, ny, dx, dy, invalid = REAL[path]
    surface = read(shared_data / path)
    assert surface.points == (nx, ny)
    np.testing.assert_allclose(surface.spacing, (dx, dy), rtol=1e-6)
    assert np.isnan(surface.heights).sum() == invalid


def test_x3p2_rms_height_matches_surfacetopography(shared_data):
    from rough.io import read
    from rough.metrology import summary

    facts = summary(read(shared_data / "SurfaceTopography/x3p-2.x3p"))
    assert facts["Sq"] == pytest.approx(7.728033273597876e-08, rel=1e-9)
    np.testing.assert_allclose(facts["size"], [8.29767313942749e-05, 2.044783737930349e-04], rtol=1e-12)


def test_csafe_logo_has_a_wrong_main_checksum(shared_data):
    """x3ptools wrote this file with an md5checksum.hex that does not match its
    main.xml; rough refuses it unless told to ignore checksums."""
    from rough.errors import InputError
    from rough.io import read

    path = shared_data / "x3ptools/csafe-logo.x3p"
    with pytest.raises(InputError, match="main.xml checksum mismatch"):
        read(path)
    surface = read(path, verify=False)
    assert surface.points == (741, 419)
    assert np.nanmin(surface.heights) == pytest.approx(2.078431372549019e-07)


def test_point_cloud_sample_is_refused(shared_data):
    from rough.errors import InputError
    from rough.io import read

    with pytest.raises(InputError, match="point clouds"):
        read(shared_data / "opengps/ISO5436-sample2.x3p")
