"""Roughness maps (issue 34, item 2): parameters per window, oriented as the input, written as a GeoTIFF
whose bands lie over the input's coordinates."""

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rough
from rough.metrology import areal_parameters, remove_form, roughness_map

from conftest import assert_one_line_error

SIGMAS = np.array([[1.0, 2.0], [3.0, 4.0]]) * 1e-6  # rows 0-31 (first rows, smallest y): 1 and 2 µm


def quadrants(seed=0):
    """64 rows × 128 columns of white noise, RMS by quadrant as SIGMAS, on a tilted plane."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:64, 0:128]
    sigma = np.kron(SIGMAS, np.ones((32, 64)))
    return rng.standard_normal((64, 128)) * sigma + 3e-5 * x / 128 - 2e-5 * y / 64 + 1e-3


def test_quadrants_give_their_sq_in_the_right_cells():
    result = roughness_map(rough.Surface(quadrants(), 10e-6), window=32, parameters=["Sq", "Sa"])
    expected = np.kron(SIGMAS, np.ones((1, 2)))  # 2 rows × 4 columns of windows
    assert result.values["Sq"].shape == (2, 4)
    np.testing.assert_allclose(result.values["Sq"], expected, rtol=0.1)
    np.testing.assert_allclose(result.values["Sa"], expected * math.sqrt(2 / math.pi), rtol=0.1)
    assert result.origin == pytest.approx((155e-6, 155e-6))  # the centre of points 0 … 31
    assert result.spacing == pytest.approx((320e-6, 320e-6))
    assert result.units == {"Sq": "m", "Sa": "m"}


def test_a_window_given_as_a_length_and_overlapping_steps():
    surface = rough.Surface(quadrants(), 10e-6, origin=(1.0, 2.0))
    by_length = roughness_map(surface, window=320e-6, step=160e-6)
    by_points = roughness_map(surface, window=32, step=16)
    np.testing.assert_array_equal(by_length.values["Sq"], by_points.values["Sq"])
    assert by_points.values["Sq"].shape == (3, 7)
    assert by_points.origin == pytest.approx((1.0 + 155e-6, 2.0 + 155e-6))
    assert by_points.spacing == pytest.approx((160e-6, 160e-6))
    # the window straddling the quadrants' rows at (row 1, column 0): half 1 µm, half 3 µm
    assert by_points.values["Sq"][1, 0] == pytest.approx(math.sqrt((1 + 9) / 2) * 1e-6, rel=0.1)


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    shape=st.tuples(st.integers(20, 40), st.integers(20, 40)),
    window=st.integers(16, 20),
    step=st.integers(3, 20),
    holes=st.sampled_from([0.0, 0.1, 0.4]),
    order=st.integers(0, 2),
)
def test_vectorised_moments_equal_each_windows_areal_parameters(seed, shape, window, step, holes, order):
    rng = np.random.default_rng(seed)
    heights = rng.standard_normal(shape) * 1e-6 + 2e-6 * np.arange(shape[1]) / shape[1]
    heights[rng.random(shape) < holes] = np.nan
    surface = rough.Surface(heights, (2e-6, 3e-6))
    names = ["Sa", "Sq", "Ssk", "Sku", "Sp", "Sv", "Sz", "Sdq", "Std"]
    result = roughness_map(surface, window, step=step, parameters=names, order=order)
    rows, columns = result.values["Sq"].shape
    assert (rows, columns) == ((shape[0] - window) // step + 1, (shape[1] - window) // step + 1)
    for row in range(rows):
        for column in range(columns):
            part = heights[row * step : row * step + window, column * step : column * step + window]
            got = {name: result.values[name][row, column] for name in names}
            if 2 * np.count_nonzero(~np.isnan(part)) < part.size:
                assert all(math.isnan(value) for value in got.values())
                continue
            expected = areal_parameters(remove_form(rough.Surface(part, (2e-6, 3e-6)), order))
            for name in names:
                scale = {"m": expected["Sq"], "1": 1.0, "deg": 1.0}[result.units[name]]
                assert got[name] == pytest.approx(expected[name], rel=1e-12, abs=1e-12 * scale, nan_ok=True), name


def test_too_few_valid_points_give_nan_with_the_reason():
    heights = quadrants()
    heights[:32, :40] = np.nan  # window (0, 0): 24 of 64 columns valid; window (0, 1): all valid
    result = roughness_map(rough.Surface(heights, 10e-6), window=32, parameters=["Sq", "hurst"])
    assert math.isnan(result.values["Sq"][0, 0]) and not math.isnan(result.values["Sq"][0, 1])
    assert result.reasons["Sq"] == {"fewer than half the window's points are valid": 1}
    assert result.reasons["hurst"]["fewer than half the window's points are valid"] == 1


def test_the_fractal_fit_needs_windows_without_holes():
    heights = quadrants()
    heights[5, 70] = np.nan
    result = roughness_map(rough.Surface(heights, 10e-6), window=32, parameters=["Sq", "dimension"])
    assert not np.isnan(result.values["Sq"]).any()
    assert np.isnan(result.values["dimension"][0, 2])
    assert result.reasons["dimension"]["the fractal fit needs a window without invalid points"] == 1


@pytest.mark.parametrize("dimension", [2.2, 2.5])
def test_hurst_of_synthetic_fbm_maps(tmp_path, run, dimension):
    path = tmp_path / "fbm.x3p"
    made = run("synth", "--size", "512x512", "--step", "10um", "--dimension", dimension, "--amplitude", "1um")
    path.write_bytes(made.stdout)
    args = ("map", path, "--window", "256px", "--parameters", "hurst,dimension", "--json")
    document = json.loads(run(*args, check=True).stdout)
    hurst, dimension_found = document["parameters"]["hurst"], document["parameters"]["dimension"]
    assert hurst["undefined"] == 0
    assert 3 - dimension - 0.1 < hurst["min"] <= hurst["max"] < 3 - dimension + 0.1
    assert hurst["median"] == pytest.approx(3 - dimension, abs=0.05)
    assert dimension_found["median"] == pytest.approx(dimension, abs=0.05)


def test_geotiff_keeps_the_crs_and_puts_each_value_at_its_window_centre(tmp_path, run):
    rasterio = pytest.importorskip("rasterio")
    rng = np.random.default_rng(7)
    heights = rng.standard_normal((100, 90)) * np.linspace(1, 5, 100)[:, None]  # rougher to the north
    source = rough.Surface(heights, (0.5, 0.5), origin=(500123.25, 5100456.75), metadata={"crs": "EPSG:32633"})
    rough.write(source, tmp_path / "dem.tif")
    out = tmp_path / "map.tif"
    run(
        "map",
        tmp_path / "dem.tif",
        "--window",
        "32px",
        "--step",
        "16px",
        "--parameters",
        "Sq,Ssk",
        "-o",
        out,
        check=True,
    )
    expected = roughness_map(rough.read(tmp_path / "dem.tif"), 32, step=16, parameters=["Sq", "Ssk"])
    with rasterio.open(tmp_path / "dem.tif") as dem, rasterio.open(out) as result:
        assert result.crs == dem.crs == rasterio.crs.CRS.from_epsg(32633)
        assert result.descriptions == ("Sq", "Ssk")
        assert result.tags(1)["UNIT"] == "m" and result.tags(2)["UNIT"] == "1"
        assert result.dtypes == ("float32", "float32")
        assert (result.height, result.width) == (5, 4)  # (100 - 32) // 16 + 1 rows, (90 - 32) // 16 + 1 columns
        bands = result.read()
        for row in range(result.height):
            for column in range(result.width):
                x, y = result.transform @ (column + 0.5, row + 0.5)
                # the window: rough rows j0 … j0 + 31 (row 0 south), raster rows of the DEM counted from the north
                j0 = (result.height - 1 - row) * 16
                centre = dem.transform @ (column * 16 + 16, dem.height - j0 - 16)
                assert (x, y) == pytest.approx(centre, abs=1e-6)
                assert bands[0, row, column] == np.float32(expected.values["Sq"][result.height - 1 - row, column])
        assert bands[0, 0].mean() > bands[0, -1].mean()  # the north row (raster row 0) is the rough one


def test_geotiff_read_back_is_the_map_in_rough_orientation(tmp_path):
    pytest.importorskip("rasterio")
    result = roughness_map(rough.Surface(quadrants(), 10e-6, origin=(3.0, 4.0)), window=32, parameters=["Sq"])
    result.write(tmp_path / "sq.tif")
    again = rough.read(tmp_path / "sq.tif")
    np.testing.assert_array_equal(again.heights, result.values["Sq"].astype(np.float32))
    assert again.origin == pytest.approx(result.origin) and again.spacing == pytest.approx(result.spacing)


def test_one_parameter_as_x3p(tmp_path, run):
    source = tmp_path / "q.npy"
    np.save(source, quadrants())
    out = tmp_path / "sq.x3p"
    run("map", source, "--spacing", "10um", "--window", "32px", "-o", out, check=True)
    again = rough.read(out)
    expected = roughness_map(rough.Surface(quadrants(), 10e-6), window=32)
    np.testing.assert_array_equal(again.heights, expected.values["Sq"])
    assert again.spacing == pytest.approx((320e-6, 320e-6))


def test_summary_without_output(tmp_path, run):
    source = tmp_path / "q.npy"
    np.save(source, quadrants())
    document = json.loads(run("map", source, "--spacing", "10um", "--window", "32px", "--json", check=True).stdout)
    sq = document["parameters"]["Sq"]
    assert sq["unit"] == "m" and sq["min"] == pytest.approx(1e-6, rel=0.1) and sq["max"] == pytest.approx(4e-6, rel=0.1)
    assert document["grid"]["shape"] == [4, 2]


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (("--window", "128px"), "larger than the map"),
        (("--window", "8px"), "at least 16"),
        (("--window", "32px", "--parameters", "Sq,Sfoo"), "known: Sa, Sq"),
        (("--window", "32px", "-o", "{out}.png"), "cannot write a surface as .png"),
        (("--window", "32px", "--parameters", "Sq,Ssk", "-o", "{out}.x3p"), "only GeoTIFF"),
        (("--window", "32"), "256px"),
    ],
)
def test_bad_input_is_one_line_and_status_2(tmp_path, run, args, fragment):
    source = tmp_path / "q.npy"
    np.save(source, quadrants()[:, :100])
    args = [arg.format(out=tmp_path / "out") for arg in args]
    assert_one_line_error(run("map", source, "--spacing", "10um", *args), fragment)
    assert sorted(path.name for path in tmp_path.iterdir()) == ["q.npy"]


def test_a_profile_is_refused(tmp_path, run):
    source = tmp_path / "p.npy"
    np.save(source, np.random.default_rng(0).standard_normal(500) * 1e-6)
    assert_one_line_error(run("map", source, "--spacing", "1um", "--window", "32px"), "not a profile")


# -- a map larger than memory, read a band of windows at a time (issue 34, item 2 on tiles) --


@pytest.mark.parametrize(
    ("window", "step", "parameters"),
    [(32, 32, ["Sq", "Sa", "Ssk", "Sku", "Sz"]), (20, 7, ["Sq", "Sdq", "Str", "lay"]), (32, 24, ["Sq", "hurst"])],
)
def test_tiled_and_parallel_maps_equal_the_map_in_memory_bit_for_bit(window, step, parameters):
    heights = quadrants(3)
    heights[5:40, 10:30] = np.nan  # windows with too few points, and holes the fractal fit refuses
    heights[50, 100] = np.nan
    surface = rough.Surface(heights, 10e-6, origin=(2.0, -1.0), metadata={"crs": "EPSG:32633"})
    whole = roughness_map(surface, window, step=step, parameters=parameters)
    assert whole.tiled is None
    for kind, result in [
        ("tiled", roughness_map(rough.io.TiledSurface.of(surface), window, step=step, parameters=parameters)),
        ("tiled, small bands", roughness_map(rough.io.TiledSurface.of(surface), window, step, parameters, budget=1)),
        ("two jobs", roughness_map(surface, window, step=step, parameters=parameters, jobs=2)),
        ("tiled, two jobs", roughness_map(rough.io.TiledSurface.of(surface), window, step, parameters, jobs=2)),
    ]:
        for name in parameters:
            assert result.values[name].tobytes() == whole.values[name].tobytes(), (kind, name)
        assert result.reasons == whole.reasons and list(result.reasons) == list(whole.reasons), kind
        assert (result.origin, result.spacing, result.metadata) == (whole.origin, whole.spacing, whole.metadata)
        assert (result.tiled is not None) == kind.startswith("tiled"), kind
    tiled = roughness_map(rough.io.TiledSurface.of(surface), window, step=step, parameters=parameters)
    assert tiled.tiled["exact"] == parameters and tiled.tiled["estimated"] == {}
    assert tiled.as_dict()["tiled"] == tiled.tiled and "tiled" not in whole.as_dict()


@pytest.fixture(scope="module")
def large_dem(tmp_path_factory):
    """A 2048² GeoTIFF in a projected CRS, in 256-point blocks, deflated."""
    rasterio = pytest.importorskip("rasterio")
    path = tmp_path_factory.mktemp("large") / "dem.tif"
    rng = np.random.default_rng(11)
    heights = (rng.standard_normal((2048, 2048)).cumsum(axis=1) * 0.01).astype(np.float32)
    heights[300:340, 500:900] = np.nan
    profile = {
        "driver": "GTiff",
        "width": 2048,
        "height": 2048,
        "count": 1,
        "dtype": "float32",
        "crs": "EPSG:32633",
        "transform": rasterio.Affine(2.0, 0.0, 500000.0, 0.0, -2.0, 5102048.0),
        "nodata": float("nan"),
        "tiled": True,
        "blockxsize": 256,
        "blockysize": 256,
        "compress": "deflate",
    }
    with rasterio.open(path, "w", **profile) as dataset:
        dataset.write(heights, 1)
    return path


def test_rough_map_of_a_dem_too_large_for_memory_is_the_same_geotiff(large_dem, tmp_path, run):
    rasterio = pytest.importorskip("rasterio")
    common = ["map", large_dem, "--window", "64px", "--step", "48px", "--parameters", "Sq,Ssk"]
    run(*common, "-o", tmp_path / "whole.tif", check=True)
    tiled = run("-v", *common, "--memory", "64MB", "-o", tmp_path / "tiled.tif", check=True)
    assert b"read in tiles" in tiled.stderr  # 2048² × 80 bytes: over 64 MB
    run(*common, "--memory", "64MB", "--jobs", "2", "-o", tmp_path / "jobs.tif", check=True)
    whole = (tmp_path / "whole.tif").read_bytes()
    assert (tmp_path / "tiled.tif").read_bytes() == whole == (tmp_path / "jobs.tif").read_bytes()
    with rasterio.open(large_dem) as dem, rasterio.open(tmp_path / "tiled.tif") as result:
        assert result.crs == dem.crs
        assert result.descriptions == ("Sq", "Ssk")
        assert (result.width, result.height) == ((2048 - 64) // 48 + 1,) * 2
        # the first window's centre: 31.5 points in from the DEM's west edge's first pixel centre
        assert result.transform.a == 96.0 and result.transform.c == pytest.approx(500000.0 + 32 * 2.0 - 48.0)
    summary = run(*common, "--memory", "64MB", check=True).stdout.decode()
    assert "every window computed whole (exact)" in summary


def test_rough_show_draws_a_band_of_the_map(large_dem, tmp_path, run):
    pytest.importorskip("matplotlib")
    out = tmp_path / "map.tif"
    run("map", large_dem, "--window", "256px", "--parameters", "Sq,lay", "--memory", "64MB", "-o", out, check=True)
    run("show", out, "--channel", "lay", "--plot", tmp_path / "lay.png", check=True)
    assert (tmp_path / "lay.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
