"""Issue 32: NumPy NPZ archives (the Corona Heights fault grid is one), read without
unpickling, their channels, spacing and orientation, and damaged archives refused in
one line."""

import io
import json
import pickle
import struct
import zipfile

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rough
from rough.errors import FormatError, InputError
from rough.io import registry, sniff
from rough.io.npz import default_channel

from conftest import assert_one_line_error, shared_data_path

CORONA = shared_data_path() / "dem" / "coronaA_grids.npz"
needs_corona = pytest.mark.skipif(not CORONA.is_file(), reason="needs ../shared/data/dem/coronaA_grids.npz")
DX = 0.005685771715431078


def archive(compressed=False, **members):
    buffer = io.BytesIO()
    (np.savez_compressed if compressed else np.savez)(buffer, **members)
    return buffer.getvalue()


HEIGHTS = np.random.default_rng(0).standard_normal((5, 7)) * 1e-6


# -- the Corona Heights grid ---------------------------------------------------------------------


@needs_corona
def test_the_corona_heights_grid_reads_as_its_raw_heights_with_its_spacing():
    scan = rough.read(CORONA)
    with np.load(CORONA) as stored:
        z_grid, xg, yg = stored["Z_grid"], stored["xg"], stored["yg"]
    assert scan.source_format == "npz" and scan.heights.shape == (388, 537)
    assert scan.spacing == (DX, DX) and scan.origin == (xg[0], yg[0])
    np.testing.assert_array_equal(scan.heights, z_grid)  # row 0 is the row at yg[0]
    assert np.isnan(scan.heights).mean() == pytest.approx(0.007, abs=0.0005)
    assert scan.metadata["channel"] == "Z_grid"
    assert scan.metadata["channels"] == "0 'Z_grid', 1 'Z_detrended'"  # meta_str (objects) is not offered


@needs_corona
@pytest.mark.parametrize("channel", ["Z_detrended", "z_detrended", 1, "1"])
def test_another_channel_by_name_or_number(channel):
    scan = rough.read(CORONA, channel=channel)
    with np.load(CORONA) as stored:
        np.testing.assert_array_equal(scan.heights, stored["Z_detrended"])


@needs_corona
def test_an_object_member_is_no_channel_and_is_never_unpickled(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("unpickled")

    monkeypatch.setattr(pickle, "load", refuse)
    monkeypatch.setattr(pickle, "loads", refuse)
    with pytest.raises(FormatError, match="no channel 'meta_str'; the file holds 0 'Z_grid', 1 'Z_detrended'"):
        rough.read(CORONA, channel="meta_str")
    assert rough.read(CORONA).heights.shape == (388, 537)


@needs_corona
def test_the_command_line_reads_the_corona_grid(run):
    facts = json.loads(run("info", "--json", CORONA, check=True).stdout)
    assert facts["shape"] == [537, 388] and facts["spacing"] == [DX, DX]  # x first


# -- archives written here -------------------------------------------------------------------------


@pytest.mark.parametrize("compressed", [False, True])
def test_spacing_from_dx_and_dy_members(compressed):
    scan = rough.read(archive(compressed, heights=HEIGHTS, dx=np.float64(2e-6), dy=np.array([3e-6])))
    assert scan.source_format == "npz" and scan.spacing == (2e-6, 3e-6) and scan.origin == (0.0, 0.0)
    np.testing.assert_array_equal(scan.heights, HEIGHTS)


def test_a_lone_dx_serves_both_axes():
    assert rough.read(archive(z=HEIGHTS, dx=2e-6)).spacing == (2e-6, 2e-6)


def test_spacing_and_origin_from_axis_members():
    x = 0.5 + 1e-3 * np.arange(7)
    y = -2.0 + 2e-3 * np.arange(5)
    scan = rough.read(archive(Z=HEIGHTS, xg=x, yg=y))
    assert scan.spacing == pytest.approx((1e-3, 2e-3), rel=1e-12)
    assert scan.origin == (0.5, -2.0)


def test_a_decreasing_y_axis_puts_row_zero_at_the_smallest_y():
    y = 10.0 - 1e-3 * np.arange(5)
    scan = rough.read(archive(height=HEIGHTS, x=1e-3 * np.arange(7), y=y))
    np.testing.assert_array_equal(scan.heights, HEIGHTS[::-1])
    assert scan.origin[1] == pytest.approx(y[-1]) and scan.spacing[1] == pytest.approx(1e-3)


@pytest.mark.parametrize(
    "members, fragment",
    [
        (dict(z=HEIGHTS, x=np.r_[0, 1, 2, 3, 4, 5, 7.0] * 1e-3), "not equally spaced"),
        (dict(z=HEIGHTS, dx=2e-3, x=1e-3 * np.arange(7)), "disagrees"),
        (dict(z=HEIGHTS, dx=-1e-3), "not a positive length"),
        (dict(z=HEIGHTS), "--spacing"),
        (dict(z=HEIGHTS, dy=1e-3), "--spacing"),
        (dict(labels=np.array(["a", "b"]), count=np.int64(3)), "no numeric 1-D or 2-D array"),
    ],
)
def test_bad_or_missing_spacing_and_no_heights_are_refused(members, fragment):
    with pytest.raises(FormatError, match=fragment):
        rough.read(archive(**members))


def test_spacing_given_serves_an_archive_without_one_and_overrides_one_that_has_it():
    assert rough.read(archive(z=HEIGHTS), spacing=1e-6).spacing == (1e-6, 1e-6)
    assert rough.read(archive(z=HEIGHTS, dx=3e-6), spacing=(1e-6, 2e-6)).spacing == (1e-6, 2e-6)


def test_the_raw_heights_are_the_default_whatever_the_order():
    scan = rough.read(archive(Z_detrended=HEIGHTS * 0, Z_grid=HEIGHTS, dx=1e-6))
    assert scan.metadata["channel"] == "Z_grid"
    assert default_channel(["phase", "amplitude"]) == 0
    assert default_channel(["phase", "topography_filtered", "Height"]) == 2
    assert default_channel(["phase", "topography_filtered"]) == 1


def test_a_1d_archive_is_a_profile_with_its_x_axis():
    heights = np.linspace(0, 1e-6, 50) ** 2
    scan = rough.read(archive(x=1e-4 + 1e-5 * np.arange(50), z=heights))
    assert scan.is_profile and scan.spacing == pytest.approx((1e-5,)) and scan.origin == pytest.approx((1e-4,))
    np.testing.assert_array_equal(scan.heights, heights)


def test_fortran_order_big_endian_and_integer_members_keep_their_values():
    stored = np.asfortranarray(HEIGHTS).astype(">f8")
    np.testing.assert_array_equal(rough.read(archive(z=stored, dx=1.0)).heights, HEIGHTS)
    counts = np.arange(35, dtype=np.int16).reshape(5, 7)
    scan = rough.read(archive(z=counts, dx=1.0))
    assert scan.heights.dtype == np.float64
    np.testing.assert_array_equal(scan.heights, counts)


def test_an_npz_is_sniffed_as_npz_and_an_x3p_is_still_an_x3p():
    assert sniff(archive(z=HEIGHTS)[: registry.HEAD]) == "npz"
    assert sniff(rough.sample("rock-map.x3p").read_bytes()[: registry.HEAD]) == "x3p"


@settings(max_examples=60, deadline=None)
@given(
    shape=st.tuples(st.integers(1, 9), st.integers(2, 9)),
    dtype=st.sampled_from(["<f8", ">f4", "<i4", "<u2"]),
    compressed=st.booleans(),
    seed=st.integers(0, 2**16),
)
def test_any_numeric_map_reads_back_exactly(shape, dtype, compressed, seed):
    values = (np.random.default_rng(seed).standard_normal(shape) * 100).astype(dtype)
    scan = rough.read(archive(compressed, surface=values, dx=1e-6, dy=2e-6))
    np.testing.assert_array_equal(scan.heights, values.astype(np.float64))


# -- damaged archives ----------------------------------------------------------------------------------


GOOD = archive(z=HEIGHTS, dx=1e-6, meta=np.array([{"a": 1}], dtype=object))
GOOD_COMPRESSED = archive(True, z=HEIGHTS, dx=1e-6)


@settings(max_examples=80, deadline=None)
@given(data=st.sampled_from([GOOD, GOOD_COMPRESSED]), cut=st.integers(4, 10**6))
def test_a_truncated_archive_is_refused_in_one_line(data, cut):
    cut = min(cut, len(data) - 1)
    with pytest.raises(InputError) as caught:
        rough.read(data[:cut])
    assert "\n" not in str(caught.value)


def test_a_member_shorter_than_its_npy_header_declares_is_refused():
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False, "shape": (10, 10)})
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as target:
        target.writestr("z.npy", header.getvalue() + np.zeros(50).tobytes())
        target.writestr("dx.npy", _npy(np.float64(1e-6)))
    with pytest.raises(FormatError, match="declares 10×10 values of 8 bytes; the member holds 400 bytes"):
        rough.read(buffer.getvalue())


def test_a_member_whose_bytes_fail_the_crc_is_refused():
    damaged = bytearray(GOOD)
    start = GOOD.index(b"\x93NUMPY") + 200  # inside z's numbers, stored
    damaged[start] ^= 0xFF
    with pytest.raises(FormatError, match="Bad CRC-32 for file .z.npy."):
        rough.read(bytes(damaged))


def test_a_zip_entry_that_declares_more_than_its_member_holds_is_refused():
    damaged = bytearray(GOOD_COMPRESSED)
    entry = damaged.index(b"PK\x01\x02")  # the central directory's first entry: z.npy
    size = struct.unpack_from("<I", damaged, entry + 24)[0]
    struct.pack_into("<I", damaged, entry + 24, size + 64)  # its uncompressed size
    with pytest.raises(FormatError, match="z.npy does not hold the .* bytes its zip entry declares"):
        rough.read(bytes(damaged))


def test_the_command_line_refuses_a_truncated_archive_in_one_line(run, tmp_path):
    path = tmp_path / "cut.npz"
    path.write_bytes(GOOD[: len(GOOD) // 2])
    assert_one_line_error(run("info", path), "cut.npz")


def _npy(value):
    buffer = io.BytesIO()
    np.save(buffer, value)
    return buffer.getvalue()
