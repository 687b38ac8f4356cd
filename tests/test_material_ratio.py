"""The material-ratio parameters (ISO 13565-2/-3, ISO 25178-2): closed forms,
invariants, surfalize's values and an instrument's own."""

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy import integrate
from scipy.stats import norm

from rough import InputError, Surface
from rough.metrology import AREAL_FUNCTIONAL, PROFILE_FUNCTIONAL, MaterialRatioCurve, functional_parameters
from rough.metrology.heights import ROUNDING

from conftest import surfalize_heights
from test_permutation import assert_same_core, length_tolerance, same_central_region

SIGMA = 1e-6


def stratified_gaussian(shape, sigma=SIGMA, seed=0):
    """A map whose heights are exactly the Gaussian quantiles σ·Φ⁻¹((k + ½)/n), shuffled:
    its material-ratio curve is the normal survival function up to the sampling."""
    n = int(np.prod(shape))
    heights = sigma * norm.ppf((np.arange(n) + 0.5) / n)
    return Surface(np.random.default_rng(seed).permutation(heights).reshape(shape), (1e-6, 1e-6))


@pytest.fixture(scope="module")
def gaussian():
    return stratified_gaussian((1024, 1024))


def material_volume(mr, sigma=SIGMA):
    """Vm(mr) of N(0, σ²): E[(z - c)⁺] at c = σ Φ⁻¹(1 - mr)."""
    c = sigma * norm.isf(mr / 100)
    return sigma * norm.pdf(c / sigma) - c * mr / 100


def void_volume(mr, sigma=SIGMA):
    c = sigma * norm.isf(mr / 100)
    return c * (1 - mr / 100) + sigma * norm.pdf(c / sigma)


def test_gaussian_material_ratio_is_the_normal_survival_function(gaussian):
    curve = MaterialRatioCurve(gaussian)
    for c in np.linspace(-2.5, 2.5, 11) * SIGMA:
        assert curve.ratio_at(c) == pytest.approx(100 * norm.sf(c / SIGMA), rel=1e-3, abs=1e-4)
    for mr in (1.0, 2.5, 10.0, 30.0, 50.0, 70.0, 90.0, 99.0):
        assert curve.height_at(mr) == pytest.approx(SIGMA * norm.isf(mr / 100), rel=1e-3, abs=1e-9 * SIGMA)


def test_gaussian_volumes_match_their_closed_forms(gaussian):
    values = functional_parameters(gaussian, ratio=25.0)
    expected = {
        "Vmp": material_volume(10),
        "Vmc": material_volume(80) - material_volume(10),
        "Vvc": void_volume(10) - void_volume(80),
        "Vvv": void_volume(80),
        "Vm": material_volume(25),
        "Vv": void_volume(25),
        "Sxp": SIGMA * (norm.isf(0.025) - norm.isf(0.5)),
        "Sdc": SIGMA * (norm.isf(0.1) - norm.isf(0.8)),
        "Smr": 50.0,
    }
    for key, value in expected.items():
        assert values[key] == pytest.approx(value, rel=1e-3), key


def gaussian_core(sigma=SIGMA):
    """Sk, Smr1, Smr2, Spk, Svk of N(0, σ²) by quadrature: the least-gradient 40 %
    window of a symmetric curve is 30–70 %, and its least-squares line follows."""

    def height(m):
        return sigma * norm.isf(m / 100)

    mean_m, mean_h = 50.0, 0.0
    covariance = integrate.quad(lambda m: (m - mean_m) * (height(m) - mean_h), 30, 70)[0]
    variance = integrate.quad(lambda m: (m - mean_m) ** 2, 30, 70)[0]
    slope = covariance / variance
    top, bottom = mean_h - slope * mean_m, mean_h + slope * (100 - mean_m)
    mr1, mr2 = 100 * norm.sf(top / sigma), 100 * norm.sf(bottom / sigma)
    a1 = integrate.quad(lambda m: height(m) - top, 0, mr1)[0]
    a2 = integrate.quad(lambda m: bottom - height(m), mr2, 100)[0]
    return {"Sk": top - bottom, "Smr1": mr1, "Smr2": mr2, "Spk": 2 * a1 / mr1, "Svk": 2 * a2 / (100 - mr2)}


def test_gaussian_core_matches_quadrature(gaussian):
    values = functional_parameters(gaussian)
    for key, value in gaussian_core().items():
        assert values[key] == pytest.approx(value, rel=1e-3), key


def test_random_gaussian_within_its_sampling_error():
    rng = np.random.default_rng(7)
    values = functional_parameters(Surface(SIGMA * rng.standard_normal((512, 512)), (1e-6, 1e-6)))
    assert values["Vmp"] == pytest.approx(material_volume(10), rel=0.02)
    assert values["Sk"] == pytest.approx(gaussian_core()["Sk"], rel=0.01)
    assert values["Spq"] == pytest.approx(SIGMA, rel=0.02) and values["Svq"] == pytest.approx(SIGMA, rel=0.02)


def test_sine_profile_material_ratio_is_the_arcsine_law():
    amplitude = 2e-6
    x = np.arange(200_000) / 200_000 * 40  # 40 periods
    curve = MaterialRatioCurve(Surface(amplitude * np.sin(2 * np.pi * x), (1e-7,)))
    for c in np.linspace(-0.9, 0.9, 7) * amplitude:  # within a sample at each of a period's two crossings
        assert curve.ratio_at(c) == pytest.approx(100 * (0.5 - np.arcsin(c / amplitude) / np.pi), abs=100 * 2 / 5000)


def test_uniform_heights_are_all_core():
    values = functional_parameters(Surface(np.linspace(-1e-6, 1e-6, 2001), (1e-6,)))
    assert values["Rk"] == pytest.approx(2e-6, rel=1e-9)
    assert values["Rpk"] == pytest.approx(0, abs=1e-15) and values["Rvk"] == pytest.approx(0, abs=1e-15)
    assert values["Mr1"] == pytest.approx(0, abs=1e-9) and values["Mr2"] == pytest.approx(100, abs=1e-9)
    assert values["Rmr"] == pytest.approx(50.0) and values["Rmc"] == pytest.approx(0.8e-6)
    assert values["Rdc"] == pytest.approx(1.4e-6)


@pytest.mark.parametrize("sign", [1, -1])
def test_flat_with_one_spike_or_one_pit(sign):
    n, spike = 2000, 5e-6
    heights = np.zeros((40, 50))
    heights[10, 20] = sign * spike
    values = functional_parameters(Surface(heights, (1e-6, 1e-6)))
    assert values["Sk"] == 0 and values["Sxp"] == 0 and values["Sdc"] == 0
    step = 100 / (n - 1)  # the material ratio of one point
    if sign > 0:  # one point above the core: Spk is the spike, Smr1 its one point
        assert values["Spk"] == pytest.approx(spike, rel=1e-12) and values["Svk"] == 0
        assert values["Smr1"] == pytest.approx(step) and values["Smr2"] == 100
        assert values["Vmp"] == pytest.approx(spike * step / 2 / 100, rel=1e-12)
        assert values["Smr"] == pytest.approx(step * (1 - 1 / n), rel=1e-9)
    else:
        assert values["Svk"] == pytest.approx(spike, rel=1e-12) and values["Spk"] == 0
        assert values["Smr1"] == 0 and values["Smr2"] == pytest.approx(100 - step)
        assert values["Vvv"] == pytest.approx(spike * step / 2 / 100, rel=1e-12)


def two_process(n, plateau, valley, break_index):
    """Heights whose normal-probability curve is two lines meeting at the deviate of
    point ``break_index``: slope ``plateau`` above it, ``valley`` below."""
    q = norm.ppf((np.arange(n) + 0.5) / n)
    b = q[break_index]
    heights = np.where(q > b, plateau * (q - b), valley * (q - b))
    return np.random.default_rng(3).permutation(heights), 100 * norm.sf(b)


def test_two_process_surface_gives_its_two_rq_and_its_transition():
    heights, transition = two_process(100_000, 0.3e-6, 1.7e-6, 20_000)
    values = functional_parameters(Surface(heights, (1e-6,)))
    assert values["Rpq"] == pytest.approx(0.3e-6, rel=1e-9)
    assert values["Rvq"] == pytest.approx(1.7e-6, rel=1e-9)
    assert values["Rmq"] == pytest.approx(transition, rel=1e-9)
    assert transition == pytest.approx(80.0, abs=0.01)


def test_too_few_points_for_the_probability_curve():
    values = functional_parameters(Surface(np.linspace(0, 1e-6, 30), (1e-6,)))
    assert math.isnan(values["Rpq"]) and math.isnan(values["Rmq"]) and math.isfinite(values["Rk"])


def test_keys_and_bad_input():
    profile = Surface(np.sin(np.arange(500) / 7.0) * 1e-6, (1e-6,))
    assert list(functional_parameters(profile)) == list(PROFILE_FUNCTIONAL)
    rows = Surface(np.sin(np.arange(600).reshape(20, 30) / 7.0) * 1e-6, (1e-6, 1e-6))
    assert list(functional_parameters(rows)) == list(AREAL_FUNCTIONAL)
    assert list(functional_parameters(rows, along="x")) == list(PROFILE_FUNCTIONAL)
    with pytest.raises(InputError, match="between 0 and 100"):
        functional_parameters(profile, ratio=120)
    with pytest.raises(InputError, match="increasing order"):
        functional_parameters(profile, volume_ratios=(80, 10))
    with pytest.raises(InputError, match="two valid points"):
        functional_parameters(Surface(np.array([np.nan, 1e-6, np.nan]), (1e-6,)))


def test_along_averages_the_rows():
    rng = np.random.default_rng(5)
    heights = rng.standard_normal((6, 400)) * 1e-6
    mean = functional_parameters(Surface(heights, (1e-6, 1e-6)), along="x")
    each = [functional_parameters(Surface(row, (1e-6,))) for row in heights]
    for key in PROFILE_FUNCTIONAL:
        assert mean[key] == pytest.approx(np.mean([v[key] for v in each]), rel=1e-12), key


heights_lists = st.lists(st.floats(-1e-3, 1e-3, allow_nan=False), min_size=3, max_size=60)


def accuracy(values):
    """``(heights, volumes)``: how closely the curve's heights and volumes are known.
    A height is read as a point's when within ``ROUNDING`` × the largest |height| of
    it, and a read may round once more: twice that. A volume is a sum of n trapezia,
    exact to n·eps of the largest |height|, per unit area."""
    largest = float(np.max(np.abs(values)))
    return 2 * ROUNDING * largest, len(values) * np.finfo(float).eps * largest


@settings(max_examples=200, deadline=None)
@given(heights_lists, st.floats(0, 100))
def test_curve_round_trip_and_monotone(values, mr):
    curve = MaterialRatioCurve(np.array(values))
    height_accuracy, volume_accuracy = accuracy(values)
    height = curve.height_at(mr)
    assert curve.heights[-1] <= height <= curve.heights[0]
    ratio = float(curve.ratio_at(height))  # where several points share the height, the ratio after them all
    assert curve.height_at(ratio) == pytest.approx(height, abs=height_accuracy)
    assert curve.material_volume(0.0) == pytest.approx(0.0, abs=volume_accuracy)
    assert curve.void_volume(100.0) == pytest.approx(0.0, abs=volume_accuracy)
    assert curve.material_volume(mr) <= curve.material_volume(min(100.0, mr + 5)) + volume_accuracy


@settings(max_examples=200, deadline=None)
@given(heights_lists, st.floats(-1e-3, 1e-3), st.floats(0.1, 10))
def test_invariant_under_shift_order_and_nan(values, shift, scale):
    heights = np.array(values)
    assume(np.ptp(heights) > 1e-9)  # not a constant lost in the rounding of the shift
    base = functional_parameters(Surface(heights, (1e-6,)))
    shuffled = np.random.default_rng(0).permutation(heights)
    with_gaps = np.concatenate([shuffled[:1], [np.nan], shuffled[1:], [np.nan]])
    reordered = functional_parameters(Surface(with_gaps, (1e-6,)))
    for key in PROFILE_FUNCTIONAL:  # the same sorted heights: the same numbers
        assert reordered[key] == base[key] or math.isnan(reordered[key]) and math.isnan(base[key]), key
    moved = heights * scale + shift
    other = functional_parameters(Surface(moved, (1e-6,)))
    tolerance = length_tolerance(heights * scale, moved, np.array([shift]))
    for key in ("Rmc", "Rdc"):
        assert other[key] == pytest.approx(base[key] * scale, abs=tolerance), key
    # The core, unless a near-tie of two windows' drops is decided differently by the
    # two roundings, which moves the whole core; Rk, A1, A2 to the heights' accuracy and
    # Mr1, Mr2 as the heights at them (Rpk = 2 A1 / Mr1 is as ill-conditioned as Mr1 is).
    if same_central_region(heights, moved, scale, tolerance):
        assert_same_core(MaterialRatioCurve(heights), MaterialRatioCurve(moved), scale, tolerance)
        assert other["Rk"] == pytest.approx(base["Rk"] * scale, abs=2 * tolerance)


def test_issue_example_core_is_order_free():
    """[1, 0, 1, 0, 0, 0, 2, 1, 2] µm: four windows of the curve drop 1 µm, equal but for
    the rounding of the mean, which the order of the points decided (Rk 2.4 or 3.2 µm,
    Mr1 15 or 0 %). ISO 13565-2 takes the first: 0–40 %, Rk 3.2 µm, Mr1 0 %."""
    heights = np.array([1, 0, 1, 0, 0, 0, 2, 1, 2]) * 1e-6
    orders = [heights, heights[::-1], *(np.random.default_rng(seed).permutation(heights) for seed in range(200))]
    for order in orders:
        values = functional_parameters(Surface(order, (1e-6,)))
        assert values["Rk"] == pytest.approx(3.2e-6, rel=1e-12) and values["Mr1"] == 0 and values["Mr2"] == 100
        assert MaterialRatioCurve(order).core().window == (0.0, 40.0)


@pytest.mark.parametrize("level", [0.1, 1e-3 / 3, 1.1e-3])
def test_level_profile_does_not_depend_on_its_offset(level):
    """A level profile: every break of the two-line fit leaves no residual, and the
    rounding of the mean (not the data) chose the break, Rmq 4.7 % or 95.3 %."""
    flat = functional_parameters(Surface(np.zeros(74), (1e-6,)))
    values = functional_parameters(Surface(np.full(74, level), (1e-6,)))
    assert values["Rpq"] == 0 and values["Rvq"] == 0 and values["Rk"] == 0
    assert values["Rmq"] == flat["Rmq"]


@pytest.mark.parametrize("factor", [1.0, 0.1, 1 / 3, 7.3])
def test_two_level_profile_fit_does_not_depend_on_the_unit(factor):
    """Two levels, 40 points each: the two-line fit's residual is the same at two breaks,
    mirror images, and the rounding of the scaled heights chose between them, swapping
    Rpq and Rvq (Rmq 18.125 or 81.875 %). The tie goes to the break at the lower deviate."""
    unit = functional_parameters(Surface(np.repeat([0.0, 1e-6], 40) + 1e-3, (1e-6,)))
    values = functional_parameters(Surface(np.repeat([0.0, 1e-6], 40) * factor + 1e-3, (1e-6,)))
    assert values["Rmq"] == unit["Rmq"] == pytest.approx(81.875)
    assert values["Rpq"] == pytest.approx(unit["Rpq"] * factor, rel=1e-9)
    assert values["Rvq"] == pytest.approx(unit["Rvq"] * factor, rel=1e-9)


def test_central_region_holds_the_point_at_its_end(shared_data):
    """SurfaceTopography's xy-4.txt, 10 001 points: the 40 % window from 10.66 % ends on
    the point at 50.66 %, which the old window test (ratio ≤ start + 40, in floating
    point) left out. The equivalent straight line is fitted through all 4001 points."""
    from rough.io import read

    curve = MaterialRatioCurve(read(shared_data / "SurfaceTopography" / "xy-4.txt"))
    core = curve.core()
    first = int(round(core.window[0] * (curve.heights.size - 1) / 100))
    slope, top = np.polyfit(curve.ratios[first : first + 4001], curve.heights[first : first + 4001], 1)
    assert core.window[0] == pytest.approx(10.66) and core.slope == pytest.approx(slope, rel=1e-9)
    assert core.top == pytest.approx(top, rel=1e-9)


def test_quantised_gaussian_core_is_order_free():
    """Gaussian heights quantised at 0.1σ tie windows of the curve; reversing the
    profile changed the core of 43 of 300 such profiles of 2000 points."""
    rng = np.random.default_rng(11)
    for _ in range(100):
        heights = np.round(rng.standard_normal(2000) / 0.1) * 0.1 * SIGMA
        forward = functional_parameters(Surface(heights, (1e-6,)))
        backward = functional_parameters(Surface(heights[::-1].copy(), (1e-6,)))
        assert forward == backward


def test_volume_is_the_mean_excess_over_the_level():
    heights = np.random.default_rng(2).gamma(2.0, 1e-6, size=(300, 300))
    surface = Surface(heights, (1e-6, 1e-6))
    curve = MaterialRatioCurve(surface)
    centred = heights - heights.mean()
    for mr in (5.0, 10.0, 50.0, 80.0):
        c = curve.height_at(mr)
        # the piecewise-linear curve gives its end points half a point's share: the two
        # differ by less than the height range over the number of points
        bound = np.ptp(heights) / (heights.size - 1)
        assert abs(curve.material_volume(mr) - np.mean(np.maximum(centred - c, 0))) < bound
        assert abs(curve.void_volume(mr) - np.mean(np.maximum(c - centred, 0))) < bound
        assert curve.material_volume(mr) == pytest.approx(np.mean(np.maximum(centred - c, 0)), rel=2e-3)


# -- surfalize -----------------------------------------------------------------------------
# surfalize 0.19.2 (GPL-3.0, github.com/fredericjs/surfalize) computes the same core as
# rough: the 40 % window of least secant gradient, then the least-squares line in it.
# Run with its curve sampled at every point (AbbottFirestoneCurve(surface, nbins=n);
# bench/compare_surfalize.py), it reproduces rough's Sk, Smr1, Smr2, Sxp, Smr(c) to
# rounding. Its default 10 000 classes move them by up to 2e-4 relative. Its Spk,
# Svk and volumes integrate with trapezoids cut at the closest class (argclosest),
# which drops the sliver between that class and the level: 1e-5 relative on this
# surface, and 30 % of Rpk on its profile fixture, where only 4.6 points stand above
# the core; rough integrates its piecewise-linear curve exactly.


def surfalize_surface():
    return Surface(surfalize_heights(), (0.1, 0.1))


def surfalize_profile():
    np.random.seed(0)
    x = np.arange(1000)
    return Surface(np.sin(x / 50 * 2 * np.pi) + np.random.normal(size=1000) * 0.1, (0.1,))


SURFALIZE_EVERY_POINT = {  # surfalize 0.19.2, nbins = number of points
    "Sk": 2.207387780098818,
    "Smr1": 2.010106787166926,
    "Smr2": 89.97518977619005,
    "Sxp": 1.1688843240730395,
    "Smr": 50.38777835368714,  # at its height 0 + the mean, rough's c = 0
    "Spk": 0.1903400690045363,
    "Svk": 0.39877400834545484,
    "Vmp": 0.014844756562169693,
    "Vmc": 0.797254819607453,
    "Vvc": 0.9248809263860549,
    "Vvv": 0.05629606513395537,
}
SURFALIZE_DEFAULT = {  # surfalize's own test expectations (tests/test_parameters.py, 10 000 classes)
    "Sk": 2.207543,
    "Spk": 0.190107,
    "Svk": 0.398828,
    "Smr1": 2.009438,
    "Smr2": 89.979619,
    "Sxp": 1.168894,
    "Vmp": 0.014831,
    "Vmc": 0.797087,
    "Vvv": 0.056308,
    "Vvc": 0.924853,
}


def test_surfalize_surface_sampled_at_every_point():
    values = functional_parameters(surfalize_surface())
    for key in ("Sk", "Smr1", "Smr2", "Sxp", "Smr"):
        assert values[key] == pytest.approx(SURFALIZE_EVERY_POINT[key], abs=1e-6), key
    for key in ("Spk", "Svk", "Vmp", "Vmc", "Vvc", "Vvv"):  # surfalize's cut trapezoid
        assert values[key] == pytest.approx(SURFALIZE_EVERY_POINT[key], rel=2e-4), key
        assert values[key] != pytest.approx(SURFALIZE_EVERY_POINT[key], rel=1e-9, abs=0), key


def test_surfalize_surface_default_classes():
    values = functional_parameters(surfalize_surface())
    for key, expected in SURFALIZE_DEFAULT.items():
        assert values[key] == pytest.approx(expected, rel=2.5e-3 if key == "Vmp" else 1.5e-3), key


def test_surfalize_profile():
    values = functional_parameters(surfalize_profile())
    every_point = {"Rk": 1.953123856276832, "Mr1": 0.4610062754475223, "Mr2": 80.07200457884917}
    for key, expected in every_point.items():
        assert values[key] == pytest.approx(expected, abs=1e-6), key
    # surfalize's Rpk with every point is 0.0362 (its trapezoid stops at the last point
    # above the core); rough's exact area: the triangle the 4.6 points make with c1.
    curve = MaterialRatioCurve(surfalize_profile())
    core = curve.core()
    above = curve.heights[curve.heights > core.top]
    ratios = curve.ratios[: above.size]
    exact = np.trapezoid(np.r_[above, core.top] - core.top, np.r_[ratios, core.mr1])
    assert values["A1"] == pytest.approx(exact, rel=1e-12)
    assert values["Rpk"] == pytest.approx(2 * exact / core.mr1, rel=1e-12)
    assert values["Rpk"] > 0.0362


def test_mitutoyo_instrument_values(shared_data):
    """Mitutoyo SurfTest export (2.5 mm Gaussian roughness profile: rough's Rz and Rt
    on it are the instrument's to the last digit). The instrument's Rk family is not
    reproduced by rough or by any variant tried (secant or least-squares line, three
    plotting positions, an ISO 13565-1 valley-suppression refilter): it evaluates
    the Rk family on data it does not export. These bounds record how far apart the
    two are; closer agreement would need the instrument's unexported profile."""
    from rough.io import read

    surface = read(shared_data / "SurfaceTopography" / "mitutoyo_2_mock.xlsx")
    values = functional_parameters(surface)
    instrument = {"Rk": 11.440e-6, "Rpk": 2.912e-6, "Rvk": 3.980e-6, "Mr2": 92.617}
    assert values["Rk"] == pytest.approx(instrument["Rk"], rel=0.08)
    assert values["Rpk"] == pytest.approx(instrument["Rpk"], rel=0.08)
    assert values["Rvk"] == pytest.approx(instrument["Rvk"], rel=0.08)
    assert values["Mr2"] == pytest.approx(instrument["Mr2"], abs=0.1)
    assert not values["Mr1"] == pytest.approx(5.822, abs=1)  # 9.93 %: the construction's least stable output
