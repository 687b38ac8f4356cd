"""The other readers: text dialects, GSF, OpenEXR, NPY, SDF and AL3D, on hand-made files
and on the third-party files of ../shared/data."""

import io

import numpy as np
import pytest

from rough.errors import FormatError
from rough.io import ReadOptions, read, read_bytes

from format_files import al3d_file, gsf, sdf_binary

UM = 1e-6


def text(content, **options):
    return read_bytes(content.encode("utf-8") if isinstance(content, str) else content, ReadOptions(**options))


# -- text dialects ------------------------------------------------------------------------


def test_x_z_columns_with_units_in_the_names():
    surface = text("x[um]\tz[nm]\n0\t1\n0.5\t2\n1.0\t3\n")
    assert surface.spacing == pytest.approx((0.5 * UM,), rel=1e-12)
    np.testing.assert_allclose(surface.heights, [1e-9, 2e-9, 3e-9])
    assert (surface.units.xy, surface.units.z) == ("um", "nm")


def test_unit_line_applies_to_every_column():
    surface = text("# unit: mm\n0 0.001\n0.1 0.002\n0.2 0.003\n")
    assert surface.spacing == pytest.approx((1e-4,), rel=1e-12)
    np.testing.assert_allclose(surface.heights, [1e-6, 2e-6, 3e-6])


def test_unit_option_when_the_file_names_none():
    surface = text("0,1\n1,2\n2,3\n", unit="um")
    assert surface.spacing == pytest.approx((UM,))
    np.testing.assert_allclose(surface.heights, [UM, 2 * UM, 3 * UM])


def test_heights_alone_need_a_spacing():
    with pytest.raises(FormatError, match="--spacing"):
        text("1\n2\n3\n")
    surface = text("1\n2\n3\n", spacing=(2e-6, 2e-6))
    assert surface.spacing == (2e-6,) and surface.heights.tolist() == [1.0, 2.0, 3.0]


def test_semicolons_with_decimal_commas_and_bad_points():
    surface = text("x;z\n0,0;1,5\n0,5;BAD\n1,0;2,5\n", unit="mm")
    assert surface.spacing == pytest.approx((0.5e-3,))
    np.testing.assert_array_equal(np.isnan(surface.heights), [False, True, False])
    assert surface.heights[2] == pytest.approx(2.5e-3)


def test_descending_x_is_reversed():
    surface = text("2 30\n1 20\n0 10\n")
    assert surface.heights.tolist() == [10.0, 20.0, 30.0]


def test_uneven_x_is_refused_not_resampled():
    with pytest.raises(FormatError, match="not evenly spaced"):
        text("0 1\n1 2\n2.5 3\n3 4\n")


def test_rounded_x_within_printed_precision_is_accepted():
    x = np.round(np.arange(200) * 0.15625, 1)
    surface = text("".join(f"{a:.1f},{b}\n" for a, b in zip(x, np.arange(200.0))), unit="um")
    assert surface.spacing[0] == pytest.approx(0.15625 * UM, rel=1e-4)


def test_x_y_z_grid_in_any_order_with_a_missing_point():
    points = [(x, y, 10 * y + x) for y in range(3) for x in range(4) if (x, y) != (2, 1)]
    np.random.default_rng(0).shuffle(points)
    surface = text("".join(f"{x} {y} {z}\n" for x, y, z in points))
    assert surface.points == (4, 3)
    assert np.isnan(surface.heights[1, 2])
    assert surface.heights[2, 3] == 23.0


@pytest.mark.parametrize(
    "body,message",
    [
        ("0 0 1\n0 0 2\n1 1 3\n1 0 4\n", "more than one height"),
        ("0 0 1\n1 0 1\n2.6 0 1\n0 1 1\n", "not evenly spaced"),
        ("x z\n", "no numeric data"),
        ("1 2\n3 x\n", "unreadable number"),
    ],
)
def test_text_refusals(body, message):
    with pytest.raises(FormatError, match=message):
        text(body)


def test_bom_latin1_and_utf16():
    assert text(b"\xef\xbb\xbfx[\xc2\xb5m] z[\xc2\xb5m]\n0 1\n1 2\n").units.xy == "µm"
    assert text(b"x[\xb5m] z[\xb5m]\n0 1\n1 2\n").spacing == pytest.approx((UM,))
    assert text("x z\n0 1\n1 2\n".encode("utf-16")).heights.tolist() == [1.0, 2.0]


def test_plain_matrix_of_heights():
    surface = text("1 2 3 4\n5 6 7 8\n", spacing=(1e-6, 2e-6))
    assert surface.heights.shape == (2, 4) and surface.spacing == (1e-6, 2e-6)


# -- GSF ------------------------------------------------------------------------------


@pytest.mark.parametrize("title", ["", "a", "ab", "abc"])  # every header length modulo 4
def test_gsf_padding_and_units(title):
    blob = gsf(
        ["XRes = 3", "YRes = 2", "XReal = 3", "YReal = 4", "XYUnits = mm", "ZUnits = um", f"Title = {title}"],
        np.arange(6),
    )
    surface = read_bytes(blob)
    assert surface.spacing == pytest.approx((1e-3, 2e-3))
    np.testing.assert_allclose(surface.heights, np.arange(6.0).reshape(2, 3) * UM)


def test_gsf_titles_with_control_characters_keep_the_header_intact():
    """Found by the round-trip property test: a NUL in a title ended the GSF header early."""
    from rough import Surface

    surface = Surface(np.zeros((2, 3)), (0.0625, 0.0625), metadata={"title": "a\x00b\nc"})
    buffer = io.BytesIO()
    surface.write(buffer, "gsf")
    back = read_bytes(buffer.getvalue())
    assert back.metadata["title"] == "a\x00b\nc" and back.heights.shape == (2, 3)
    assert b"Title = a b c\n" in buffer.getvalue()


def test_gsf_one_row_is_a_profile():
    surface = read_bytes(gsf(["XRes = 4", "YRes = 1", "XReal = 4e-6"], [1, 2, 3, 4]))
    assert surface.is_profile and surface.spacing == pytest.approx((1e-6,))


@pytest.mark.parametrize(
    "lines,values,message",
    [
        (["XRes = 3"], [1, 2, 3], "YRes"),
        (["XRes = 3", "YRes = 2"], [1, 2, 3], "holds 12 bytes"),
        (["XRes = 1000000", "YRes = 1000000"], [1], "declares 1000000×1000000"),
        (["XRes = 2", "YRes = 1", "XReal = -1"], [1, 2], "positive"),
    ],
)
def test_gsf_refusals(lines, values, message):
    with pytest.raises(FormatError, match=message):
        read_bytes(gsf(lines, values))


# -- OpenEXR, NPY, SDF ---------------------------------------------------------------------


def test_foreign_exr_z_channel_needs_a_spacing():
    import OpenEXR

    buffer = io.BytesIO()
    OpenEXR.File({"type": OpenEXR.scanlineimage}, {"Z": np.arange(6, dtype="f4").reshape(2, 3)}).write(buffer)
    with pytest.raises(FormatError, match="--spacing"):
        read_bytes(buffer.getvalue())
    surface = read_bytes(buffer.getvalue(), ReadOptions(spacing=(1e-6, 1e-6)))
    np.testing.assert_array_equal(surface.heights, np.arange(6.0).reshape(2, 3))


def test_exr_colour_image_is_refused():
    import OpenEXR

    buffer = io.BytesIO()
    planes = {c: np.zeros((2, 2), "f4") for c in "GB"}
    OpenEXR.File({"type": OpenEXR.scanlineimage}, planes).write(buffer)
    with pytest.raises(FormatError, match="height channel"):
        read_bytes(buffer.getvalue())


def test_npy_without_spacing_is_refused():
    buffer = io.BytesIO()
    np.save(buffer, np.zeros(5))
    with pytest.raises(FormatError, match="--spacing"):
        read_bytes(buffer.getvalue())


def test_binary_sdf():
    surface = read_bytes(sdf_binary(3, 2, 1e-6, 2e-6, datatype=5, body=np.array([1, 2, 3, 4, 5, -6], "<i2").tobytes()))
    np.testing.assert_allclose(surface.heights, np.array([[1, 2, 3], [4, 5, -6]]) * 1e-9)
    assert surface.spacing == (1e-6, 2e-6)
    assert surface.metadata["date"] == "2020-01-01T12:00:00"


def test_ascii_sdf_with_bad_points():
    body = (
        "aISO-1.0\nNumPoints = 2\nNumProfiles = 2\nXscale = 1e-6\nYscale = 1e-6\nZscale = 1e-6\nDataType = 7\n"
        "*\n1 BAD\n3 4\n*\n"
    )
    surface = text(body)
    assert np.isnan(surface.heights[0, 1]) and surface.heights[1, 1] == pytest.approx(4e-6)


def test_al3d_rows_padded_to_eight_bytes_and_invalid_points():
    depth = np.arange(15, dtype=np.float32).reshape(3, 5) * np.float32(1e-6)
    depth[1, 2] = 3e15
    surface = read_bytes(al3d_file(depth))
    expected = depth.astype(np.float64)
    expected[1, 2] = np.nan
    np.testing.assert_array_equal(surface.heights, expected)
    assert surface.spacing == (1e-6, 2e-6)
    assert surface.metadata["instrument"] == "hand-made"
    assert surface.source_format == "al3d"


@pytest.mark.parametrize(
    "blob_options,message",
    [
        ({"cut": 8}, "runs past the end"),
        ({"tags": {"Cols": "abc"}}, "Cols is 'abc'"),
        ({"tags": {"PixelSizeXMeter": "0"}}, "not a pixel size"),
        ({"tags": {"DepthImageOffset": 0}}, "no depth image"),
        ({"tags": {"DepthImageOffset": 10**9}}, "runs past the end"),
    ],
)
def test_al3d_refusals(blob_options, message):
    with pytest.raises(FormatError, match=message):
        read_bytes(al3d_file(np.ones((4, 6), np.float32), **blob_options))


def test_al3d_broken_header_is_refused():
    blob = bytearray(al3d_file(np.ones((4, 6), np.float32)))
    blob[17 + 52 * 3 - 2] = ord("X")
    with pytest.raises(FormatError, match="CRLF"):
        read_bytes(bytes(blob))
    with pytest.raises(FormatError, match="truncated"):
        read_bytes(bytes(blob[:100]))


def test_gzipped_input(tmp_path):
    import gzip

    surface = read_bytes(gzip.compress(b"x z\n0 1\n1 2\n2 3\n"))
    assert surface.heights.tolist() == [1.0, 2.0, 3.0]


# -- third-party files: the sizes data/INDEX.md lists ---------------------------------------


@pytest.mark.parametrize(
    "name,points,size",
    [
        ("matrix-3.txt", (256, 256), (10e-6, 10e-6)),
        ("matrix-4.txt.gz", (75, 305), (2.773965e-05, 1.1280791e-04)),
        ("hfm-1.hfm", (9600,), (4.8e-3,)),
        ("dektak-1.csv", (9600,), (1500e-6,)),
        ("sdf-1.sdf", (7, 4), (7e-6, 4e-6)),
        ("xyz-1.txt", (4, 4), (4.0, 4.0)),
        ("gwyddion-export-english.txt", (3, 4), (12.34e-6, 5678.9e-9)),
    ],
)
def test_third_party_text_files(shared_data, name, points, size):
    surface = read(shared_data / "SurfaceTopography" / name)
    assert surface.points == points
    np.testing.assert_allclose(surface.size, size, rtol=1e-6)


def test_matrix3_and_matrix4_heights(shared_data):
    from rough.metrology import summary

    assert summary(read(shared_data / "SurfaceTopography/matrix-3.txt"))["Sq"] == pytest.approx(
        3.5222918750198742e-08, rel=1e-12
    )
    assert summary(read(shared_data / "SurfaceTopography/matrix-4.txt.gz"))["Sq"] == pytest.approx(
        1.1745891510991089e-07, rel=1e-12
    )


def test_hfm_line_scan_rms(shared_data):
    from rough.metrology import summary

    assert summary(read(shared_data / "SurfaceTopography/hfm-1.hfm"))["Rq"] == pytest.approx(0.000905688e-3, rel=1e-6)


def test_al3d_matches_surfacetopography(shared_data):
    """INDEX.md's values: Sq about the mean, Rq with each x profile's own mean removed,
    and Rq of the transpose (profiles along y), which tells the axes apart."""
    surface = read(shared_data / "SurfaceTopography/al3d-1.al3d")
    assert surface.points == (200, 296)
    np.testing.assert_allclose(surface.size, (8.76054e-05, 1.29655992e-04), rtol=1e-6)
    heights = surface.heights

    def rq(rows):
        return np.sqrt(np.mean((rows - rows.mean(axis=1, keepdims=True)) ** 2))

    assert np.std(heights) == pytest.approx(7.688266102603082e-06, rel=1e-6)
    assert rq(heights) == pytest.approx(3.915731160953795e-06, rel=1e-6)
    assert rq(heights.T) == pytest.approx(6.620846789152015e-06, rel=1e-6)


def test_xyz_grid_matches_surfacetopography_transposed(shared_data):
    """SurfaceTopography indexes heights[x, y]; rough holds z[y, x]."""
    surface = read(shared_data / "SurfaceTopography/xyz-1.txt")
    expected = np.array([[1, 1, 1, 1], [1, 2, 2, 1], [1, 1, 1, 1], [1, 1, 1, 1]])
    np.testing.assert_array_equal(surface.heights, expected.T)


def test_dektak_export(shared_data):
    surface = read(shared_data / "SurfaceTopography/dektak-1.csv")
    assert surface.spacing[0] == pytest.approx(0.15625e-6, rel=1e-6)
    assert surface.metadata["dektak_resolution"] == "0.156 um/sample"
    assert surface.heights[0] == pytest.approx(-0.00933e-6)


def test_nonuniform_line_scan_is_refused(shared_data):
    from rough.errors import InputError

    with pytest.raises(InputError, match="xy-3.txt: x values are not evenly spaced"):
        read(shared_data / "SurfaceTopography/xy-3.txt")


def test_exr_in_gwyddion_units_and_scale():
    """As Gwyddion writes it: a Gwy::ZScale and prefixed units (µm lateral, nm heights)."""
    import OpenEXR

    header = {
        "type": OpenEXR.scanlineimage,
        "Gwy::XReal": np.array([30.0]),
        "Gwy::YReal": np.array([20.0]),
        "Gwy::XYUnit": "µm",
        "Gwy::ZUnit": "nm",
        "Gwy::ZScale": np.array([2.0]),
    }
    buffer = io.BytesIO()
    OpenEXR.File(header, {"Y": np.ones((2, 3), "f4")}).write(buffer)
    surface = read_bytes(buffer.getvalue())
    assert surface.spacing == pytest.approx((10e-6, 10e-6))
    np.testing.assert_allclose(surface.heights, 2e-9)
