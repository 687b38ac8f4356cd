"""Issue 14, the command line's part: outputs that are not regular files, SIGTERM and
SIGHUP, and the one-line contract in edge cases (names, closed standard streams)."""

import json
import os
import signal
import stat
import subprocess
import sys
import threading

import numpy as np
import pytest
from test_faults import start_writing

from conftest import assert_one_line_error, rough
from x3p_files import x3p_file

EPOCH = {"SOURCE_DATE_EPOCH": "1700000000"}


@pytest.fixture
def scan(tmp_path):
    path = tmp_path / "scan.x3p"
    rough("synth", "--length", "5mm", "--dimension", "1.3", "--rq", "1um", "--seed", "1", "-o", path, check=True)
    return path


def in_shell(script, *args):
    """Run ``rough`` (as ``$R``) in a bash ``script`` with positional ``args``."""
    return subprocess.run(
        ["bash", "-c", f'R() {{ "{sys.executable}" -m rough "$@"; }}; {script}', "bash", *map(str, args)],
        capture_output=True,
        timeout=120,
    )


# 1. outputs that are not regular files


def test_a_device_is_written_not_replaced(scan, tmp_path):
    if os.geteuid() != 0:
        pytest.skip("making a device node needs root")
    node = tmp_path / "null"
    os.mknod(node, stat.S_IFCHR | 0o666, os.makedev(1, 3))
    for output in (["-f", "x3p", "-o", node], ["-f", "tsv", "-o", node]):
        rough("convert", scan, *output, check=True)
        assert stat.S_ISCHR(node.stat().st_mode)
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".rough-")] == []


def test_a_fifo_gets_the_whole_output(scan, tmp_path):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    received = []
    reader = threading.Thread(target=lambda: received.append(fifo.read_bytes()))
    reader.start()
    rough("convert", scan, "-f", "x3p", "-o", fifo, env=EPOCH, check=True)
    reader.join(timeout=60)
    assert stat.S_ISFIFO(fifo.stat().st_mode)
    assert received == [rough("convert", scan, env=EPOCH, check=True).stdout]


def test_a_symlink_is_kept_and_its_target_replaced(scan, tmp_path):
    target, link = tmp_path / "target.x3p", tmp_path / "link.x3p"
    target.write_bytes(b"old")
    link.symlink_to(target.name)
    rough("convert", scan, "-o", link, check=True)
    assert link.is_symlink() and os.readlink(link) == target.name
    assert target.read_bytes()[:2] == b"PK"
    dangling = tmp_path / "dangling.tsv"
    dangling.symlink_to("made.tsv")
    rough("convert", scan, "-o", dangling, check=True)
    assert dangling.is_symlink() and (tmp_path / "made.tsv").read_bytes().startswith(b"#")


def test_dev_stdout_on_a_pipe_is_the_pipe(scan):
    assert rough("convert", scan, "-f", "tsv", "-o", "/dev/stdout", check=True).stdout.startswith(b"#")


@pytest.mark.parametrize(
    "option, command, start",
    [
        ("--psd", "fit-fractal", b"# rough fit-fractal: log-binned spectrum"),
        ("--list", "features", b"# rough features: one row per feature"),
        ("--plot", "features", b"\x89PNG"),
    ],
)
def test_a_dash_writes_a_side_file_to_standard_output(scan, option, command, start):
    if option == "--plot":
        pytest.importorskip("matplotlib")
    result = rough(command, option, "-", scan, check=True)
    assert result.stdout.startswith(start)  # instead of the report


def test_two_side_files_on_standard_output_are_refused(scan):
    assert_one_line_error(rough("features", "--list", "-", "--plot", "-", scan), "cannot both go to standard output")


# 6. SIGTERM and SIGHUP clean up as Ctrl-C does


@pytest.mark.parametrize("signum, status, said", [(signal.SIGTERM, 143, "terminated"), (signal.SIGHUP, 129, "hung up")])
def test_a_stop_signal_while_writing_cleans_up(tmp_path, signum, status, said):
    process = start_writing(tmp_path)
    process.send_signal(signum)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == status, stderr
    assert stderr.decode().strip() == f"rough synth: {said}"
    assert list(tmp_path.iterdir()) == []


# 7. the one-line contract in edge cases


@pytest.fixture
def flat(tmp_path):
    path = tmp_path / "flat.txt"
    path.write_text("0 1\n1 1\n2 1\n3 1\n")
    return path


def test_a_refusal_from_the_analysis_names_its_input(flat):
    assert_one_line_error(rough("fit-fractal", flat), f"rough fit-fractal: {flat}: the surface is flat")
    assert_one_line_error(rough("fit-fractal", input=flat.read_bytes()), "rough fit-fractal: <stdin>: the surface is")


def test_a_file_name_with_a_newline_and_an_escape_stays_on_one_line(flat, scan, tmp_path):
    odd = tmp_path / "two\nlines\x1b[31m.txt"
    flat.rename(odd)
    result = rough("fit-fractal", odd)
    assert_one_line_error(result, "two\\nlines\\x1b[31m.txt: the surface is flat")
    assert b"\x1b" not in result.stderr
    missing = rough("info", tmp_path / "no\nsuch\x1b.x3p")
    assert_one_line_error(missing, "no\\nsuch\\x1b.x3p: no such file")
    table = rough("info", scan.rename(tmp_path / "a\x1b]0;title\x07.x3p"), check=True).stdout
    assert b"\x1b" not in table and b"a\\x1b]0;title\\x07.x3p" in table


def test_library_warnings_do_not_leak(tmp_path):
    valid = np.ones((3, 4), bool)
    valid[1] = False  # an all-invalid row: its y comes from the rows around it
    path = tmp_path / "nan-y.x3p"
    path.write_bytes(x3p_file(np.ones((3, 4)), absolute_y=np.array([0, 1, 2], dtype=np.int16), valid=valid))
    result = rough("info", "--json", path, check=True)
    assert result.stderr == b""
    facts = json.loads(result.stdout)
    assert facts["shape"] == [4, 3] and facts["valid_points"] == 8 and facts["spacing"][1] == 2.0  # CY Increment


@pytest.mark.parametrize(
    "command", [["info"], ["features"], ["fit-fractal"], ["convert"], ["convert", "-f", "tsv"], ["rose"]]
)
def test_a_closed_standard_output_is_an_error(scan, command):
    if command == ["rose"]:
        rough("synth", "--size", "64x64", "--dimension", "2.3", "--amplitude", "1um", "-o", scan, check=True)
    result = in_shell('R -q "$@" >&-', *command, scan)
    assert_one_line_error(result, "standard output is closed", status=1)


def test_a_closed_standard_error_sends_nothing_to_standard_output(tmp_path):
    result = in_shell('R info "$1" 2>&-', tmp_path / "missing.x3p")
    assert result.returncode == 2 and result.stdout == b"" and result.stderr == b""


def test_a_closed_standard_input_is_refused():
    assert_one_line_error(in_shell("R info <&-"), "<stdin>: standard input is closed")


def test_names_too_long_for_the_system(scan, tmp_path):
    long = "a" * 300 + ".x3p"
    assert_one_line_error(rough("info", tmp_path / long), long)
    assert_one_line_error(rough("convert", scan, "-o", tmp_path / long), long)
    assert_one_line_error(rough("convert", scan, "-o", scan / "x.x3p"), "Not a directory")
    loop = tmp_path / "loop.x3p"
    loop.symlink_to(loop.name)
    assert_one_line_error(rough("convert", scan, "-o", loop), "loop.x3p")
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".rough-")] == []
