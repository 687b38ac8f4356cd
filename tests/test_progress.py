"""Long work: progress bars on a terminal only, Ctrl-C within a second (status 130,
nothing written), tips wider than the scan, and the chunked passes giving the same
numbers, bit for bit, as one call over everything."""

import fcntl
import io
import os
import pty
import re
import select
import signal
import struct
import subprocess
import sys
import termios
import time

import numpy as np
import pytest

from rough import Surface, progress
from rough.metrology import tip

from conftest import ROOT, assert_one_line_error, children_cpu_seconds, cpu_seconds_of, rough

ENV = {"PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
ANISOTROPY = "2.2,1um,2.5,3um,30"


@pytest.fixture(autouse=True)
def progress_enabled():
    progress.configure(True)
    yield
    progress.configure(True)


@pytest.fixture(scope="module")
def big_map(tmp_path_factory):
    """2.048 mm × 2.048 mm at 2 µm: a 0.5 mm tip takes seconds here."""
    path = tmp_path_factory.mktemp("maps") / "big.x3p"
    command = ("synth", "--size", "1024x1024", "--step", "2um", "--dimension", "2.3", "--rq", "20um")
    rough(*command, "--seed", "5", "-o", path, check=True, env=ENV)
    return path


@pytest.fixture(scope="module")
def medium_map(tmp_path_factory):
    """1.024 mm × 1.024 mm at 2 µm: a 0.25 mm tip takes a fraction of a second."""
    path = tmp_path_factory.mktemp("maps") / "medium.x3p"
    command = ("synth", "--size", "512x512", "--step", "2um", "--dimension", "2.3", "--rq", "20um")
    rough(*command, "--seed", "6", "-o", path, check=True, env=ENV)
    return path


def start(*args, stderr=subprocess.PIPE):
    return subprocess.Popen(
        [sys.executable, "-m", "rough", *map(str, args)],
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=stderr,
        env={**os.environ, **ENV},
    )


def interrupt_when(process, announcement, after=0.5):
    """Read the -v notes until ``announcement`` (the work is starting), wait ``after``
    seconds, send SIGINT; return (CPU seconds the process used from the signal to its
    exit, stderr). CPU time, not wall time: a loaded machine stretches the wall time
    of the same work, not its CPU time."""
    seen, announcement = b"", announcement.encode()
    while announcement not in seen:
        line = process.stderr.readline()
        assert line, f"the process ended before {announcement!r}: {seen.decode()}"
        seen += line
    time.sleep(after)
    assert process.poll() is None, "the work ended before the signal: make it longer"
    before, used = children_cpu_seconds(), cpu_seconds_of(process.pid)
    process.send_signal(signal.SIGINT)
    rest = process.communicate(timeout=60)[1]
    return children_cpu_seconds() - before - used, (seen + rest).decode()


# -- Ctrl-C ------------------------------------------------------------------------------------------


def test_ctrl_c_stops_a_tip_pass_within_a_second_with_nothing_written(big_map, tmp_path):
    out = tmp_path / "traced.x3p"
    process = start("-v", "detrend", "--tip", "fingernail", big_map, "-o", out)
    seconds, stderr = interrupt_when(process, "tip: a kernel of 501 × 501 samples")
    assert process.returncode == 130, stderr
    assert seconds < 2, f"{seconds:.2f} s of CPU from SIGINT to the exit"
    assert "Traceback" not in stderr and stderr.rstrip().endswith("rough detrend: interrupted"), stderr
    assert list(tmp_path.iterdir()) == []


def test_ctrl_c_stops_a_large_synthesis_within_a_second_with_nothing_written(tmp_path):
    out = tmp_path / "synth.x3p"
    process = start("-v", "synth", "--size", "8192x8192", "--dimension", "2.3", "--anisotropy", ANISOTROPY, "-o", out)
    seconds, stderr = interrupt_when(process, "a 8192 × 8192 map in", after=0.3)
    assert process.returncode == 130, stderr
    assert seconds < 2, f"{seconds:.2f} s of CPU from SIGINT to the exit"
    assert "Traceback" not in stderr and stderr.rstrip().endswith("rough synth: interrupted"), stderr
    assert list(tmp_path.iterdir()) == []


def test_ctrl_c_stops_a_segmentation_within_a_second(tmp_path):
    heights = tmp_path / "rough.npy"
    rng = np.random.default_rng(7)
    np.save(heights, np.cumsum(rng.standard_normal((2048, 2048)), axis=1) * 1e-9)  # many basins
    process = start("-v", "features", "--spacing", "1um", heights)
    seconds, stderr = interrupt_when(process, "segmenting hills: 2048 × 2048 points by compiled passes", after=0.3)
    assert process.returncode == 130, stderr
    assert seconds < 2, f"{seconds:.2f} s of CPU from SIGINT to the exit"
    assert "Traceback" not in stderr and stderr.rstrip().endswith("rough features: interrupted"), stderr


# -- progress bars --------------------------------------------------------------------------------------


def test_no_progress_when_standard_error_is_not_a_terminal(medium_map, tmp_path):
    result = rough("detrend", "--tip", "0.25mm", medium_map, "-o", tmp_path / "traced.x3p", env=ENV)
    assert result.returncode == 0 and result.stderr == b""


def run_on_a_terminal(*args):
    """Run rough with standard error on a pseudo-terminal (80 columns); returns the
    exit status and what the terminal received."""
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 80, 0, 0))
    process = start(*args, stderr=slave)
    os.close(slave)
    received = b""
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline:
        ready, _, _ = select.select([master], [], [], 1)
        if ready:
            try:
                chunk = os.read(master, 4096)
            except OSError:  # EIO: the child closed the terminal
                break
            if not chunk:
                break
            received += chunk
        elif process.poll() is not None:
            break
    os.close(master)
    return process.wait(timeout=60), received.decode(errors="replace")


def test_a_progress_bar_on_a_terminal_once_the_work_takes_two_seconds_and_none_with_q(big_map, tmp_path):
    status, shown = run_on_a_terminal("detrend", "--tip", "fingernail", big_map, "-o", tmp_path / "traced.x3p")
    assert status == 0, shown
    assert "tip:" in shown and "%|" in shown and "point/s" in shown, shown
    assert re.search("\r +\r$", shown), shown[-200:]  # erased at the end (leave=False)
    status, shown = run_on_a_terminal("-q", "detrend", "--tip", "fingernail", big_map, "-o", tmp_path / "q.x3p")
    assert status == 0 and shown == "", shown


class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_progress_draws_on_a_terminal_only_when_enabled(monkeypatch):
    terminal = Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    monkeypatch.setattr(progress, "DELAY", 0.0)
    assert list(progress.progress(range(5), description="rows", unit="row")) == [0, 1, 2, 3, 4]
    drawn = terminal.getvalue()
    assert "rows:" in drawn and "/5 [" in drawn and "row/s" in drawn, drawn
    progress.configure(False)
    terminal.truncate(0)
    terminal.seek(0)
    with progress.progress(total=3, description="rows") as bar:
        assert bar.disable
        bar.update(3)
    assert list(progress.progress([7, 8])) == [7, 8]
    assert terminal.getvalue() == ""


def test_progress_is_silent_on_a_stream_that_is_not_a_terminal_and_before_the_delay(monkeypatch):
    plain = io.StringIO()
    monkeypatch.setattr(sys, "stderr", plain)
    monkeypatch.setattr(progress, "DELAY", 0.0)
    with progress.progress(total=4) as bar:
        assert bar.disable
        bar.update(4)
    assert plain.getvalue() == ""
    terminal = Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    monkeypatch.setattr(progress, "DELAY", 2.0)
    with progress.progress(total=4) as bar:
        assert not bar.disable
        bar.update(4)  # quick work: no bar
    assert terminal.getvalue().strip() == ""
    monkeypatch.setattr(sys, "stderr", None)
    assert progress.progress(total=1).disable


def test_a_warning_during_the_work_gets_its_own_line_and_the_bar_comes_back(monkeypatch):
    import logging

    terminal = Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    monkeypatch.setattr(progress, "DELAY", 0.0)
    logger = logging.getLogger("rough")
    handler = logging.StreamHandler(terminal)
    monkeypatch.setattr(logger, "handlers", [handler])
    with progress.progress(total=3, description="work") as bar:
        bar.update(1)
        logger.warning("careful")
        bar.update(2)
    assert logger.handlers == [handler]
    drawn = terminal.getvalue()
    before, after = drawn.split("careful\n")
    assert before.startswith("\rwork:") and re.search("\r +\r$", before)  # the bar, erased for the line
    assert after.startswith("\rwork:") and re.search("\r +\r$", after)  # drawn again, erased at the end


# -- tips wider than the scan -------------------------------------------------------------------


def test_a_tip_wider_than_a_map_is_refused_when_the_pass_would_be_long(tmp_path):
    wide = tmp_path / "wide.x3p"
    command = ("synth", "--size", "4096x2048", "--step", "1um", "--dimension", "2.3", "--rq", "20um")
    rough(*command, "--seed", "7", "-o", wide, check=True, env=ENV)
    out = tmp_path / "finger.x3p"
    result = rough("detrend", "--tip", "fingertip", wide, "-o", out, env=ENV, timeout=120)
    assert_one_line_error(result, "8 mm tip (16 mm across) is wider than the 4.096 mm × 2.048 mm scan", "coarser")
    assert not out.exists()


def test_a_tip_wider_than_the_scan_is_warned_about_in_one_line(tmp_path):
    small = tmp_path / "small.x3p"
    rough("synth", "--size", "64x64", "--step", "10um", "--dimension", "2.3", "--rq", "5um", "-o", small, env=ENV)
    result = rough("detrend", "--tip", "0.5mm", small, "-o", tmp_path / "out.x3p", env=ENV)
    assert result.returncode == 0
    lines = result.stderr.decode().splitlines()
    assert lines == ["rough detrend: warning: a 500 µm tip (1 mm across) is wider than the 640 µm × 640 µm scan: "
                     "its path depends on where the scan ends"]  # fmt: skip
    profile = tmp_path / "profile.x3p"
    rough("synth", "--points", "200", "--step", "10um", "--dimension", "1.3", "--rq", "5um", "-o", profile, env=ENV)
    result = rough("detrend", "--tip", "fingertip", profile, "-o", tmp_path / "p.x3p", env=ENV)
    assert result.returncode == 0 and "wider than the 2 mm scan" in result.stderr.decode()
    inside = rough("detrend", "--tip", "0.2mm", small, "-o", tmp_path / "inside.x3p", env=ENV)
    assert inside.returncode == 0 and inside.stderr == b""


# -- the chunked work gives what one call gives ----------------------------------------------


def bits(array):
    return np.ascontiguousarray(array).view(np.uint64)


def test_a_profile_traced_in_tiles_is_scipys_grey_morphology_bit_for_bit(monkeypatch):
    from scipy import ndimage

    monkeypatch.setattr(tip, "CHUNK_SECONDS", 1e-5)
    rng = np.random.default_rng(5)
    z = rng.normal(size=3000) * 1e-5
    z[z > 1.5e-5] = 0.0
    z[z < -1.5e-5] = -0.0
    z[rng.random(z.size) < 0.03] = np.nan
    surface = Surface(z, (1e-6,))
    disk = tip.tip_profile(2e-4, (1e-6,), z.shape)
    lowering = disk - disk[disk.size // 2]
    raised = np.where(np.isnan(z), -np.inf, z)
    path = ndimage.grey_dilation(raised, structure=lowering, mode="constant", cval=-np.inf)
    expected = np.where(np.isnan(z) | ~np.isfinite(path), np.nan, np.fmax(path, z))
    assert np.array_equal(bits(tip.traced(surface, 2e-4).heights), bits(expected))
    known = np.where(np.isnan(expected), np.inf, expected)
    eroded = ndimage.grey_erosion(known, structure=lowering, mode="constant", cval=np.inf)
    closed = np.where(np.isnan(z), np.nan, np.fmax(eroded, z))
    assert np.array_equal(bits(tip.closing_envelope(surface, 2e-4).heights), bits(closed))


@pytest.mark.parametrize("shape", [(512, 512), (300, 511), (1000, 257), (700, 3), (12, 10)])
def test_the_synthesis_inverse_transform_in_blocks_is_irfft2_bit_for_bit(shape):
    from scipy import fft

    from rough.fractal import synth, synth_map

    ny, nx = shape
    rng = np.random.default_rng(ny * nx)
    spectrum = (rng.standard_normal((ny, nx // 2 + 1)) + 1j * rng.standard_normal((ny, nx // 2 + 1))).astype(
        np.complex64
    )
    expected = fft.irfft2(spectrum.copy(), (ny, nx), workers=-1).astype(np.float64)
    steps = []
    heights = synth_map._inverse_transform(
        spectrum, nx, synth.slices(nx // 2 + 1, 7), synth.slices(ny, 5), lambda: steps.append(1)
    )
    assert np.array_equal(bits(heights), bits(expected))
    assert len(steps) == len(synth.slices(nx // 2 + 1, 7)) + len(synth.slices(ny, 5))
