"""Property tests: every ISO parameter whose definition depends only on the heights'
distribution (the height-distribution parameters, the material-ratio family, the
amplitude density) is the same for any order of the points, with or without invalid
points among them, and scales and shifts as its definition says.

The data include the inputs that break naive code: a few quantised levels (ties in
the material-ratio curve's windows and plateaus), values drawn from a small pool,
exactly repeated values, and general floats, scaled by powers of two and by awkward
factors.

Tolerances follow float accuracy. The material-ratio family works on the sorted
valid heights, so for a permutation (with NaN holes or not) it must agree exactly,
and under scaling by a power of two too (every operation on the heights is then
exact). Elsewhere a sum of n terms is exact to n·eps of the sum of their magnitudes
(the worst case of floating-point summation), and every length here is built from
such sums of heights no larger than the largest |height| H: lengths agree to
``TOLERANCE · n · eps · H``; ratios (material ratios) are compared through the curve,
as the heights at them, since on a nearly flat stretch of the curve a ratio moves a
long way for a last-bit change of a height.
"""

import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rough import Surface
from rough.metrology import (
    AREAL_FUNCTIONAL,
    PROFILE_FUNCTIONAL,
    MaterialRatioCurve,
    amplitude_density,
    areal_parameters,
    functional_parameters,
    profile_parameters,
)
from rough.metrology.heights import ROUNDING

EXAMPLES = settings(max_examples=max(1000, settings.default.max_examples), deadline=None)
EPS = np.finfo(float).eps
TOLERANCE = 16  # a few roundings per operation, on top of the worst-case n·eps of a sum

STEPS = [2.0**-20, 1e-6, 0.1e-6, 1e-6 / 3, 0.7e-9, 25e-6]  # quantisation steps, metres
OFFSETS = [0.0, 1e-3, -2.5e-6, 1e-6 / 3, 0.1]
AWKWARD = [0.1, 1 / 3, 7.3, 1e-6, 1e6 / 7, 3.0]
magnitudes = st.one_of(st.just(0.0), st.floats(1e-12, 1e-3), st.floats(-1e-3, -1e-12))  # no subnormals


@st.composite
def heights(draw, min_size=2, max_size=160):
    """Heights in metres: quantised on a few levels, drawn from a small pool, or any floats."""
    size = draw(st.integers(min_size, max_size))
    kind = draw(st.sampled_from(["levels", "pool", "floats"]))
    if kind == "levels":
        top = draw(st.integers(0, 5))
        codes = np.array(draw(st.lists(st.integers(0, top), min_size=size, max_size=size)), dtype=float)
        return codes * draw(st.sampled_from(STEPS)) + draw(st.sampled_from(OFFSETS))
    if kind == "pool":
        pool = draw(st.lists(magnitudes, min_size=1, max_size=4))
        return np.array(draw(st.lists(st.sampled_from(pool), min_size=size, max_size=size)))
    return np.array(draw(st.lists(magnitudes, min_size=size, max_size=size)))


@st.composite
def shuffled(draw, values):
    """``values`` in another order, with NaN holes put anywhere."""
    order = draw(st.permutations(range(values.size)))
    holes = draw(st.lists(st.integers(0, values.size), max_size=5))
    return np.insert(values[list(order)], holes, np.nan)


@st.composite
def map_and_shuffled(draw, values, rows):
    """A map of ``rows`` rows from ``values`` (cycled to fill them), and its heights in
    another order with ``rows`` NaN holes put anywhere, one column wider."""
    columns = max(2, values.size // rows)
    values = np.resize(values, rows * columns)
    order = list(draw(st.permutations(range(values.size))))
    holes = draw(st.lists(st.integers(0, values.size), min_size=rows, max_size=rows))
    return values.reshape(rows, columns), np.insert(values[order], holes, np.nan).reshape(rows, columns + 1)


def same(a, b):
    """Equal, counting NaN as equal to NaN."""
    return a == b or (math.isnan(a) and math.isnan(b))


def length_tolerance(*arrays):
    """``TOLERANCE · n · eps · H`` for the valid points of ``arrays`` (see the module docstring)."""
    valid = np.concatenate([a[~np.isnan(a)] for a in arrays])
    return TOLERANCE * valid.size * EPS * float(np.max(np.abs(valid)))


def quiet(function, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return function(*args, **kwargs)


# -- the material-ratio family: exact ----------------------------------------------------


@EXAMPLES
@given(st.data(), heights())
def test_profile_material_ratio_family_is_order_free(data, values):
    other = data.draw(shuffled(values))
    base = functional_parameters(Surface(values, (1e-6,)))
    moved = functional_parameters(Surface(other, (1e-6,)))
    for key in PROFILE_FUNCTIONAL:
        assert same(moved[key], base[key]), (key, base[key], moved[key])


@EXAMPLES
@given(st.data(), heights(min_size=4, max_size=150), st.integers(2, 6))
def test_areal_material_ratio_family_is_order_free(data, values, rows):
    values, other = data.draw(map_and_shuffled(values, rows))
    base = functional_parameters(Surface(values, (1e-6, 1e-6)))
    moved = functional_parameters(Surface(other, (1e-6, 1e-6)))
    for key in AREAL_FUNCTIONAL:
        assert same(moved[key], base[key]), (key, base[key], moved[key])


@EXAMPLES
@given(st.data(), heights(), st.floats(-2e-3, 2e-3), st.floats(0, 100))
def test_curve_is_order_free(data, values, level, ratio):
    other = data.draw(shuffled(values))
    a, b = MaterialRatioCurve(values), MaterialRatioCurve(other)
    assert np.array_equal(a.heights, b.heights) and np.array_equal(a.ratios, b.ratios)
    assert a.core() == b.core()
    assert a.ratio_at(level) == b.ratio_at(level) and a.height_at(ratio) == b.height_at(ratio)
    assert a.material_volume(ratio) == b.material_volume(ratio) and a.void_volume(ratio) == b.void_volume(ratio)
    fits = a.probability(), b.probability()
    assert all(same(x, y) for x, y in zip(*(vars(fit).values() for fit in fits)))


@EXAMPLES
@given(heights(), st.integers(-8, 8))
def test_material_ratio_scales_exactly_by_powers_of_two(values, power):
    factor = 2.0**power
    base = functional_parameters(Surface(values, (1e-6,)))
    scaled = functional_parameters(Surface(values * factor, (1e-6,)))
    for key, (unit, _) in PROFILE_FUNCTIONAL.items():
        expected = base[key] * factor if unit in ("m", "m·%") else base[key]
        assert same(scaled[key], expected), (key, expected, scaled[key])


def least_drop_windows(curve, band):
    """The start ratios of the 40 % windows whose secant drop, by its definition
    ``h(mr) - h(mr + 40 %)``, is within ``band`` of the least."""
    starts = curve.ratios[: (3 * (curve.ratios.size - 1)) // 5 + 1]  # up to 60 %
    drops = curve.heights[: starts.size] - np.interp(starts + 40, curve.ratios, curve.heights)
    return starts[drops <= drops.min() + band]


def same_central_region(values, moved, factor, tolerance):
    """Whether the curves of ``values`` and ``moved`` (``values`` × ``factor``, shifted,
    to within rounding) take the same central region. When not, both must be among the
    windows whose drops differ by less than the two curves' tie tolerances (ROUNDING
    times the largest height each was given) and the drops' rounding: a near-tie that
    the precision of the two sets of heights decides differently."""
    curve = MaterialRatioCurve(values)
    a, b = curve.core().window, MaterialRatioCurve(moved).core().window
    if a != b:
        band = ROUNDING * (np.max(np.abs(values)) + np.max(np.abs(moved)) / factor) + 2 * tolerance / factor
        assert {a[0], b[0]} <= set(least_drop_windows(curve, band)), (a, b)
    return a == b


def assert_same_core(curve, other, factor, tolerance):
    """The cores of ``curve`` and of ``other`` (its heights × ``factor``, to within
    rounding) agree: lengths to ``tolerance``, areas to ``tolerance`` × 100 %, and the
    material ratios as the heights the curves have there."""
    a, b = curve.core(), other.core()
    assert b.top == pytest.approx(a.top * factor, abs=tolerance)
    assert b.bottom == pytest.approx(a.bottom * factor, abs=tolerance)
    assert b.peak_area == pytest.approx(a.peak_area * factor, abs=100 * tolerance)
    assert b.valley_area == pytest.approx(a.valley_area * factor, abs=100 * tolerance)
    for level, ratio, moved_ratio in ((a.top, a.mr1, b.mr1), (a.bottom, a.mr2, b.mr2)):
        at = float(np.clip(level, curve.heights[-1], curve.heights[0]))  # Smr(c) is 0 or 100 % beyond the curve
        assert curve.height_at(moved_ratio) == pytest.approx(at, abs=tolerance / factor)
        assert other.height_at(ratio) == pytest.approx(at * factor, abs=tolerance)


@EXAMPLES
@given(heights(min_size=4), st.sampled_from(AWKWARD), st.sampled_from([0.0, *OFFSETS, 1e-6 / 7]))
def test_material_ratio_scales_and_shifts(values, factor, shift):
    moved = values * factor + shift
    tolerance = length_tolerance(values * factor, moved, np.array([shift]))
    curve, other = MaterialRatioCurve(values), MaterialRatioCurve(moved)
    assert other.heights == pytest.approx(curve.heights * factor, abs=tolerance)
    for ratio in (2.5, 10.0, 50.0, 80.0):
        assert other.height_at(ratio) == pytest.approx(curve.height_at(ratio) * factor, abs=tolerance)
        assert other.material_volume(ratio) == pytest.approx(curve.material_volume(ratio) * factor, abs=tolerance)
        assert other.void_volume(ratio) == pytest.approx(curve.void_volume(ratio) * factor, abs=tolerance)
    if same_central_region(values, moved, factor, tolerance):
        assert_same_core(curve, other, factor, tolerance)
    # Not Rpq, Rvq, Rmq: the two-line fit's break minimises a residual that is flat about
    # its least, and the rounding of the scaled heights may move it to another near-least
    # break; they are checked under permutation and exact (power-of-two) scaling.


# -- height distribution and amplitude density -------------------------------------------


def moment_tolerances(values):
    """Absolute tolerances for (lengths, skewness, kurtosis). The mean is exact to about
    n·eps·H, which moves Rsk by 3 (and Rku by 4 Rsk) times that over Rq, and the sums of
    d³, d⁴ are exact to n·eps·H times (max |d| / Rq)^(1, 2) relative to Rq³, Rq⁴. None
    (undefined) for data constant to within rough's rounding rule (ROUNDING = 64 eps)."""
    valid = values[~np.isnan(values)]
    deviations = valid - valid.mean()
    rq = float(np.sqrt(np.mean(deviations**2)))
    if np.ptp(valid) <= 2 * ROUNDING * float(np.max(np.abs(valid))):
        return length_tolerance(values), None, None
    condition, spread = length_tolerance(values) / rq, float(np.max(np.abs(deviations))) / rq
    return length_tolerance(values), 4 * condition * (1 + spread), 8 * condition * spread * (1 + spread)


PROFILE_DISTRIBUTION = ("Ra", "Rq", "Rsk", "Rku", "Rp", "Rv", "Rz", "Rt")  # over one sampling length: Pa … Pt
AREAL_DISTRIBUTION = ("Sa", "Sq", "Ssk", "Sku", "Sp", "Sv", "Sz")


def assert_distribution_close(base, moved, keys, tolerances):
    length, skewness, kurtosis = tolerances
    for key in keys:
        tolerance = {"sk": skewness, "ku": kurtosis}.get(key[-2:], length)
        if tolerance is None:  # Rsk, Rku of a constant, or within the rounding of one
            continue
        assert moved[key] == pytest.approx(base[key], abs=tolerance, nan_ok=True), (key, base[key], moved[key])


@EXAMPLES
@given(st.data(), heights())
def test_primary_profile_height_distribution_is_order_free(data, values):
    other = data.draw(shuffled(values))
    base = quiet(profile_parameters, Surface(values, (1e-6,)), sampling_lengths=1)
    moved = quiet(profile_parameters, Surface(other, (1e-6,)), sampling_lengths=1)
    assert_distribution_close(base, moved, PROFILE_DISTRIBUTION, moment_tolerances(values))


@EXAMPLES
@given(st.data(), heights(min_size=4, max_size=64), st.integers(2, 4))
def test_areal_height_distribution_is_order_free(data, values, rows):
    values, other = data.draw(map_and_shuffled(values, rows))
    base = quiet(areal_parameters, Surface(values, (1e-6, 1e-6)))
    moved = quiet(areal_parameters, Surface(other, (1e-6, 1e-6)))
    assert_distribution_close(base, moved, AREAL_DISTRIBUTION, moment_tolerances(values))


@EXAMPLES
@given(heights(), st.sampled_from([*AWKWARD, 2.0**-7, 8.0]), st.sampled_from([0.0, *OFFSETS, 1e-6 / 7]))
def test_primary_profile_height_distribution_scales_and_shifts(values, factor, shift):
    moved = values * factor + shift
    base = quiet(profile_parameters, Surface(values, (1e-6,)), sampling_lengths=1)
    other = quiet(profile_parameters, Surface(moved, (1e-6,)), sampling_lengths=1)
    length, skewness, kurtosis = moment_tolerances(moved)
    # rough counts deviations within ROUNDING of the mean as none (a level profile)
    length += 2 * ROUNDING * float(np.max(np.abs(moved))) + length_tolerance(values * factor, np.array([shift]))
    scaled = {key: base[key] * factor if key not in ("Rsk", "Rku") else base[key] for key in PROFILE_DISTRIBUTION}
    assert_distribution_close(scaled, other, PROFILE_DISTRIBUTION, (length, skewness, kurtosis))


@EXAMPLES
@given(st.data(), heights(), st.integers(1, 60))
def test_amplitude_density_is_order_free(data, values, bins):
    other = data.draw(shuffled(values))
    centres, density = amplitude_density(Surface(values, (1e-6,)), bins=bins)
    moved_centres, moved_density = amplitude_density(Surface(other, (1e-6,)), bins=bins)
    assert moved_centres == pytest.approx(centres, abs=length_tolerance(values))
    assert np.array_equal(moved_density, density)


def test_amplitude_density_of_a_point_on_a_bin_edge():
    """1/30 µm + (0.1, 0, 0, 0, 0.2, 0) µm: the point at 0.1 µm lies on the edge between
    the two bins, and the rounding of the mean, which the order of the points decided,
    put it in one bin or the other (5 and 1 points, or 4 and 2)."""
    heights = 1e-6 / 30 + np.array([0.1, 0, 0, 0, 0.2, 0]) * 1e-6
    counts = set()
    for seed in range(50):
        centres, density = amplitude_density(Surface(np.random.default_rng(seed).permutation(heights), (1e-6,)), 2)
        counts.add(tuple(np.round(density * (centres[1] - centres[0]) * heights.size)))
    assert len(counts) == 1
