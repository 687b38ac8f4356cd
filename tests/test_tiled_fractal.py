"""fit-fractal on a map read in tiles: the 2-D spectrum by a stated estimator (the tiles'
Welch average plus a block-averaged coarse level) agrees with the in-memory fit within
its standard error; the profiles along x and y are the in-memory ones exactly."""

import dataclasses
import json
import math

import numpy as np
import pytest

import rough
from rough.fractal import tiled, tiled_profiles

from conftest import assert_one_line_error
from conftest import rough as run

MB = 1 << 20


def holed(side, seed, dimension=2.3, spacing=1e-6):
    """A synthesised fractal map with rectangular NaN holes (and its history kept)."""
    scan = rough.synthesize_map((side, side), (spacing, spacing), dimension, rq=1e-6, seed=seed)
    heights = scan.heights.copy()
    rng = np.random.default_rng(seed)
    for row, column in rng.integers(0, side - 12, (24, 2)):
        heights[row : row + 7, column : column + 11] = np.nan
    return dataclasses.replace(scan, heights=heights)


@pytest.fixture(scope="module")
def big():
    """A 4096² map with holes and its in-memory fit (holes filled, as --fill does)."""
    scan = holed(4096, 34)
    return scan, rough.fit_fractal(rough.fractal.fill_invalid(scan))


def assert_agrees(fit, expected):
    """D and C within two of the in-memory fit's standard errors. The two estimators
    weigh the same data differently: the tiles' overlapped Welch average is the more
    efficient (its standard error is 0.6-0.8 of the in-memory one, and honest: over 24
    maps its z-scores have SD 1.02), so their difference has an SD of about 0.7 of the
    in-memory standard error, and two of them bound it at ~1 in 200."""
    assert fit.fractal_dimension_stderr < expected.fractal_dimension_stderr
    assert abs(fit.fractal_dimension - expected.fractal_dimension) < 2 * expected.fractal_dimension_stderr
    assert abs(fit.amplitude_coefficient - expected.amplitude_coefficient) < 2 * expected.amplitude_coefficient_stderr
    assert fit.verdict == expected.verdict == "power law"


def test_the_tiled_fit_of_a_4096_map_agrees_with_the_in_memory_fit(big):
    scan, expected = big
    fit = rough.fractal.fit_fractal_tiles(rough.io.TiledSurface.of(scan), fill=True, budget=64 * MB)
    assert_agrees(fit, expected)
    assert fit.tiled["tiles"] == 64 and fit.tiled["coarse_factor"] == 5 and fit.tiled["skipped"] == 0
    assert "Welch average of 64 tiles of 900 × 900" in fit.method and "coarse level ×5" in fit.method
    assert fit.band[0] == pytest.approx(expected.band[0], rel=0.05)  # the band starts at the whole map's 4th ring
    assert fit.as_dict()["tiled"]["exact"] == [] and "spectrum" in fit.as_dict()["tiled"]["estimated"]


def test_small_tiles_of_a_2048_map_agree_too():
    scan = holed(2048, 3, dimension=2.6)
    expected = rough.fit_fractal(rough.fractal.fill_invalid(scan))
    fit = rough.fractal.fit_fractal_tiles(rough.io.TiledSurface.of(scan), fill=True, budget=80 * 256 * 256)
    assert fit.tiled["tile_shape"] == [256, 256] and fit.tiled["tiles"] == 225 and fit.tiled["coarse_factor"] == 8
    assert_agrees(fit, expected)


def test_invalid_points_need_fill_and_a_flat_map_is_refused():
    scan = holed(256, 5)
    with pytest.raises(rough.InputError, match="gap-free"):
        rough.fractal.fit_fractal_tiles(rough.io.TiledSurface.of(scan), budget=80 * 64 * 64)
    plane = rough.Surface(np.add.outer(np.arange(256.0), np.arange(256.0)) * 1e-9, 1e-6)
    with pytest.raises(rough.InputError, match="flat"):
        rough.fractal.fit_fractal_tiles(rough.io.TiledSurface.of(plane), budget=80 * 64 * 64)


def test_the_coarse_level_is_the_block_mean_and_its_transfer_is_the_dirichlet_kernel():
    heights = np.arange(70.0 * 50).reshape(70, 50)
    heights[3, 4] = np.nan
    plan = tiled.Tiling((70, 50), (1.0, 1.0), (70, 50), (1, 1), 3)
    row, column, sums, counts = tiled._block_sums(heights, (0, 0), plan)
    means = sums / counts
    assert (row, column, means.shape) == (0, 0, (23, 16))
    np.testing.assert_allclose(means[5, 7], heights[15:18, 21:24].mean())
    assert means[1, 1] == pytest.approx(np.nanmean(heights[3:6, 3:6]))
    # H(f) = sin(πfkΔ)/(k sin(πfΔ)): 1 at f = 0, 2/π-ish at the coarse Nyquist frequency, the mean of k phasors
    f = np.array([0.0, 0.01, 1 / 6])
    expected = [abs(np.mean(np.exp(2j * np.pi * value * np.arange(3)))) for value in f]
    np.testing.assert_allclose(tiled._transfer(f, 1.0, 3), expected, rtol=1e-12)


@pytest.mark.parametrize("direction", ["x", "y"])
def test_the_profiles_of_a_tiled_map_are_the_in_memory_ones(direction):
    scan = holed(512, 8)
    scan.heights[5, :-40] = np.nan  # a row, and columns, that keep too few points in a row
    expected = rough.fractal.fit_profiles(scan, direction).as_dict()
    fit = tiled_profiles.fit_profiles_tiles(rough.io.TiledSurface.of(scan), direction, budget=80 * 512 * 130)
    values = fit.as_dict()
    assert fit.tiled["strips"] == 4 and fit.tiled["estimated"] == {}
    for key, value in expected.items():
        if isinstance(value, float) and math.isfinite(value):
            assert values[key] == pytest.approx(value, rel=TOLERANCE.get(key, 1e-6), abs=1e-12), key
        else:
            assert values[key] == value, key


#: The pooled sums are the in-memory ones up to the order of summation (1e-15); where the
#: fits' optimiser (L-BFGS-B) stops carries that to 1e-7 at most in an estimate, and the
#: jackknife, which divides the replicates' small differences, to 1e-5 in the standard
#: errors and the design effect.
TOLERANCE = dict.fromkeys(
    ["fractal_dimension_stderr", "hurst_stderr", "amplitude_coefficient_stderr", "design_effect"], 1e-4
)


def test_the_strip_height_does_not_change_the_profiles_fit():
    scan = holed(512, 9)
    surface = rough.io.TiledSurface.of(scan)
    fits = [tiled_profiles.fit_profiles_tiles(surface, "y", "fill", budget=80 * 512 * rows) for rows in (200, 512)]
    assert fits[0].tiled["strips"] == 3 and fits[1].tiled["strips"] == 1
    first, second = (fit.as_dict() for fit in fits)
    for key in ("hurst", "hurst_stderr", "amplitude_coefficient", "hurst_spread", "design_effect"):
        assert first[key] == pytest.approx(second[key], rel=TOLERANCE.get(key, 1e-6)), key
    assert first["band"] == pytest.approx(second["band"], rel=1e-12)


@pytest.fixture(scope="module")
def geotiff(tmp_path_factory):
    rasterio = pytest.importorskip("rasterio")
    scan = holed(1024, 11, spacing=1.0)
    path = tmp_path_factory.mktemp("tiled") / "dem.tif"
    profile = dict(driver="GTiff", width=1024, height=1024, count=1, dtype="float64", crs="EPSG:32610")
    profile.update(transform=rasterio.transform.from_origin(500000.0, 4300000.0, 1.0, 1.0), nodata=np.nan)
    with rasterio.open(path, "w", tiled=True, blockxsize=256, blockysize=256, compress="deflate", **profile) as out:
        out.write(scan.heights, 1)
    return path


def test_the_command_reads_a_large_geotiff_in_tiles(geotiff, tmp_path):
    whole = json.loads(run("fit-fractal", "--json", "--fill", geotiff, check=True).stdout)
    spectrum = tmp_path / "psd.tsv"
    tiles = run("fit-fractal", "--json", "--memory", "64MB", "--fill", "--psd", spectrum, geotiff, check=True)
    assert spectrum.read_text().startswith("# rough fit-fractal: log-binned spectrum (ring-averaged P2, tiles'")
    values = json.loads(tiles.stdout)
    assert values["tiled"]["tiles"] == 4 and values["tiled"]["coarse_factor"] == 2 and "tiled" not in whole
    assert abs(values["fractal_dimension"] - whole["fractal_dimension"]) < whole["fractal_dimension_stderr"]
    text = run("fit-fractal", "--memory", "8MB", "--fill", geotiff, check=True).stdout.decode()
    assert [line for line in text.splitlines() if line.startswith("tiled ")][0].count("Welch average of 36") == 1
    rows = json.loads(run("fit-fractal", "--json", "--memory", "8MB", "--profiles", "x", geotiff, check=True).stdout)
    memory = json.loads(run("fit-fractal", "--json", "--profiles", "x", geotiff, check=True).stdout)
    assert rows["hurst"] == pytest.approx(memory["hurst"], rel=1e-6) and rows["tiled"]["passes"] == 2


@pytest.mark.parametrize(
    "options, named",
    [
        (["--tip-radius", "2um"], "--tip-radius"),
        ([], "gap-free"),
        (["--profiles", "x", "--estimator", "dfa"], "--estimator"),
        (["--profiles", "x", "--fill"], "--fill with --profiles"),
        (["--profiles", "30", "--gaps", "fill"], "along x or y"),
    ],
)
def test_what_tiles_cannot_do_is_one_line_and_status_2(geotiff, options, named):
    assert_one_line_error(run("fit-fractal", "--memory", "8MB", *options, geotiff), named)
