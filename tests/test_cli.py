"""The command-line contract (docs/conventions.rst, "Command-line contract"), run as a
user runs it: a separate process."""

import json
import os
import pty
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from rough import Surface, __version__

from conftest import ROOT, assert_one_line_error, children_cpu_seconds, rough
from x3p_files import x3p_file


@pytest.fixture
def sample(tmp_path):
    """A small map with a hole, written in every format rough writes."""
    heights = np.random.default_rng(1).normal(size=(12, 17)) * 1e-6
    heights[3, 4] = np.nan
    surface = Surface(heights, (2e-6, 3e-6), metadata={"title": "test map"})
    paths = {}
    for fmt in ("x3p", "exr", "gsf", "tsv", "npy"):
        paths[fmt] = tmp_path / f"map.{fmt}"
        surface.write(paths[fmt])
    return paths


def test_version_and_help():
    assert rough("--version", check=True).stdout.decode().startswith(f"rough {__version__}\n")
    help_text = rough("--help", check=True).stdout.decode()
    assert "info" in help_text and "convert" in help_text and "name their unit" in help_text


def test_info_json_keys(sample):
    facts = json.loads(rough("info", "--json", sample["x3p"], check=True).stdout)
    assert facts["shape"] == [17, 12]
    assert facts["spacing"] == [2e-6, 3e-6]
    assert facts["valid_points"] == 12 * 17 - 1
    assert facts["format"] == "x3p" and facts["metadata"]["title"] == "test map"


def test_info_table_names_units(sample):
    table = rough("info", sample["x3p"], check=True).stdout.decode()
    assert "2 µm × 3 µm" in table and "34 µm × 36 µm" in table and "203 of 204" in table


def test_info_tsv_rows(sample):
    rows = [
        line.split("\t")[1:] for line in rough("info", "--tsv", sample["gsf"], check=True).stdout.decode().splitlines()
    ]
    assert ["valid_points", "203", "points"] in rows
    assert ["spacing.0", "2e-06", "m"] in rows and ["spacing.1", "3e-06", "m"] in rows


@pytest.mark.parametrize("fmt", ["x3p", "exr", "gsf", "tsv", "npy"])
def test_info_reads_every_format_from_standard_input(sample, fmt):
    extra = ["--spacing", "2um,3um"] if fmt == "npy" else []
    facts = json.loads(rough("info", "--json", *extra, input=sample[fmt].read_bytes(), check=True).stdout)
    assert facts["format"] == fmt
    assert facts["shape"] == [17, 12] and facts["valid_points"] == 203
    np.testing.assert_allclose(facts["spacing"], [2e-6, 3e-6], rtol=1e-12)


def test_convert_from_standard_input_to_exr(sample, tmp_path):
    result = rough("convert", "-f", "exr", "-o", tmp_path / "scan.exr", input=sample["x3p"].read_bytes(), check=True)
    assert result.stdout == b""
    facts = json.loads(rough("info", "--json", tmp_path / "scan.exr", check=True).stdout)
    assert facts["format"] == "exr" and facts["history"][-1]["command"] == "convert"
    assert facts["history"][-1]["parameters"] == {"input": "-", "format": "exr"}


def test_pipeline_of_conversions_keeps_history(sample):
    first = rough("convert", sample["gsf"], check=True).stdout
    second = rough("convert", "-f", "tsv", input=first, check=True).stdout
    facts = json.loads(rough("info", "--json", input=second, check=True).stdout)
    assert [entry["parameters"]["format"] for entry in facts["history"]] == ["x3p", "tsv"]


def test_stdout_gets_x3p_by_default(sample):
    assert rough("convert", sample["tsv"], check=True).stdout[:4] == b"PK\x03\x04"


# -- bad input: exit 2, one line naming the file, no traceback, no output ---------------------


def bad_inputs(tmp_path):
    good = Surface(np.ones((4, 4)), (1e-6, 1e-6))
    good.write(tmp_path / "good.x3p")
    blob = (tmp_path / "good.x3p").read_bytes()
    corrupted = bytearray(blob)
    corrupted[blob.find(np.ones(16).tobytes()) + 3] ^= 0x40
    cases = {
        "empty.x3p": (b"", "empty file"),
        "truncated.x3p": (blob[: len(blob) // 2], "not a valid X3P zip archive"),
        "corrupt.x3p": (bytes(corrupted), "checksum mismatch"),
        "magic.dat": (bytes(range(256)) * 4, "unrecognised binary data"),
        "column.txt": (b"1.0\n2.0\n3.0\n", "needs the spacing"),
        "huge.x3p": (x3p_file(np.ones((2, 2)), size=(1000000, 1000000, 1)), "more than rough handles"),
        "huge.gsf": (
            b"Gwyddion Simple Field 1.0\nXRes = 1000000\nYRes = 1000000\n\0\0\0\0" + bytes(16),
            "declares 1000000×1000000",
        ),
    }
    for name, (content, _) in cases.items():
        (tmp_path / name).write_bytes(content)
    return cases


def test_bad_input_fails_cleanly(tmp_path):
    for name, (_, message) in bad_inputs(tmp_path).items():
        out = tmp_path / f"out-{name}.x3p"
        started = children_cpu_seconds()
        result = rough("convert", tmp_path / name, "-o", out)
        assert_one_line_error(result, f"{tmp_path / name}: ", message)
        assert children_cpu_seconds() - started < 10  # refused at once, not after reading a huge declaration
        assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []


def test_bad_input_on_standard_input_is_named():
    assert_one_line_error(rough("info", input=b""), "<stdin>: empty file")


def test_failure_leaves_an_existing_output_untouched(tmp_path):
    out = tmp_path / "kept.x3p"
    out.write_bytes(b"previous")
    result = rough("convert", tmp_path / "missing.x3p", "-o", out)
    assert_one_line_error(result, "missing.x3p: no such file")
    assert out.read_bytes() == b"previous"


def test_usage_errors_are_one_line():
    assert_one_line_error(rough("info", "--no-such-option"), "No such option", "rough info --help")
    assert_one_line_error(rough("convert", "--spacing", "fast", "-"), "not a length")
    assert_one_line_error(rough("nonsense"), "No such command")


def test_unknown_output_extension(sample, tmp_path):
    assert_one_line_error(rough("convert", sample["x3p"], "-o", tmp_path / "x.xyz"), "cannot tell the format")
    assert not (tmp_path / "x.xyz").exists()


def test_checksum_override_warns_and_quiet_silences_it(tmp_path):
    path = tmp_path / "bad-sum.x3p"
    path.write_bytes(x3p_file(np.ones((2, 3)), main_checksum="bad"))
    assert_one_line_error(rough("info", path), "main.xml checksum mismatch", "--ignore-checksums")
    loud = rough("info", "--ignore-checksums", path, check=True)
    assert b"warning: main.xml checksum mismatch" in loud.stderr
    assert rough("-q", "info", "--ignore-checksums", path, check=True).stderr == b""


# -- terminals, pipes and signals -----------------------------------------------------


def test_binary_output_to_a_terminal_is_refused(sample):
    controller, terminal = pty.openpty()
    try:
        result = subprocess.run(
            [sys.executable, "-m", "rough", "convert", str(sample["gsf"])],
            check=False,
            stdout=terminal,
            stderr=subprocess.PIPE,
            timeout=60,
        )
    finally:
        os.close(terminal)
        os.close(controller)
    assert result.returncode == 2
    assert b"refusing to write binary X3P to a terminal" in result.stderr


def test_closed_downstream_pipe_ends_quietly(tmp_path):
    Surface(np.zeros(200000), (1e-6,)).write(tmp_path / "long.x3p")
    pipeline = subprocess.run(
        f"{sys.executable} -m rough convert -f tsv {tmp_path / 'long.x3p'} | head -n 3",
        check=False,
        shell=True,
        capture_output=True,
        timeout=60,
    )
    assert pipeline.stdout.decode().startswith("# rough")
    assert pipeline.stderr == b""


def test_closed_pipe_status(tmp_path):
    Surface(np.zeros(200000), (1e-6,)).write(tmp_path / "long.x3p")
    process = subprocess.Popen(
        [sys.executable, "-m", "rough", "convert", "-f", "tsv", str(tmp_path / "long.x3p")],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    process.stdout.read(100)
    process.stdout.close()
    assert process.wait(timeout=60) == 141
    assert process.stderr.read() == b""


def test_ctrl_c_exits_130_with_nothing_written(tmp_path):
    out = tmp_path / "never.x3p"
    process = subprocess.Popen(
        [sys.executable, "-m", "rough", "convert", "-o", str(out)],
        stdin=subprocess.PIPE,
        stderr=subprocess.PIPE,
        cwd=ROOT,
    )
    time.sleep(1.5)
    process.send_signal(signal.SIGINT)
    assert process.wait(timeout=30) == 130
    assert b"interrupted" in process.stderr.read()
    process.stdin.close()
    assert list(tmp_path.iterdir()) == []
