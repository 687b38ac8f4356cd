"""Every writable format reads back what was written: float64 formats bit for bit,
float32 formats (GSF, EXR) to float32 rounding, with spacing, origin, units,
metadata and history (NPY holds heights only; GeoTIFF, maps only, has its own in
test_geotiff.py)."""

import importlib.util
import io

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rough import Surface, Units
from rough.io import ReadOptions, read_bytes

FLOAT64 = ("x3p", "tsv") + (("gwy",) if importlib.util.find_spec("gwyfile") else ())
FLOAT32 = ("gsf", "exr")
EXACT_GRID = ("x3p", "tsv")

lengths = st.floats(min_value=1e-10, max_value=1e-1, allow_nan=False, allow_infinity=False)
offsets = st.floats(min_value=-1.0, max_value=1.0, allow_nan=False, allow_infinity=False)
texts = st.text(max_size=30)
metadata = st.dictionaries(st.sampled_from(["title", "instrument", "date", "comment", "operator"]), texts, max_size=4)
history = st.lists(
    st.fixed_dictionaries(
        {
            "command": st.sampled_from(["synth", "detrend", "convert"]),
            "parameters": st.dictionaries(
                st.sampled_from(["seed", "order", "cutoff", "input"]),
                st.one_of(st.integers(-(10**6), 10**6), texts, st.floats(allow_nan=False)),
            ),
            "version": st.just("0.1.0"),
            "time": st.just("2026-11-20T00:00:00Z"),
        }
    ),
    max_size=3,
)


@st.composite
def surfaces(draw):
    is_profile = draw(st.booleans())
    shape = (draw(st.integers(2, 200)),) if is_profile else (draw(st.integers(2, 24)), draw(st.integers(2, 24)))
    scale = draw(st.sampled_from([1e-9, 1e-6, 1e-3, 1.0]))
    heights = draw(st.sampled_from(["normal", "ramp", "constant"]))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    values = {
        "normal": rng.normal(size=shape),
        "ramp": np.arange(np.prod(shape), dtype=float).reshape(shape),
        "constant": np.full(shape, 0.25),
    }[heights] * scale
    holes = draw(st.sampled_from([0.0, 0.1, 0.5]))
    missing = rng.random(shape) < holes
    missing.flat[rng.integers(missing.size)] = False  # a surface with no valid point is refused on reading
    values[missing] = np.nan
    ndim = len(shape)
    return Surface(
        values,
        tuple(draw(lengths) for _ in range(ndim)),
        tuple(draw(offsets) for _ in range(ndim)),
        Units(draw(st.sampled_from(["m", "mm", "um", "nm"])), draw(st.sampled_from(["m", "um", "nm"]))),
        draw(metadata),
        draw(history),
    )


@pytest.mark.parametrize("fmt", FLOAT64 + FLOAT32)
def test_a_surface_with_no_valid_point_is_written_but_refused_on_reading(fmt):
    from rough.errors import InputError

    with pytest.raises(InputError, match="no valid points"):
        round_trip(Surface(np.full((3, 4), np.nan), (1e-6, 1e-6)), fmt)


def round_trip(surface, fmt, options=None):
    buffer = io.BytesIO()
    surface.write(buffer, fmt)
    return read_bytes(buffer.getvalue(), options or ReadOptions())


@pytest.mark.parametrize("fmt", FLOAT64 + FLOAT32)
def test_a_title_with_nul_characters_survives(fmt):
    """GWY strings end at NUL: a title holding one broke the written file (found by
    hypothesis). Every format keeps the title as given."""
    surface = Surface(np.arange(6.0).reshape(2, 3) * 1e-9, (1e-6, 1e-6), metadata={"title": "a\x00b"})
    assert round_trip(surface, fmt).metadata["title"] == "a\x00b"


@pytest.mark.parametrize("fmt", FLOAT64 + FLOAT32)
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(surface=surfaces())
def test_round_trip_keeps_everything(fmt, surface):
    back = round_trip(surface, fmt)
    assert back.kind == surface.kind
    assert back.heights.shape == surface.heights.shape
    if fmt in FLOAT64:
        assert back.heights.tobytes() == surface.heights.tobytes()
    else:
        expected = surface.heights.astype(np.float32).astype(np.float64)
        assert np.array_equal(back.heights, expected, equal_nan=True)
    if fmt in EXACT_GRID:
        assert back.spacing == surface.spacing
        assert back.origin == surface.origin
    else:  # the file stores the physical size n·dx, so dx comes back to rounding
        np.testing.assert_allclose(back.spacing, surface.spacing, rtol=1e-14)
        np.testing.assert_allclose(back.origin, surface.origin, rtol=1e-14, atol=0)
    assert back.units == surface.units
    assert back.metadata == surface.metadata
    assert back.history == surface.history


@settings(max_examples=40, deadline=None)
@given(surface=surfaces())
def test_npy_keeps_the_heights(surface):
    back = round_trip(surface, "npy", ReadOptions(spacing=(surface.spacing * 2)[:2]))
    assert back.heights.tobytes() == surface.heights.tobytes()
    assert back.spacing == surface.spacing


@pytest.mark.parametrize("fmt", FLOAT64 + FLOAT32 + ("npy",))
def test_history_accumulates_across_conversions(fmt):
    surface = Surface(np.linspace(0, 1e-6, 50), (1e-6,))
    for step in range(3):
        surface = round_trip(surface.derive("convert", {"step": step}), fmt, ReadOptions(spacing=(1e-6, 1e-6)))
    expected = 0 if fmt == "npy" else 3
    assert [entry["parameters"]["step"] for entry in surface.history] == list(range(expected))
