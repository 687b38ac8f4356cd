"""rough rose: direction dependence of D and C."""

import json
import math
import re

import numpy as np
import pytest

from rough import Surface, read
from rough.errors import InputError
from rough.fractal.sectors import rose
from rough.fractal.synth_map import synthesize_map

from conftest import assert_one_line_error, rough


def angular_distance(a, b):
    return abs((a - b + 90.0) % 180.0 - 90.0)


@pytest.mark.parametrize("seed", [1, 2])
def test_isotropic_map_gives_a_flat_rose_and_str_near_one(seed):
    surface = synthesize_map((512, 512), (1e-6, 1e-6), 2.4, amplitude=2e-6, seed=seed, rolloff=32e-6)
    result = rose(surface)
    d, d_error = np.array(result.fractal_dimension), np.array(result.fractal_dimension_stderr)
    c, c_error = np.array(result.amplitude_coefficient), np.array(result.amplitude_coefficient_stderr)
    assert np.all(np.abs(d - d.mean()) < 3.5 * d_error)
    assert np.all(np.abs(np.log(c / np.exp(np.log(c).mean()))) < 3.5 * c_error / c)
    assert result.isotropy_p_value["fractal_dimension"] > 0.001
    assert result.isotropy_p_value["amplitude_coefficient"] > 0.001
    assert result.Str > 0.85


@pytest.mark.parametrize("angle", [30.0, 75.0, 160.0])
def test_anisotropic_map_gives_its_principal_directions(angle):
    spec = (2.2, 1e-6, 2.5, 4e-6, math.radians(angle))
    result = rose(synthesize_map((512, 512), (1e-6, 1e-6), None, seed=int(angle), anisotropy=spec))
    expected = (angle + 90.0) % 180.0  # the larger C is along the second direction
    assert angular_distance(result.principal_direction, expected) <= result.step
    for along, (dimension, amplitude) in ((result.principal, spec[2:4]), (result.perpendicular, spec[:2])):
        assert abs(along["dimension"] - dimension) < 3 * along["dimension_error"]
        assert abs(math.log(along["amplitude"] / amplitude)) < 3 * along["amplitude_error"] / along["amplitude"]
    assert result.isotropy_p_value["amplitude_coefficient"] < 1e-6
    assert angular_distance(result.lay["resolution"]["direction"], angle) <= result.step


def test_rotating_the_map_rotates_the_rose():
    spec = (2.25, 1e-6, 2.5, 3e-6, math.radians(20))
    surface = synthesize_map((512, 512), (1e-6, 1e-6), None, seed=3, anisotropy=spec)
    turned = Surface(np.rot90(surface.heights).copy(), surface.spacing, history=surface.history)
    first, second = rose(surface), rose(turned)
    assert angular_distance(second.principal_direction, first.principal_direction + 90.0) <= 2.0
    shifted = np.roll(first.fractal_dimension, 9)
    assert np.all(np.abs(np.array(second.fractal_dimension) - shifted) < 2 * np.array(first.fractal_dimension_stderr))


def test_a_tilted_non_periodic_map_shows_no_false_cross():
    """A window cut from a larger isotropic map has edges that do not meet, and a tilt
    a hundred times its roughness: neither may raise C at 0° or 90°."""
    big = synthesize_map((1024, 1024), (1e-6, 1e-6), 2.4, amplitude=2e-6, seed=8, rolloff=40e-6)
    part = big.heights[100:612, 300:812]
    rows, columns = np.mgrid[0:512, 0:512]
    tilted = part + 100 * part.std() * (columns / 512.0 + 0.5 * rows / 512.0)
    result = rose(Surface(tilted, (1e-6, 1e-6)))
    c = np.log(result.amplitude_coefficient)
    errors = np.array(result.amplitude_coefficient_stderr) / np.array(result.amplitude_coefficient)
    for index in (0, 9):  # 0° and 90°
        neighbours = np.median(np.delete(c, index))
        assert abs(c[index] - neighbours) < 3 * errors[index]
    assert result.isotropy_p_value["amplitude_coefficient"] > 0.001


def test_unequal_spacing_and_non_square_maps_are_handled_exactly():
    surface = synthesize_map((512, 256), (1e-6, 2e-6), 2.4, amplitude=2e-6, seed=4, rolloff=40e-6)
    result = rose(surface, step=15)
    assert result.isotropy_p_value["fractal_dimension"] > 0.001
    assert result.isotropy_p_value["amplitude_coefficient"] > 0.001
    assert np.mean(result.fractal_dimension) == pytest.approx(2.4, abs=0.03)


def test_profiles_and_gaps_are_refused():
    with pytest.raises(InputError, match="a rose needs a map"):
        rose(Surface(np.zeros(100), (1e-6,)))
    heights = synthesize_map((128, 128), (1e-6, 1e-6), 2.4, amplitude=1e-6, seed=1).heights.copy()
    heights[5, 5] = np.nan
    with pytest.raises(InputError, match="--fill"):
        rose(Surface(heights, (1e-6, 1e-6)))


def test_rose_command(tmp_path):
    surface = rough(
        "synth",
        "--size",
        "256x256",
        "--step",
        "10um",
        "--anisotropy",
        "2.2,1um,2.5,3um,30",
        "--seed",
        "5",
        check=True,
    ).stdout
    values = json.loads(rough("rose", "--json", "--plot", tmp_path / "rose.png", input=surface, check=True).stdout)
    assert {"sectors", "sectors_at_bound", "Str", "Std"} <= set(values)
    assert [sector["angle"] for sector in values["sectors"]] == [10.0 * k for k in range(18)]
    assert all({"fractal_dimension", "amplitude_coefficient"} <= set(sector) for sector in values["sectors"])
    assert (tmp_path / "rose.png").read_bytes()[:4] == b"\x89PNG"
    rows = rough("rose", "--tsv", "--angle-step", "30", input=surface, check=True).stdout.decode().splitlines()
    angles = [row.split("\t")[2] for row in rows if re.search(r"\tsectors\.\d+\.angle\t", row)]
    assert angles == ["0.0", "30.0", "60.0", "90.0", "120.0", "150.0"]
    profile = rough("synth", "--length", "5mm", "--dimension", "1.3", "--rq", "0.1mm", "--seed", "1", check=True).stdout
    assert_one_line_error(rough("rose", input=profile), "a rose needs a map")
    assert_one_line_error(rough("rose", "--angle-step", "7", input=surface), "must divide 180")


@pytest.mark.parametrize(
    "name,extra",
    [
        ("SurfaceTopography/x3p-2.x3p", []),
        ("SurfaceTopography/al3d-1.al3d", []),
        ("opengps/KautschukInfiniteFocus.x3p", ["--fill"]),
        ("x3ptools/sample-land.x3p", ["--fill"]),
    ],
)
def test_real_files(shared_data, name, extra):
    values = json.loads(rough("rose", "--json", *extra, shared_data / name, check=True).stdout)
    sectors = values["sectors"]
    assert len(sectors) == 18 and all(2.0 <= sector["fractal_dimension"] <= 3.0 for sector in sectors)
    assert all(sector["amplitude_coefficient"] > 0 for sector in sectors)


def test_x3p2_is_strongly_anisotropic(shared_data):
    """The MountainsMap export is a machined, grooved surface: C depends on direction
    far beyond its errors, and the principal wavevector lies near 157°."""
    result = rose(read(shared_data / "SurfaceTopography/x3p-2.x3p"))
    assert result.isotropy_p_value["amplitude_coefficient"] < 1e-6
    assert angular_distance(result.principal_direction, 157.0) <= result.step
