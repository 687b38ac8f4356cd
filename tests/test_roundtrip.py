"""Every writable format reads back what was written, within what it carries: heights
bit for bit (or to float32 rounding, per ``Format.height_type``), spacing and origin,
units, metadata and history where ``Format.carries`` names them. Parametrised over
``registry.writable()`` at collection, so a new writable format, built-in or plugin,
gets these tests with no other edit (GeoTIFF's CRS and windows: test_geotiff.py)."""

import importlib.util
import io

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rough import Surface, Units
from rough.errors import InputError
from rough.io import ReadOptions, read_bytes, registry

WRITABLE = registry.writable()

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


def facts(fmt):
    """The format's facts, skipping the test when the library writing or reading it
    needs is not installed."""
    found = registry.formats()[fmt]
    for library in (found.read_library, found.write_library):
        if library and importlib.util.find_spec(library) is None:
            pytest.skip(f"{fmt} needs {library}")
    return found


@st.composite
def surfaces(draw, profiles=True):
    is_profile = profiles and draw(st.booleans())
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


def round_trip(surface, fmt):
    """``surface`` written as ``fmt`` and read back (with its spacing given, for a
    format that carries none)."""
    buffer = io.BytesIO()
    surface.write(buffer, fmt)
    carried = "spacing" in registry.formats()[fmt].carries
    options = ReadOptions() if carried else ReadOptions(spacing=(surface.spacing * 2)[:2])
    return read_bytes(buffer.getvalue(), options)


@pytest.mark.parametrize("fmt", WRITABLE)
def test_a_surface_with_no_valid_point_is_written_but_refused_on_reading(fmt):
    facts(fmt)
    with pytest.raises(InputError, match="no valid points"):
        round_trip(Surface(np.full((3, 4), np.nan), (1e-6, 1e-6)), fmt)


@pytest.mark.parametrize("fmt", WRITABLE)
def test_a_title_with_nul_characters_survives(fmt):
    """GWY strings end at NUL: a title holding one broke the written file (found by
    hypothesis). Every format that carries metadata keeps the title as given."""
    if "metadata" not in facts(fmt).carries:
        pytest.skip(f"{fmt} carries no metadata")
    surface = Surface(np.arange(6.0).reshape(2, 3) * 1e-9, (1e-6, 1e-6), metadata={"title": "a\x00b"})
    assert round_trip(surface, fmt).metadata["title"] == "a\x00b"


@pytest.mark.parametrize("fmt", WRITABLE)
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_round_trip_keeps_everything_the_format_carries(fmt, data):
    format_facts = facts(fmt)
    surface = data.draw(surfaces(profiles=format_facts.writes_profiles))
    back = round_trip(surface, fmt)
    assert back.kind == surface.kind
    assert back.heights.shape == surface.heights.shape
    if format_facts.height_type == "float64":
        assert back.heights.tobytes() == surface.heights.tobytes()  # bit for bit: -0.0 and NaN too
    else:
        expected = surface.heights.astype(format_facts.height_type).astype(np.float64)
        assert np.array_equal(back.heights, expected, equal_nan=True)
    if "exact-grid" in format_facts.carries:
        assert back.spacing == surface.spacing and back.origin == surface.origin
    elif "spacing" in format_facts.carries:  # a file that stores the size n·dx, or a corner, gives them to rounding
        np.testing.assert_allclose(back.spacing, surface.spacing, rtol=1e-14)
        np.testing.assert_allclose(back.origin, surface.origin, rtol=1e-14, atol=1e-14 * max(surface.spacing))
    else:
        assert back.spacing == surface.spacing  # as given on reading
    if "units" in format_facts.carries:
        assert back.units == surface.units
    if "metadata" in format_facts.carries:  # a reader may add keys of its own (a CRS, the channel)
        assert {key: back.metadata.get(key) for key in surface.metadata} == surface.metadata
    if "history" in format_facts.carries:
        assert back.history == surface.history


@pytest.mark.parametrize("fmt", WRITABLE)
def test_history_accumulates_across_conversions(fmt):
    format_facts = facts(fmt)
    surface = Surface(np.linspace(0, 1e-6, 50), (1e-6,))
    if not format_facts.writes_profiles:
        surface = Surface(np.linspace(0, 1e-6, 50).reshape(5, 10), (1e-6, 1e-6))
    for step in range(3):
        surface = round_trip(surface.derive("convert", {"step": step}), fmt)
    expected = 3 if "history" in format_facts.carries else 0
    assert [entry["parameters"]["step"] for entry in surface.history] == list(range(expected))
