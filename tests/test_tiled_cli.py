"""The commands that take a map larger than memory (``--memory``): ``info`` reads it a
strip at a time and gives the facts of the whole read; a bad budget is one line."""

import json

import numpy as np
import pytest

import rough

from conftest import assert_one_line_error


@pytest.fixture
def holed(tmp_path):
    surface = rough.synthesize_map((300, 200), (1e-3, 1e-3), dimension=2.3, rq=1e-3, seed=3)
    heights = np.round(surface.heights, 6)  # ties
    heights[40:60, 100:180] = np.nan
    path = tmp_path / "holed.npy"
    np.save(path, heights)
    return path


def test_info_of_a_tiled_map_is_that_of_the_whole_map(holed, run):
    whole, tiled = (
        json.loads(run("info", "--json", "--spacing", "1mm", *memory, holed, check=True).stdout)
        for memory in ((), ("--memory", "64KB"))
    )
    assert tiled.pop("tiled") is True and "tiled" not in whole
    for key in ("valid_points", "z_min", "z_max", "shape", "spacing", "size", "points"):
        assert tiled[key] == whole[key], key
    assert tiled["Sq"] == pytest.approx(whole["Sq"], rel=1e-12)
    assert tiled["z_mean"] == pytest.approx(whole["z_mean"], rel=1e-12, abs=1e-18)


def test_a_memory_budget_that_is_not_a_size_is_one_line(holed, run):
    assert_one_line_error(run("info", "--memory", "lots", "--spacing", "1mm", holed), "--memory", "not a size")


def test_a_crop_of_a_tiled_map_is_recorded_and_read_alone(holed):
    options = {"spacing": 1e-3, "crop": ((10e-3, 50e-3), (5e-3, 30e-3))}
    whole = rough.io.read(holed, **options)
    tiled = rough.io.open_surface(holed, memory=1 << 16, **options)
    assert isinstance(tiled, rough.io.TiledSurface)
    np.testing.assert_array_equal(tiled.read(), whole.heights)
    assert tiled.origin == whole.origin
    assert [entry["command"] for entry in tiled.history] == [entry["command"] for entry in whole.history] == ["crop"]


def test_a_spacing_that_overrides_the_file_s_warns_whether_tiled_or_not(tmp_path, run):
    path = tmp_path / "scan.x3p"
    rough.Surface(np.random.default_rng(0).standard_normal((300, 200)) * 1e-6, 1e-6).write(path)
    for memory in ((), ("--memory", "1KB")):
        result = run("info", "--json", "--spacing", "2um,3um", *memory, path, check=True)
        assert "overrides the file's own" in result.stderr.decode(), memory
        assert json.loads(result.stdout)["spacing"] == [2e-6, 3e-6]
