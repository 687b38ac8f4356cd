"""rough features' tribology parameters as a user runs them: options, units, the
segment list and the Abbott–Firestone plot."""

import csv
import io
import json

import numpy as np
import pytest

from rough import Surface
from rough.metrology import feature_parameters, functional_parameters

from conftest import assert_one_line_error, rough

PROFILE_KEYS = ["Rmr", "Rmc", "Rdc", "Rk", "Rpk", "Rvk", "Mr1", "Mr2", "A1", "A2", "Rpq", "Rvq", "Rmq"]
MAP_KEYS = ["Smr", "Smc", "Sdc", "Sk", "Spk", "Svk", "Smr1", "Smr2", "Sxp", "Vm", "Vv", "Vmp", "Vmc", "Vvc", "Vvv"]
FEATURE_KEYS = ["Spd", "Spc", "S5p", "S5v", "S10z", "Sda", "Sha", "Sdv", "Shv"]


@pytest.fixture(scope="module")
def egg_box(tmp_path_factory):
    u = 2 * np.pi * (np.arange(8 * 31) - 15) / 31  # 8 × 8 periods of 31 points at 10 µm, a peak on a point
    heights = 1e-6 * (np.cos(u)[None, :] + np.cos(u)[:, None])
    path = tmp_path_factory.mktemp("egg") / "egg.x3p"
    Surface(heights, (10e-6, 10e-6)).write(path)
    return path, Surface(heights, (10e-6, 10e-6))


@pytest.fixture(scope="module")
def profile(tmp_path_factory):
    heights = np.random.default_rng(4).normal(size=5000) * 1e-6
    path = tmp_path_factory.mktemp("profile") / "profile.x3p"
    Surface(heights, (1e-6,)).write(path)
    return path, Surface(heights, (1e-6,))


def report(*args):
    return json.loads(rough("features", "--json", *args, check=True).stdout)


def test_map_reports_the_library_values(egg_box):
    path, surface = egg_box
    document = report(str(path))
    expected = {**functional_parameters(surface), **feature_parameters(surface)}
    for key in MAP_KEYS + FEATURE_KEYS:
        assert document[key] == pytest.approx(expected[key], rel=1e-12), key
    assert document["Spd"] == pytest.approx(36 / (8 * 310e-6) ** 2)  # the 6 × 6 hills clear of the border
    assert document["Sha"] == pytest.approx(310e-6**2)
    assert document["evaluation"]["segmentation"] == {
        "pruning": 5.0,
        "threshold": pytest.approx(0.05 * (np.ptp(surface.heights))),
        "edges": "exclude",
    }


def test_profile_reports_the_library_values(profile):
    path, surface = profile
    document = report("--height", "0.5um", "--ratio", "20%", "--dc-ratios", "5:95", str(path))
    expected = functional_parameters(surface, height=0.5e-6, ratio=20.0, dc_ratios=(5.0, 95.0))
    for key in PROFILE_KEYS:
        assert document[key] == pytest.approx(expected[key], rel=1e-12), key
    assert not set(FEATURE_KEYS) & set(document)
    assert document["evaluation"]["material_ratio"] == {
        "height": 0.5e-6,
        "ratio": 20.0,
        "dc_ratios": [5.0, 95.0],
        "volume_ratios": [10.0, 80.0],
    }


def test_tsv_units_and_text_labels(egg_box, profile):
    rows = [
        line.split("\t")
        for line in rough("features", "--tsv", str(egg_box[0]), check=True).stdout.decode().splitlines()
    ]
    units = {key: unit for _, key, _, unit in rows}
    assert units["Vmp"] == "m3/m2" and units["Spd"] == "1/m2" and units["Sha"] == "m2" and units["Shv"] == "m3"
    assert units["evaluation.segmentation.threshold"] == "m"
    assert units["evaluation.material_ratio.volume_ratios.0"] == "%"
    text = rough("features", str(profile[0]), check=True).stdout.decode()
    assert "µm·%" in text and "(mr = 10 %)" in text and "(between 10 % and 80 %)" in text
    text = rough("features", "--volume-ratios", "5:85", str(egg_box[0]), check=True).stdout.decode()
    assert "µm³/µm²" in text and "(p = 5 %, q = 85 %)" in text and "mm²" in text


def test_options_change_what_they_name(egg_box):
    path, surface = egg_box
    base, other = report(str(path)), report("--height", "1um", "--ratio", "30", "--volume-ratios", "20:70", str(path))
    assert other["Smr"] < base["Smr"] and other["Smc"] < base["Smc"] and other["Vmp"] > base["Vmp"]
    assert other["Sk"] == base["Sk"]
    pruned = report("--pruning", "60", str(path))  # a 60 % threshold merges the 2 µm-deep egg cups
    assert pruned["Spd"] < base["Spd"]
    included = report("--edge-features", "include", str(path))
    assert included["Spd"] == pytest.approx(64 / (8 * 310e-6) ** 2)


def test_segments_list(egg_box, tmp_path):
    path, surface = egg_box
    listing = tmp_path / "motifs.tsv"
    document = report("--segments", str(listing), str(path))
    lines = listing.read_text().splitlines()
    assert lines[0].startswith("# rough features: one row per hill and dale")
    rows = list(csv.DictReader(io.StringIO("\n".join(lines[1:])), delimiter="\t"))
    hills = [row for row in rows if row["kind"] == "hill"]
    dales = [row for row in rows if row["kind"] == "dale"]
    assert len(hills) == 64 and len(dales) >= 49  # the hills are the 31 × 31 squares about the peaks
    inner = [row for row in hills if row["edge"] == "0"]
    assert len(inner) == 36
    assert np.mean([float(row["area"]) for row in inner]) == pytest.approx(document["Sha"])
    assert np.mean([float(row["volume"]) for row in inner]) == pytest.approx(document["Shv"])
    assert max(float(row["height"]) for row in inner) == pytest.approx(document["S5p"])


def test_segments_to_standard_output_replaces_the_report(egg_box):
    result = rough("features", "--segments", "-", str(egg_box[0]), check=True)
    assert result.stdout.decode().startswith("# rough features: one row per hill and dale")


def test_plot_draws_the_abbott_curve(profile, egg_box, tmp_path):
    for path in (profile[0], egg_box[0]):
        picture = tmp_path / f"{path.stem}.png"
        rough("features", "--plot", str(picture), str(path), check=True)
        assert picture.read_bytes().startswith(b"\x89PNG")


@pytest.mark.parametrize(
    "args,message",
    [
        (["--ratio", "120"], "between 0 and 100"),
        (["--ratio", "ten"], "is not a percentage"),
        (["--dc-ratios", "80:10"], "must be below the second"),
        (["--volume-ratios", "10"], "MR1:MR2"),
        (["--pruning", "100"], "--pruning"),
        (["--height", "1parsec"], "--height"),
    ],
)
def test_bad_options_are_one_line_errors(profile, args, message):
    assert_one_line_error(rough("features", *args, str(profile[0])), message)


def test_segments_of_a_profile_is_refused(profile, tmp_path):
    out = tmp_path / "motifs.tsv"
    assert_one_line_error(rough("features", "--segments", str(out), str(profile[0])), "--segments needs a map")
    assert not out.exists()


def test_segments_with_along_is_refused(egg_box, tmp_path):
    out = tmp_path / "motifs.tsv"
    assert_one_line_error(rough("features", "--along", "x", "--segments", str(out), str(egg_box[0])), "--along")
    assert not out.exists()
