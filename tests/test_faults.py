"""Faults from outside: a job killed mid-write, Ctrl-C mid-write, a full disk. (A closed
downstream pipe: tests/test_cli.py; the haptic loop's faults: tests/test_render.py.)"""

import os
import shutil
import signal
import subprocess
import sys
import time

import pytest

from conftest import assert_one_line_error, rough

BIG = ["synth", "--size", "4096x4096", "--step", "1um", "--dimension", "2.3", "--amplitude", "1um", "--seed", "1"]


def start_writing(folder):
    """Start writing a 134 MB map to ``folder/big.x3p``; return once its temporary file has data."""
    process = subprocess.Popen(
        [sys.executable, "-m", "rough", *BIG, "-o", str(folder / "big.x3p")],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        partial = [p for p in folder.iterdir() if p.name.startswith(".rough-") and p.stat().st_size > 1 << 20]
        if partial or process.poll() is not None:
            break
        time.sleep(0.005)
    assert process.poll() is None, "the write finished before it could be interrupted"
    return process


def test_kill_9_while_writing_leaves_no_output_file(tmp_path):
    process = start_writing(tmp_path)
    process.kill()
    process.wait(timeout=30)
    assert not (tmp_path / "big.x3p").exists()
    leftovers = [p.name for p in tmp_path.iterdir()]
    assert all(name.startswith(".rough-") and name.endswith(".tmp") for name in leftovers)  # hidden, never the target
    rough(*BIG, "-o", tmp_path / "big.x3p", check=True, timeout=300)
    assert rough("info", "--json", tmp_path / "big.x3p", check=True).returncode == 0


def test_ctrl_c_while_writing_exits_130_and_leaves_nothing(tmp_path):
    process = start_writing(tmp_path)
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, stderr
    assert stderr.decode().strip().endswith("interrupted") and len(stderr.splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def test_a_full_standard_output_is_a_clear_error():
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full on this system")
    with open("/dev/full", "wb") as full:
        result = subprocess.run(
            [
                sys.executable,
                "-m",
                "rough",
                "synth",
                "--length",
                "20mm",
                "--dimension",
                "1.3",
                "--rq",
                "0.1mm",
                "-f",
                "tsv",
            ],
            stdout=full,
            stderr=subprocess.PIPE,
            timeout=60,
            check=False,
        )
    assert_one_line_error(result, "standard output: No space left on device", status=1)


@pytest.fixture
def tiny_disk(tmp_path):
    mount = shutil.which("mount")
    if os.geteuid() != 0 or mount is None:
        pytest.skip("mounting a tiny tmpfs needs root")
    folder = tmp_path / "disk"
    folder.mkdir()
    if subprocess.run(
        [mount, "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(folder)], capture_output=True, check=False
    ).returncode:
        pytest.skip("this system does not let tests mount a tmpfs")
    yield folder
    subprocess.run(["umount", str(folder)], check=False)


def test_a_full_disk_is_a_clear_error_and_leaves_nothing(tiny_disk):
    result = rough(
        "synth",
        "--size",
        "256x256",
        "--step",
        "1um",
        "--dimension",
        "2.3",
        "--amplitude",
        "1um",
        "-o",
        tiny_disk / "map.x3p",
    )
    assert_one_line_error(result, f"{tiny_disk / 'map.x3p'}: No space left on device", status=1)
    assert list(tiny_disk.iterdir()) == []
    plot = rough("synth", "--length", "5mm", "--dimension", "1.3", "--rq", "0.1mm", check=True).stdout
    result = rough("fit-fractal", "--psd", tiny_disk / "psd.tsv", "--plot", tiny_disk / "psd.png", input=plot)
    if result.returncode:
        assert_one_line_error(result, "No space left on device", status=1)
    assert not [p for p in tiny_disk.iterdir() if p.name.startswith(".rough-")]
