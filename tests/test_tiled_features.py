"""``rough features`` on a map read a strip at a time (rough.metrology.tiled_evaluation):
the exact parameters equal the in-memory ones, order statistics equal a sort's,
the estimated ones stay within their stated bounds, and the command line reports
a map too large for its --memory through the tiled path."""

import json
import math
import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.ndimage import gaussian_filter

import rough
from rough.io import TiledSurface
from rough.metrology import functional_parameters, parameters, tiled_evaluation, tiled_form, tiled_material
from rough.metrology.areal import gradient_means
from rough.metrology.form import form_factors
from rough.metrology.heights import amplitude

from conftest import assert_one_line_error
from conftest import rough as run_rough

EXACT_AREAL = ("Sa", "Sq", "Ssk", "Sku", "Sp", "Sv", "Sz", "Sdq", "Sdr")
EXACT_FUNCTIONAL = ("Smr", "Smc", "Sdc", "Sxp", "Vm", "Vv", "Vmp", "Vmc", "Vvc", "Vvv")
ORDERED = ("Smr", "Smc", "Sdc", "Sxp", "Sk", "Spk", "Svk", "Smr1", "Smr2", "Spq", "Svq", "Smq")
QUANTUM = 1e-8  # m: heights are whole multiples of it, so many tie
PURE_NUMBERS = ("Ssk", "Sku", "Sdq", "Sdr", "Smr")  # near zero (a symmetric map's Ssk), rounding is absolute


def synthetic(n, seed=0, angle=30.0):
    """A quantised, directional map with a hole and scattered invalid points."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:n, 0:n].astype(float)
    a = math.radians(angle)
    z = np.sin(2 * np.pi * (x * math.cos(a) + y * math.sin(a)) / 40) + 3 * gaussian_filter(
        rng.standard_normal((n, n)), 3
    )
    z = np.round(z * 1e-6 / QUANTUM) * QUANTUM
    z[rng.random((n, n)) < 0.001] = np.nan
    z[n // 3 : n // 3 + 40, n // 2 : n // 2 + 90] = np.nan
    return rough.Surface(z, (1e-6, 1.5e-6))


def close(a, b, relative=1e-9, scale=0.0):
    return math.isclose(a, b, rel_tol=relative, abs_tol=relative * scale) or (math.isnan(a) and math.isnan(b))


@pytest.fixture(scope="module")
def map2048():
    surface = synthetic(2048)
    reference = parameters(surface)
    reference.update(functional_parameters(surface))
    found = tiled_evaluation(TiledSurface.of(surface), rows=128)
    return surface, reference, found


def test_exact_group_equals_in_memory(map2048):
    _, reference, found = map2048
    for key in EXACT_AREAL + EXACT_FUNCTIONAL:
        assert close(found.values[key], reference[key], scale=reference["Sq"]), key
    assert found.section["tiles"] == 16 and set(found.section["exact"]) == set(EXACT_AREAL + EXACT_FUNCTIONAL)


def test_estimated_within_stated_bounds(map2048):
    _, reference, found = map2048
    values = found.values
    for key in ("Sk", "Spk", "Svk", "Spq", "Svq"):  # heights: the sampled curve, 65536 of 4 million points
        assert abs(values[key] - reference[key]) <= 2e-3 * reference["Sq"], key
    for key in ("Smr1", "Smr2", "Smq"):  # material ratios, %
        assert abs(values[key] - reference[key]) <= 0.02, key
    assert abs(values["Sal"] / reference["Sal"] - 1) <= 0.02
    assert abs((values["Std"] - reference["Std"] + 90) % 180 - 90) <= 3.0  # degrees, on a directional map
    assert math.isnan(values["Str"]) == math.isnan(reference["Str"]) or math.isnan(values["Str"])
    assert set(found.section["estimated"]) == {"Sal", "Str", "Std", *ORDERED[4:]}


def test_features_undefined_with_one_warning(map2048, caplog):
    surface = map2048[0]
    values = tiled_evaluation(TiledSurface.of(surface.crop(y=(0, 255e-6))), rows=64).values
    assert all(math.isnan(values[key]) for key in rough.metrology.FEATURE)
    warned = [r.getMessage() for r in caplog.records if "Spd" in r.getMessage()]
    assert len(warned) == 1 and "Wolf pruning" in warned[0]


def test_order_statistics_are_a_sorts(map2048, monkeypatch):
    surface = map2048[0]
    tiled = TiledSurface.of(surface)
    ordered = np.sort(surface.heights[~np.isnan(surface.heights)])
    ranks = np.unique(np.random.default_rng(2).integers(0, ordered.size, 5000))
    ranks = np.concatenate([[0, ordered.size - 1], ranks])
    assert np.array_equal(tiled_material.order_statistics(tiled, ranks, rows=100), ordered[ranks])
    monkeypatch.setattr(tiled_material, "GATHER", 1000)  # the refining pass
    assert np.array_equal(tiled_material.order_statistics(tiled, ranks, rows=300), ordered[ranks])


def test_seven_point_slope_exact(map2048):
    surface = map2048[0].crop(y=(0, 600e-6))
    found = tiled_evaluation(TiledSurface.of(surface), slope="7point", rows=64).values
    sdq, sdr = gradient_means(surface, "7point")
    assert close(found["Sdq"], sdq) and close(found["Sdr"], sdr)


@pytest.mark.parametrize("order", [0, 1, 2, 3])
def test_tiled_form_coefficients(map2048, order):
    surface = map2048[0].crop(y=(0, 1000e-6))
    tilt = surface.derive("tilt", {}, heights=surface.heights + 1e-3 * np.linspace(-1, 1, surface.heights.shape[1]))
    _, expected, _ = form_factors(tilt, order)
    found = tiled_form(TiledSurface.of(tilt), order, budget=80 * 70000)
    assert np.allclose(found, expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max())


def test_4096_matches_in_memory():
    surface = synthetic(4096, seed=5)
    found = tiled_evaluation(TiledSurface.of(surface), rows=512).values
    moments = amplitude(surface.heights)
    expected = {"Sa": moments["a"], "Sq": moments["q"], "Ssk": moments["sk"], "Sku": moments["ku"]}
    expected["Sz"] = moments["p"] + moments["v"]
    expected["Sdq"], expected["Sdr"] = gradient_means(surface)
    for key, value in expected.items():
        assert close(found[key], value, scale=moments["q"]), key
    reference = functional_parameters(surface)
    for key in EXACT_FUNCTIONAL:
        assert close(found[key], reference[key], scale=moments["q"]), key
    for key in ("Sk", "Spk", "Svk", "Spq", "Svq"):
        assert abs(found[key] - reference[key]) <= 2e-3 * moments["q"], key


small_maps = st.tuples(
    st.integers(9, 40), st.integers(9, 30), st.integers(0, 2**32 - 1), st.integers(2, 12), st.booleans()
)


def small(ny, nx, seed, levels, holes):
    rng = np.random.default_rng(seed)
    z = rng.integers(-levels, levels + 1, (ny, nx)) * QUANTUM
    if holes:
        z[rng.random((ny, nx)) < 0.1] = np.nan
        z[0, 0] = z[-1, -1] = QUANTUM
    return rough.Surface(z, 1e-6)


@settings(max_examples=25, deadline=None)
@given(small_maps, st.integers(1, 40))
def test_strip_height_changes_no_exact_value(shape, rows):
    surface = small(*shape)
    whole = tiled_evaluation(TiledSurface.of(surface), rows=surface.heights.shape[0]).values
    strips = tiled_evaluation(TiledSurface.of(surface), rows=rows).values
    for key in ORDERED:  # order statistics less the exactly rounded mean: the very same numbers
        assert strips[key] == whole[key] or (math.isnan(strips[key]) and math.isnan(whole[key])), key
    for key in EXACT_AREAL + EXACT_FUNCTIONAL:  # sums in another order: rounding, in the key's own unit
        assert close(strips[key], whole[key], 1e-12, 1.0 if key in PURE_NUMBERS else QUANTUM), key
    reference = functional_parameters(surface)
    for key in EXACT_FUNCTIONAL:
        assert close(strips[key], reference[key], 1e-9, 1.0 if key in PURE_NUMBERS else QUANTUM), key


def test_small_map_sampled_curve_is_the_whole_curve():
    """With no more points than the sampled curves hold, the core and the
    probability fit are the in-memory ones."""
    surface = small(60, 50, 11, 40, True)
    found = tiled_evaluation(TiledSurface.of(surface), rows=16).values
    reference = functional_parameters(surface)
    for key in ORDERED:
        assert close(found[key], reference[key], 1e-9, QUANTUM), key


@settings(max_examples=25, deadline=None)
@given(small_maps, st.randoms(use_true_random=False))
def test_permuted_rows_keep_the_material_ratio(shape, random):
    surface = small(*shape)
    order = list(range(surface.heights.shape[0]))
    random.shuffle(order)
    permuted = surface.derive("permute", {}, heights=surface.heights[order])
    one, other = (tiled_evaluation(TiledSurface.of(s), rows=8).values for s in (surface, permuted))
    for key in ORDERED:  # from order statistics and the exactly rounded mean: the very same numbers
        assert one[key] == other[key] or (math.isnan(one[key]) and math.isnan(other[key])), key
    for key in ("Vm", "Vv", "Vmp", "Vmc", "Vvc", "Vvv", "Sa", "Sq", "Sz"):  # sums in another order
        assert close(one[key], other[key], 1e-12, QUANTUM), key


def test_cli_geotiff_in_tiles(tmp_path):
    rasterio = pytest.importorskip("rasterio")
    surface = synthetic(1024, seed=7)
    path = tmp_path / "big.tif"
    profile = dict(driver="GTiff", height=1024, width=1024, count=1, dtype="float64", tiled=True)
    profile |= dict(blockxsize=256, blockysize=256, compress="deflate", nodata=np.nan)
    profile |= dict(crs="EPSG:32633", transform=rasterio.Affine(1.0, 0.0, 5e5, 0.0, -1.0, 4e6))  # metres
    with rasterio.open(path, "w", **profile) as target:
        target.write(surface.heights, 1)
    document = json.loads(run_rough("features", "--json", path, "--memory", "16MB", check=True).stdout)
    whole = rough.read(str(path))
    reference = parameters(whole)
    reference.update(functional_parameters(whole))
    for key in EXACT_AREAL + EXACT_FUNCTIONAL:
        assert close(document[key], reference[key], scale=reference["Sq"]), key
    assert document["tiled"]["tiles"] > 1 and "Sal" in document["tiled"]["estimated"]
    assert document["Spd"] is None and len(document["amplitude_density"]["density"]) == 50
    text = run_rough("features", path, "--memory", "16MB", check=True).stdout.decode()
    assert sum("read in" in line and "estimated: Sal" in line for line in text.splitlines()) == 1
    refused = run_rough("features", "--cutoff", "0.1mm", "--along", "x", path, "--memory", "16MB")
    assert_one_line_error(refused, "--cutoff, --along", "tiles")


def test_tasks_travel_between_processes(map2048, monkeypatch):
    """Every strip's task and its item pickle, as a worker process or a cluster needs."""
    calls = []

    def through_pickle(function, items, *, jobs=1, scheduler=None):
        for item in items:
            function, item = pickle.loads(pickle.dumps((function, item)))
            calls.append(function.__name__)
            yield function(item)

    monkeypatch.setattr(rough.tasks, "map_ordered", through_pickle)
    surface = map2048[0].crop(y=(0, 300e-6))
    expected = tiled_evaluation(TiledSurface.of(surface), rows=64, jobs=2).values
    assert {"first_pass", "second_pass", "gather_cells", "level_sums"} <= set(calls)
    monkeypatch.undo()
    found = tiled_evaluation(TiledSurface.of(surface), rows=64).values
    assert all(close(found[key], expected[key], 0.0) for key in found)


def test_constant_and_nearly_empty_maps():
    flat = tiled_evaluation(TiledSurface.of(rough.Surface(np.full((40, 30), 2e-6), 1e-6)), rows=8).values
    assert flat["Sq"] == 0 and math.isnan(flat["Ssk"]) and flat["Smc"] == 0 and math.isnan(flat["Sal"])
    empty = np.full((40, 30), np.nan)
    empty[5, 5] = 1e-6
    with pytest.raises(rough.InputError, match="fewer than two valid points"):
        tiled_evaluation(TiledSurface.of(rough.Surface(empty, 1e-6)), rows=8)
    with pytest.raises(rough.InputError, match="increasing order"):
        tiled_evaluation(TiledSurface.of(rough.Surface(np.ones((40, 30)), 1e-6)), dc_ratios=(80, 10))
