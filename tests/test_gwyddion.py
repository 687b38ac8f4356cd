"""A third party reads rough's files: Gwyddion 2.62 (Debian package ``gwyddion``,
headless) identifies them and converts them to .gwy, which the gwyfile package reads
back. .ci/run installs Gwyddion; elsewhere these tests skip."""

import shutil
import subprocess

import numpy as np
import pytest

from rough import Surface

gwyfile = pytest.importorskip("gwyfile")
pytestmark = pytest.mark.skipif(
    shutil.which("gwyddion") is None, reason="Gwyddion is not installed (apt-get install gwyddion)"
)

IDENTIFIED = {"x3p": "ISO 5436-2 OpenGPS data (.x3p)", "gsf": "Gwyddion Simple Field (.gsf)"}


def gwyddion(*args):
    return subprocess.run(["gwyddion", *map(str, args)], check=False, capture_output=True, text=True, timeout=120)


def converted(path, tmp_path):
    target = tmp_path / f"{path.stem}-{path.suffix[1:]}.gwy"
    result = gwyddion(f"--convert-to-gwy={target}", path)
    assert target.exists(), result.stderr
    return gwyfile.load(str(target))


@pytest.fixture
def rock_map():
    heights = np.cumsum(np.random.default_rng(7).normal(size=(40, 64)), axis=1) * 1e-7
    heights[5, 9] = np.nan
    return Surface(heights, (1.5e-6, 2.5e-6), (1e-5, -2e-5))


@pytest.mark.parametrize("fmt", ["x3p", "gsf"])
def test_gwyddion_identifies_rough_files(rock_map, tmp_path, fmt):
    path = tmp_path / f"map.{fmt}"
    rock_map.write(path)
    assert IDENTIFIED[fmt] in gwyddion("--identify", path).stdout


@pytest.mark.parametrize("fmt,rtol", [("x3p", 0.0), ("gsf", 1e-6)])
def test_gwyddion_reads_heights_and_size_of_a_map(rock_map, tmp_path, fmt, rtol):
    path = tmp_path / f"map.{fmt}"
    rock_map.write(path)
    field = converted(path, tmp_path)["/0/data"]
    assert field.data.shape == rock_map.heights.shape
    valid = ~np.isnan(rock_map.heights)
    np.testing.assert_allclose(field.data[valid], rock_map.heights[valid], rtol=rtol, atol=0)
    np.testing.assert_allclose([field.xreal, field.yreal], rock_map.size, rtol=1e-12)


def test_gwyddion_reads_a_profile_from_x3p_as_a_graph(tmp_path):
    profile = Surface(np.sin(np.arange(300) / 7.0) * 1e-6, (2e-6,))
    profile.write(tmp_path / "profile.x3p")
    curve = converted(tmp_path / "profile.x3p", tmp_path)["/0/graph/graph/0"]["curves"][0]
    np.testing.assert_array_equal(curve["ydata"], profile.heights)
    np.testing.assert_allclose(curve["xdata"], np.arange(300) * 2e-6, rtol=1e-12)


def test_gwyddion_reads_a_profile_from_gsf_as_one_row(tmp_path):
    profile = Surface(np.sin(np.arange(300) / 7.0) * 1e-6, (2e-6,))
    profile.write(tmp_path / "profile.gsf")
    field = converted(tmp_path / "profile.gsf", tmp_path)["/0/data"]
    np.testing.assert_allclose(field.data[0], profile.heights, rtol=1e-6)
    assert field.xreal == pytest.approx(300 * 2e-6, rel=1e-12)


def test_gwyddion_reads_al3d_as_rough_does(shared_data, tmp_path):
    """A real Alicona file, read by Gwyddion's own AL3D module and by rough."""
    from rough import read

    path = shared_data / "SurfaceTopography/al3d-1.al3d"
    field = converted(path, tmp_path)["/0/data"]
    surface = read(path)
    np.testing.assert_array_equal(field.data, surface.heights)
    assert (field["xreal"], field["yreal"]) == pytest.approx(surface.size, rel=1e-12)
