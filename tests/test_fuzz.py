"""Mutation fuzzing of every reader inside the test suite (hypothesis): valid seeds of
each format, mutated by bit flips, boundary values, truncation, insertion, deletion,
duplication, and (tests/damaged_files.py finds the data block) the data block shifted
by 1-7 bytes, overwritten by random bytes or given a height near the float range, must
either read as a sane surface (heights within ±100 km) or be refused with an
InputError — never another exception. bench/fuzz_readers.py runs the coverage-guided version
(atheris, `make fuzz`) for a million inputs."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rough.errors import InputError
from rough.io import ReadOptions, read_bytes

from damaged_files import data_block
from seed_files import seeds

SEEDS = seeds()
BLOCKS = {name: data_block(blob) for name, blob in SEEDS.items()}
OPTIONS = ReadOptions(spacing=None)
SPACED = ReadOptions(spacing=(1e-6, 1e-6))


@st.composite
def mutated(draw, seed, block=None):
    data = bytearray(seed)
    if block is not None and draw(st.booleans()):
        data = bytearray(draw(damaged_block(seed, block)))
    for _ in range(draw(st.integers(0 if block else 1, 4))):
        kind = draw(st.sampled_from(["flip", "set", "truncate", "insert", "delete", "duplicate"]))
        at = draw(st.integers(0, max(len(data) - 1, 0)))
        if kind == "flip" and data:
            data[at] ^= 1 << draw(st.integers(0, 7))
        elif kind == "set" and data:
            data[at] = draw(st.sampled_from([0x00, 0x01, 0x7F, 0x80, 0xFF, ord("9"), ord("-"), ord(".")]))
        elif kind == "truncate":
            del data[at:]
        elif kind == "insert":
            data[at:at] = draw(st.binary(min_size=1, max_size=16))
        elif kind == "delete":
            del data[at : at + draw(st.integers(1, 16))]
        elif kind == "duplicate":
            data[at:at] = data[at : at + draw(st.integers(1, 64))]
    return bytes(data)


@st.composite
def damaged_block(draw, seed, block):
    """``seed`` with its data block ``(start, end, dtype)`` shifted by 1-7 bytes, its
    bytes random, or one of its floats near the top of the float range."""
    start, end, dtype = block
    kind = draw(st.sampled_from(["shift", "noise", "huge"] if dtype[1] == "f" else ["shift", "noise"]))
    if kind == "shift":
        shift = draw(st.integers(1, 7))
        if draw(st.booleans()):
            return seed[:start] + draw(st.binary(min_size=shift, max_size=shift)) + seed[start:]
        return seed[: max(start - shift, 0)] + seed[start:]
    if kind == "noise":
        return seed[:start] + draw(st.binary(min_size=end - start, max_size=end - start)) + seed[end:]
    size = int(dtype[2:])
    at = start + size * draw(st.integers(0, (end - start) // size - 1))
    top = draw(st.sampled_from([1e308, -1e308, 1e300, 1.7e308] if size == 8 else [3e38, -3e38, 1e30]))
    return seed[:at] + np.array(top, dtype).tobytes() + seed[at + size :]


def read_or_refuse(data, options, name=None):
    try:
        surface = read_bytes(data, options, name=name)
    except InputError:
        return
    assert_sane(surface)


def assert_sane(surface):
    heights = surface.heights
    assert heights.dtype == np.float64 and heights.ndim in (1, 2) and heights.size >= 2
    assert not np.isnan(heights).all() and not np.isinf(heights).any()
    assert np.nanmax(np.abs(heights)) <= 1e5  # HEIGHT_LIMIT: no surface reaches 100 km
    assert all(np.isfinite(d) and d > 0 for d in surface.spacing) and len(surface.spacing) == heights.ndim


@pytest.mark.parametrize("name", sorted(SEEDS))
def test_the_seeds_are_valid(name):
    assert_sane(read_bytes(SEEDS[name], SPACED, name=name))


@pytest.mark.parametrize("name", sorted(SEEDS))
@pytest.mark.filterwarnings("error::pytest.PytestUnraisableExceptionWarning")  # a library's traceback on stderr
@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(data=st.data())
def test_mutated_files_are_read_or_refused(name, data):
    blob = data.draw(mutated(SEEDS[name], BLOCKS[name]))
    read_or_refuse(blob, SPACED if name.endswith(".npy") else OPTIONS, name)
