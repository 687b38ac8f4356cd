"""X3P in full, against x3pio's 33 sample files (``../shared/data/x3pio``, CC0-1.0):
regular surfaces and profiles equal to an independent plain-numpy decoding of each
file, layers chosen by number, placements (rotation and offsets), irregular grids and
point clouds gridded on request and refused otherwise; plus hand-made files for the
placements and axes the samples lack."""

import hashlib
import io
import logging
import re
import zipfile
from xml.etree import ElementTree

import numpy as np
import pytest

from rough.errors import FormatError, InputError
from rough.io import ReadOptions, read, read_bytes

from conftest import shared_data_path

DATA = shared_data_path()  # ../shared/data, or $ROUGH_SHARED/data
X3PIO = DATA / "x3pio"
needs_shared = pytest.mark.skipif(not X3PIO.is_dir(), reason="needs ../shared/data")
TYPES = {"I": "<i2", "L": "<i4", "F": "<f4", "D": "<f8"}

# name: (points (nx,) or (nx, ny), layers, z data type, invalid points per layer), from SAMPLES-README.md
# and counted in the files; "surface*" files exist in both folders.
REGULAR = {
    "profile": ((256,), 1, "D", [0]),
    "profile_int16": ((256,), 1, "I", [4]),
    "profile_int32": ((256,), 1, "L", [0]),
    "profile_layers": ((256,), 3, "F", [0, 3, 0]),
    "surface": ((200, 150), 1, "I", [180]),
    "surface_int32": ((120, 90), 1, "L", [60]),
    "surface_layers": ((160, 120), 3, "D", [0, 0, 0]),
    "surface_extensions": ((100, 80), 1, "F", [0]),
}
GRIDDED = {  # name: (what the refusal says, points per layer, layers)
    "surface_irregular": ("irregular grid of 96×72 points", 96 * 72, 1),
    "surface_irregular_layers": ("irregular grid of 80×60 points", 80 * 60, 3),
    "point_cloud": ("point cloud of 1000 points", 1000, 1),
    "point_cloud_int16": ("point cloud of 1000 points", 1000, 1),
    "point_cloud_int32": ("point cloud of 1000 points", 1000, 1),
    "point_cloud_float64": ("point cloud of 1000 points", 1000, 1),
}
PLACED = ("surface_placed", "surface_absolute_placed")


def sample_files():
    """Every sample file as ``(folder/file name, sample name)``: 33 of them."""
    if not X3PIO.is_dir():
        return []
    return [
        (f"{path.parent.name}/{path.name}", re.sub(r"_(binary|xml)$", "", path.stem))
        for path in sorted(X3PIO.glob("*/*.x3p"))
    ]


# -- an independent decoding: zipfile, ElementTree and numpy ------------------------------


def decode(path):
    """``(z per layer, x step, y step, x offset, y offset)`` of a regular sample file,
    decoded here without rough: z scaled by Increment (integer types) and shifted by
    Offset, NaN where the valid-point mask says so, for empty Datum elements and NaN floats."""
    with zipfile.ZipFile(path) as archive:
        root = ElementTree.fromstring(archive.read("main.xml"))
        for element in root.iter():
            element.tag = element.tag.rpartition("}")[2]
        axes = {name: root.find(f"Record1/Axes/{name}") for name in ("CX", "CY", "CZ")}
        assert axes["CX"].findtext("AxisType") == "I" and axes["CY"].findtext("AxisType") == "I"
        nx, ny, layers = (int(root.findtext(f"Record3/MatrixDimension/Size{c}")) for c in "XYZ")
        code = axes["CZ"].findtext("DataType")
        if root.find("Record3/DataLink") is not None:
            z = np.frombuffer(archive.read("bindata/data.bin"), TYPES[code]).astype(float)
            mask = root.findtext("Record3/DataLink/ValidPointsLink")
            if mask:
                valid = np.unpackbits(np.frombuffer(archive.read(mask), np.uint8), bitorder="little")[: len(z)]
                z[valid == 0] = np.nan
        else:
            texts = [datum.text for datum in root.findall("Record3/DataList/Datum")]
            z = np.array([float(text) if text and text.strip() else np.nan for text in texts])
    increment = float(axes["CZ"].findtext("Increment")) if code in "IL" else 1.0
    z = z * increment + float(axes["CZ"].findtext("Offset"))
    shape = (layers, nx) if ny == 1 else (layers, ny, nx)
    steps = [float(axes[name].findtext("Increment")) for name in ("CX", "CY")]
    offsets = [float(axes[name].findtext("Offset")) for name in ("CX", "CY")]
    return z.reshape(shape), *steps, *offsets


# -- every sample file ---------------------------------------------------------------------


@needs_shared
def test_all_33_sample_files_are_here():
    assert len(sample_files()) == 33


@needs_shared
@pytest.mark.parametrize("name,sample", sample_files())
def test_every_sample_file_reads_or_is_refused_as_documented(name, sample):
    path = X3PIO / name
    if sample in REGULAR:
        points, layers, _, invalid = REGULAR[sample]
        expected, dx, dy, x0, y0 = decode(path)
        for layer in range(layers):
            surface = read(path, layer=layer)
            assert surface.points == points
            np.testing.assert_array_equal(surface.heights, expected[layer])  # NaN in the same places
            assert int(np.isnan(surface.heights).sum()) == invalid[layer]
            assert surface.spacing == ((dx,) if len(points) == 1 else (dx, dy))
            assert surface.origin == ((x0,) if len(points) == 1 else (x0, y0))
            assert surface.metadata["creator"] == "x3pio sample generator"
            assert surface.metadata["date"] == "2026-01-01T12:00:00.0+00:00"
            assert ("layers" in surface.metadata) == (layers > 1)
    elif sample in GRIDDED:
        what, count, _ = GRIDDED[sample]
        with pytest.raises(InputError, match=f"{what}: give --regrid SPACING to grid it"):
            read(path)
        surface = read(path, regrid=(2e-6, "linear"))
        assert surface.history[-1]["command"] == "regrid"
        assert surface.history[-1]["parameters"]["points_read"] == count
    else:
        assert sample in PLACED
        with pytest.raises(InputError, match=r"rotated by 10\.0° about x in its placement; rough keeps grids"):
            read(path)


@needs_shared
@pytest.mark.parametrize("sample", [*REGULAR, *PLACED, "surface_irregular", "point_cloud"])
def test_binary_and_xml_files_hold_the_same_data(sample):
    folder = X3PIO / "iso25178-72-fdam1"
    if not (folder / f"{sample}_xml.x3p").is_file():
        pytest.skip(f"{sample} exists only as binary")
    options = {"regrid": 2e-6} if sample not in REGULAR else {}
    binary, xml = (read(folder / f"{sample}_{kind}.x3p", **options) for kind in ("binary", "xml"))
    np.testing.assert_allclose(xml.heights, binary.heights, rtol=1e-6, atol=1e-12)  # float32 printed in XML
    assert xml.spacing == binary.spacing and xml.points == binary.points


@needs_shared
def test_the_two_revisions_hold_the_same_surface():
    old = read(X3PIO / "iso25178-72-2017/surface_binary.x3p")
    new = read(X3PIO / "iso25178-72-fdam1/surface_binary.x3p")
    np.testing.assert_array_equal(old.heights, new.heights)


# -- layers ----------------------------------------------------------------------------


@needs_shared
def test_layers_are_chosen_by_number_and_recorded(caplog):
    path = X3PIO / "iso25178-72-fdam1/surface_layers_binary.x3p"
    expected = decode(path)[0]
    with caplog.at_level(logging.INFO, logger="rough"):
        first = read(path)
    assert "holds 3 layers; reading layer 0 (--layer N picks another)" in caplog.text
    assert (first.metadata["layer"], first.metadata["layers"]) == ("0", "3")
    caplog.clear()
    with caplog.at_level(logging.INFO, logger="rough"):
        last = read(path, layer=2)
    assert "reading layer" not in caplog.text  # layer 2 was asked for: no note about the choice
    assert last.metadata["layer"] == "2"
    np.testing.assert_array_equal(last.heights, expected[2])
    assert not np.array_equal(last.heights, first.heights)


@needs_shared
@pytest.mark.parametrize(
    "name,layer,held", [("surface_layers_xml", 3, "3 layers (0 to 2)"), ("profile_xml", 1, "1 layer")]
)
def test_a_layer_out_of_range_is_refused(name, layer, held):
    with pytest.raises(InputError, match=f"no layer {layer}; the file holds {re.escape(held)}"):
        read(X3PIO / f"iso25178-72-fdam1/{name}.x3p", layer=layer)


@needs_shared
def test_layers_of_an_irregular_grid_are_gridded_separately():
    path = X3PIO / "iso25178-72-fdam1/surface_irregular_layers_binary.x3p"
    layers = [read(path, layer=layer, regrid=2e-6) for layer in range(3)]
    assert len({layer.points for layer in layers}) == 1  # the same x, y in every layer
    assert not np.allclose(layers[0].heights, layers[1].heights, equal_nan=True)
    assert layers[2].metadata["layer"] == "2"


# -- placements: the samples' 10° rotation about x ---------------------------------------------


@needs_shared
@pytest.mark.parametrize("sample", PLACED)
def test_a_rotated_placement_is_resampled_on_request(sample):
    """Placed at R · p + offsets, the 10° tilt about x adds up to sin 10° × 89 µm to the
    heights (1.5e-5 m, the difference to x3pio that INDEX.md reports)."""
    surface = read(X3PIO / f"iso25178-72-fdam1/{sample}_binary.x3p", regrid=1e-6)
    local = decode(X3PIO / "iso25178-72-fdam1/surface_placed_binary.x3p")[0][0] - 1.0  # z without its Offset
    cos, sin = np.cos(np.radians(10)), np.sin(np.radians(10))
    y = 1e-6 * np.arange(90)[:, np.newaxis]
    assert surface.origin == pytest.approx((1e-6, 0.005 + (cos * y - sin * local).min()), abs=1e-12)
    assert np.nanmax(surface.heights) == pytest.approx((sin * y + cos * local).max() + 1.0, abs=2e-7)
    tilt = np.nanmean(surface.heights[70]) - np.nanmean(surface.heights[10])
    assert tilt == pytest.approx(sin / cos * 60e-6, rel=0.05)  # dz/dy of the placed surface is tan 10°


# -- hand-made files: placements, uneven absolute profiles, a smooth point cloud -------------


def x3p(records, axes, *, feature="SUR", size=None, rotation=None):
    """An X3P archive of structured ``records`` (fields CX/CY/CZ as present); ``axes``
    maps CX/CY/CZ to (AxisType, DataType, Increment, Offset)."""
    xml_axes = "".join(
        f"<{name}><AxisType>{kind}</AxisType><DataType>{code}</DataType><Increment>{step!r}</Increment>"
        f"<Offset>{offset!r}</Offset></{name}>"
        for name, (kind, code, step, offset) in axes.items()
    )
    if rotation is not None:
        xml_axes += (
            "<Rotation>"
            + "".join(
                f"<r{i + 1}{j + 1}>{float(rotation[i][j])!r}</r{i + 1}{j + 1}>" for i in range(3) for j in range(3)
            )
            + "</Rotation>"
        )
    dimension = (
        f"<ListDimension>{len(records)}</ListDimension>"
        if size is None
        else "<MatrixDimension>"
        + "".join(f"<Size{c}>{n}</Size{c}>" for c, n in zip("XYZ", size))
        + "</MatrixDimension>"
    )
    payload = records.tobytes()
    main = (
        '<?xml version="1.0" encoding="UTF-8"?>\n<p:ISO5436_2 xmlns:p="http://www.opengps.eu/2008/ISO5436_2">'
        f"<Record1><Revision>ISO5436 - 2000</Revision><FeatureType>{feature}</FeatureType><Axes>{xml_axes}</Axes>"
        f"</Record1><Record3>{dimension}<DataLink><PointDataLink>bindata/data.bin</PointDataLink>"
        f"<MD5ChecksumPointData>{hashlib.md5(payload).hexdigest()}</MD5ChecksumPointData></DataLink></Record3>"
        "<Record4><ChecksumFile>md5checksum.hex</ChecksumFile></Record4></p:ISO5436_2>"
    ).encode()
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        archive.writestr("main.xml", main)
        archive.writestr("md5checksum.hex", f"{hashlib.md5(main).hexdigest()} *main.xml\n")
        archive.writestr("bindata/data.bin", payload)
    return buffer.getvalue()


def grid_file(heights, spacing=(1e-6, 2e-6), offsets=(5e-6, -3e-6), rotation=None):
    ny, nx = heights.shape
    axes = {
        "CX": ("I", "D", spacing[0], offsets[0]),
        "CY": ("I", "D", spacing[1], offsets[1]),
        "CZ": ("A", "D", 1.0, 0.0),
    }
    records = np.array(heights.ravel(), dtype=[("CZ", "<f8")])
    return x3p(records, axes, size=(nx, ny, 1), rotation=rotation)


def turn(degrees):
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    return [[round(c, 15), round(-s, 15), 0.0], [round(s, 15), round(c, 15), 0.0], [0.0, 0.0, 1.0]]


@pytest.mark.parametrize("degrees", [0, 90, 180, 270, -90])
def test_quarter_turns_about_z_are_applied_exactly(degrees):
    """Every point lands where R · (i dx, j dy) + offsets puts it."""
    heights = np.arange(12.0).reshape(3, 4)
    surface = read_bytes(grid_file(heights, rotation=turn(degrees)))
    rotation = np.array(turn(degrees))[:2, :2]
    for (j, i), z in np.ndenumerate(heights):
        x, y = rotation @ (i * 1e-6, j * 2e-6) + (5e-6, -3e-6)
        column = round((x - surface.origin[0]) / surface.spacing[0])
        row = round((y - surface.origin[1]) / surface.spacing[1])
        assert surface.heights[row, column] == z
    assert sorted(surface.spacing) == [1e-6, 2e-6]
    assert surface.heights.shape == ((3, 4) if degrees % 180 == 0 else (4, 3))


@pytest.mark.parametrize(
    "rotation,words",
    [
        (turn(30), "30.0° about z"),
        ([[1, 0, 0], [0, 0, -1], [0, 1, 0]], "90.0° about x"),
        ([[np.cos(0.1), 0, np.sin(0.1)], [0, 1, 0], [-np.sin(0.1), 0, np.cos(0.1)]], "5.7° about y"),
    ],
)
def test_other_rotations_are_refused_naming_the_angle(rotation, words):
    with pytest.raises(FormatError, match=f"rotated by {words} in its placement; rough keeps grids axis-aligned: give"):
        read_bytes(grid_file(np.ones((3, 4)), rotation=rotation))


def test_a_matrix_that_is_no_rotation_is_refused():
    with pytest.raises(FormatError, match="not a rotation matrix"):
        read_bytes(grid_file(np.ones((3, 4)), rotation=[[2, 0, 0], [0, 1, 0], [0, 0, 1]]))


def test_a_profile_turned_about_z_keeps_its_heights():
    records = np.array(np.arange(5.0), dtype=[("CZ", "<f8")])
    axes = {"CX": ("I", "D", 1e-6, 0.0), "CY": ("I", "D", 1e-6, 0.0), "CZ": ("A", "D", 1.0, 0.0)}
    surface = read_bytes(x3p(records, axes, feature="PRF", size=(5, 1, 1), rotation=turn(30)))
    assert surface.heights.tolist() == [0, 1, 2, 3, 4]
    assert surface.metadata["x3p_rotation"].startswith("30° about z, not applied")


def absolute_profile(x):
    records = np.zeros(len(x), dtype=[("CX", "<f8"), ("CZ", "<f8")])
    records["CX"], records["CZ"] = x, 2 * np.asarray(x)
    axes = {"CX": ("A", "D", 1.0, 1e-3), "CY": ("I", "D", 1.0, 0.0), "CZ": ("A", "D", 1.0, 0.0)}
    return x3p(records, axes, feature="PRF", size=(len(x), 1, 1))


def test_an_absolute_profile_on_a_regular_grid_is_read_as_it_is():
    surface = read_bytes(absolute_profile(np.arange(6) * 1e-6))
    assert surface.spacing == pytest.approx((1e-6,)) and surface.origin == pytest.approx((1e-3,))
    assert surface.history == []


def test_an_uneven_absolute_profile_goes_through_the_shared_regrid():
    blob = absolute_profile(np.array([0, 1, 3, 4, 6]) * 1e-6)
    with pytest.raises(FormatError, match="x values are not evenly spaced .*give --regrid SPACING"):
        read_bytes(blob)
    surface = read_bytes(blob, ReadOptions(regrid=(1e-6, "linear")))
    np.testing.assert_allclose(surface.heights, 2e-6 * np.arange(7), atol=1e-18)
    assert surface.origin == pytest.approx((1e-3,)) and surface.history[-1]["command"] == "regrid"


def smooth(x, y):
    return 1e-6 * np.sin(x / 20e-6) * np.cos(y / 30e-6)


def test_a_point_cloud_of_a_smooth_surface_is_gridded_to_within_interpolation_error():
    points = np.random.default_rng(7).uniform(0, 200e-6, size=(4000, 2))
    records = np.zeros(len(points), dtype=[("CX", "<f4"), ("CY", "<f4"), ("CZ", "<f8")])
    records["CX"], records["CY"] = points.T
    records["CZ"] = smooth(records["CX"].astype(float), records["CY"].astype(float))
    axes = {"CX": ("A", "F", 1.0, 0.0), "CY": ("A", "F", 1.0, 0.0), "CZ": ("A", "D", 1.0, 0.0)}
    blob = x3p(records, axes, feature="PCL")
    with pytest.raises(FormatError, match="point cloud of 4000 points: give --regrid SPACING"):
        read_bytes(blob)
    surface = read_bytes(blob, ReadOptions(regrid=(4e-6, "bandlimited")))  # maps are gridded linearly
    x = surface.origin[0] + surface.spacing[0] * np.arange(surface.points[0])
    y = surface.origin[1] + surface.spacing[1] * np.arange(surface.points[1])
    error = surface.heights - smooth(x[np.newaxis, :], y[:, np.newaxis])
    inside = np.isfinite(surface.heights)
    assert inside.mean() > 0.9 and not inside[0].all()  # NaN outside the convex hull only
    assert np.median(np.abs(error[inside])) < 0.003e-6  # 0.3 % of the amplitude
    assert np.abs(error[5:-5, 5:-5][inside[5:-5, 5:-5]]).max() < 0.03e-6  # long thin triangles lie at the hull
    assert surface.history[-1]["parameters"] == {"spacing": 4e-6, "method": "linear", "points_read": 4000}


def test_gridding_refuses_a_spacing_that_leaves_one_point_or_too_many():
    records = np.zeros(3, dtype=[("CX", "<f8"), ("CY", "<f8"), ("CZ", "<f8")])
    records["CX"], records["CY"] = [0, 1e-6, 0], [0, 0, 1e-6]
    blob = x3p(records, {name: ("A", "D", 1.0, 0.0) for name in ("CX", "CY", "CZ")}, feature="PCL")
    with pytest.raises(FormatError, match="fewer than two points"):
        read_bytes(blob, ReadOptions(regrid=(1e-3, "linear")))
    with pytest.raises(InputError, match="more than rough's limit"):
        read_bytes(blob, ReadOptions(regrid=(1e-12, "linear")))


# -- damaged files -----------------------------------------------------------------------------


@needs_shared
@pytest.mark.parametrize("sample", ["profile_layers_binary", "surface_irregular_xml", "point_cloud_int16_binary"])
def test_truncated_and_flipped_sample_files_fail_with_one_line(sample):
    blob = (X3PIO / f"iso25178-72-fdam1/{sample}.x3p").read_bytes()
    rng = np.random.default_rng(3)
    damaged = [blob[:cut] for cut in (10, 100, len(blob) // 3, len(blob) // 2, len(blob) - 30)]
    for offset in rng.integers(0, min(len(blob), 2000), size=12):
        flipped = bytearray(blob)
        flipped[offset] ^= 0xFF
        damaged.append(bytes(flipped))
    for data in damaged:
        for options in (ReadOptions(), ReadOptions(regrid=(2e-6, "linear"), verify=False, layer=1)):
            try:
                read_bytes(data, options)
            except InputError as error:
                assert "\n" not in str(error)
