"""Issue 32, profiles by direction: the profiles of a map along x, y or an angle (exact
rotation of the sampling lines, bilinear heights), their pooled Whittle fit, the
jackknife over blocks of neighbouring profiles, the profile rose, and the Corona
Heights fault's H along and across slip."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize_scalar

import rough
from rough.fractal.pooled import whittle_hurst
from rough.fractal.profile_set import ProfileSet, _rotated_lines, take_profiles
from rough.fractal.profiles import fit_profiles, profile_rose
from rough.fractal.scales import reliability_cutoff
from rough.fractal.synth_map import synthesize_map

from conftest import shared_data_path
from fbm import fbm

CORONA = shared_data_path() / "dem" / "coronaA_grids.npz"


def fbm_rows(rows, points, hurst, seed, spacing=1e-6):
    rng = np.random.default_rng(seed)
    return np.array([fbm(points, hurst, rng, spacing=spacing, scale=1e-6) for _ in range(rows)])


ROWS = fbm_rows(64, 128, 0.6, seed=5)
MAP = synthesize_map((128, 128), (1e-6, 1e-6), 2.4, amplitude=1e-7, seed=5).heights
FIXED = (2e4, 5e5)  # 1/m: a band given, so that the fit is a smooth function of the data
SYNTHETIC_BAND = (4e3, 1.25e5)  # 1/m: up to a quarter of the Nyquist frequency, where a profile's spectrum
# is still its map's: synthesize_map stops the 2-D spectrum at the Nyquist frequency in x and in y, which
# takes from a profile's spectrum the power of the wavevectors beyond it, more the nearer the Nyquist frequency


# -- taking the profiles -----------------------------------------------------------------


def test_x_takes_the_rows_and_y_the_columns_with_their_positions():
    heights = np.random.default_rng(0).standard_normal((5, 7))
    scan = rough.Surface(heights, (1e-3, 2e-3), origin=(0.5, 1.0))
    rows = take_profiles(scan, "x", order=0, min_points=2)
    columns = take_profiles(scan, "y", order=0, min_points=2)
    for taken, expected in ((rows, heights), (columns, heights.T)):
        assert len(taken.heights) == len(expected)
        for profile, line in zip(taken.heights, expected):
            np.testing.assert_allclose(profile, line - line.mean(), rtol=0, atol=1e-15)
    np.testing.assert_allclose(rows.positions, 1.0 + 2e-3 * np.arange(5))
    np.testing.assert_allclose(columns.positions, 0.5 + 1e-3 * np.arange(7))
    assert (rows.spacing, columns.spacing) == (1e-3, 2e-3)
    assert (rows.label, columns.label, rows.interpolation) == ("x", "y", "none (grid lines)")


def test_angle_zero_is_the_rows_and_ninety_degrees_the_columns_reversed():
    heights = np.random.default_rng(1).standard_normal((6, 9))
    scan = rough.Surface(heights, 1e-3)
    at_zero = take_profiles(scan, 0.0, order=0, min_points=2)
    at_ninety = take_profiles(scan, math.pi / 2, order=0, min_points=2)
    assert at_zero.interpolation == "bilinear" and at_zero.label == "0°" and at_ninety.label == "90°"
    assert [p.size for p in at_zero.heights] == [9] * 6 and [p.size for p in at_ninety.heights] == [6] * 9
    for profile, row in zip(at_zero.heights, take_profiles(scan, "x", order=0, min_points=2).heights):
        np.testing.assert_array_equal(profile, row)
    columns = take_profiles(scan, "y", order=0, min_points=2).heights[::-1]  # lines ordered by offset along -x
    for profile, column in zip(at_ninety.heights, columns):
        np.testing.assert_allclose(profile, column, rtol=0, atol=1e-14)


@settings(max_examples=40, deadline=None)
@given(
    angle=st.floats(0.0, 2 * math.pi),
    plane=st.tuples(st.floats(-5, 5), st.floats(-1e3, 1e3), st.floats(-1e3, 1e3)),
    spacing=st.sampled_from([(1e-3, 1e-3), (1e-3, 1.5e-3), (2e-3, 1e-3)]),
)
def test_bilinear_heights_of_a_plane_are_exact(angle, plane, spacing):
    """Every point of every line lies on the plane: its heights step by Δ (b cos θ + c sin θ)."""
    a, b, c = plane
    y, x = np.mgrid[0:7, 0:10] * np.array(spacing[::-1])[:, None, None]
    scan = rough.Surface(a + b * x + c * y, spacing)
    taken = take_profiles(scan, angle, order=0, min_points=2)
    rise = taken.spacing * (b * math.cos(angle) + c * math.sin(angle))
    scale = abs(a) + 1e3 * 0.02
    for profile in taken.heights:
        np.testing.assert_allclose(np.diff(profile), rise, rtol=0, atol=1e-9 * scale)


@pytest.mark.parametrize("angle", [0.3, math.radians(45), 2.0, math.radians(150)])
def test_the_lines_cover_the_map_on_a_rotated_lattice(angle):
    """Counted independently: the lattice j·h·u + k·h·v (h the smaller spacing) inside the
    grid's rectangle, lines of at least two points."""
    nx, ny, dx, dy = 13, 8, 1.0, 1.5
    scan = rough.Surface(np.ones((ny, nx)) + np.arange(nx), (dx, dy))
    taken = take_profiles(scan, angle, order=0, min_points=2)
    u, v = np.array([math.cos(angle), math.sin(angle)]), np.array([-math.sin(angle), math.cos(angle)])
    reach = 30
    lines = {}
    for k in range(-reach, reach + 1):
        inside = 0
        for j in range(-reach, reach + 1):
            x, y = j * u + k * v
            inside += -1e-9 <= x <= (nx - 1) * dx + 1e-9 and -1e-9 <= y <= (ny - 1) * dy + 1e-9
        if inside >= 2:
            lines[k] = inside
    assert [p.size for p in taken.heights] == [lines[k] for k in sorted(lines)]
    np.testing.assert_allclose(taken.positions, np.array(sorted(lines)) * min(dx, dy), atol=1e-12)


def test_a_point_whose_stencil_touches_an_invalid_point_is_invalid():
    """Counted independently: the lattice points within one cell (in x and in y) of the
    invalid point are lost, and no other."""
    heights = np.ones((9, 9))
    heights[4, 5] = np.nan
    angle = 0.4
    lines, offsets, step = _rotated_lines(heights, (1.0, 1.0), angle)
    clean, _, _ = _rotated_lines(np.ones((9, 9)), (1.0, 1.0), angle)
    u, v = np.array([math.cos(angle), math.sin(angle)]), np.array([-math.sin(angle), math.cos(angle)])
    touching = 0
    for k in np.round(offsets / step).astype(int):
        for j in range(-30, 31):
            x, y = j * u + k * v
            touching += abs(x - 5) < 1 and abs(y - 4) < 1
    lost = sum(int(np.isfinite(a).sum() - np.isfinite(b).sum()) for a, b in zip(clean, lines))
    assert touching > 0 and lost == touching
    assert all(np.allclose(line[np.isfinite(line)], 1.0, rtol=1e-15, atol=0) for line in lines)


def test_the_gap_rules_keep_the_longest_run_or_fill_linearly():
    row = np.array([np.nan, 1, 2, np.nan, 4, 5, 6, 7, np.nan, 9, np.nan]) * 1e-6
    scan = rough.Surface(np.vstack([row, row * 2]), 1e-3)
    longest = take_profiles(scan, "x", "longest", order=0, min_points=3)
    filled = take_profiles(scan, "x", "fill", order=0, min_points=3)
    np.testing.assert_allclose(longest.heights[0], np.array([4, 5, 6, 7]) * 1e-6 - 5.5e-6, atol=1e-20)
    np.testing.assert_allclose(filled.heights[0], np.arange(1, 10) * 1e-6 - 5e-6, atol=1e-20)
    assert (longest.gaps, filled.gaps) == ("longest", "fill")
    assert all(np.isfinite(p).all() for p in longest.heights + filled.heights)


def test_short_profiles_are_dropped_and_none_left_is_refused():
    heights = np.ones((4, 100)) * np.linspace(0, 1e-6, 100) ** 2
    heights[1, 50] = np.nan
    scan = rough.Surface(heights, 1e-6)
    taken = take_profiles(scan, "x", "longest", min_points=60)
    assert len(taken.heights) == 3
    np.testing.assert_allclose(taken.positions, [0.0, 2e-6, 3e-6])
    with pytest.raises(rough.InputError, match="keeps 200 valid points"):
        take_profiles(scan, "x", min_points=200)


@pytest.mark.parametrize(
    "arguments, fragment",
    [
        (("z",), "x, y or an angle"),
        (("x", "all"), "gaps must be"),
        ((math.inf,), "finite"),
        (("x", "fill", -1), "order"),
    ],
)
def test_bad_directions_gaps_and_orders_are_refused(arguments, fragment):
    scan = rough.Surface(ROWS, 1e-6)
    with pytest.raises(rough.InputError, match=fragment):
        take_profiles(scan, *arguments)


def test_a_flat_map_is_refused():
    y, x = np.mgrid[0:16, 0:128]
    with pytest.raises(rough.InputError, match="flat"):
        fit_profiles(rough.Surface(1e-6 * x + 2e-6 * y, 1e-6), "x")


def test_a_profile_is_a_set_of_one_fitted_with_the_fisher_error():
    profile = rough.Surface(fbm_rows(1, 1024, 0.7, seed=2)[0], 1e-6)
    taken = take_profiles(profile)
    assert (taken.label, math.isnan(taken.angle), len(taken.heights)) == ("profile", True, 1)
    result = fit_profiles(profile, band=FIXED)
    assert result.profiles == 1 and result.stderr_method.startswith("Fisher information")
    assert math.isnan(result.hurst_spread) and result.as_dict()["angle"] is None
    assert abs(result.fit.hurst - 0.7) < 0.1


# -- the pooled fit ------------------------------------------------------------------------------


def test_the_pooled_fit_maximises_the_summed_whittle_likelihood():
    """Written out here: Σ over profiles and ordinates of log S + I/S, S = A·2 sin²(πfΔ) f^-β
    (band-limited), A profiled out; profiles of different lengths, some frequencies shared."""
    rng = np.random.default_rng(3)
    profiles = [fbm(n, 0.4, rng, spacing=1e-6) for n in (257, 513, 300)]
    spacing = 1e-6

    def nll(beta):
        terms, count = [], 0
        for profile in profiles:
            d = np.diff(profile)
            m = d.size
            k = np.arange(1, (m - 1) // 2 + 1)
            f = k / (m * spacing)
            periodogram = spacing / m * np.abs(np.fft.rfft(d)[k]) ** 2
            shape = 2 * np.sin(np.pi * f * spacing) ** 2 * f**-beta
            terms.append((periodogram / shape, np.log(shape)))
            count += k.size
        level = sum(ratio.sum() for ratio, _ in terms) / count
        return count * math.log(level) + sum(logs.sum() for _, logs in terms)

    beta = minimize_scalar(nll, bounds=(1.01, 2.99), method="bounded", options={"xatol": 1e-9}).x
    pooled = whittle_hurst(profiles, spacing, sampling="band-limited", noise=False)
    assert pooled == pytest.approx((beta - 1) / 2, abs=1e-6)


def test_whittle_hurst_agrees_with_fit_profiles_over_the_same_band():
    taken = take_profiles(rough.Surface(ROWS, 1e-6), "x")
    result = fit_profiles(taken, band=FIXED, noise=False)
    low, high = result.fit.band
    direct = whittle_hurst(taken.heights, taken.spacing, (1 / high / (1 + 1e-9), 1 / low / (1 - 1e-9)), noise=False)
    assert direct == pytest.approx(result.fit.hurst, abs=1e-6)
    assert whittle_hurst(taken.heights[0], taken.spacing) == pytest.approx(
        whittle_hurst([taken.heights[0]], taken.spacing)
    )


def test_whittle_hurst_refuses_nan_and_a_band_without_frequencies():
    with pytest.raises(rough.InputError, match="invalid"):
        whittle_hurst([np.array([0.0, np.nan, 1.0])], 1e-6)
    with pytest.raises(rough.InputError, match="fewer than 8"):
        whittle_hurst(list(ROWS), 1e-6, scales=(1e-5, 1.2e-5))
    with pytest.raises(rough.InputError, match="λmin < λmax"):
        whittle_hurst(list(ROWS), 1e-6, scales=(1e-5, 1e-6))


@settings(max_examples=25, deadline=None)
@given(
    plane=st.tuples(st.floats(-1e-5, 1e-5), st.floats(-0.05, 0.05), st.floats(-0.05, 0.05)),
    direction=st.sampled_from(["x", "y", 0.5]),
)
def test_adding_a_plane_to_the_map_does_not_change_the_fit(plane, direction):
    a, b, c = plane
    y, x = np.mgrid[0:128, 0:128] * 1e-6
    options = dict(band=SYNTHETIC_BAND, noise=False, spread=False)
    base = fit_profiles(rough.Surface(MAP, 1e-6), direction, **options)
    tilted = fit_profiles(rough.Surface(MAP + a + b * x + c * y, 1e-6), direction, **options)
    assert base.fit.verdict == tilted.fit.verdict == "power law"
    assert tilted.fit.hurst == pytest.approx(base.fit.hurst, abs=1e-6)
    assert tilted.fit.amplitude_coefficient == pytest.approx(base.fit.amplitude_coefficient, rel=1e-5)
    assert tilted.hurst_stderr == pytest.approx(base.hurst_stderr, rel=1e-3)
    assert tilted.design_effect == pytest.approx(base.design_effect, rel=1e-3)


@settings(max_examples=25, deadline=None)
@given(order=st.permutations(range(64)))
def test_the_fit_does_not_depend_on_the_order_of_the_profiles(order):
    taken = take_profiles(rough.Surface(ROWS, 1e-6), "x")
    shuffled = ProfileSet(
        [taken.heights[i] for i in order],
        taken.spacing,
        "x",
        0.0,
        taken.interpolation,
        "longest",
        taken.positions[order],
    )
    base = fit_profiles(taken, band=FIXED, noise=False)
    again = fit_profiles(shuffled, band=FIXED, noise=False)
    assert again.fit.hurst == pytest.approx(base.fit.hurst, abs=1e-6)
    assert again.hurst_stderr == pytest.approx(base.hurst_stderr, rel=1e-3)
    assert again.hurst_spread == pytest.approx(base.hurst_spread, rel=1e-9)


def test_independent_fbm_rows_give_unbiased_h_and_a_jackknife_error_that_matches_the_scatter():
    """Rows of exact fBm (Davies-Harte, tests/fbm.py), H = 0.7, 16 rows × 1024, the default
    path: the mean H within 0.02, the mean jackknife error within ±30 % of the scatter."""
    estimates, errors = [], []
    for seed in range(40):
        result = fit_profiles(rough.Surface(fbm_rows(16, 1024, 0.7, seed=100 + seed), 1e-6), "x", spread=False)
        estimates.append(result.fit.hurst)
        errors.append(result.hurst_stderr)
    assert result.stderr_method.startswith("delete-one-block jackknife (16 blocks")
    assert abs(np.mean(estimates) - 0.7) < 0.02
    scatter = np.std(estimates, ddof=1)
    assert 0.7 * scatter < np.mean(errors) < 1.3 * scatter


def mean_hurst(anisotropy, direction, seeds=(0, 1, 2)):
    values = []
    for seed in seeds:
        scan = synthesize_map((256, 256), (1e-6, 1e-6), None, anisotropy=anisotropy, seed=seed)
        values.append(fit_profiles(scan, direction, band=SYNTHETIC_BAND, noise=False, spread=False).fit)
    return np.mean([fit.hurst for fit in values]), np.mean([fit.amplitude_coefficient for fit in values]), values[0]


def test_h_by_direction_of_a_map_whose_amplitude_depends_on_direction():
    """synthesize_map with one Ds and C larger along y: every profile's spectrum is then a
    power law of H = 3 - Ds, and C along y exceeds C along x."""
    anisotropy = (2.4, 1e-7, 2.4, 4e-7, 0.0)
    (hurst_x, amplitude_x, fit), (hurst_y, amplitude_y, _) = (mean_hurst(anisotropy, d) for d in "xy")
    assert hurst_x == pytest.approx(0.6, abs=0.04) and hurst_y == pytest.approx(0.6, abs=0.04)
    assert amplitude_y > 1.3 * amplitude_x  # C2 is 16 times larger along y; a profile's C mixes directions
    assert fit.sampling == "band-limited" and fit.sampling_source == "history"


def test_h_by_direction_of_a_map_whose_dimension_depends_on_direction():
    """Ds 2.2 along x, 2.6 along y (H 0.8 and 0.4 in the principal directions): a profile's
    spectrum mixes those of every wavevector direction, weighted towards its own, so its H
    is no single direction's; it lies between the two, and along x well above along y."""
    anisotropy = (2.2, 1e-7, 2.6, 1e-7, 0.0)
    (hurst_x, _, _), (hurst_y, _, _) = (mean_hurst(anisotropy, d) for d in "xy")
    assert 0.65 < hurst_x < 0.82 and 0.4 < hurst_y < 0.65
    assert hurst_y < hurst_x - 0.1


def test_the_result_names_what_it_is_and_merges_the_fit():
    result = fit_profiles(rough.Surface(ROWS, 1e-6), 0.3, band=FIXED)
    values = result.as_dict()
    for key in (
        "fractal_dimension",
        "fractal_dimension_stderr",
        "amplitude_coefficient",
        "resolution",
        "psd_prefactor",
        "hurst",
        "band",
        "hurst_stderr",
        "hurst_spread",
        "stderr_method",
    ):
        assert key in values, key
    assert values["kind"] == "profiles" and values["interpolation"] == "bilinear"
    assert values["direction"] == "17.1887°" and values["angle"] == pytest.approx(math.degrees(0.3))
    assert values["fractal_dimension"] == pytest.approx(2 - values["hurst"])
    assert values["fractal_dimension_stderr"] == values["hurst_stderr"] and values["design_effect"] >= 1


def test_a_tip_radius_stops_the_band_at_its_reliability_cutoff():
    taken = take_profiles(rough.Surface(ROWS, 1e-6), "x")
    radius = 1e-7
    cutoff = reliability_cutoff(taken.heights, taken.spacing, radius)
    result = fit_profiles(taken, band=(2e4, None), tip_radius=radius)
    assert result.reliability_cutoff == cutoff
    if cutoff is not None:
        assert result.fit.band[1] <= 1 / cutoff * (1 + 1e-12)


# -- the profile rose -------------------------------------------------------------------------------


def test_the_profile_rose_records_each_direction():
    scan = synthesize_map((256, 256), (1e-6, 1e-6), None, anisotropy=(2.4, 1e-7, 2.4, 4e-7, 0.0), seed=8)
    result = profile_rose(scan, step=math.radians(45), band=SYNTHETIC_BAND, noise=False)
    assert [record["angle"] for record in result.directions] == [0.0, 45.0, 90.0, 135.0]
    assert result.kind == "profiles" and result.as_dict()["kind"] == "profiles" and result.step == 45.0
    assert result.stderr_method.startswith("delete-one-block jackknife")
    amplitude = [record["amplitude_coefficient"] for record in result.directions]
    assert amplitude[2] == max(amplitude) and amplitude[0] == min(amplitude)
    for record in result.directions:
        assert record["hurst"] == pytest.approx(0.6, abs=0.08)
        assert record["fractal_dimension"] == pytest.approx(2 - record["hurst"])
        assert record["profiles"] > 100 and record["verdict"] == "power law"


@pytest.mark.parametrize("step", [0.0, math.radians(25), math.radians(120)])
def test_the_profile_rose_refuses_a_step_that_does_not_divide_180_degrees(step):
    with pytest.raises(rough.InputError, match="divide 180"):
        profile_rose(rough.Surface(ROWS, 1e-6), step=step)


def test_the_profile_rose_needs_a_map():
    with pytest.raises(rough.InputError, match="needs a map"):
        profile_rose(rough.Surface(ROWS[0], 1e-6))


# -- the Corona Heights fault (Candela et al. 2012: H along slip 0.58 ± 0.07, across 0.81 ± 0.04) --


@pytest.fixture(scope="module")
def corona():
    if not CORONA.is_file():
        pytest.skip("../shared/data/dem/coronaA_grids.npz (third-party reference file) is not there")
    return rough.read(CORONA)


def test_corona_heights_h_along_slip_is_below_h_across_slip_and_near_the_literature(corona):
    along, across = fit_profiles(corona, "x"), fit_profiles(corona, "y")
    assert along.profiles == 386 and across.profiles == 536  # the all-NaN edge rows and column dropped
    assert along.stderr_method.startswith("delete-one-block jackknife")
    assert along.fit.hurst < across.fit.hurst
    assert along.fit.hurst == pytest.approx(0.58, abs=0.1)
    assert across.fit.hurst == pytest.approx(0.81, abs=0.1)
