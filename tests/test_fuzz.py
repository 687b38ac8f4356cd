"""Mutation fuzzing of every reader inside the test suite (hypothesis): valid seeds of
each format, mutated by bit flips, boundary values, truncation, insertion, deletion and
duplication, must either read as a sane surface or be refused with an InputError —
never another exception. bench/fuzz_readers.py runs the coverage-guided version
(atheris, `make fuzz`) for a million inputs."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from seed_files import seeds

from rough.errors import InputError
from rough.io import ReadOptions, read_bytes

SEEDS = seeds()
OPTIONS = ReadOptions(spacing=None)
SPACED = ReadOptions(spacing=(1e-6, 1e-6))


@st.composite
def mutated(draw, seed):
    data = bytearray(seed)
    for _ in range(draw(st.integers(1, 4))):
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
    assert all(np.isfinite(d) and d > 0 for d in surface.spacing) and len(surface.spacing) == heights.ndim


@pytest.mark.parametrize("name", sorted(SEEDS))
def test_the_seeds_are_valid(name):
    assert_sane(read_bytes(SEEDS[name], SPACED, name=name))


@pytest.mark.parametrize("name", sorted(SEEDS))
@pytest.mark.filterwarnings("error::pytest.PytestUnraisableExceptionWarning")  # a library's traceback on stderr
@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(data=st.data())
def test_mutated_files_are_read_or_refused(name, data):
    blob = data.draw(mutated(SEEDS[name]))
    read_or_refuse(blob, SPACED if name.endswith(".npy") else OPTIONS, name)
