"""rough detrend and rough features as a user runs them."""

import json
import subprocess
import sys

import numpy as np
import pytest

from rough import Surface

from conftest import assert_one_line_error, rough

PROFILE_KEYS = {"Ra", "Rq", "Rsk", "Rku", "Rp", "Rv", "Rz", "Rt", "RSm", "Rdq", "peak_density"}
MAP_KEYS = {"Sa", "Sq", "Ssk", "Sku", "Sp", "Sv", "Sz", "Sdq", "Sal", "Str", "Std"}


@pytest.fixture
def rock(tmp_path):
    x = np.arange(6000) * 10e-6
    heights = (
        3e-4 * x + 40e-6 * np.sin(2 * np.pi * x / 7e-3) + np.cumsum(np.random.default_rng(8).normal(size=x.size)) * 2e-7
    )
    path = tmp_path / "rock.x3p"
    Surface(heights, (10e-6,)).write(path)
    return path


@pytest.fixture
def rock_map(tmp_path):
    rows, columns = np.mgrid[0:120, 0:160]
    heights = 1e-3 * columns * 1e-5 + np.random.default_rng(9).normal(size=rows.shape) * 1e-7
    path = tmp_path / "map.x3p"
    Surface(heights, (5e-6, 5e-6)).write(path)
    return path


def features_json(*args, input=None):
    return json.loads(rough("features", "--json", *args, input=input, check=True).stdout)


def test_dektak_instrument_results_to_the_printed_digits(shared_data):
    """The Dektak's own Analytical Results for 468–733 µm: Ra 0.00525 µm, Rq 0.01143 µm,
    Skew 6.96, RzDin 0.04917 µm (levelled by a least-squares line over the region)."""
    levelled = rough(
        "detrend", "--order", "1", "--crop", "468um:733um", shared_data / "SurfaceTopography/dektak-1.csv", check=True
    )
    values = features_json(input=levelled.stdout)
    assert round(values["Ra"] * 1e6, 5) == 0.00525
    assert round(values["Rq"] * 1e6, 5) == 0.01143
    assert round(values["Rsk"], 2) == 6.96
    assert round(values["Rz"] * 1e6, 5) == 0.04917
    assert values["evaluation"]["points"] == 1697


def test_profile_json_has_the_spec_keys(rock):
    values = features_json(rock)
    assert PROFILE_KEYS <= set(values)
    assert {"Z2", "JRC", "evaluation", "features", "amplitude_density"} <= set(values)
    assert values["evaluation"]["basis"] == "data as given, mean removed"
    density = values["amplitude_density"]
    assert np.trapezoid(density["density"], density["height"]) == pytest.approx(1.0, rel=0.05)


def test_map_json_has_the_spec_keys(rock_map):
    values = features_json(rock_map)
    assert MAP_KEYS <= set(values)
    assert "features" not in values
    along = features_json("--along", "x", rock_map)
    assert PROFILE_KEYS <= set(along)


def test_table_names_units_and_definitions(rock):
    table = rough("features", rock, check=True).stdout.decode()
    assert "arithmetic mean deviation" in table and "µm" in table
    assert "/m" in table and "2point slope" in table  # peak density per mm or per m and "5 sampling lengths" in table


def test_tsv_rows(rock):
    rows = [line.split("\t") for line in rough("features", "--tsv", rock, check=True).stdout.decode().splitlines()]
    units = {row[1]: row[3] for row in rows}
    assert units["Ra"] == "m" and units["Rsk"] == "1" and units["peak_density"] == "1/m"


def test_cutoff_evaluates_the_roughness(rock):
    raw = features_json(rock)
    filtered = features_json("--cutoff", "0.8mm", rock)
    assert filtered["Rq"] < raw["Rq"] / 3
    assert filtered["evaluation"]["points"] == 6000 - 2 * 40
    assert "roughness at λc = 800 µm" in filtered["evaluation"]["basis"]


def test_feature_list_and_plot(rock, tmp_path):
    listing, picture = tmp_path / "features.tsv", tmp_path / "profile.png"
    rough("detrend", "--order", "1", rock, "-o", tmp_path / "level.x3p", check=True)
    values = features_json("--list", listing, "--plot", picture, tmp_path / "level.x3p")
    lines = listing.read_text().splitlines()
    assert lines[1] == "kind\tposition\tstart\tend\theight\tprominence\twidth"
    assert len(lines) - 2 == len(values["features"]) > 0
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_rq_against_length(rock):
    values = features_json("--vs-length", rock)
    scaling = values["rq_vs_length"]
    assert scaling["length"][0] == pytest.approx(0.06)
    assert len(scaling["length"]) == len(scaling["Rq"]) == len(scaling["windows"])
    assert 0 < scaling["hurst"] < 1.2


def test_detrend_outputs(rock, tmp_path):
    for keep in ("roughness", "waviness", "form"):
        extra = ["--cutoff", "1mm"] if keep != "form" else []
        rough("detrend", "--keep", keep, *extra, rock, "-o", tmp_path / f"{keep}.x3p", check=True)
    facts = {
        keep: json.loads(rough("info", "--json", tmp_path / f"{keep}.x3p", check=True).stdout)
        for keep in ("roughness", "waviness", "form")
    }
    assert facts["roughness"]["shape"] == facts["waviness"]["shape"] == [5900]
    assert facts["form"]["shape"] == [6000]
    assert [entry["command"] for entry in facts["roughness"]["history"]] == ["detrend", "filter"]


def test_crop_of_a_map(rock_map):
    values = features_json("--crop", "0.1mm:0.3mm,:0.2mm", rock_map)
    assert values["evaluation"]["points"] == 41 * 41


def test_pipeline_detrend_to_features(rock):
    levelled = rough("detrend", rock, check=True).stdout
    values = features_json(input=levelled)
    assert abs(values["Rsk"]) < 5


@pytest.mark.parametrize(
    "args,message",
    [
        (["features", "--cutoff", "0.2mm"], "longer than the data"),
        (["detrend", "--order", "9"], "order 9"),
        (["features", "--crop", "1mm"], "write a range as X0:X1"),
        (["features", "--crop", "0:1mm,0:1mm"], "a profile has no y range"),
    ],
)
def test_refusals(tmp_path, args, message):
    Surface(np.linspace(0, 1e-6, 8), (10e-6,)).write(tmp_path / "short.x3p")
    assert_one_line_error(rough(*args, tmp_path / "short.x3p"), message)


def test_all_invalid_points_are_refused(tmp_path):
    Surface(np.full(50, np.nan), (1e-6,)).write(tmp_path / "empty.x3p")
    assert_one_line_error(rough("features", tmp_path / "empty.x3p"), "no valid points")
    assert_one_line_error(rough("detrend", tmp_path / "empty.x3p", "-o", tmp_path / "out.x3p"), "no valid points")
    assert not (tmp_path / "out.x3p").exists()


def test_help_starts_without_numpy():
    code = "import sys; from rough.cli.main import run; run(['--help']); print('numpy' in sys.modules, file=sys.stderr)"
    result = subprocess.run([sys.executable, "-c", code], check=False, capture_output=True, text=True, timeout=60)
    assert result.stderr.strip().endswith("False")
