"""rough.tasks.map_ordered (issue 34, items 3 and 4): results in the items' order
whatever ran where, an item's own error raised in the caller, and the workers stopped
when the caller is interrupted."""

import contextlib
import os
import pathlib
import signal
import threading
import time

import numpy as np
import pytest

import rough
from rough import tasks

forking = pytest.mark.skipif(not tasks.can_fork(), reason="a pool of processes is forked, on Linux only")


def _slow_square(item):
    time.sleep(0.05 * (item % 3 == 0))  # some finish before the ones before them
    return item * item


def _checked(item):
    if item == 3:
        raise rough.InputError(f"item {item} is bad")
    if item == 5:
        raise ZeroDivisionError("the second failure")
    return item


def _solve(seed):
    """Some floating-point work through LAPACK and reductions, to be reproduced bit for bit."""
    rng = np.random.default_rng(seed)
    matrix = rng.standard_normal((60, 60))
    return np.linalg.solve(matrix @ matrix.T + np.eye(60), rng.standard_normal(60)), np.sum(matrix**3)


def _pid(item):
    time.sleep(0.2 if item else 0)
    return os.getpid()


def _gone(pid):
    return not pathlib.Path(f"/proc/{pid}").exists()


@pytest.mark.parametrize("jobs", [1, pytest.param(2, marks=forking), pytest.param(0, marks=forking)])
def test_results_come_in_the_items_order(jobs):
    assert list(tasks.map_ordered(_slow_square, range(10), jobs=jobs)) == [i * i for i in range(10)]
    assert list(tasks.map_ordered(_slow_square, iter([]), jobs=jobs)) == []


@pytest.mark.parametrize("jobs", [1, pytest.param(2, marks=forking)])
def test_an_items_own_error_is_raised_in_the_caller(jobs):
    results = tasks.map_ordered(_checked, range(8), jobs=jobs)
    assert [next(results) for _ in range(3)] == [0, 1, 2]
    with pytest.raises(rough.InputError, match=r"^item 3 is bad$") as raised:
        next(results)
    assert raised.value.exit_code == 2


@forking
def test_an_error_that_does_not_pickle_is_reported_by_its_message():
    class Local(Exception):  # a class defined here cannot be unpickled by name
        pass

    def fails(item):
        raise Local("nope")

    with pytest.raises(rough.RoughError, match="internal error: Local: nope"):
        list(tasks.map_ordered(fails, range(2), jobs=2))


@forking
def test_two_jobs_give_what_one_gives_bit_for_bit():
    one = list(tasks.map_ordered(_solve, range(6), jobs=1))
    two = list(tasks.map_ordered(_solve, range(6), jobs=2))
    for (a, s), (b, t) in zip(one, two):
        assert a.tobytes() == b.tobytes() and s == t


@forking
def test_a_dead_worker_raises_a_rough_error():
    def dies(item):
        if item == 1:
            os.kill(os.getpid(), signal.SIGKILL)
        return item

    with pytest.raises(rough.RoughError, match="worker process died .killed by SIGKILL"):
        list(tasks.map_ordered(dies, range(4), jobs=2))


class _InterruptedWhenCollected:
    def __del__(self):
        raise KeyboardInterrupt  # as Ctrl-C landing in a finaliser: Python cannot raise it


@forking
def test_a_stop_where_python_cannot_raise_it_ends_the_worker_quietly(capfd):
    """Ctrl-C or SIGTERM that lands in a finaliser or a weakref callback (an import's
    lock) ends the worker, printing nothing ("Exception ignored in …" was printed and
    the worker went on)."""

    def interrupted(item):
        if item == 1:
            _InterruptedWhenCollected()
            time.sleep(30)  # not reached: the worker ends as the object is collected
        return item

    with pytest.raises(rough.RoughError, match="worker process died"):
        list(tasks.map_ordered(interrupted, range(4), jobs=2))
    assert "Exception ignored" not in capfd.readouterr().err


@forking
def test_keyboard_interrupt_in_the_consumer_stops_the_workers():
    seen = []
    with pytest.raises(KeyboardInterrupt), contextlib.closing(tasks.map_ordered(_pid, range(20), jobs=2)) as pids:
        for pid in pids:
            seen.append(pid)
            raise KeyboardInterrupt  # as Ctrl-C while the caller handles a result
    assert seen and seen[0] != os.getpid()
    assert _gone(seen[0])


@forking
def test_ctrl_c_while_waiting_stops_the_workers():
    before = set(_children())
    workers = []

    def slow(item):
        time.sleep(30)
        return item

    def ctrl_c():
        workers.extend(set(_children()) - before)
        os.kill(os.getpid(), signal.SIGINT)  # delivered to the main thread, waiting on the workers

    timer = threading.Timer(1.0, ctrl_c)
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            for _ in tasks.map_ordered(slow, range(4), jobs=2):
                pass
    finally:
        timer.cancel()
    assert len(workers) == 2
    assert all(_gone(pid) for pid in workers)


def _children():
    path = pathlib.Path(f"/proc/{os.getpid()}/task/{os.getpid()}/children")
    return [int(pid) for pid in path.read_text().split()] if path.exists() else []


def test_usable_jobs():
    assert tasks.usable_jobs(4, 1) == (1, None)
    assert tasks.usable_jobs(4, 3)[0] == (3 if tasks.can_fork() else 1)
    assert tasks.usable_jobs(0, 100)[0] == (tasks.cores() if tasks.can_fork() else 1)


def test_outcomes_keep_going_past_a_failed_item():
    found = list(tasks.outcomes(_checked, range(7)))
    assert found[:3] == [0, 1, 2] and found[4] == 4 and found[6] == 6
    assert isinstance(found[3], tasks.Failed) and isinstance(found[3].error, rough.InputError)
    assert isinstance(found[5], tasks.Failed) and "ZeroDivisionError: the second failure" in found[5].message
