"""fit-fractal --profiles / --estimator and rose --profiles as a user runs them (issue 32)."""

import json
import math

import numpy as np
import pytest

import rough as library
from rough.fractal.synth_map import synthesize_map

from conftest import assert_one_line_error, rough
from fbm import fbm

ESTIMATOR_NAMES = ["whittle", "variogram", "dfa", "wavelet", "higuchi"]


def test_the_command_line_offers_every_registered_estimator():
    from rough.cli.fit_fractal import fit_fractal
    from rough.fractal import ESTIMATORS

    offered = next(param for param in fit_fractal.params if param.name == "estimator").type.choices
    assert list(offered) == [*ESTIMATORS, "all"] == [*ESTIMATOR_NAMES, "all"]


def fit_json(*args, input=None):
    return json.loads(rough("fit-fractal", "--json", *args, input=input, check=True, timeout=300).stdout)


@pytest.fixture(scope="module")
def fbm_rows_map(tmp_path_factory):
    """A map whose rows are independent exact fBm of H = 0.7 (the columns are white)."""
    rng = np.random.default_rng(32)
    heights = np.array([fbm(512, 0.7, rng, 1e-5, 1e-6) for _ in range(48)])
    path = tmp_path_factory.mktemp("maps") / "rows.x3p"
    library.write(library.Surface(heights, (1e-5, 1e-5)), path)
    return path


def test_profiles_along_x_measure_the_rows_hurst_exponent(fbm_rows_map):
    values = fit_json("--profiles", "x", fbm_rows_map)
    assert values["kind"] == "profiles" and values["direction"] == "x" and values["profiles"] == 48
    assert values["hurst"] == pytest.approx(0.7, abs=0.05)
    assert values["fractal_dimension"] == pytest.approx(2 - values["hurst"], abs=1e-12)
    assert values["band"][0] < values["band"][1]


def test_profiles_by_angle_and_the_direction_spellings(fbm_rows_map):
    for spelling, degrees in (("30", 30.0), ("30deg", 30.0), ("-150°", 30.0), ("210", 30.0)):
        assert fit_json("--profiles", spelling, fbm_rows_map)["angle"] == pytest.approx(degrees), spelling
    result = rough("fit-fractal", "--profiles", "z", fbm_rows_map)
    assert_one_line_error(result, "x, y or an angle")


def test_every_estimator_side_by_side_on_a_profile():
    surface = rough("synth", "--length", "40mm", "--dimension", "1.3", "--rq", "0.2mm", "--seed", "5", check=True)
    values = fit_json("--estimator", "all", "--replicates", "6", input=surface.stdout)
    names = [record["estimator"] for record in values["estimators"]]
    assert names == ESTIMATOR_NAMES
    for record in values["estimators"]:
        low, high = record["interval"]
        assert low <= record["hurst"] <= high, record["estimator"]
        assert record["bias"] == pytest.approx(record["raw"] - record["hurst"], abs=1e-12)
    assert values["hurst"] == values["estimators"][0]["hurst"]
    assert values["fractal_dimension"] == pytest.approx(2 - values["hurst"], abs=1e-12)
    text = rough("fit-fractal", "--estimator", "all", "--replicates", "6", input=surface.stdout, check=True)
    lines = text.stdout.decode().splitlines()
    assert [line.split()[1] for line in lines if line.startswith("estimator ")] == ESTIMATOR_NAMES


def test_an_estimator_on_a_map_needs_a_direction(fbm_rows_map):
    assert_one_line_error(rough("fit-fractal", "--estimator", "dfa", fbm_rows_map), "--profiles")


def test_rose_with_profiles_names_both_roses(tmp_path):
    surface = synthesize_map((128, 128), (1e-6, 1e-6), 2.4, amplitude=1e-7, seed=8)
    path = tmp_path / "map.x3p"
    library.write(surface, path)
    values = json.loads(rough("rose", "--json", "--angle-step", "45", "--profiles", path, check=True).stdout)
    assert values["kind"] == "sectors" and values["profiles"]["kind"] == "profiles"
    angles = [record["angle"] for record in values["profiles"]["directions"]]
    assert angles == [0.0, 45.0, 90.0, 135.0]
    text = rough("rose", "--angle-step", "45", "--profiles", path, check=True).stdout.decode()
    assert "profiles along θ" in text


@pytest.mark.parametrize("direction, expected, tolerance", [("x", 0.58, 0.1), ("y", 0.81, 0.1)])
def test_corona_heights_profiles_match_the_fault_literature(shared_data, direction, expected, tolerance):
    """Candela et al. (2012): H = 0.58 ± 0.07 along slip (x here), 0.81 ± 0.04 across."""
    values = fit_json("--profiles", direction, shared_data / "dem" / "coronaA_grids.npz")
    assert values["hurst"] == pytest.approx(expected, abs=tolerance)
    assert math.isfinite(values["hurst_stderr"])


def test_a_scan_without_a_power_law_band_gets_its_roughness_against_scale(shared_data, tmp_path):
    """stp-1 (WSxM, SurfaceTopography's test file): no band of a decade keeps its local
    exponent, so the answer is the scale-dependent table, in text, JSON and a figure."""
    path = shared_data / "SurfaceTopography" / "stp-1.stp"
    values = fit_json(path)
    assert values["verdict"] == "no power-law range"
    table = values["scale_dependent"]
    assert len(table["scale"]) >= 5 and table["direction"] == "x"
    assert all(np.diff(table["scale"]) > 0) and all(np.diff(table["rms_height"]) > 0)
    text = rough("fit-fractal", path, check=True).stdout.decode()
    assert text.count("λ = ") == len(table["scale"])
    rough("fit-fractal", "--plot", tmp_path / "scales.png", path, check=True)
    assert (tmp_path / "scales.png").read_bytes()[:4] == b"\x89PNG"


def test_a_tip_radius_cuts_the_band_and_says_so(tmp_path):
    surface = rough("synth", "--length", "20mm", "--dimension", "1.3", "--rq", "0.2mm", "--seed", "6", check=True)
    free = fit_json(input=surface.stdout)
    tipped = fit_json("--tip-radius", "2mm", input=surface.stdout)
    assert "reliability_cutoff" not in free
    assert tipped["band"][1] <= 1 / tipped["reliability_cutoff"] * (1 + 1e-9)
    assert tipped["band"][1] < free["band"][1]


def test_side_by_side_an_estimator_that_cannot_measure_is_named_not_fatal():
    """70-point profiles hold too few wavelet levels: with every estimator asked for, the
    wavelet's row says why and the others are measured; asked for alone, it refuses."""
    from rough.errors import InputError
    from rough.fractal.hurst import hurst_exponents

    rng = np.random.default_rng(4)
    surface = library.Surface(np.array([fbm(70, 0.6, rng, 1e-5, 1e-6) for _ in range(64)]), (1e-5, 1e-5))
    table = hurst_exponents(surface, "x", replicates=4)
    wavelet = next(e for e in table.estimates if e.estimator == "wavelet")
    assert math.isnan(wavelet.hurst) and wavelet.method.startswith("refused: wavelet")
    assert all(math.isfinite(e.hurst) for e in table.estimates if e.estimator != "wavelet")
    with pytest.raises(InputError, match="wavelet"):
        hurst_exponents(surface, "x", ["wavelet"], replicates=4)


def test_a_noise_floor_beyond_the_increments_is_not_calibrated_as_white_noise(caplog):
    from rough.fractal.calibrate import largest_noise
    from rough.fractal.hurst import _calibrated_noise

    walk = np.cumsum(np.random.default_rng(1).standard_normal(512))
    largest = largest_noise([walk])
    assert _calibrated_noise(0.5 * largest, [walk]) == 0.5 * largest
    with caplog.at_level("WARNING", logger="rough"):
        assert _calibrated_noise(1.5 * largest, [walk]) is None
    assert "calibrated without noise" in caplog.text


def test_a_flat_row_leaves_the_per_profile_spread_defined():
    """A constant row (frt-1 has them) has no H of its own: it is left out of the spread
    instead of ending the fit in a math domain error."""
    from rough.fractal.profiles import fit_profiles

    rng = np.random.default_rng(7)
    rows = np.array([fbm(256, 0.7, rng, 1e-5, 1e-6) for _ in range(16)])
    rows[5] = 0.0
    result = fit_profiles(library.Surface(rows, (1e-5, 1e-5)), "x")
    assert math.isfinite(result.hurst_spread) and math.isfinite(result.fit.hurst)


def test_profiles_write_their_mean_spectrum_and_its_spread(fbm_rows_map, tmp_path):
    """--psd with --profiles: the mean Hann periodogram of the rows, with how many
    profiles reach each bin and their spread in decades; --plot draws it with the fit."""
    rough("fit-fractal", "--profiles", "x", "--psd", tmp_path / "psd.tsv", fbm_rows_map, check=True)
    lines = (tmp_path / "psd.tsv").read_text().splitlines()
    assert lines[0].startswith("# rough fit-fractal: log-binned spectrum (mean Hann periodogram G of 48 profiles")
    assert lines[1] == "frequency_per_m\tdensity_m3\tcount\tprofiles\tlog10_spread"
    rows = np.array([[float(cell) for cell in line.split("\t")] for line in lines[2:]])
    assert np.all(np.diff(rows[:, 0]) > 0) and np.all(rows[:, 3] == 48)
    slope = np.polyfit(np.log(rows[2:-2, 0]), np.log(rows[2:-2, 1]), 1)[0]
    assert slope == pytest.approx(-(1 + 2 * 0.7), abs=0.15)
    assert np.all((rows[:, 4] > 0) & (rows[:, 4] < 1))
    rough("fit-fractal", "--profiles", "x", "--plot", tmp_path / "psd.png", fbm_rows_map, check=True)
    assert (tmp_path / "psd.png").read_bytes()[:4] == b"\x89PNG"
    assert_one_line_error(rough("fit-fractal", "--estimator", "dfa", "--psd", "-", fbm_rows_map), "--estimator")
