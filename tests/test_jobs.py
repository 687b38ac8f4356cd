"""``--jobs N``: several inputs on several processes print exactly what one process
prints, in input order; a bad input, a killed worker and Ctrl-C are handled as with
one process (rough/cli/batch.py, rough/tasks.py)."""

import os
import pathlib
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import threadpoolctl

import rough
from rough import tasks as pool

from conftest import rough as run

pytestmark = pytest.mark.skipif(not pool.can_fork(), reason="--jobs works in parallel only where fork is")


def _map(path, size, seed):
    heights = np.random.default_rng(seed).standard_normal((size, size)).cumsum(axis=0).cumsum(axis=1) * 1e-9
    rough.io.write(rough.Surface(heights, 1e-6), str(path))
    return str(path)


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """Six inputs, the first the slowest and the third not a surface."""
    folder = tmp_path_factory.mktemp("jobs")
    names = [_map(folder / "slow.x3p", 512, 0)]
    names += [_map(folder / f"m{index}.x3p", 48, index) for index in range(1, 5)]
    (folder / "bad.x3p").write_bytes(b"not a surface\n")
    names.insert(2, str(folder / "bad.x3p"))
    return names


def _same(one, two):
    assert one.returncode == two.returncode
    assert one.stdout == two.stdout
    assert one.stderr == two.stderr


@pytest.mark.parametrize(
    "command",
    [["features"], ["features", "--tsv"], ["fit-fractal", "--json"], ["info"], ["info", "--tsv"]],
)
def test_two_jobs_print_what_one_prints_in_input_order(inputs, command):
    one = run(*command, *inputs)
    two = run(*command, "--jobs", "2", *inputs)
    assert one.returncode == 2  # the bad input
    assert b"bad.x3p" in one.stderr and b"Traceback" not in two.stderr
    assert one.stdout  # the other inputs were reported
    _same(one, two)


def test_the_slowest_first_input_still_comes_first(inputs):
    good = [name for name in inputs if "bad" not in name]
    result = run("features", "--tsv", "--jobs", "auto", *good, check=True)
    files = list(dict.fromkeys(line.split(b"\t")[0].decode() for line in result.stdout.splitlines()))
    assert files == good


def test_one_input_takes_the_sequential_path(inputs):
    # one input: no "file" row and an error raised as by one process, not a worker's line
    _same(run("info", inputs[1]), run("info", "--jobs", "2", inputs[1]))
    bad = run("info", "--jobs", "2", inputs[2])
    assert bad.returncode == 2 and bad.stderr.count(b"\n") == 1


def test_outputs_in_a_folder_are_the_same(inputs, tmp_path):
    good = [name for name in inputs if "bad" not in name]
    environment = {"SOURCE_DATE_EPOCH": "1700000000"}
    run("detrend", *good, "-o", f"{tmp_path / 'one'}/", env=environment, check=True)
    run("detrend", "--jobs", "2", *good, "-o", f"{tmp_path / 'two'}/", env=environment, check=True)
    one, two = sorted((tmp_path / "one").iterdir()), sorted((tmp_path / "two").iterdir())
    assert [path.name for path in one] == [path.name for path in two] == sorted(pathlib.Path(n).name for n in good)
    assert all(a.read_bytes() == b.read_bytes() for a, b in zip(one, two))


def test_jobs_refuses_a_negative_or_unknown_count(inputs):
    for value in ("-1", "two", "100000"):
        result = run("info", "--jobs", value, *inputs[:2])
        assert result.returncode == 2 and b"--jobs" in result.stderr


@pytest.fixture(scope="module")
def slow_inputs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("slow")
    return [_map(folder / f"s{index}.x3p", 1024, index) for index in range(4)]


def _start(*args, folder):
    return subprocess.Popen(
        [sys.executable, "-m", "rough", *args],
        cwd=folder,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        start_new_session=True,
    )


def _children(pid, count, timeout=20):
    """The child processes of ``pid`` once there are ``count`` of them."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        found = pathlib.Path(f"/proc/{pid}/task/{pid}/children").read_text().split()
        if len(found) >= count:
            return [int(child) for child in found]
        time.sleep(0.05)
    raise AssertionError("the workers did not start")


def test_ctrl_c_stops_every_worker_and_leaves_no_temporary_file(slow_inputs, tmp_path):
    process = _start("features", "--jobs", "2", *slow_inputs, "--plot", "{stem}.png", folder=tmp_path)
    workers = _children(process.pid, 2)
    time.sleep(0.5)
    os.killpg(process.pid, signal.SIGINT)  # as Ctrl-C at a terminal: the whole group
    try:
        stdout, stderr = process.communicate(timeout=10)
    finally:
        process.kill()
    assert process.returncode == 130, stderr
    assert stderr.decode().strip().endswith("interrupted") and b"Traceback" not in stderr
    assert not [path for path in tmp_path.iterdir() if path.name.startswith(".rough-")]
    for worker in workers:  # ended and reaped
        assert not pathlib.Path(f"/proc/{worker}").exists() or "Z" in _state(worker)


def test_sigint_to_the_parent_alone_stops_the_workers(slow_inputs, tmp_path):
    process = _start("features", "--jobs", "2", *slow_inputs, folder=tmp_path)
    workers = _children(process.pid, 2)
    process.send_signal(signal.SIGINT)
    try:
        _, stderr = process.communicate(timeout=10)
    finally:
        process.kill()
    assert process.returncode == 130, stderr
    for worker in workers:
        assert not pathlib.Path(f"/proc/{worker}").exists() or "Z" in _state(worker)


def _state(pid):
    try:
        return pathlib.Path(f"/proc/{pid}/stat").read_text().split(")")[1].split()[0]
    except FileNotFoundError:
        return "Z"


def test_a_killed_worker_is_reported_for_its_input_and_the_rest_kept(slow_inputs, tmp_path):
    process = _start("features", "--tsv", "--jobs", "2", *slow_inputs, folder=tmp_path)
    workers = _children(process.pid, 2)  # each takes over a second per input
    os.kill(workers[0], signal.SIGKILL)
    stdout, stderr = process.communicate(timeout=60)
    assert process.returncode == 1, stderr
    assert b"worker process died (killed by SIGKILL)" in stderr
    files = {line.split(b"\t")[0] for line in stdout.splitlines()}
    assert len(files & {name.encode() for name in slow_inputs}) == 3


def test_the_pool_keeps_order_and_reports_a_dead_worker():
    def task(index):
        if index == 1:
            os.kill(os.getpid(), signal.SIGKILL)
        time.sleep(0.2 if index == 0 else 0)
        return index * index

    done = []
    results = list(pool.ordered(task, 6, 2, lambda: done.append(1)))
    assert results[0] == 0 and results[2:] == [4, 9, 16, 25]
    assert isinstance(results[1], pool.Died) and "SIGKILL" in results[1].message()
    assert len(done) == 6


def test_usable_jobs():
    assert pool.usable_jobs(4, 1) == (1, None)
    assert pool.usable_jobs(4, 3) == (3, None)
    assert pool.usable_jobs(0, 100)[0] == pool.cores()


def test_standard_input_is_read_by_a_worker(inputs):
    data = pathlib.Path(inputs[1]).read_bytes()
    names = [inputs[3], "-", inputs[4]]
    _same(run("info", "--tsv", *names, input=data), run("info", "--tsv", "--jobs", "2", *names, input=data))


def _blas_threads(index):
    return {info["internal_api"]: info["num_threads"] for info in threadpoolctl.threadpool_info()}


def test_workers_keep_blas_to_one_thread():
    if not threadpoolctl.threadpool_info():
        pytest.skip("no BLAS or OpenMP library loaded")
    with threadpoolctl.threadpool_limits(2):  # the parent's pool, as a user's OPENBLAS_NUM_THREADS=2 makes it
        assert max(_blas_threads(0).values()) == 2
        found = list(pool.ordered(_blas_threads, 2, 2))
    assert all(threads == {api: 1 for api in threads} for threads in found), found
