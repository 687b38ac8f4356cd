"""Issue 31, item 3 and 7 and the 1e308 refusals: ISO 4288 sampling lengths of λc, Std on
grooves at every angle, S5p with fewer than five hills, Sal/Str with ISO's
autocorrelation or the per-lag one, and heights too large for float64's powers."""

import json
import logging
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rough
from rough.errors import InputError
from rough.metrology import areal_parameters, feature_parameters, parameters, profile_parameters
from rough.metrology.profile import sampling_sections
from rough.metrology.spatial import autocorrelation, texture_direction

from conftest import assert_one_line_error
from conftest import rough as run

MITUTOYO = "SurfaceTopography/mitutoyo_2_mock.xlsx"


def test_mitutoyo_rz_over_sampling_lengths_of_the_cutoff(shared_data):
    """The SurfTest's own results at λc = 2.5 mm over N = 4 sampling lengths (the sheet's
    "N"): Rz 18.485, Rp 8.244, Rv 10.24 µm. The export is the evaluation length, so the
    ends kept (``correct``) give the instrument's four sampling lengths; the default
    trim leaves three. Before: five sections of what is left, Rz 16.77 µm."""
    scan = rough.read(shared_data / MITUTOYO)
    assert scan.metadata["mitutoyo_sampling_lengths"] == "4"
    kept = parameters(scan, cutoff=2.5e-3, ends="correct")
    assert kept["Rz"] * 1e6 == pytest.approx(18.485, rel=0.01)
    assert kept["Rp"] * 1e6 == pytest.approx(8.244, rel=0.01)
    assert kept["Rv"] * 1e6 == pytest.approx(10.24, rel=0.02)
    trimmed = parameters(scan, cutoff=2.5e-3)
    assert trimmed["Rz"] * 1e6 == pytest.approx(18.485, rel=0.02)


def test_features_cli_states_the_sampling_lengths_of_the_cutoff(shared_data):
    result = run("features", "--json", "--cutoff", "2.5mm", "--ends", "correct", shared_data / MITUTOYO, check=True)
    values = json.loads(result.stdout)
    assert values["evaluation"]["sampling_lengths"] == 4
    assert values["evaluation"]["sampling_length"] == pytest.approx(2.5e-3, rel=1e-3)
    assert values["Rz"] * 1e6 == pytest.approx(18.485, rel=0.01)
    too_many = run("features", "--cutoff", "2.5mm", "--sampling-lengths", "5", shared_data / MITUTOYO)
    assert_one_line_error(too_many, "holds 3 sampling lengths")


def test_sampling_sections_are_whole_cutoffs_in_the_middle():
    assert sampling_sections(6664, 1.5e-6, 2.5e-3) == [(0, 1666), (1666, 3332), (3332, 4998), (4998, 6664)]
    assert sampling_sections(4996, 1.5e-6, 2.5e-3) == [(0, 1666), (1666, 3331), (3331, 4996)]  # 1 % short
    assert sampling_sections(100, 1.0, 30.0) == [(5, 35), (35, 65), (65, 95)]  # the rest dropped at both ends
    assert sampling_sections(100, 1.0, 30.0, 1) == [(35, 65)]
    assert sampling_sections(20, 1.0, 30.0) == []
    assert sampling_sections(10, 1.0) == [(0, 2), (2, 4), (4, 6), (6, 8), (8, 10)]  # no length: five sections
    with pytest.raises(InputError, match="holds 3 sampling lengths"):
        sampling_sections(100, 1.0, 30.0, 4)


@settings(max_examples=1000, deadline=None)
@given(
    points=st.integers(2, 10**6),
    spacing=st.floats(1e-9, 1e-3),
    per=st.floats(2.0, 5e5),
    count=st.none() | st.integers(1, 8),
)
def test_sampling_lengths_are_contiguous_and_each_lambda_c(points, spacing, per, count):
    per = per * spacing / spacing  # the ratio the function sees, to the last bit
    whole = math.floor(points / per + 0.01)
    if count is not None and count > whole:
        with pytest.raises(InputError):
            sampling_sections(points, spacing, per * spacing, count)
        return
    sections = sampling_sections(points, spacing, per * spacing, count)
    assert len(sections) == (whole if count is None else count)
    assert all(a == b for (_, a), (b, _) in zip(sections, sections[1:]))
    assert not sections or (sections[0][0] >= 0 and sections[-1][1] <= points)
    for start, stop in sections:
        assert abs((stop - start) - per) <= 0.01 * per + 1


def test_rz_of_sampling_lengths_on_a_known_profile():
    """350 points hold three sampling lengths of 100 (points 25 … 324), with spikes of 1,
    2 and 3; the spikes of 100 in the 25 points left over at each end lie outside them.
    Before: five sections of 70 points, two of them holding a spike of 100."""
    heights = np.zeros(350)
    heights[[10, 340]] = 100.0
    heights[[100, 200, 300]] = [1.0, 2.0, 3.0]
    mean = heights.mean()
    values = profile_parameters(rough.Surface(heights, 1.0), sampling_length=100.0)
    assert values["Rp"] == pytest.approx(2.0 - mean)
    assert values["Rv"] == pytest.approx(mean)
    assert values["Rz"] == pytest.approx(2.0)


def test_a_profile_shorter_than_the_cutoff_has_no_rz(caplog):
    surface = rough.Surface(np.sin(np.arange(50.0)), 1.0)
    with caplog.at_level(logging.WARNING, logger="rough"):
        values = parameters(surface, sampling_length=80.0)
    assert all(math.isnan(values[key]) for key in ("Rp", "Rv", "Rz", "peak_density"))
    assert math.isfinite(values["Rq"])
    assert "shorter than one sampling length" in caplog.text


def _grooves(angle, rng, random_phases=False):
    """Ridges that run at ``angle`` degrees from +x (heights vary at right angles)."""
    y, x = np.mgrid[0:128, 0:128] * 1e-6
    across = -x * math.sin(math.radians(angle)) + y * math.cos(math.radians(angle))
    if random_phases:
        z = sum(np.sin(2 * np.pi * across / (w * 1e-6) + rng.uniform(0, 2 * np.pi)) / w for w in (7, 11, 17, 29))
    else:
        z = np.sin(2 * np.pi * across / 12e-6)
    return rough.Surface(1e-6 * (z + 0.05 * np.std(z) * rng.standard_normal(z.shape)), 1e-6)


@pytest.mark.parametrize("random_phases", [False, True])
def test_std_is_the_lay_of_grooves_at_every_angle(random_phases):
    rng = np.random.default_rng(7)
    for angle in range(0, 180, 5):
        std = texture_direction(_grooves(angle, rng, random_phases))
        assert abs((std - angle + 90) % 180 - 90) <= 1.5, (angle, std)


def _egg_box(nx, rows=27, plateau=0):
    """The egg box of :func:`rough.metrology.segment` over ``nx`` × ``rows`` points (45: 3
    complete hills, 63: 5), with ``plateau`` rows of a flat 20 µm shelf after it."""
    u, v = 2 * np.pi * (np.arange(nx) - 4) / 9, 2 * np.pi * (np.arange(rows) - 4) / 9
    z = np.cos(u)[None, :] + np.cos(v)[:, None]
    return rough.Surface(1e-6 * np.vstack([z, np.full((plateau, nx), 20.0)]), 1e-6)


def test_s5p_needs_five_hills():
    three = feature_parameters(_egg_box(45))
    assert three["Spd"] * 45 * 27e-12 == pytest.approx(3)
    assert math.isnan(three["S5p"]) and math.isnan(three["S10z"])
    five = feature_parameters(_egg_box(63))
    assert five["S5p"] == pytest.approx(2e-6) and five["S10z"] == five["S5p"] + five["S5v"]


def test_s5p_undefined_is_one_warning_with_the_count(tmp_path):
    path = tmp_path / "three.npy"
    np.save(path, _egg_box(45).heights)
    result = run("features", "--json", "--spacing", "1um", path, check=True)
    values = json.loads(result.stdout)
    assert values["S5p"] is None and values["S10z"] is None and values["S5v"] > 0
    warnings = [line for line in result.stderr.decode().splitlines() if "S5p" in line]
    assert len(warnings) == 1 and "3 significant hills" in warnings[0], result.stderr


def test_negative_s5p_is_warned(caplog):
    """Five hills beside a high shelf: their peaks lie below the mean plane."""
    with caplog.at_level(logging.WARNING, logger="rough"):
        values = feature_parameters(_egg_box(63, plateau=60))
    assert values["S5p"] < 0
    assert "S5p = -" in caplog.text and "detrend" in caplog.text


def _brute_force_acf(z, kind):
    d = np.where(np.isnan(z), 0.0, z - np.nanmean(z))
    valid = (~np.isnan(z)).astype(float)
    ny, nx = z.shape
    hy, hx = ny // 2, nx // 2
    acf = np.empty((2 * hy + 1, 2 * hx + 1))
    for j, ty in enumerate(range(-hy, hy + 1)):
        for i, tx in enumerate(range(-hx, hx + 1)):
            a = d[max(0, -ty) : ny - max(0, ty), max(0, -tx) : nx - max(0, tx)]
            b = d[max(0, ty) : ny - max(0, -ty), max(0, tx) : nx - max(0, -tx)]
            va = valid[max(0, -ty) : ny - max(0, ty), max(0, -tx) : nx - max(0, tx)]
            vb = valid[max(0, ty) : ny - max(0, -ty), max(0, tx) : nx - max(0, -tx)]
            if kind == "iso":
                acf[j, i] = np.sum(a * b) / np.sum(d * d)
            else:
                acf[j, i] = (np.sum(a * b) / np.sum(va * vb)) / (np.sum(d * d) / valid.sum())
    return acf


@pytest.mark.parametrize("kind", ["iso", "per-lag"])
def test_autocorrelation_against_brute_force(kind):
    rng = np.random.default_rng(5)
    z = rng.standard_normal((9, 12))
    z[2, 3] = z[7, 0] = np.nan
    acf, lag_x, lag_y = autocorrelation(rough.Surface(z, (2.0, 3.0)), kind)
    np.testing.assert_allclose(acf, _brute_force_acf(z, kind), atol=1e-12)
    assert lag_x[-1] == 12.0 and lag_y[-1] == 12.0


def test_iso_acf_by_hand():
    """+1, -1 along x: every pair one spacing apart has product -1. ISO's ACF sums
    nx - 1 of them over nx squares; the per-lag one is their mean, -1."""
    stripes = rough.Surface(np.tile([1.0, -1.0], (4, 5)), 1.0)  # 4 × 10
    assert autocorrelation(stripes, "iso")[0][2, 6] == pytest.approx(-0.9)
    assert autocorrelation(stripes, "per-lag")[0][2, 6] == pytest.approx(-1.0)
    with pytest.raises(InputError, match="acf must be one of iso, per-lag"):
        autocorrelation(stripes, "biased")


def test_acf_choice_reaches_sal_and_the_command_line(tmp_path):
    rng = np.random.default_rng(2)
    z = rng.standard_normal((64, 64))
    from scipy.ndimage import gaussian_filter

    surface = rough.Surface(1e-6 * gaussian_filter(z, (2, 5), mode="wrap"), 1e-6)
    iso, per_lag = areal_parameters(surface), areal_parameters(surface, acf="per-lag")
    assert iso["Sal"] < per_lag["Sal"]  # ISO's ACF shrinks with the overlap, so it falls to 0.2 sooner
    path = tmp_path / "map.npy"
    np.save(path, surface.heights)
    for option, expected in (("iso", iso), ("per-lag", per_lag)):
        values = json.loads(run("features", "--json", "--spacing", "1um", "--acf", option, path, check=True).stdout)
        assert values["Sal"] == pytest.approx(expected["Sal"], rel=1e-9)
        assert values["evaluation"]["acf"] == option


@pytest.mark.parametrize(
    "heights",
    [
        np.array([1e308, -1e308] * 50),
        1e300 * np.sin(np.arange(100.0)),
        np.array([[1e308, -1e308, 1.0, 0.0]] * 8),
        np.full((6, 6), 1.7e308),
        1e200 * np.cos(np.arange(64.0)).reshape(8, 8),
    ],
)
def test_heights_beyond_float64s_powers_are_refused(heights):
    surface = rough.Surface(heights, 1e-6)
    with np.errstate(all="raise"):
        with pytest.raises(InputError, match="beyond ±1e\\+60 m"):
            parameters(surface)
        if not surface.is_profile:
            with pytest.raises(InputError, match="beyond ±1e\\+60 m"):
                feature_parameters(surface)


def test_large_heights_within_the_limit_scale_exactly():
    rng = np.random.default_rng(4)
    z = rng.standard_normal((32, 32))
    unit, huge = parameters(rough.Surface(z, 1.0)), parameters(rough.Surface(1e50 * z, 1.0))
    for key in ("Sa", "Sq", "Sp", "Sv", "Sz", "Sdq"):
        assert huge[key] == pytest.approx(1e50 * unit[key], rel=1e-12), key
    for key in ("Ssk", "Sku", "Sal", "Str", "Std"):
        assert huge[key] == pytest.approx(unit[key], rel=1e-9), key


def test_features_on_an_npy_of_huge_heights_is_one_line(tmp_path):
    """The reader may refuse them first (its own range check); either way one line, status 2."""
    path = tmp_path / "huge.npy"
    np.save(path, np.array([1e308, -1e308] * 50))
    assert_one_line_error(run("features", "--spacing", "1um", path))
