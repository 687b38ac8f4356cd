"""Issue 14, the readers' part: no silent change to the data, no internal error on bad
input, and one size and ratio policy (rough.io.limits) for every container and codec,
checked while unpacking."""

import gzip
import io
import logging
import pathlib
import tracemalloc

import numpy as np
import pytest

from rough import Surface
from rough.errors import FormatError, InputError
from rough.io import limits, read

from conftest import assert_one_line_error
from format_files import al3d_file

HOSTILE = pathlib.Path(__file__).resolve().parent / "hostile"
PROFILE = b"x z\n0 1\n1 2\n2 3\n"


# -- silent changes to the data -------------------------------------------------------------


def test_concatenated_gzip_members_are_read_whole():
    first, second = gzip.compress(b"x z\n0 1\n1 2\n"), gzip.compress(b"2 3\n3 4\n")
    assert read(first + second).heights.tolist() == [1, 2, 3, 4]
    assert read(first + second + bytes(512)).heights.size == 4  # tape padding
    with pytest.raises(FormatError, match="junk after the gzip"):
        read(first + b"junk")


def test_a_real_header_row_is_column_names():
    scan = read(b"x[um]  z[um]\n0 1\n1 2\n2 3\n")
    assert scan.units.xy == "um" and scan.heights.size == 3 and abs(scan.origin[0]) < 1e-18
    assert read(b"Lateral um,Raw Micrometer,\n0,1,\n1,2,\n").heights.size == 2


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        (b"O.5 1.2\n1 2\n2 3\n", "line 1: 'O.5 1.2' is neither column names nor numbers"),
        (b"0.O 1.2\n1 2\n2 3\n", "line 1: unreadable number in '0.O 1.2'"),
        ("\u202e0 1.2\n1 2\n2 3\n".encode(), "line 1: invisible character U+202E"),
        (b"x z\n\nO 1\n1 2\n", "line 3:"),
        (b"# unit: um\nx z\n0 1\n1 1e400\n", "line 4: the number '1e400' is beyond the float64 range"),
        (b"x z\n0 1\n1 " + b"7" * 500001 + b"\n", "line 3: the number '7777"),
    ],
)
def test_a_typo_or_an_overflow_in_text_is_refused_naming_the_line(text, fragment):
    with pytest.raises(FormatError) as caught:
        read(text)
    assert fragment in str(caught.value)


def test_infinite_heights_are_announced_at_the_default_verbosity(caplog):
    with caplog.at_level(logging.WARNING, logger="rough"):
        scan = read(b"x z\n0 1\n1 inf\n2 3\n")
    assert np.isnan(scan.heights[1])
    assert "1 infinite heights marked invalid (NaN), the first at point 1" in caplog.text


def test_infinite_heights_warn_in_one_line_on_the_command_line(tmp_path, run):
    path = tmp_path / "inf.txt"
    path.write_bytes(b"x z\n0 1\n1 inf\n2 3\n")
    result = run("info", path)
    assert result.returncode == 0
    assert "warning: 1 infinite heights marked invalid" in result.stderr.decode()


def test_an_sdf_zscale_that_overflows_is_refused():
    with pytest.raises(FormatError, match="Zscale 1e\\+308 scales heights beyond the float64 range"):
        read(HOSTILE / "sdf-zscale-overflow.sdf")


def test_an_x3p_increment_that_overflows_is_refused():
    from x3p_files import x3p_file

    with pytest.raises(FormatError, match="Increment"):
        read(x3p_file(np.array([[1, 2], [3, 4]]), code="I", increment=1e308))


def test_an_npy_shape_with_minus_one_is_refused():
    with pytest.raises(FormatError, match="shape"):
        read(HOSTILE / "npy-negative-shape.npy", spacing=1e-6)


def test_a_negative_al3d_pixel_size_is_refused():
    with pytest.raises(FormatError, match="PixelSizeXMeter"):
        read(al3d_file(np.zeros((2, 2)), pixel=(-1e-6, 1e-6)))


def test_a_multi_part_exr_is_refused():
    with pytest.raises(FormatError, match="2 parts"):
        read(HOSTILE / "exr-two-parts.exr")


# -- internal errors ----------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["x3p", "exr", "gsf", "tsv"])
def test_history_parameters_that_are_not_an_object_are_refused(name, tmp_path, run):
    suffix = {"tsv": "txt"}.get(name, name)
    result = run("info", HOSTILE / f"{name}-history-not-object.{suffix}")
    assert_one_line_error(result, "history record in the file is damaged")


def test_a_null_history_entry_is_refused():
    text = b'# history: {"command": "synth", "parameters": null}\nx z\n0 1\n1 2\n'
    with pytest.raises(FormatError, match="history"):
        read(text)


def test_json_nested_100000_deep_is_refused(run):
    assert_one_line_error(run("info", HOSTILE / "x3p-deep-json.x3p"), "nested too deeply")
    deep = b"# metadata: " + b"[" * 100000 + b"]" * 100000 + b"\n" + PROFILE
    with pytest.raises(FormatError, match="nested too deeply"):
        read(deep)


def test_gzip_nested_1100_times_is_refused(run):
    assert_one_line_error(run("info", HOSTILE / "gzip-nested.txt.gz"), "gzip nested more than 4 deep")
    assert read(gzip.compress(gzip.compress(PROFILE))).heights.size == 3  # two layers are fine


# -- bombs past the bounds ------------------------------------------------------------------------


@pytest.mark.parametrize(
    "name",
    ["text-bomb.txt.gz", "sdf-bomb.sdf.gz", "x3p-deflate-ratio.x3p", "x3p-bzip2-main.x3p", "x3p-lzma-main.x3p"],
)
def test_compression_bombs_are_refused_while_unpacking(name):
    size = (HOSTILE / name).stat().st_size
    tracemalloc.start()
    try:
        with pytest.raises(FormatError, match="compression bomb"):
            read(HOSTILE / name)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < limits.MAX_RATIO * size + (48 << 20), f"{peak >> 20} MB for a {size >> 10} kB file"


def test_the_ratio_cap_is_raised_through_the_environment(monkeypatch):
    monkeypatch.setenv("ROUGH_MAX_RATIO", "2000")
    assert read(HOSTILE / "x3p-deflate-ratio.x3p").heights.shape == (1024, 1024)


def test_well_compressed_real_data_pass():
    heights = np.random.default_rng(3).normal(size=(512, 512)) * 1e-6
    buffer = io.BytesIO()
    Surface(heights, (1e-6, 1e-6)).write(buffer, "x3p")
    assert read(gzip.compress(buffer.getvalue())).heights.shape == (512, 512)


def test_the_input_cap_stops_an_endless_device(run):
    result = run("info", "/dev/zero", env={"ROUGH_MAX_INPUT_BYTES": "64M"})
    assert_one_line_error(result, "/dev/zero: larger than 64 MiB", "ROUGH_MAX_INPUT_BYTES")


def test_the_input_cap_applies_to_standard_input_and_files(run, tmp_path, monkeypatch):
    result = run("info", "-", input=b"x z\n" + b"0 1\n" * 300000, env={"ROUGH_MAX_INPUT_BYTES": "1M"})
    assert_one_line_error(result, "<stdin>: larger than 1 MiB")
    path = tmp_path / "big.txt"
    path.write_bytes(b"x z\n" + b"0 1\n" * 300000)
    monkeypatch.setenv("ROUGH_MAX_INPUT_BYTES", "1M")
    with pytest.raises(InputError, match="larger than 1 MiB"):
        read(path)


def test_the_unpacked_size_cap_holds_for_gzip(monkeypatch):
    data = np.random.default_rng(4).normal(size=400000).astype("<f8").tobytes()
    packed = gzip.compress(data)
    monkeypatch.setenv("ROUGH_MAX_INPUT_BYTES", "3M")
    with pytest.raises(FormatError, match="unpacks to more than 3 MiB"):
        read(packed, spacing=1e-6)


def test_text_beyond_its_cap_is_refused_with_a_hint(monkeypatch):
    monkeypatch.setenv("ROUGH_MAX_TEXT_BYTES", "1K")
    with pytest.raises(FormatError, match="convert it to X3P or NPY"):
        read(b"x z\n" + b"0 1\n" * 1000)


def test_a_cap_that_is_not_a_number_is_refused(monkeypatch):
    monkeypatch.setenv("ROUGH_MAX_RATIO", "lots")
    with pytest.raises(InputError, match="ROUGH_MAX_RATIO"):
        read(gzip.compress(PROFILE))


def test_an_extreme_spacing_ratio_is_refused_by_analysis_not_a_traceback(tmp_path, run):
    """Spacings outside 1 pm to 1000 km are refused when the surface is made; the
    widest ratio inside that range gives a one-line refusal from the fit."""
    with pytest.raises(InputError, match="outside what any instrument samples"):
        Surface(np.zeros((6, 8)), (1e-300, 1.0))
    path = tmp_path / "ratio.x3p"
    Surface(np.random.default_rng(1).normal(size=(6, 8)) * 1e-6, (1e-12, 1e6)).write(path)
    assert_one_line_error(run("fit-fractal", path), "ratio.x3p")


def test_a_repeated_line_is_reported_where_it_stands():
    """A header repeated mid-file (two exports concatenated) is named by its own line
    number, not the first line's."""
    with pytest.raises(FormatError, match="line 4: unreadable number in 'x z'"):
        read(b"x z\n0 1\n1 2\nx z\n2 3\n")
