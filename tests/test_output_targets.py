"""Issue 31: output names of descriptors are written through them, never replaced; the
temporary file is flushed to the disk before its rename and removed on every
terminating signal a process can catch; an output whose format cannot be told is
refused before any work."""

import os
import signal
import subprocess
import sys

import pytest
from test_faults import start_writing

from rough.io import atomic

from conftest import assert_one_line_error, rough


@pytest.fixture
def profile(tmp_path):
    path = tmp_path / "p.tsv"
    rough("synth", "--length", "1mm", "--dimension", "1.3", "--rq", "1um", "--seed", "1", "-o", path, check=True)
    return path


EPOCH = {"SOURCE_DATE_EPOCH": "1700000000"}  # the same history line in every output


def in_shell(script, *args):
    """Run ``rough`` (as ``$R``) in a bash ``script`` with positional ``args``."""
    return subprocess.run(
        ["bash", "-c", f'R() {{ "{sys.executable}" -m rough "$@"; }}; {script}', "bash", *map(str, args)],
        capture_output=True,
        timeout=120,
        env={**os.environ, **EPOCH},
    )


def converted(path):
    return rough("convert", path, "-f", "tsv", env=EPOCH, check=True).stdout


# -- descriptors -----------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["/dev/stdout", "/dev/fd/1", "/proc/self/fd/1"])
def test_output_to_standard_output_by_name_appends_after_a_shell_append(profile, tmp_path, name):
    log = tmp_path / "app.tsv"
    log.write_bytes(b"earlier line\n")
    in_shell('R convert "$1" -f tsv -o "$2" >> "$3"', profile, name, log).check_returncode()
    assert log.read_bytes() == b"earlier line\n" + converted(profile)


def test_output_to_dev_stderr_keeps_the_log_it_is_appended_to(profile, tmp_path):
    log = tmp_path / "log.txt"
    log.write_bytes(b"log line\n")
    in_shell('R convert "$1" -f tsv -o /dev/stderr 2>> "$2"', profile, log).check_returncode()
    assert log.read_bytes() == b"log line\n" + converted(profile)


def test_a_numbered_descriptor_and_a_link_to_one_are_written_through(profile, tmp_path):
    log, link = tmp_path / "app.tsv", tmp_path / "link.tsv"
    log.write_bytes(b"earlier line\n")
    link.symlink_to("/dev/fd/5")
    in_shell('R convert "$1" -f tsv -o /dev/fd/5 5>> "$2"', profile, log).check_returncode()
    in_shell('R convert "$1" -o "$2" 5>> "$3"', profile, link, log).check_returncode()
    assert log.read_bytes() == b"earlier line\n" + 2 * converted(profile)
    assert link.is_symlink()


def test_a_descriptor_written_after_a_truncating_redirection_holds_just_the_output(profile, tmp_path):
    out = tmp_path / "out.x3p"
    out.write_bytes(b"x" * 100_000)
    in_shell('R convert "$1" -f x3p -o /dev/stdout > "$2"', profile, out).check_returncode()
    assert rough("info", "--json", out, check=True).returncode == 0


def test_binary_output_through_dev_stdout_to_a_terminal_is_refused_as_through_a_dash(profile):
    import pty

    terminal, device = pty.openpty()
    try:
        for output in ("-", "/dev/stdout"):
            command = [sys.executable, "-m", "rough", "convert", str(profile), "-f", "x3p", "-o", output]
            result = subprocess.run(command, stdout=device, stderr=subprocess.PIPE, timeout=120)
            assert_one_line_error(result, "refusing to write binary X3P to a terminal")
    finally:
        os.close(device)
        os.close(terminal)


def test_a_descriptor_that_is_not_open_is_refused_in_one_line(profile):
    assert_one_line_error(
        rough("convert", profile, "-f", "tsv", "-o", "/dev/fd/9"), "/dev/fd/9: descriptor 9 is not open"
    )


def test_an_output_whose_format_cannot_be_told_is_refused_before_the_input_is_read(profile):
    result = rough("-v", "detrend", "--tip", "needle", profile, "-o", "/dev/null")
    assert_one_line_error(result, "/dev/null: cannot tell the format from the extension")
    result = rough("-v", "synth", "--size", "64x64", "--dimension", "2.3", "--rq", "1um", "-o", "/dev/null")
    assert_one_line_error(result, "/dev/null: cannot tell the format from the extension")


# -- the temporary file --------------------------------------------------------------------------


def test_the_data_reach_the_disk_before_the_rename_and_the_rename_after(tmp_path, monkeypatch):
    events = []
    real_fsync, real_replace = os.fsync, os.replace

    def fsync(fd):
        events.append(("fsync", os.path.basename(os.readlink(f"/proc/self/fd/{fd}"))))
        real_fsync(fd)

    def replace(source, target):
        events.append(("replace", os.path.basename(target)))
        real_replace(source, target)

    monkeypatch.setattr(os, "fsync", fsync)
    monkeypatch.setattr(os, "replace", replace)
    with atomic.atomic_output(tmp_path / "out.bin") as stream:
        stream.write(b"data")
    assert [kind for kind, _ in events] == ["fsync", "replace", "fsync"]
    assert events[0][1].startswith(".rough-") and events[2][1] == tmp_path.name
    assert (tmp_path / "out.bin").read_bytes() == b"data"


WRITING = """
import sys, time
from rough.io.atomic import atomic_output

with atomic_output(sys.argv[1]) as stream:
    stream.write(b"partial")
    stream.flush()
    print("writing", flush=True)
    while True:
        time.sleep(0.01)
"""
# the terminating signals a Python process leaves at their default action (it ignores
# SIGPIPE and SIGXFSZ, and SIGINT is KeyboardInterrupt)
SIGNALS = [
    getattr(signal, name)
    for name in ("SIGHUP", "SIGQUIT", "SIGTERM", "SIGUSR1", "SIGUSR2", "SIGALRM", "SIGVTALRM", "SIGPROF", "SIGXCPU")
    + ("SIGIO", "SIGPWR")
    if hasattr(signal, name)
]


@pytest.mark.parametrize("signum", SIGNALS, ids=lambda signum: signal.Signals(signum).name)
def test_a_terminating_signal_mid_write_removes_the_temporary_file_and_ends_by_that_signal(tmp_path, signum):
    target = tmp_path / "out.bin"
    target.write_bytes(b"old")
    process = subprocess.Popen(
        [sys.executable, "-c", WRITING, str(target)], stdout=subprocess.PIPE, stderr=subprocess.PIPE
    )
    assert process.stdout.readline() == b"writing\n"
    assert len(list(tmp_path.iterdir())) == 2  # the target and the temporary file
    process.send_signal(signum)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == -signum, stderr
    assert [p.name for p in tmp_path.iterdir()] == ["out.bin"] and target.read_bytes() == b"old"


@pytest.mark.parametrize("signum", [signal.SIGQUIT, signal.SIGUSR1], ids=["SIGQUIT", "SIGUSR1"])
def test_quit_and_usr1_while_rough_writes_a_large_map_leave_nothing(tmp_path, signum):
    process = start_writing(tmp_path)
    process.send_signal(signum)
    process.communicate(timeout=60)
    assert process.returncode == -signum
    assert list(tmp_path.iterdir()) == []


def test_a_handler_of_the_program_is_left_alone(tmp_path):
    """A signal the program handles itself (here by raising SystemExit) is its business:
    the temporary file goes, as with any exception, and the program goes on."""
    script = (
        "import signal, sys, time\n"
        "from rough.io.atomic import atomic_output\n"
        "def stop(signum, frame):\n"
        "    raise SystemExit(7)\n"
        "signal.signal(signal.SIGUSR1, stop)\n" + WRITING.split("\n", 3)[3]
    )
    process = subprocess.Popen([sys.executable, "-c", script, str(tmp_path / "out.bin")], stdout=subprocess.PIPE)
    assert process.stdout.readline() == b"writing\n"
    process.send_signal(signal.SIGUSR1)
    process.communicate(timeout=60)
    assert process.returncode == 7 and list(tmp_path.iterdir()) == []
