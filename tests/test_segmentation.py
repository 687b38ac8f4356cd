"""Watershed segmentation, Wolf pruning and the ISO 25178-2 feature parameters
(rough.metrology.segmentation)."""

import math
from unittest import mock

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import ndimage
from skimage.segmentation import watershed

from rough import InputError, Surface
from rough.metrology import flooding
from rough.metrology.heights import centred
from rough.metrology.segmentation import EDGES, FEATURE, feature_parameters, segment

A = 1e-6  # egg-box amplitude, m
DX = 1e-6  # spacing, m


def egg_box(points, periods, amplitude=A):
    """z = A (cos 2πx/λ + cos 2πy/λ), λ = ``points`` spacings, over ``periods`` whole
    periods on each axis, sampled so that a peak falls on a point: x = (i - c)·dx with
    c = (points - 1) // 2. With an odd number of points per period, the lines between
    the hills (x = ±λ/2 from a peak, through the pits and the saddles) fall half-way
    between points, so every hill is exactly points × points points and its peak is on
    a point; the pits are then between points. No sampling puts both the peaks and the
    pits on points and the lines between the hills between points (those lines pass
    through the pits), so the dales are tested on -z, whose pits are on points; and
    the ten-point height on an even number of points per period, which puts both the
    peaks and the pits on points (and the lines between the motifs on points)."""
    u = 2 * np.pi * (np.arange(points * periods) - (points - 1) // 2) / points
    return amplitude * (np.cos(u)[None, :] + np.cos(u)[:, None])


def indices(surface, motif):
    """(row, column) of a motif's peak or pit."""
    x0, y0 = surface.origin
    dx, dy = surface.spacing
    return round((motif.y - y0) / dy), round((motif.x - x0) / dx)


def smoothed_noise(shape, seed, sigma=1.5):
    rng = np.random.default_rng(seed)
    return ndimage.gaussian_filter(rng.standard_normal(shape), sigma) * 1e-6


# ---------------------------------------------------------------------------------
# 1. The egg box


@pytest.mark.parametrize("kind", ["hills", "dales"])
def test_egg_box_motifs_are_whole_periods(kind):
    """Hills of z with the peaks on points, and (by symmetry) dales of -z with the
    pits on points: 5 × 5 motifs of exactly n × n points, 3 × 3 of them inside."""
    n, k = 31, 5
    heights = egg_box(n, k) if kind == "hills" else -egg_box(n, k)
    surface = Surface(heights, DX)
    result = segment(surface, kind)
    assert len(result.motifs) == k * k
    assert sum(not motif.edge for motif in result.motifs) == (k - 2) ** 2
    assert np.bincount(result.labels.ravel())[1:].tolist() == [n * n] * (k * k)
    lam = n * DX
    for motif in result.motifs:
        assert motif.area == pytest.approx(lam**2, rel=1e-14)
        row, column = indices(surface, motif)
        assert (row % n, column % n) == ((n - 1) // 2, (n - 1) // 2)  # peak / pit on its point
    discrete = A * (2 - 2 * math.cos(2 * math.pi * DX / lam)) / DX**2  # central differences of the cosines
    for motif in result.motifs:
        if not motif.edge:
            sign = 1 if kind == "hills" else -1
            assert motif.curvature == pytest.approx(sign * discrete, rel=1e-9)
            assert sign * motif.height == pytest.approx(2 * A, rel=1e-12)


def test_egg_box_feature_parameters():
    n, k = 31, 5
    lam = n * DX
    hills = Surface(egg_box(n, k), DX)  # peaks on points
    dales = Surface(-egg_box(n, k), DX)  # pits on points
    values = feature_parameters(hills)
    nx, ny = hills.points
    assert values["Spd"] == (k - 2) ** 2 / (nx * DX * ny * DX)
    assert values["Sha"] == pytest.approx(lam**2, rel=1e-14)
    assert values["S5p"] == pytest.approx(2 * A, rel=1e-12)
    assert values["Spc"] == pytest.approx(A * (2 - 2 * math.cos(2 * math.pi * DX / lam)) / DX**2, rel=1e-9)
    low = feature_parameters(dales)
    assert low["Sda"] == pytest.approx(lam**2, rel=1e-14)
    assert low["S5v"] == pytest.approx(2 * A, rel=1e-12)
    # Volume. Above its saddle (at height 0) a hill is the diamond |u| + |v| < π where
    # cos u + cos v > 0, and ∫∫ (cos u + cos v) over it is 16: V = 16 A (λ/2π)² = 4Aλ²/π².
    # The discrete saddle is the highest pour point, between the points either side of
    # the valley line on the peak's row: b = A (1 - cos(π/n)) above 0, which takes a slab
    # of b over the diamond (area λ²/2) off the volume, to first order in b (the rest is
    # O(b²) ~ 1/n⁴). What remains is the sampling: the sum over points is the midpoint
    # rule on cells of h = 2π/n (in u, v), whose error is at most (h²/24)·|Δf| ≤ h²/12
    # per unit area over the 2π² of the diamond, i.e. h²π²/6 of the 16, relative
    # (2π/n)²π²/96 = 0.42 % for n = 31 (measured: 0.085 %). Without the base
    # correction the volume would be 0.63 % low, so the test tells them apart.
    base = A * (1 - math.cos(math.pi / n))
    expected = 4 * A * lam**2 / math.pi**2 - base * lam**2 / 2
    tolerance = (2 * math.pi / n) ** 2 * math.pi**2 / 96
    assert values["Shv"] == pytest.approx(expected, rel=tolerance)
    assert low["Sdv"] == pytest.approx(expected, rel=tolerance)
    assert abs(values["Shv"] / (4 * A * lam**2 / math.pi**2) - 1) > tolerance
    for motif in segment(hills, "hills").motifs:
        if not motif.edge:
            assert motif.saddle == pytest.approx(base, rel=1e-9)


def test_egg_box_ten_point_height():
    """With an even number of points per period both the peaks (2A) and the pits (-2A)
    are on points: S10z = 4A. The mean of whole periods is 0 (to rounding), so S5p and
    S5v are 2A each (5 × 5 periods: enough complete hills and dales for five of each)."""
    values = feature_parameters(Surface(egg_box(16, 5), DX))
    assert values["S5p"] == pytest.approx(2 * A, rel=1e-12)
    assert values["S5v"] == pytest.approx(2 * A, rel=1e-12)
    assert values["S10z"] == pytest.approx(4 * A, rel=1e-12)
    assert set(values) == set(FEATURE)
    assert all(isinstance(value, float) for value in values.values())


@pytest.mark.parametrize("kind", ["hills", "dales"])
def test_five_point_heights_take_the_five_most_extreme(kind):
    """Raise the nine inner peaks of the egg box by different amounts (lower the pits
    of -z): S5p (S5v) is the mean of the five highest (deepest), about the mean; with
    only the four inner motifs of a 4 × 4 egg box, undefined (ISO 25178-2 averages five)."""
    n = 15
    raise_by = A * np.array([0.09, 0.01, 0.05, 0.08, 0.02, 0.07, 0.03, 0.06, 0.04])
    sign = 1 if kind == "hills" else -1
    heights = sign * egg_box(n, 5)
    peaks = [(n * a + n // 2, n * b + n // 2) for a in (1, 2, 3) for b in (1, 2, 3)]
    for (row, column), amount in zip(peaks, raise_by):
        heights[row, column] += sign * amount
    values = feature_parameters(Surface(heights, DX))
    extremes = sign * (heights[tuple(np.transpose(peaks))] - heights.mean())
    name = "S5p" if kind == "hills" else "S5v"
    assert values[name] == pytest.approx(np.sort(extremes)[-5:].mean(), rel=1e-12)
    small = sign * egg_box(n, 4)
    small[n + n // 2, n + n // 2] += sign * 0.1 * A
    assert math.isnan(feature_parameters(Surface(small, DX))[name])


def test_egg_box_merges_into_one_motif_above_half_sz():
    """Every hill of the egg box is 2A above its saddles, half of Sz (4A): pruning at
    60 % merges them all (their peaks tie, so this also covers equal extremes), at 45 %
    none."""
    surface = Surface(egg_box(16, 4), DX)
    for kind in ("hills", "dales"):
        merged = segment(surface, kind, pruning=60)
        assert len(merged.motifs) == 1
        assert (merged.labels == 1).all()
        assert math.isnan(merged.motifs[0].saddle)
        assert len(segment(surface, kind, pruning=45).motifs) > 9


# ---------------------------------------------------------------------------------
# 2. One spike, one pit


def test_flat_with_a_spike_and_a_pit():
    """On a flat map the one hill is the whole map (water runs off the spike across the
    flat to the border): it touches the border, so by default it is not counted; with
    edges="include" it is."""
    heights = np.zeros((32, 32))
    heights[10, 12] = 3e-6
    heights[20, 22] = -2e-6
    surface = Surface(heights, DX)
    mean = heights.mean()
    hills = segment(surface, "hills")
    assert len(hills.motifs) == 1 and hills.motifs[0].edge
    assert indices(surface, hills.motifs[0]) == (10, 12)
    # no neighbour: the base is the hill's lowest height (the pit), the saddle NaN
    assert math.isnan(hills.motifs[0].saddle)
    assert hills.motifs[0].volume == pytest.approx(np.sum(heights - heights.min()) * DX * DX, rel=1e-12)
    included = feature_parameters(surface, edges="include")
    assert math.isnan(included["S5p"]) and math.isnan(included["S5v"])  # one hill, one dale: not five
    assert hills.motifs[0].height == 3e-6 - mean
    assert segment(surface, "dales").motifs[0].height == -2e-6 - mean
    assert included["Spd"] == 1 / (32 * DX * 32 * DX)
    assert included["Sha"] == pytest.approx(32 * 32 * DX * DX, rel=1e-14)
    excluded = feature_parameters(surface)  # edges="exclude"
    assert excluded["Spd"] == 0.0
    for name in ("Spc", "S5p", "S5v", "S10z", "Sda", "Sha", "Sdv", "Shv"):
        assert math.isnan(excluded[name]), name


# ---------------------------------------------------------------------------------
# 3. Wolf pruning against a slow, obvious reference


def wolf_reference(heights, threshold):
    """Wolf pruning the obvious way: one region per regional minimum (a valid point
    lower than all its valid 8-neighbours; random data has no plateaus), watershed,
    then over and over: find the saddles between the motifs by looking at every pair
    of neighbouring points, take the motif with the smallest local height (pit to its
    lowest saddle) below the threshold and merge it into the neighbour across that
    saddle, the deeper pit surviving. Returns the pits (row, column) and the labels."""
    ny, nx = heights.shape
    valid = ~np.isnan(heights)
    around = [(di, dj) for di in (-1, 0, 1) for dj in (-1, 0, 1) if di or dj]
    markers = np.zeros(heights.shape, dtype=int)
    pits = {}
    for i in range(ny):
        for j in range(nx):
            others = [
                heights[i + di, j + dj]
                for di, dj in around
                if 0 <= i + di < ny and 0 <= j + dj < nx and valid[i + di, j + dj]
            ]
            if valid[i, j] and all(heights[i, j] < other for other in others):
                markers[i, j] = len(pits) + 1
                pits[len(pits) + 1] = (i, j)
    filled = np.where(valid, heights, np.nanmax(heights))
    labels = watershed(filled, markers, connectivity=2, mask=valid)
    while True:
        saddles = {}
        for i in range(ny):
            for j in range(nx):
                for di, dj in ((0, 1), (1, 0), (1, 1), (1, -1)):
                    k, m = i + di, j + dj
                    if not (0 <= k < ny and 0 <= m < nx):
                        continue
                    a, b = labels[i, j], labels[k, m]
                    if a and b and a != b:
                        pour = max(heights[i, j], heights[k, m])
                        saddles[min(a, b), max(a, b)] = min(saddles.get((min(a, b), max(a, b)), math.inf), pour)
        smallest = None
        for motif, pit in pits.items():
            passes = [(s, b if a == motif else a) for (a, b), s in saddles.items() if motif in (a, b)]
            if not passes:
                continue
            saddle, neighbour = min(passes)
            local = saddle - heights[pit]
            if local < threshold and (smallest is None or local < smallest[0]):
                smallest = (local, motif, neighbour)
        if smallest is None:
            return sorted(pits.values()), labels
        _, motif, neighbour = smallest
        if heights[pits[motif]] < heights[pits[neighbour]]:
            pits[neighbour] = pits[motif]
        del pits[motif]
        labels[labels == motif] = neighbour


def same_partition(one, other):
    """The two label images cut the map into the same regions (up to numbering)."""
    pairs = set(zip(one.ravel().tolist(), other.ravel().tolist()))
    return len(pairs) == len(set(one.ravel().tolist())) == len(set(other.ravel().tolist()))


def split_map(seed):
    """Smoothed noise with an invalid column that cuts it in two and a hole."""
    heights = smoothed_noise((16, 16), seed)
    heights[:, 9] = np.nan
    heights[3:5, 3:5] = np.nan
    return heights


MAPS = [smoothed_noise((16, 16), seed) for seed in range(6)] + [split_map(seed) for seed in (6, 7)]


@pytest.mark.parametrize("index", range(len(MAPS)))
@pytest.mark.parametrize("pruning", [0, 3, 8, 15, 30])
@pytest.mark.parametrize("kind", ["hills", "dales"])
def test_wolf_pruning_matches_the_reference(index, pruning, kind):
    heights = MAPS[index]
    surface = Surface(heights, DX)
    result = segment(surface, kind, pruning)
    levels = centred(heights)
    image = -levels if kind == "hills" else levels
    assert result.threshold == pruning * (np.nanmax(image) - np.nanmin(image)) / 100
    pits, labels = wolf_reference(image, result.threshold)
    assert sorted(indices(surface, motif) for motif in result.motifs) == pits
    assert same_partition(result.labels, labels)
    for motif in result.motifs:  # every surviving motif is significant
        if not math.isnan(motif.saddle):
            assert abs(motif.saddle - motif.height) >= result.threshold


def test_a_motif_exactly_at_the_threshold_stays():
    """Integer heights on 64 points: the mean (a sum over 64) and the heights about it
    are exact, Sz = 100, and a pit 10 below its saddle is significant at 10 % (10 >= 10)
    and not a hair above."""
    heights = np.full((8, 8), 60.0)
    heights[2, 1], heights[2, 2], heights[2, 3], heights[2, 4], heights[2, 5] = 0, 20, 40, 35, 30
    heights[6, 6] = 100
    surface = Surface(heights * 2.0**-20, DX)  # about 1 µm per unit, exactly
    assert [indices(surface, m) for m in segment(surface, "dales", 10).motifs] == [(2, 1), (2, 5)]
    assert [indices(surface, m) for m in segment(surface, "dales", 10.000001).motifs] == [(2, 1)]


def test_a_shallow_lone_pit_is_kept():
    """The deepest pit always stays, however shallow. On this map scikit-image 0.26's
    h_minima(levels, threshold) finds no minimum at all: on floats its marker is the
    minimum m plus h plus a relative resolution, and it keeps m when (that - m) >= h,
    which rounds below h for about 0.4 % of such dents (|m| a small fraction of h)."""
    heights = np.zeros((40, 40))
    heights[5, 5] = 1e-6  # a particle
    heights[30, 20] = -1.343e-10  # a dent 0.13 nm deep, the only pit
    surface = Surface(heights, DX)
    result = segment(surface, "dales", 5)
    assert [indices(surface, m) for m in result.motifs] == [(30, 20)]


# ---------------------------------------------------------------------------------
# 4. Monotonic in the pruning


@pytest.mark.parametrize("seed", range(4))
def test_more_pruning_never_adds_motifs(seed):
    surface = Surface(smoothed_noise((48, 48), seed, sigma=1.0), DX)
    for kind in ("hills", "dales"):
        counts = [len(segment(surface, kind, pruning).motifs) for pruning in (0, 1, 2, 5, 10, 20, 40, 80, 99)]
        assert counts == sorted(counts, reverse=True)
        assert counts[0] > counts[-1] >= 1


# ---------------------------------------------------------------------------------
# 5. Invalid points


def test_a_hole_makes_edge_motifs():
    """A 2 × 2 hole on the pit between four inner hills of the egg box (the pits are
    between points) makes those four edge motifs; the other five inner hills stay."""
    n, k = 15, 5
    heights = egg_box(n, k)
    row = 2 * n + (n - 1) // 2 + (n + 1) // 2  # the pit half-way between two peaks (rows 37, 52)
    heights[row - 1 : row + 1, row - 1 : row + 1] = np.nan
    surface = Surface(heights, DX)
    hills = segment(surface, "hills")
    assert (hills.labels[np.isnan(heights)] == 0).all()
    assert (hills.labels[~np.isnan(heights)] > 0).all()
    touching = set(np.unique(hills.labels[row - 2 : row + 2, row - 2 : row + 2]).tolist()) - {0}
    assert len(touching) == 4
    for label, motif in enumerate(hills.motifs, start=1):
        assert motif.edge == (label in touching or not _inside(hills.labels, label))
        assert all(math.isfinite(value) for value in (motif.height, motif.saddle, motif.area, motif.volume))
    assert sum(not motif.edge for motif in hills.motifs) == (k - 2) ** 2 - 4
    values = feature_parameters(surface)
    assert all(math.isfinite(value) for value in values.values())
    nx, ny = surface.points
    assert values["Spd"] == 5 / (nx * DX * ny * DX)


def _inside(labels, label):
    """The region does not touch the border of the map."""
    region = labels == label
    return not (region[0].any() or region[-1].any() or region[:, 0].any() or region[:, -1].any())


def test_invalid_points_next_to_a_peak_leave_its_curvature_undefined():
    heights = egg_box(15, 3)
    heights[22, 23] = np.nan  # right of the central peak at (22, 22)
    hills = segment(Surface(heights, DX), "hills")
    centre = [m for m in hills.motifs if indices(Surface(heights, DX), m) == (22, 22)]
    assert len(centre) == 1 and centre[0].edge and math.isnan(centre[0].curvature)


def test_a_constant_map_is_one_motif_per_connected_part():
    heights = np.full((10, 10), 3e-6)
    heights[:, 4] = np.nan
    result = segment(Surface(heights, DX), "dales")
    assert len(result.motifs) == 2
    assert all(motif.volume == 0 and motif.height == 0 and math.isnan(motif.saddle) for motif in result.motifs)


# ---------------------------------------------------------------------------------
# 6. Bad input


@pytest.mark.parametrize(
    "call",
    [
        lambda: segment(Surface(np.zeros(10), DX)),
        lambda: feature_parameters(Surface(np.zeros(10), DX)),
        lambda: segment(Surface(np.zeros((5, 5)), DX), pruning=100),
        lambda: segment(Surface(np.zeros((5, 5)), DX), pruning=-1),
        lambda: segment(Surface(np.zeros((5, 5)), DX), pruning=math.nan),
        lambda: segment(Surface(np.zeros((5, 5)), DX), pruning="five"),
        lambda: segment(Surface(np.zeros((5, 5)), DX), kind="peaks"),
        lambda: feature_parameters(Surface(np.zeros((5, 5)), DX), edges="maybe"),
        lambda: segment(Surface(np.full((5, 5), np.nan), DX)),
    ],
)
def test_bad_input(call):
    with pytest.raises(InputError):
        call()


def test_the_edge_choices():
    assert EDGES == ("exclude", "include")


# ---------------------------------------------------------------------------------
# 4. The compiled passes give what scikit-image and the plain definitions give


def flooded_and_descended(image):
    """scikit-image's watershed from the markers of ``segment`` and the steepest descent
    (None where it does not decide), on ``image`` with NaN at invalid points."""
    valid = ~np.isnan(image)
    filled = np.where(valid, image, np.nanmax(image))
    markers, _ = flooding.basin_markers(filled, valid)
    flooded = watershed(filled, markers, connectivity=2, mask=valid)
    return flooded, flooding.descend(filled, valid, markers)


def tied_pits(image):
    """Whether two pits (markers) of ``image`` have one height: where they meet,
    rough's rule (the pit first in row-major order) and scikit-image's heap may
    differ."""
    valid = ~np.isnan(image)
    filled = np.where(valid, image, np.nanmax(image))
    markers, count = flooding.basin_markers(filled, valid)
    levels = ndimage.minimum(filled, markers, np.arange(1, count + 1))
    return np.unique(levels).size < count


def takes_a_lowest_neighbour(image, labels):
    """Whether every valid point that is not a pit and has a lower neighbour carries
    the label of one of its lowest neighbours (what any flood gives)."""
    valid = ~np.isnan(image)
    filled = np.where(valid, image, np.inf)
    markers, _ = flooding.basin_markers(np.where(valid, image, np.nanmax(image)), valid)
    padded = np.pad(filled, 1, constant_values=np.inf)
    padded_labels = np.pad(labels, 1)
    ny, nx = image.shape
    near = [
        (padded[1 + r : 1 + r + ny, 1 + c : 1 + c + nx], padded_labels[1 + r : 1 + r + ny, 1 + c : 1 + c + nx])
        for r in (-1, 0, 1)
        for c in (-1, 0, 1)
        if r or c
    ]
    lowest = np.min([heights for heights, _ in near], axis=0)
    among = np.zeros(image.shape, bool)
    for heights, neighbour_labels in near:
        among |= (heights == lowest) & (neighbour_labels == labels)
    checked = valid & (markers == 0) & (lowest < filled)
    return bool(among[checked].all())


@st.composite
def images(draw):
    """Small maps of float heights (smooth or rough), of a few levels (plateaus and
    ties), or of both, with or without invalid points."""
    shape = (draw(st.integers(1, 24)), draw(st.integers(1, 24)))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    image = rng.standard_normal(shape)
    if draw(st.booleans()) and min(shape) > 1:
        image = ndimage.gaussian_filter(image, draw(st.floats(0.5, 3.0)))
    if draw(st.booleans()):
        image = np.round(image * draw(st.sampled_from([1.0, 3.0, 30.0, 1000.0, 10000.0])))
    if draw(st.booleans()):
        image[rng.random(shape) < draw(st.floats(0.0, 0.5))] = np.nan
    if np.isnan(image).all():
        image[0, 0] = 1.0
    return image


@settings(max_examples=400, deadline=None)
@given(images())
def test_the_descent_is_the_flood_wherever_it_decides(image):
    """Equal to scikit-image's flood unless two pits have one height (there rough's
    rule decides, scikit-image's heap history may differ); a flood's labels either way."""
    flooded, descended = flooded_and_descended(image)
    if descended is None:
        return
    assert takes_a_lowest_neighbour(image, descended)
    if not tied_pits(image):
        assert np.array_equal(descended, flooded)


def same_regions(one, other):
    """Whether two labellings cut the map into the same regions (numbers aside)."""
    pairs = np.unique(np.stack([one.ravel(), other.ravel()]), axis=1)
    return pairs.shape[1] == np.unique(one).size == np.unique(other).size


TRANSFORMS = (np.transpose, np.fliplr, np.flipud, lambda a: np.rot90(a, 1), lambda a: np.rot90(a, 2))


@settings(max_examples=150, deadline=None)
@given(st.integers(1, 20), st.integers(1, 20), st.integers(0, 2**32 - 1), st.floats(0.0, 0.4), st.booleans())
def test_the_descent_turns_with_a_map_without_ties(ny, nx, seed, holes, smooth):
    """On a map of distinct heights the regions follow the map through a transpose, a
    flip, a rotation: no order of traversal enters them."""
    rng = np.random.default_rng(seed)
    image = rng.permutation(ny * nx).reshape(ny, nx).astype(float)
    if smooth and min(ny, nx) > 1:
        image = np.argsort(np.argsort(ndimage.gaussian_filter(image, 1.5).ravel(), kind="stable"))
        image = image.reshape(ny, nx).astype(float)  # smooth, still distinct ranks
    image[rng.random(image.shape) < holes] = np.nan
    if np.isnan(image).all():
        image[0, 0] = 1.0
    descended = flooded_and_descended(image)[1]
    assert descended is not None
    for transform in TRANSFORMS:
        turned = flooded_and_descended(np.ascontiguousarray(transform(image)))[1]
        assert same_regions(turned, transform(descended))


@pytest.mark.parametrize("seed", range(4))
def test_the_descent_decides_on_float_heights(seed):
    image = smoothed_noise((120, 90), seed)
    image[40:50, 20:35] = np.nan
    flooded, descended = flooded_and_descended(image)
    assert descended is not None and np.array_equal(descended, flooded)


@pytest.mark.parametrize("seed", [1, 2, 4, 5])
def test_the_descent_settles_ties_and_small_plateaus_as_the_flood(seed):
    """Smooth heights rounded to a fine step: ties between neighbours and small raised
    plateaus, which the descent once left to scikit-image."""
    image = np.round(smoothed_noise((160, 150), seed, 2.0) * 1e10) / 1e4
    image[70:74, 30:90] = np.nan
    flooded, descended = flooded_and_descended(image)
    assert np.sum(image[:, 1:] == image[:, :-1]) >= 10  # ties there are
    assert descended is not None and np.array_equal(descended, flooded)


def test_a_plateau_is_flooded_as_the_flood_does():
    image = smoothed_noise((40, 40), 1)
    image[10:20, 10:20] = image[10:20, 10:20].max()  # a raised plateau, lower on some sides
    flooded, descended = flooded_and_descended(image)
    assert descended is not None and np.array_equal(descended, flooded)
    image = np.array([[0.0, 1.0, 2.0, 2.0, 2.0, 1.0, 0.5]])  # the exit above the lower descent is taken first
    flooded, descended = flooded_and_descended(image)
    assert np.array_equal(descended, flooded) and descended.tolist() == [[1, 1, 1, 1, 2, 2, 2]]
    image = np.round(smoothed_noise((40, 40), 1) * 3e6)  # three levels or so: ties everywhere
    assert flooded_and_descended(image)[1] is None


def test_a_point_between_two_basins_at_one_height_takes_the_first_reached():
    image = np.array([[0.0, 2.0, 3.0, 2.0, 0.0]])  # 3's two lowest neighbours reached from two equal pits
    assert flooded_and_descended(image)[1].tolist() == [[1, 1, 1, 2, 2]]  # rough's rule
    for image in ([[0.0, 1.0, 2.0, 3.0, 2.0, 0.5]], [[0.5, 1.0, 2.0, 3.0, 2.0, 0.0]]):
        flooded, descended = flooded_and_descended(np.array(image))  # the 2 above the lower pit is reached first
        assert np.array_equal(descended, flooded) and descended[0, 3] == 2
    image = np.array([[0.0, 2.0, 3.0, 2.5, 0.0]])
    flooded, descended = flooded_and_descended(image)
    assert np.array_equal(descended, flooded) and descended.tolist() == [[1, 1, 1, 2, 2]]


def test_two_equal_pits_at_one_point_give_it_to_the_pit_first_in_row_major_order():
    """rough's rule for tied pits, where scikit-image's heap history decides: the pit
    whose first point comes first in row-major order wins, whichever of its points
    the tied point touches and in whatever orientation the map is given."""
    assert flooded_and_descended(np.array([[0.0, 2.0, 0.0]]))[1].tolist() == [[1, 1, 2]]
    assert flooded_and_descended(np.array([[0.0], [2.0], [0.0]]))[1].tolist() == [[1], [1], [2]]
    image = np.array(  # pit A, column 2 (first point (0, 2)); pit B at (2, 0), touched before A
        [
            [9.0, 8.0, 0.0],
            [7.0, 6.0, 0.0],
            [0.0, 4.0, 0.0],
            [3.0, 5.0, 0.0],
        ]
    )
    descended = flooded_and_descended(image)[1]
    assert descended.tolist() == [[1, 1, 1], [2, 1, 1], [2, 1, 1], [2, 1, 1]]
    for transform in TRANSFORMS:
        turned = np.ascontiguousarray(transform(image))
        labels = flooded_and_descended(turned)[1]
        pits = [np.flatnonzero((labels.ravel() == label) & (turned.ravel() == 0))[0] for label in (1, 2)]
        assert pits[0] < pits[1]  # markers are numbered in row-major order of their first point
        point = np.flatnonzero(turned.ravel() == 5.0)[0]
        assert labels.ravel()[point] == 1  # the one between: the pit first in row-major order


def regions_by_hand(filled, labels):
    """What region_figures gives, the slow and obvious way: per label its lowest value and
    first point with it, highest value, points, whether on the border or next to an
    invalid point; per two neighbouring labels the lowest pour height."""
    ny, nx = labels.shape
    figures, saddles = {}, {}
    for i in range(ny):
        for j in range(nx):
            label = int(labels[i, j])
            if label:
                low, pit, high, area, edge = figures.get(label, (math.inf, -1, -math.inf, 0, False))
                if filled[i, j] < low:
                    low, pit = filled[i, j], i * nx + j
                edge = edge or i in (0, ny - 1) or j in (0, nx - 1)
                figures[label] = (low, pit, max(high, filled[i, j]), area + 1, edge)
            for di, dj in ((0, 1), (1, -1), (1, 0), (1, 1)):
                k, m = i + di, j + dj
                if 0 <= k < ny and 0 <= m < nx and labels[k, m] != label:
                    other = int(labels[k, m])
                    if label and other:
                        key = (label, other)
                        saddles[key] = min(saddles.get(key, math.inf), max(filled[i, j], filled[k, m]))
                    else:
                        touching = label or other
                        low, pit, high, area, _ = figures.get(touching, (math.inf, -1, -math.inf, 0, False))
                        figures[touching] = (low, pit, high, area, True)
    return figures, saddles


@settings(max_examples=200, deadline=None)
@given(images(), st.sampled_from([0, math.inf]))
def test_the_regions_are_the_plain_definition(image, compiled_from):
    valid = ~np.isnan(image)
    filled = np.where(valid, image, np.nanmax(image))
    labels, count = flooding.basins(filled, valid)
    with mock.patch.object(flooding, "COMPILED_MIN", compiled_from), mock.patch.object(flooding, "BAND", 7):
        regions = flooding.region_figures(filled, labels, count)
    figures, saddles = regions_by_hand(filled, labels)
    assert sorted(figures) == list(range(1, count + 1))
    for label, (low, pit, high, area, edge) in figures.items():
        assert (regions["low"][label], regions["pit"][label], regions["high"][label]) == (low, pit, high)
        assert (regions["area"][label], regions["edge"][label]) == (area, edge)
    listed = {}
    for a, b, pour in zip(regions["first"].tolist(), regions["second"].tolist(), regions["pour"].tolist()):
        listed[a, b] = min(listed.get((a, b), math.inf), pour)
    assert listed == saddles
    assert not regions["edge"][0]


@pytest.mark.parametrize("index", range(len(MAPS)))
@pytest.mark.parametrize("kind", ["hills", "dales"])
def test_the_compiled_passes_give_the_same_motifs(index, kind, monkeypatch):
    heights = np.repeat(np.repeat(MAPS[index], 3, axis=0), 2, axis=1)  # a larger map with plateaus: floods
    for image in (MAPS[index], heights + smoothed_noise(heights.shape, index) * 1e-3):
        surface = Surface(image, DX)
        monkeypatch.setattr(flooding, "COMPILED_MIN", 0)
        monkeypatch.setattr(flooding, "COMPILED_SADDLES", 0)
        monkeypatch.setattr(flooding, "BAND", 37)  # many bands
        descended = segment(surface, kind, 3.0)
        monkeypatch.setattr(flooding, "COMPILED_MIN", math.inf)
        monkeypatch.setattr(flooding, "COMPILED_SADDLES", math.inf)
        flooded = segment(surface, kind, 3.0)
        assert np.array_equal(descended.labels, flooded.labels)
        assert repr(descended.motifs) == repr(flooded.motifs)  # NaN fields too


@st.composite
def quantised_images(draw):
    """Maps of a few height levels (plateaus and ties everywhere), some with invalid
    points: where the two routes most easily part."""
    image = draw(images())
    levels = draw(st.sampled_from([2.0, 4.0, 16.0]))
    return np.round(image / np.nanmax(np.abs(image)) * levels) if np.nanmax(np.abs(image)) > 0 else image


@settings(max_examples=150, deadline=None)
@given(quantised_images(), st.sampled_from(["hills", "dales"]), st.sampled_from([0.0, 5.0, 30.0]))
def test_the_two_routes_give_the_same_labels(image, kind, pruning):
    """The same labels and motifs, ties included: where two pits have one height,
    both routes take the descent's regions (rough's rule), not scikit-image's heap."""
    surface = Surface(image * 1e-6, DX)
    routes = []
    for threshold in (0, math.inf):  # compiled passes everywhere, then array operations everywhere
        with (
            mock.patch.object(flooding, "COMPILED_MIN", threshold),
            mock.patch.object(flooding, "COMPILED_SADDLES", threshold),
            mock.patch.object(flooding, "BAND", 7),
        ):
            routes.append(segment(surface, kind, pruning))
    compiled, arrays = routes
    assert np.array_equal(compiled.labels, arrays.labels)
    assert repr(compiled.motifs) == repr(arrays.motifs)
