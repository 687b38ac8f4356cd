"""A 32 768 × 32 768 elevation model (4 GiB of float32 heights, tiled and compressed):
``features``, ``fit-fractal`` and ``map`` read it in tiles within 1.5 GB of memory.

The model is a periodic 4096² fractal map laid 8 × 8 times, so the whole model's
height statistics are those of the one map: its moments, extremes and material ratio
are known exactly from the map in memory, and so is the spectrum it is fitted on.
The three commands run at once, each measured on its own. Marked slow (about four
minutes here); ``make test`` and ``.ci/run`` run it.
"""

import json
import subprocess
import sys

import numpy as np
import pytest

import rough

rasterio = pytest.importorskip("rasterio")
pytestmark = pytest.mark.slow

SIDE = 32768
BASE = 4096
STEP = 1.0  # metres: a 1 m LiDAR DEM, 32.8 km square
CRS = "EPSG:32610"
PEAK = 1.5e9  # bytes of resident memory a command may reach


@pytest.fixture(scope="module")
def dem(tmp_path_factory):
    """(path, the 4096² map it repeats, in metres as float32 → float64)."""
    base = rough.synthesize_map((BASE, BASE), (STEP, STEP), dimension=2.25, rq=2.0, seed=34)
    tile = base.heights.astype(np.float32)
    path = tmp_path_factory.mktemp("dem") / "dem.tif"
    transform = rasterio.transform.from_origin(500000.0, 4300000.0, STEP, STEP)
    profile = dict(
        driver="GTiff",
        width=SIDE,
        height=SIDE,
        count=1,
        dtype="float32",
        crs=CRS,
        transform=transform,
        tiled=True,
        blockxsize=512,
        blockysize=512,
        compress="deflate",
        predictor=3,
        zlevel=1,
        BIGTIFF="YES",
    )
    band = 512
    with rasterio.open(path, "w", **profile) as dataset:
        for row in range(0, SIDE, band):
            rows = np.tile(tile[row % BASE : row % BASE + band], (1, SIDE // BASE))
            dataset.write(rows, 1, window=rasterio.windows.Window(0, row, SIDE, band))
    return path, rough.Surface(tile.astype(np.float64), (STEP, STEP))


#: Runs rough as its child and prints the peak resident memory of its process tree (kB) last on stderr.
MEASURED = (
    "import resource, subprocess, sys\n"
    "status = subprocess.run([sys.executable, '-m', 'rough', *sys.argv[1:]]).returncode\n"
    "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, file=sys.stderr)\n"
    "sys.exit(status)\n"
)


@pytest.fixture(scope="module")
def runs(dem, tmp_path_factory):
    """The three commands, run at once (each measured on its own): {name: (stdout, path written)}."""
    path, _ = dem
    written = tmp_path_factory.mktemp("map") / "sq.tif"
    commands = {
        "features": ("features", "--json", path),
        "fit-fractal": ("fit-fractal", "--json", path),
        "map": ("map", path, "--window", "1024px", "--parameters", "Sq,Ssk", "-o", written),
    }
    folder = written.parent
    started = {}
    for name, args in commands.items():
        with open(folder / f"{name}.out", "wb") as stdout, open(folder / f"{name}.err", "wb") as stderr:
            command = [sys.executable, "-c", MEASURED, *map(str, args)]
            started[name] = subprocess.Popen(command, stdout=stdout, stderr=stderr)
    for process in started.values():
        process.wait(timeout=1800)
    return {name: (within_memory(process, folder / name), written) for name, process in started.items()}


def within_memory(process, stem):
    """The standard output of a measured rough, which must have succeeded below :data:`PEAK`."""
    *lines, resident = stem.with_suffix(".err").read_text().strip().splitlines()
    assert process.returncode == 0, "\n".join(lines)
    assert int(resident) * 1024 < PEAK, f"peak RSS {int(resident) * 1024 / 1e9:.2f} GB"
    return stem.with_suffix(".out").read_bytes()


def test_features_of_the_whole_model_are_the_repeated_map_s(dem, runs):
    _, base = dem
    values = json.loads(runs["features"][0])
    expected = rough.metrology.parameters(base)
    for name in ("Sa", "Sq", "Ssk", "Sku"):
        assert values[name] == pytest.approx(expected[name], rel=1e-9), name
    for name in ("Sp", "Sv", "Sz"):
        assert values[name] == expected[name], name
    functional = rough.metrology.functional_parameters(base)
    for name in ("Smc", "Sdc"):
        assert values[name] == pytest.approx(functional[name], rel=1e-6), name
    assert values["tiled"]


def test_fit_fractal_of_the_whole_model_is_the_map_s(dem, runs):
    _, base = dem
    values = json.loads(runs["fit-fractal"][0])
    expected = rough.fit_fractal(base)
    error = expected.fractal_dimension_stderr  # the tiled one is smaller: tests/test_tiled_fractal.py
    found = values["fractal_dimension"]
    assert abs(found - expected.fractal_dimension) < 2 * error, (found, expected.fractal_dimension, error)
    assert values["tiled"]


def test_a_roughness_map_of_the_whole_model_keeps_its_georeference(dem, runs):
    path, _ = dem
    output = runs["map"][1]
    with rasterio.open(path) as source, rasterio.open(output) as result:
        assert result.crs == source.crs
        assert result.transform == source.transform @ rasterio.Affine.scale(1024)
        assert result.descriptions == ("Sq", "Ssk")
        sq = result.read(1)
    assert sq.shape == (SIDE // 1024, SIDE // 1024)
    assert np.isfinite(sq).all()
    period = BASE // 1024  # the model repeats every 4096 points: so do its windows
    np.testing.assert_array_equal(sq[:period, :period], sq[period : 2 * period, -period:])
