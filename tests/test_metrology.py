"""Metrology: analytic results, third-party reference values and NaN handling."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rough import Surface
from rough.errors import InputError
from rough.metrology import (
    areal_parameters,
    detect_features,
    detrend,
    mean_line,
    parameters,
    polynomial_form,
    profile_parameters,
    rq_versus_length,
    split,
    transmission,
)
from rough.metrology.features import local_maxima
from rough.metrology.filters import ALPHA, convolved, gaussian_kernel

from conftest import surfalize_heights

# -- analytic results -------------------------------------------------------------------


@pytest.mark.parametrize("amplitude", [1e-6, 3e-3])
def test_sine_amplitude_parameters(amplitude):
    periods, per_period = 40, 250
    x = np.arange(periods * per_period)
    surface = Surface(amplitude * np.sin(2 * np.pi * x / per_period), (1e-6,))
    values = profile_parameters(surface)
    assert values["Ra"] == pytest.approx(2 * amplitude / np.pi, rel=1e-4)
    sampled = 2 / per_period / np.tan(np.pi / per_period) * amplitude  # mean |sin| of the samples
    assert values["Ra"] == pytest.approx(sampled, rel=1e-12)
    assert values["Rq"] == pytest.approx(amplitude / np.sqrt(2), rel=1e-12)
    assert values["Rsk"] == pytest.approx(0, abs=1e-9)
    assert values["Rku"] == pytest.approx(1.5, rel=1e-9)
    assert values["Rp"] == pytest.approx(amplitude, rel=1e-4)
    assert values["Rz"] == pytest.approx(2 * amplitude, rel=1e-4)
    assert values["RSm"] == pytest.approx(per_period * 1e-6, rel=1e-9)
    assert values["peak_density"] * 10e-3 == pytest.approx(periods - 1)


def test_sine_slopes():
    wavelength, amplitude, dx = 1e-3, 1e-5, 1e-6
    x = np.arange(20001) * dx
    surface = Surface(amplitude * np.sin(2 * np.pi * x / wavelength), (dx,))
    derivative = amplitude * 2 * np.pi / wavelength * np.cos(2 * np.pi * x / wavelength)
    seven = profile_parameters(surface, slope="7point")["Rdq"]
    assert seven == pytest.approx(np.sqrt(np.mean(derivative[3:-3] ** 2)), rel=1e-9)
    midpoints = amplitude * 2 * np.pi / wavelength * np.cos(2 * np.pi * (x[:-1] + dx / 2) / wavelength)
    forward = profile_parameters(surface)["Rdq"]
    assert forward == pytest.approx(np.sqrt(np.mean(midpoints**2)) * np.sinc(dx / wavelength), rel=1e-9)


@pytest.mark.parametrize("order", [0, 1, 2, 3, 5])
def test_polynomials_up_to_the_order_are_removed_to_rounding(order):
    rng = np.random.default_rng(order)
    x = np.linspace(-3e-3, 7e-3, 777)
    coefficients = rng.normal(size=order + 1) * 1e-3
    heights = np.polyval(coefficients, x / 1e-3)
    heights[::13] = np.nan
    residual = detrend(Surface(heights, (x[1] - x[0],)), order=order).heights
    assert np.nanmax(np.abs(residual)) <= 1e-12 * np.nanmax(np.abs(heights))
    assert np.array_equal(np.isnan(residual), np.isnan(heights))


@pytest.mark.parametrize("order", [1, 2, 4])
def test_map_polynomials_of_total_degree_are_removed(order):
    y, x = np.mgrid[0:90, 0:130] * 1e-6
    rng = np.random.default_rng(order)
    heights = (
        sum(rng.normal() * (x / 1e-4) ** i * (y / 1e-4) ** j for i in range(order + 1) for j in range(order + 1 - i))
        * 1e-6
    )
    heights[30:40, 50:70] = np.nan
    residual = detrend(Surface(heights, (1e-6, 1e-6)), order=order).heights
    assert np.nanmax(np.abs(residual)) <= 1e-11 * np.nanmax(np.abs(heights))


def test_a_higher_term_is_not_removed():
    x = np.linspace(-1, 1, 500)
    residual = detrend(Surface(x**3, (1e-6,)), order=2).heights
    assert np.abs(residual).max() > 0.1


def test_gaussian_filter_transmits_half_at_the_cutoff():
    cutoff, dx = 0.8e-3, 0.5e-6
    x = np.arange(int(20 * cutoff / dx)) * dx
    line = mean_line(Surface(np.sin(2 * np.pi * x / cutoff), (dx,)), cutoff)
    core = slice(int(cutoff / dx), x.size - int(cutoff / dx))
    gain = np.sqrt(2 * np.mean(line[core] ** 2))
    assert gain == pytest.approx(0.5, abs=0.001)


@pytest.mark.parametrize("ratio", np.geomspace(0.1, 10, 17))
def test_gaussian_transmission_curve(ratio):
    cutoff, dx = 2.5e-3, 2e-6
    wavelength = ratio * cutoff
    x = np.arange(int(max(12 * cutoff, 6 * wavelength) / dx)) * dx
    line = mean_line(Surface(np.cos(2 * np.pi * x / wavelength), (dx,)), cutoff)
    core = slice(int(cutoff / dx), x.size - int(cutoff / dx))
    basis = np.exp(2j * np.pi * x[core] / wavelength)
    gain = abs(np.vdot(basis, line[core])) / abs(np.vdot(basis, np.cos(2 * np.pi * x[core] / wavelength)))
    assert gain == pytest.approx(np.exp(-np.pi * (ALPHA * cutoff / wavelength) ** 2), abs=2e-4)
    assert transmission(cutoff, cutoff) == pytest.approx(0.5, abs=1e-12)


def test_filter_keeps_constants_and_ignores_gaps():
    heights = np.full(4000, 3e-6)
    heights[1000:1100] = np.nan
    line = mean_line(Surface(heights, (1e-6,)), 0.25e-3)
    assert np.nanmax(np.abs(line - 3e-6)) < 1e-18
    assert np.isnan(line[1000:1100]).all()


def test_trimmed_ends_and_corrected_ends():
    surface = Surface(np.random.default_rng(0).normal(size=5000), (1e-6,))
    trimmed = split(surface, 0.8e-3, ends="trim")
    kept = split(surface, 0.8e-3, ends="correct")
    assert kept.points == (5000,)
    assert trimmed.points == (5000 - 2 * 400,)
    assert trimmed.origin[0] == pytest.approx(0.4e-3)
    np.testing.assert_array_equal(trimmed.heights, kept.heights[400:4600])


def test_roughness_and_waviness_add_up():
    surface = Surface(np.cumsum(np.random.default_rng(1).normal(size=3000)) * 1e-8, (1e-6,))
    roughness = split(surface, 0.25e-3, "roughness", "correct").heights
    waviness = split(surface, 0.25e-3, "waviness", "correct").heights
    np.testing.assert_allclose(roughness + waviness, surface.heights, rtol=0, atol=1e-20)


# -- third-party values --------------------------------------------------------------------


def test_surfalize_profile_fixture():
    """surfalize's seeded profile (tests/conftest.py) and its expected values."""
    np.random.seed(0)
    x = np.arange(1000)
    data = np.sin(x / 50 * 2 * np.pi) + np.random.normal(size=1000) * 0.1
    values = profile_parameters(Surface(data, (0.1,)))
    expected = {
        "Ra": 0.638341,
        "Rq": 0.713584,
        "Rp": 1.146977,
        "Rv": 1.179609,
        "Rz": 2.326586,
        "Rt": 2.479203,
        "Rsk": -0.002984,
        "Rku": 1.564224,
        "Rdq": 1.667171,
    }
    for key, value in expected.items():
        assert values[key] == pytest.approx(value, abs=1e-6), key


def test_surfalize_surface_fixture():
    values = areal_parameters(Surface(surfalize_heights(), (0.1, 0.1)), acf="per-lag")  # surfalize's ACF
    expected = {
        "Sa": 0.653132,
        "Sq": 0.745961,
        "Sp": 1.854956,
        "Sv": 1.998661,
        "Sz": 3.853617,
        "Ssk": -0.08144,
        "Sku": 1.818014,
    }
    for key, value in expected.items():
        assert values[key] == pytest.approx(value, abs=1e-6), key
    # Differences explained in the README: surfalize's gradient scheme, and its Str
    # from autocorrelation lags beyond half the map.
    assert values["Sal"] == pytest.approx(4.347147, rel=1e-3)
    assert values["Sdq"] == pytest.approx(4.079605, rel=1e-3)
    assert values["Sdr"] == pytest.approx(276.112693, rel=5e-3)
    assert np.isnan(values["Str"])


@pytest.mark.parametrize(
    "name,expected",
    [
        ("x3p-2.x3p", 0.062070073998443276),
        ("matrix-3.txt", 0.19235602282848963),
        ("matrix-4.txt.gz", 0.06776316911544318),
    ],
)
def test_sdq_is_surfacetopography_rms_gradient(shared_data, name, expected):
    from rough.io import read

    values = areal_parameters(read(shared_data / "SurfaceTopography" / name))
    assert values["Sdq"] == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize(
    "name,sq",
    [
        ("x3p-2.x3p", 7.728033273597876e-08),
        ("matrix-3.txt", 3.5222918750198742e-08),
        ("matrix-4.txt.gz", 1.1745891510991089e-07),
    ],
)
def test_sq_matches_surfacetopography(shared_data, name, sq):
    from rough.io import read

    assert parameters(read(shared_data / "SurfaceTopography" / name))["Sq"] == pytest.approx(sq, rel=1e-9)


def test_profile_rq_of_a_map_matches_surfacetopography(shared_data):
    from rough.io import read

    values = parameters(read(shared_data / "SurfaceTopography/matrix-4.txt.gz"), along="x")
    assert values["Rq"] == pytest.approx(7.198047e-08, rel=1e-6)


def test_hfm_rq_with_and_without_quadratic_detrending(shared_data):
    from rough.io import read

    scan = read(shared_data / "SurfaceTopography/hfm-1.hfm")
    assert parameters(scan)["Rq"] == pytest.approx(0.000906e-3, rel=1e-3)
    assert parameters(detrend(scan, order=2))["Rq"] == pytest.approx(0.000138e-3, rel=1e-3)
    assert parameters(scan)["Rq"] == pytest.approx(0.000905688e-3, rel=1e-6)
    assert parameters(detrend(scan, order=2))["Rq"] == pytest.approx(0.000138057e-3, rel=1e-5)


# -- invalid points ---------------------------------------------------------------------------


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10**6), fraction=st.floats(0.0, 0.6))
def test_dropouts_give_the_parameters_of_the_valid_points(seed, fraction):
    rng = np.random.default_rng(seed)
    heights = np.cumsum(rng.normal(size=600)) * 1e-7
    holes = rng.random(600) < fraction
    holes[[0, -1]] = False
    gappy = profile_parameters(Surface(np.where(holes, np.nan, heights), (1e-6,)))
    alone = profile_parameters(Surface(heights[~holes], (1e-6,)))
    for key in ("Ra", "Rq", "Rsk", "Rku", "Rt"):
        assert gappy[key] == pytest.approx(alone[key], rel=1e-12, abs=1e-300), key


def test_map_dropouts_give_the_parameters_of_the_valid_points():
    rng = np.random.default_rng(5)
    heights = rng.normal(size=(60, 80)) * 1e-6
    holes = rng.random(heights.shape) < 0.2
    gappy = areal_parameters(Surface(np.where(holes, np.nan, heights), (1e-6, 1e-6)))
    alone = heights[~holes]
    centred = alone - alone.mean()
    assert gappy["Sq"] == pytest.approx(np.sqrt(np.mean(centred**2)), rel=1e-12)
    assert gappy["Sa"] == pytest.approx(np.mean(np.abs(centred)), rel=1e-12)
    assert gappy["Sz"] == pytest.approx(centred.max() - centred.min(), rel=1e-12)


@settings(max_examples=30, deadline=None)
@given(
    rows=st.integers(2, 11),
    columns=st.integers(2, 11),
    fraction=st.sampled_from([0.0, 0.3]),
    seed=st.integers(0, 2**16),
)
def test_autocorrelation_is_the_mean_product_over_pairs_of_valid_points(rows, columns, fraction, seed):
    from rough.metrology.spatial import autocorrelation

    rng = np.random.default_rng(seed)
    heights = rng.normal(size=(rows, columns))
    heights[rng.random(heights.shape) < fraction] = np.nan
    heights[0, 0] = 1.5  # at least one valid point
    acf, lag_x, lag_y = autocorrelation(Surface(heights, (2e-6, 3e-6)), "per-lag")
    deviation = heights - np.nanmean(heights)
    zero = np.nanmean(deviation**2)
    for j, ly in enumerate(np.rint(lag_y / 3e-6).astype(int)):
        for i, lx in enumerate(np.rint(lag_x / 2e-6).astype(int)):
            first = deviation[max(0, -ly) : rows - max(0, ly), max(0, -lx) : columns - max(0, lx)]
            second = deviation[max(0, ly) : rows - max(0, -ly), max(0, lx) : columns - max(0, -lx)]
            products = (first * second)[~np.isnan(first * second)]
            expected = products.mean() / zero if products.size and zero > 0 else np.nan
            assert acf[j, i] == pytest.approx(expected, rel=1e-9, abs=1e-12, nan_ok=True), (ly, lx)


@pytest.mark.parametrize("slope", ["2point", "7point"])
def test_gradients_of_a_gappy_map_with_unequal_sides(slope):
    from rough.metrology.heights import SEVEN_POINT

    rng = np.random.default_rng(3)
    heights = rng.normal(size=(37, 90)) * 1e-6
    heights[rng.random(heights.shape) < 0.1] = np.nan
    dx, dy = 1e-6, 2.5e-6
    if slope == "2point":
        gx = (heights[:-1, 1:] - heights[:-1, :-1]) / dx
        gy = (heights[1:, :-1] - heights[:-1, :-1]) / dy
    else:
        gx = sum(w * heights[3:-3, 3 - k : heights.shape[1] - 3 - k] for k, w in zip(range(-3, 4), SEVEN_POINT)) / dx
        gy = sum(w * heights[3 - k : heights.shape[0] - 3 - k, 3:-3] for k, w in zip(range(-3, 4), SEVEN_POINT)) / dy
    squared = (gx**2 + gy**2)[np.isfinite(gx**2 + gy**2)]
    values = areal_parameters(Surface(heights, (dx, dy)), slope=slope)
    assert values["Sdq"] == pytest.approx(np.sqrt(squared.mean()), rel=1e-12)
    assert values["Sdr"] == pytest.approx(100 * np.mean(np.sqrt(1 + squared) - 1), rel=1e-12)


# -- texture, features, scale ----------------------------------------------------------------


def test_texture_direction_is_the_lay():
    rows, columns = np.mgrid[0:256, 0:256]
    along_y = Surface(np.sin(2 * np.pi * columns / 32.0), (1e-6, 1e-6))
    diagonal = Surface(np.sin(2 * np.pi * (columns + rows) / 32.0), (1e-6, 1e-6))
    assert areal_parameters(along_y)["Std"] == pytest.approx(90.0, abs=0.5)
    assert areal_parameters(diagonal)["Std"] == pytest.approx(135.0, abs=0.5)


def test_isotropic_texture_has_str_near_one():
    from scipy.ndimage import gaussian_filter

    heights = gaussian_filter(np.random.default_rng(2).normal(size=(400, 400)), 5)
    values = areal_parameters(Surface(heights, (1e-6, 1e-6)))
    assert values["Str"] > 0.8
    correlation_length = values["Sal"] / 1e-6
    assert 5 < correlation_length < 20


def test_feature_detection_finds_a_bump_and_a_pit():
    dx = 10e-6
    x = np.arange(6000) * dx
    rng = np.random.default_rng(3)
    heights = 2e-6 * rng.normal(size=x.size)
    heights += 60e-6 * np.exp(-(((x - 15e-3) / 2e-3) ** 2)) - 50e-6 * np.exp(-(((x - 40e-3) / 2.5e-3) ** 2))
    features, info = detect_features(Surface(heights, (dx,)))
    assert [f.kind for f in features] == ["peak", "pit"]
    assert features[0].position == pytest.approx(15e-3, abs=0.3e-3)
    assert features[1].position == pytest.approx(40e-3, abs=0.3e-3)
    assert features[0].height > 40e-6 and features[1].height < -30e-6
    assert info["threshold"] == pytest.approx(2 * info["rq_high_frequency"])


def test_mode_a_rejects_wide_gentle_undulations():
    """Mode A's threshold grows with the base width, so a hump as wide as a hill but
    low is rejected where mode B keeps it; a tall narrow rock feature passes both."""
    dx = 20e-6
    x = np.arange(10000) * dx
    heights = 1e-5 * np.random.default_rng(6).normal(size=x.size)
    heights += 5e-3 * np.exp(-(((x - 50e-3) / 1e-3) ** 2)) + 0.4e-3 * np.exp(-(((x - 150e-3) / 15e-3) ** 2))
    surface = Surface(heights, (dx,))
    mode_b, _ = detect_features(surface, polarity="peaks", mode="B")
    mode_a, _ = detect_features(surface, polarity="peaks", mode="A")
    assert [round(f.position, 2) for f in mode_b] == [0.05, 0.15]
    assert [round(f.position, 2) for f in mode_a] == [0.05]


def test_rq_grows_with_length_as_brownian_motion():
    heights = np.cumsum(np.random.default_rng(4).normal(size=2**16)) * 1e-8
    scaling = rq_versus_length(Surface(heights, (1e-6,)))
    assert scaling["hurst"] == pytest.approx(0.5, abs=0.06)
    assert scaling["fractal_dimension"] == pytest.approx(1.5, abs=0.06)
    assert scaling["windows"][-1] == 2**12


# -- refusals --------------------------------------------------------------------------------


def test_profile_shorter_than_the_cutoff():
    with pytest.raises(InputError, match="longer than the data"):
        split(Surface(np.zeros(100), (1e-6,)), 0.8e-3)


def test_all_invalid_points():
    with pytest.raises(InputError, match="no valid points"):
        detrend(Surface(np.full(10, np.nan), (1e-6,)))
    with pytest.raises(InputError, match="no valid points"):
        profile_parameters(Surface(np.full(10, np.nan), (1e-6,)))


def test_order_higher_than_the_data_allow():
    with pytest.raises(InputError, match="order 5"):
        polynomial_form(Surface(np.arange(4.0), (1e-6,)), 5)
    with pytest.raises(InputError, match="order 3"):
        polynomial_form(Surface(np.ones((2, 50)), (1e-6, 1e-6)), 3)


def test_waviness_needs_a_cutoff():
    with pytest.raises(InputError, match="cut-off"):
        detrend(Surface(np.zeros(10), (1e-6,)), keep="waviness")


def test_math_is_consistent():
    assert math.isclose(ALPHA, math.sqrt(math.log(2) / math.pi))


# -- the pieces that stand in for scipy.signal (whose import costs half a second) ------


@settings(max_examples=300, deadline=None)
@given(
    st.lists(st.sampled_from([-np.inf, -2.0, -1.0, 0.0, 1.0, 2.0, np.inf]), max_size=40),
)
def test_local_maxima_are_those_of_find_peaks(values):
    from scipy.signal import find_peaks

    values = np.array(values, dtype=np.float64)
    assert local_maxima(values).tolist() == find_peaks(values)[0].tolist()


@settings(max_examples=150, deadline=None)
@given(
    st.integers(1, 3),
    st.integers(1, 3000),  # up to many segments of the overlap-add
    st.integers(0, 60),
    st.integers(0, 1),
    st.integers(0, 2**32 - 1),
)
def test_the_convolution_is_oaconvolves(lines, length, reach, axis, seed):
    from scipy.signal import oaconvolve

    rng = np.random.default_rng(seed)
    values = rng.standard_normal((lines, length) if axis else (length, lines)) * 10.0 ** rng.uniform(-9, 3)
    kernel = gaussian_kernel(1.0, reach + 0.5)
    expected = oaconvolve(values, kernel.reshape((1, -1) if axis else (-1, 1)), mode="same", axes=axis)
    scale = np.max(np.abs(values)) * np.sum(np.abs(kernel))
    np.testing.assert_allclose(convolved(values, kernel, axis), expected, rtol=0, atol=1e-13 * scale)
