"""Several inputs on several cores: ``--jobs N`` as a small pool of forked workers.

The workers are forked (Linux's "fork" start method), so they inherit the command,
its options and the list of inputs without pickling them; each is handed the
*index* of its next input and sends back what ``task(index)`` returned, which must
pickle. The parent yields the results in input order, whatever order they finish
in. A worker that dies (killed, out of memory) yields :class:`Died` for the input it
was working on and is replaced; Ctrl-C, SIGTERM or any exception in the parent stops
every worker (SIGTERM, then SIGKILL after :data:`GRACE` seconds), and each worker's
outputs remove their temporary files on the way out (``rough.io.atomic_output``).

Inside a worker BLAS and OpenMP keep to one thread (threadpoolctl, which reaches the
libraries already loaded, and the environment variables for those loaded later):
``--jobs`` spreads the inputs over the cores, and a BLAS pool per worker would only
compete with the others. Where fork is not available (Windows, macOS, where it is
unsafe) :func:`usable_jobs` says so and the inputs are worked on one at a time.
"""

import collections
import dataclasses
import multiprocessing
import os
import signal
import sys
import time
from multiprocessing import connection

#: Seconds the workers have to clean up after SIGTERM before they are killed.
GRACE = 1.0
#: The variables that size BLAS and OpenMP thread pools, set to 1 in the workers.
_STOPPING = {signal.SIGINT, signal.SIGTERM, signal.SIGHUP}
THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS")


@dataclasses.dataclass
class Died:
    """A worker ended while working on an input: ``exitcode`` is ``-signal`` when a
    signal killed it (``-9``: SIGKILL, as the out-of-memory killer sends)."""

    exitcode: int

    def message(self):
        if self.exitcode is not None and self.exitcode < 0:
            try:
                cause = f"killed by {signal.Signals(-self.exitcode).name}"
            except ValueError:
                cause = f"killed by signal {-self.exitcode}"
        else:
            cause = f"exit status {self.exitcode}"
        return f"the worker process died ({cause})"


@dataclasses.dataclass
class Failed:
    """``task(index)`` raised in the worker, or returned what does not pickle."""

    message: str


def cores():
    """The number of cores this process may run on (its CPU affinity)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def can_fork():
    """Whether workers can be forked here (Linux)."""
    return sys.platform.startswith("linux") and "fork" in multiprocessing.get_all_start_methods()


def usable_jobs(jobs, count):
    """The number of workers for ``count`` inputs when ``jobs`` were asked for (0:
    :func:`cores`), and the reason when that is fewer than asked (None otherwise)."""
    jobs = cores() if jobs == 0 else jobs
    if jobs > 1 and count > 1 and not can_fork():
        return 1, f"--jobs {jobs}: working in parallel needs fork (Linux); the inputs are worked on one at a time"
    return max(1, min(jobs, count)), None


def ordered(task, count, jobs, finished=None):
    """Yield ``task(0)``, ``task(1)``… ``task(count - 1)`` in that order, computed by
    ``jobs`` forked workers; a :class:`Died` or :class:`Failed` in place of a result
    that never came. ``finished()`` is called as each input is done, in any order (a
    progress bar). Close the generator (``contextlib.closing``) to stop the workers
    at once when the caller is interrupted."""
    workers = []
    results = {}
    waiting = collections.deque(range(count))
    following = 0
    context = multiprocessing.get_context("fork")
    stdin = _copy_of_stdin()
    try:
        for _ in range(min(jobs, count)):
            _hand_next(_start(context, task, workers, stdin), waiting)
        while following < count:
            if following in results:
                yield results.pop(following)
                following += 1
                continue
            busy = [worker for worker in workers if worker.index is not None]
            connection.wait([item for worker in busy for item in (worker.connection, worker.process.sentinel)])
            for worker in busy:
                outcome = _outcome(worker)
                if outcome is None:
                    continue
                results[worker.index] = outcome
                if finished is not None:
                    finished()
                if isinstance(outcome, Died):
                    workers.remove(worker)
                    worker.connection.close()
                    if not waiting:
                        continue
                    worker = _start(context, task, workers, stdin)
                _hand_next(worker, waiting)
    finally:
        _stop(workers)
        if stdin is not None:
            os.close(stdin)


@dataclasses.dataclass
class _Worker:
    process: multiprocessing.process.BaseProcess
    connection: connection.Connection
    index: int = None


def _copy_of_stdin():
    """A descriptor copied from standard input's, which multiprocessing closes in the
    workers (an input ``-`` is read by one of them); None when it is closed."""
    try:
        return os.dup(sys.stdin.fileno())
    except (AttributeError, OSError, ValueError):
        return None


def _start(context, task, workers, stdin):
    ours, theirs = context.Pipe()
    process = context.Process(target=_serve, args=(task, theirs, stdin), daemon=True)
    # the new worker starts with Ctrl-C and SIGTERM held back, until it can end quietly
    held = signal.pthread_sigmask(signal.SIG_BLOCK, _STOPPING)
    try:
        process.start()
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, held)
    theirs.close()
    worker = _Worker(process, ours)
    workers.append(worker)
    return worker


def _hand_next(worker, waiting):
    worker.index = waiting.popleft() if waiting else None
    try:
        worker.connection.send(worker.index)
    except OSError:  # it died meanwhile: found by its sentinel
        pass


def _outcome(worker):
    """What the busy ``worker`` sent, a :class:`Died`, or None while it still works."""
    try:
        if worker.connection.poll():
            return worker.connection.recv()
    except (EOFError, OSError):
        pass
    else:
        if worker.process.exitcode is None:
            return None
    worker.process.join()
    return Died(worker.process.exitcode)


def _serve(task, channel, stdin):
    """A worker's life: standard input back, one BLAS thread, then ``task(index)`` for
    each index sent until None comes. It ends by ``os._exit``: nothing of the parent's
    (atexit, buffered output) runs twice."""
    status = 0
    try:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, _STOPPING)
        if stdin is not None:
            os.dup2(stdin, 0)
            os.close(stdin)
            sys.stdin = open(0, closefd=False)  # noqa: SIM115 -- standard input, open for the worker's life
        one_thread()
        while (index := channel.recv()) is not None:
            try:
                result = task(index)
                channel.send(result)
            except Exception as error:  # noqa: BLE001 -- reported for this input, the worker goes on
                channel.send(Failed(f"internal error: {type(error).__name__}: {error} (run with --debug for details)"))
    except BaseException:  # noqa: BLE001 -- Ctrl-C, SIGTERM, the parent gone: end quietly
        status = 1
    finally:
        os._exit(status)


def one_thread():
    """Limit BLAS and OpenMP to one thread in this process: through threadpoolctl (it
    reaches libraries already loaded), and through the environment for those loaded
    later."""
    for name in THREAD_VARIABLES:
        os.environ[name] = "1"
    import threadpoolctl  # deferred: only in a worker (this module is loaded by every several-input command)

    threadpoolctl.threadpool_limits(1)


def _stop(workers):
    """End every worker: None to the idle ones, SIGTERM to the busy ones, SIGKILL to
    any still running :data:`GRACE` seconds later."""
    for worker in workers:
        if worker.process.exitcode is not None:
            continue
        if worker.index is None:
            try:
                worker.connection.send(None)
            except OSError:
                worker.process.terminate()
        else:
            worker.process.terminate()
    deadline = time.monotonic() + GRACE
    for worker in workers:
        worker.process.join(max(0.0, deadline - time.monotonic()))
        if worker.process.exitcode is None:
            worker.process.kill()
            worker.process.join()
        worker.connection.close()
