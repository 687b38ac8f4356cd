"""The faster routes give the numbers the slower ones gave, to the last bit: BLAS on
one thread around the fits (rough.compiled.one_blas_thread), the steepest descent
that now settles ties and plateaus itself (rough.metrology.flooding.descend), and the
probability fit's running sums in one compiled pass (rough.metrology.material_ratio)."""

import math

import numpy as np
import pytest
import threadpoolctl
from scipy import ndimage

from rough import Surface
from rough.compiled import compiled, one_blas_thread
from rough.fractal import whittle
from rough.fractal.scaling import ring_bins
from rough.fractal.sectors import rose
from rough.fractal.synth_map import synthesize_map
from rough.metrology import flooding, functional_parameters, segment
from rough.metrology import material_ratio as mr


def blas_threads():
    return {pool["num_threads"] for pool in threadpoolctl.threadpool_info() if pool["user_api"] == "blas"}


# ---------------------------------------------------------------------------------
# 1. One BLAS thread around the fits


def test_one_blas_thread_limits_inside_and_restores_after():
    before = blas_threads()

    @one_blas_thread
    def inner():
        return blas_threads()

    @one_blas_thread
    def outer():
        return blas_threads(), inner(), blas_threads()

    assert outer() == ({1}, {1}, {1}) or not before
    assert blas_threads() == before

    @one_blas_thread
    def failing():
        raise ValueError("inside")

    with pytest.raises(ValueError, match="inside"):
        failing()
    assert blas_threads() == before


@pytest.fixture(scope="module")
def anisotropic():
    anisotropy = (2.2, 1e-6, 2.5, 3e-6, math.radians(30))
    return synthesize_map((128, 128), (1e-5, 1e-5), None, anisotropy=anisotropy, seed=3)


def test_the_fits_on_one_thread_are_the_fits_on_many(anisotropic):
    """The same sector fits, bit for bit, with BLAS on one thread (the wrapper) and on
    as many as the machine gives (the function it wraps)."""
    rings = whittle.ring_spectrum(*whittle.windowed_map(anisotropic, 1), anisotropic.spacing, 1e3, 4e4, 800.0, None)
    bins = ring_bins(rings, anisotropic.spacing)
    options = whittle.Options()
    for limited, plain in (
        (whittle.ring_fit(bins, 1e-5, options), whittle.ring_fit.__wrapped__(bins, 1e-5, options)),
        (
            whittle.band_outcome(bins, whittle.MAP_RANGE, None, options).fit,
            whittle.band_outcome.__wrapped__(bins, whittle.MAP_RANGE, None, options).fit,
        ),
    ):
        limited = limited["fit"] if isinstance(limited, dict) else limited
        plain = plain["fit"] if isinstance(plain, dict) else plain
        assert (limited.exponent, limited.prefactor, limited.noise_variance, limited.nll) == (
            plain.exponent,
            plain.prefactor,
            plain.noise_variance,
            plain.nll,
        )


def test_the_rose_is_the_same_whatever_the_threads(anisotropic):
    first = rose(anisotropic, step=30)
    with threadpoolctl.threadpool_limits(1):
        second = rose(anisotropic, step=30)
    assert first.as_dict() == second.as_dict()


# ---------------------------------------------------------------------------------
# 2. The steepest descent that settles ties and plateaus (its equality with
# scikit-image's flood: tests/test_segmentation.py)

DESCENT = (
    flooding._descend_rows,
    flooding._visit,
    flooding._first_taken,
    flooding._flood_plateau,
    flooding._lowest_label,
)


@pytest.mark.parametrize("kind", ["hills", "dales"])
def test_segment_gives_the_motifs_of_the_flood(kind, monkeypatch):
    image = ndimage.gaussian_filter(np.random.default_rng(7).standard_normal((200, 180)), 2.0)
    surface = Surface(np.round(image * 10000) / 10000 * 1e-6, 1e-6)  # ties and small plateaus
    monkeypatch.setattr(flooding, "COMPILED_MIN", 0)
    monkeypatch.setattr(flooding, "BAND", 97)
    descended = segment(surface, kind, 2.0)
    monkeypatch.setattr(flooding, "COMPILED_MIN", math.inf)
    flooded = segment(surface, kind, 2.0)
    assert np.array_equal(descended.labels, flooded.labels)
    assert repr(descended.motifs) == repr(flooded.motifs)


def test_compiled_helpers_are_compiled_with_the_function_and_stay_plain():
    image = np.round(ndimage.gaussian_filter(np.random.default_rng(2).standard_normal((60, 50)), 2.0) * 3000)
    valid = np.ones(image.shape, bool)
    markers, _ = flooding.basin_markers(image, valid)
    heights, marked = image.ravel(), markers.ravel()
    results = []
    for kernel in (
        flooding._descend_rows,
        compiled(*DESCENT),
    ):
        labels = markers.copy()
        stack, plateau = np.empty(4, np.int64), np.empty(flooding.PLATEAU, np.int64)
        stack = kernel(heights, valid.ravel(), labels.ravel(), marked, image.shape[1], 0, image.size, stack, plateau)
        results.append((stack.size > 0, labels))
    assert results[0][0] == results[1][0] and np.array_equal(results[0][1], results[1][1])
    assert flooding._visit(10, 55, 44) == 4  # plain Python still


# ---------------------------------------------------------------------------------
# 3. The probability fit's running sums


@pytest.mark.parametrize("seed", range(3))
def test_the_compiled_running_sums_are_numpys_cumulative_sums(seed, monkeypatch):
    rng = np.random.default_rng(seed)
    n = 50_000
    q = np.sort(rng.standard_normal(n))
    h = np.round(rng.standard_normal(n), 2)[::-1]  # a reversed view, with ties
    h[:10] = -0.0
    ends = np.append(np.arange(2500, n - 2500, 37), n)
    monkeypatch.setattr(mr, "COMPILED_SUMS", 0)
    fast = mr._sums_at(q, h, ends)
    monkeypatch.setattr(mr, "COMPILED_SUMS", math.inf)
    slow = mr._sums_at(q, h, ends)
    assert fast.keys() == slow.keys()
    for name in slow:
        assert fast[name].tobytes() == slow[name].tobytes(), name


@pytest.mark.parametrize("shape", [(300, 257), (4001,)])
def test_the_material_ratio_set_is_the_same_on_either_route(shape, monkeypatch):
    rng = np.random.default_rng(11)
    heights = ndimage.gaussian_filter(rng.standard_normal(shape), 2.0) * 1e-6
    heights[rng.random(shape) < 0.01] = np.nan
    surface = Surface(heights, *(1e-6,) * len(shape))
    monkeypatch.setattr(mr, "COMPILED_SUMS", 0)
    fast = functional_parameters(surface)
    monkeypatch.setattr(mr, "COMPILED_SUMS", math.inf)
    slow = functional_parameters(surface)
    assert np.array(list(fast.values())).tobytes() == np.array(list(slow.values())).tobytes()


@pytest.mark.parametrize(
    ("row", "labels"),
    [
        ([0.0, 2.0, 0.0], [1, 1, 2]),
        ([0.0, 2.0, 0.5], [1, 1, 2]),
        ([0.5, 2.0, 0.0], [1, 2, 2]),
        ([0.0, 0.0, 2.0], [1, 1, 1]),
    ],
)
def test_two_pits_of_one_height_beside_a_point_are_settled_by_the_descent(row, labels):
    """Two pits of one height (0 beside 2 beside 0): no longer left to scikit-image's
    heap; the pit first in row-major order takes the point between."""
    image = np.array([row])
    valid = np.ones(image.shape, bool)
    markers, _ = flooding.basin_markers(image, valid)
    assert flooding.descend(image, valid, markers).tolist() == [labels]
