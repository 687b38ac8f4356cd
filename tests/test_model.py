"""The data model and the units: what a Surface accepts, and lengths with units."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rough import Surface, __version__
from rough.errors import InputError
from rough.surface import history_entry
from rough.units import format_length, metres_per, parse_length


@pytest.mark.parametrize(
    "text,metres",
    [
        ("0.1545mm", 1.545e-4),
        ("30.9um", 30.9e-6),
        ("30.9 µm", 30.9e-6),
        ("30.9μm", 30.9e-6),
        ("2e-3m", 2e-3),
        ("0", 0.0),
        ("1.5nm", 1.5e-9),
        ("3km", 3e3),
        ("-2mm", -2e-3),
        (".5mm", 0.5e-3),
    ],
)
def test_parse_length(text, metres):
    assert parse_length(text) == pytest.approx(metres, rel=1e-15)


@pytest.mark.parametrize("text", ["", "mm", "fast", "1.5 parsecs", "1e999m", "nan mm", "1..2mm", "80"])
def test_parse_length_refuses(text):
    with pytest.raises(InputError):
        parse_length(text)


@pytest.mark.parametrize("name,metres", [("Micrometer", 1e-6), ("[mm]", 1e-3), ("Angstrom", 1e-10), ("microns", 1e-6)])
def test_unit_names_in_files(name, metres):
    assert metres_per(name) == metres


@given(st.floats(min_value=1e-13, max_value=1e5))
def test_format_length_round_trips_to_its_digits(metres):
    text = format_length(metres, digits=12)
    assert parse_length(text.replace(" ", "")) == pytest.approx(metres, rel=1e-11)


def test_format_length_picks_a_readable_prefix():
    assert format_length(7.728033273597876e-08) == "77.28 nm"
    assert format_length(0.0309e-3) == "30.9 µm"
    assert format_length(0.0) == "0 m"


def test_surface_validates_its_inputs():
    with pytest.raises(InputError, match="profile \\(1-D\\) or a map"):
        Surface(np.zeros((2, 2, 2)), (1, 1))
    with pytest.raises(InputError, match="positive"):
        Surface(np.zeros(3), (0.0,))
    with pytest.raises(InputError, match="2 spacing values"):
        Surface(np.zeros((2, 2)), (1, 2, 3))
    with pytest.raises(InputError, match="at least one point"):
        Surface(np.zeros(0), (1,))
    assert Surface(np.zeros((2, 3), dtype=np.float32), 1e-6).spacing == (1e-6, 1e-6)
    assert Surface(np.zeros(3, dtype=np.int16), 1e-6).heights.dtype == np.float64


def test_points_and_size_are_x_first():
    surface = Surface(np.zeros((3, 5)), (1e-6, 2e-6))
    assert surface.points == (5, 3)
    assert surface.size == pytest.approx((5e-6, 6e-6))


def test_derive_appends_history_and_keeps_the_original(monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    original = Surface(np.zeros(4), (1e-6,), metadata={"title": "a"})
    derived = original.derive("detrend", {"order": 2}, heights=np.ones(4))
    assert original.history == [] and original.heights.sum() == 0
    assert derived.history == [
        {"command": "detrend", "parameters": {"order": 2}, "version": __version__, "time": "2023-11-14T22:13:20Z"}
    ]
    derived.metadata["title"] = "b"
    assert original.metadata["title"] == "a"


def test_history_entry_uses_the_current_time_without_source_date_epoch(monkeypatch):
    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    assert history_entry("synth", {})["time"].startswith("20")
