"""Many independent pieces of work — files, tiles, windows — run in order or at once.

:func:`map_ordered` is the one place that decides how: in this process, in a pool of
worker processes (``jobs``), or on a Dask distributed cluster (``scheduler``). The
results come back in the order of the items whatever ran where, and a failed item
raises its own error in the caller.

The pool of processes is forked (Linux's "fork" start method), so the workers inherit
the function and the items without pickling them; each is handed the *index* of its
next item and sends back what the function returned, which must pickle. A worker that
dies (killed, out of memory) gives :class:`Died` for the item it was working on and is
replaced; Ctrl-C, SIGTERM or any exception in the parent stops every worker (SIGTERM,
then SIGKILL after :data:`GRACE` seconds), and each worker's outputs remove their
temporary files on the way out (``rough.io.atomic_output``). Inside a worker BLAS and
OpenMP keep to one thread (threadpoolctl, which reaches the libraries already loaded,
and the environment variables for those loaded later): the items are spread over the
cores, and a BLAS pool per worker would only compete with the others. Where fork is
not available (Windows, macOS, where it is unsafe) :func:`usable_jobs` says so and the
items are worked on one at a time.

On a cluster (the ``cluster`` extra: Dask's ``distributed``) the function and each item
are pickled (cloudpickle) and sent to the workers as tasks, ``client.map`` with pure
keys; the results are gathered as they complete and yielded in order. The scheduler
unpickles the tasks and the workers run them, so both need ``rough`` importable, at the
same version as here; the workers also need the files the items name. Ctrl-C (or
closing the iterator) cancels the tasks not yet done.
"""

import collections
import contextlib
import dataclasses
import functools
import logging
import multiprocessing
import os
import signal
import socket
import sys
import time
from multiprocessing import connection

from . import extras
from .errors import InputError, RoughError

log = logging.getLogger("rough")

#: Seconds the workers have to clean up after SIGTERM before they are killed.
GRACE = 1.0
#: Seconds to wait for a Dask scheduler to answer before giving up on it.
CONNECT_TIMEOUT = 10.0
#: The variables that size BLAS and OpenMP thread pools, set to 1 in the workers.
THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS")
_STOPPING = {signal.SIGINT, signal.SIGTERM, signal.SIGHUP}


@dataclasses.dataclass
class Died:
    """A worker ended while working on an item: ``exitcode`` is ``-signal`` when a
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
    """The function raised in the worker (``error``, when it pickles), or returned
    what does not pickle."""

    message: str
    error: BaseException = None


def map_ordered(function, items, *, jobs=1, scheduler=None):
    """``function(item)`` for each of ``items``, yielded in the items' order.

    Parameters
    ----------
    function : callable
        A module-level function (it must pickle to reach a cluster; a pool of forked
        processes inherits it).
    items : iterable
        Its arguments, one per call; each must pickle to reach a cluster. A worker
        should read its own data from what the item names (a file, a
        :class:`~rough.io.TiledSurface` and rows), not be sent big arrays.
    jobs : int, default 1
        Worker processes; 1 runs in this process, 0 one per core.
    scheduler : str or distributed.Client, optional
        A Dask distributed scheduler's address (``tcp://host:8786``) or a client of
        one, to run on instead of here (``jobs`` is then ignored).

    Yields
    ------
    object
        What ``function`` returned for each item, in the items' order, whatever
        order they finished in. NaN in the results is passed on as it is.

    Raises
    ------
    Exception
        The first item (in order) that failed raises its own error here (an
        :class:`~rough.InputError` stays one, with its message); the other workers
        are stopped. A worker process that died raises :class:`~rough.RoughError`.
    rough.InputError
        The scheduler cannot be reached (the message names its address).

    Notes
    -----
    Close the iterator (``contextlib.closing``) when you stop early: that stops the
    workers (and cancels a cluster's tasks) at once, as Ctrl-C does while it waits.

    Examples
    --------
    >>> from rough import tasks
    >>> list(tasks.map_ordered(abs, [-3, 1, -2], jobs=2))
    [3, 1, 2]
    """
    with contextlib.closing(outcomes(function, items, jobs=jobs, scheduler=scheduler)) as results:
        for result in results:
            if isinstance(result, Died):
                raise RoughError(result.message())
            if isinstance(result, Failed):
                raise result.error if result.error is not None else RoughError(result.message)
            yield result


def outcomes(function, items, *, jobs=1, scheduler=None, finished=None):
    """As :func:`map_ordered`, but an item that failed gives a :class:`Failed` (or a
    :class:`Died`) in its place and the others go on (``rough.cli.batch`` reports a bad
    file and keeps the rest). ``finished()`` is called as each item is done, in any
    order (a progress bar). Close it (``contextlib.closing``) to stop early."""
    if scheduler is not None:
        yield from _on_cluster(function, items, scheduler, finished)
        return
    items = list(items)
    jobs, note = usable_jobs(jobs, len(items))
    if note:
        log.warning(note)
    if jobs <= 1:
        with one_thread_here():
            for item in items:
                try:
                    result = function(item)
                except Exception as error:  # noqa: BLE001 -- handed to the caller in the item's place
                    result = Failed(_internal(error), error)
                if finished is not None:
                    finished()
                yield result
        return
    with contextlib.closing(ordered(lambda index: function(items[index]), len(items), jobs, finished)) as results:
        yield from results


def _internal(error):
    return f"internal error: {type(error).__name__}: {error} (run with --debug for details)"


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
    """The number of workers for ``count`` items when ``jobs`` were asked for (0:
    :func:`cores`), and the reason when that is fewer than asked (None otherwise)."""
    jobs = cores() if jobs == 0 else jobs
    if jobs > 1 and count > 1 and not can_fork():
        return 1, f"--jobs {jobs}: working in parallel needs fork (Linux); the work is done one piece at a time"
    return max(1, min(jobs, count)), None


# -- a pool of forked processes ------------------------------------------------------


def ordered(task, count, jobs, finished=None):
    """Yield ``task(0)``, ``task(1)``… ``task(count - 1)`` in that order, computed by
    ``jobs`` forked workers; a :class:`Died` or :class:`Failed` in place of a result
    that never came. ``finished()`` is called as each index is done, in any order (a
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
    sys.unraisablehook = _stop_where_unraisable
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
            except Exception as error:  # noqa: BLE001 -- reported for this index, the worker goes on
                result = Failed(_internal(error), error)
            try:
                channel.send(result)  # pickled whole before anything is sent
            except Exception as error:  # noqa: BLE001 -- a result (or an error) that does not pickle
                message = result.message if isinstance(result, Failed) else _internal(error)
                channel.send(Failed(message))
    except BaseException:  # noqa: BLE001 -- Ctrl-C, SIGTERM, the parent gone: end quietly
        status = 1
    finally:
        os._exit(status)


def _stop_where_unraisable(unraisable):
    """A worker's hook for an exception Python cannot raise (one in a finaliser or a
    weakref callback, such as an import's lock): Ctrl-C or SIGTERM landing there ends
    the worker at once and quietly, as anywhere else; other exceptions are printed as
    Python prints them."""
    if isinstance(unraisable.exc_value, Exception) or unraisable.exc_value is None:
        sys.__unraisablehook__(unraisable)
        return
    os._exit(1)


def one_thread():
    """Limit BLAS and OpenMP to one thread in this process: through threadpoolctl (it
    reaches libraries already loaded), and through the environment for those loaded
    later."""
    for name in THREAD_VARIABLES:
        os.environ[name] = "1"
    import threadpoolctl  # deferred: only in a worker (the several-input commands load this module)

    threadpoolctl.threadpool_limits(1)


@contextlib.contextmanager
def one_thread_here():
    """BLAS and OpenMP at one thread in this process for the block, as in the workers:
    a sum split over threads may round differently, and the results must be the same
    bit for bit wherever they were computed (``import rough`` before numpy starts
    OpenBLAS with one thread already)."""
    import threadpoolctl  # deferred: as in one_thread

    with threadpoolctl.threadpool_limits(1):
        yield


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


# -- a Dask cluster ----------------------------------------------------------------------


def connect(scheduler):
    """``(client, owned)``: a ``distributed.Client`` of the scheduler at address
    ``scheduler`` (owned: close it when done), or ``scheduler`` itself when it is a
    client already. Raises InputError naming the address when it is not one, refuses
    the connection, or does not answer within :data:`CONNECT_TIMEOUT` seconds, and
    MissingExtra without ``distributed``."""
    distributed = extras.require("distributed")  # optional: cluster
    if isinstance(scheduler, distributed.Client):
        return scheduler, False
    address = str(scheduler).strip()
    try:
        scheme, _ = distributed.comm.parse_address(address)
        distributed.comm.registry.get_backend(scheme)
        if scheme in ("tcp", "tls"):  # a refusal is known at once, not after the timeout
            socket.create_connection(distributed.comm.get_address_host_port(address), CONNECT_TIMEOUT).close()
        return distributed.Client(address, timeout=CONNECT_TIMEOUT, set_as_default=False), True
    except Exception as error:  # noqa: BLE001 -- whatever the cause (refused, timed out, a bad address): one line
        reason = (getattr(error, "strerror", None) or str(error)).splitlines()[0] or type(error).__name__
        raise InputError(f"cannot reach the Dask scheduler at {address}: {reason}", filename=address) from None


def _on_cluster(function, items, scheduler, finished):
    """:func:`outcomes` on a Dask cluster."""
    distributed = extras.require("distributed")  # optional: cluster
    client, owned = connect(scheduler)
    futures = []
    try:
        futures = client.map(functools.partial(_in_cluster_worker, function), list(items), pure=True)
        places = collections.defaultdict(list)
        for index, future in enumerate(futures):
            places[id(future)].append(index)
        results, following = {}, 0
        for future in distributed.as_completed(futures, loop=client.loop):
            indexes = places.pop(id(future), ())
            if not indexes:
                continue  # a duplicate item's future, answered already
            try:
                result = future.result()
            except Exception as error:  # noqa: BLE001 -- the item's own error, handed over in its place
                result = Failed(_internal(error), error)
            for index in indexes:
                results[index] = result
                if finished is not None:
                    finished()
            while following in results:
                futures[following] = None  # the cluster may forget it
                yield results.pop(following)
                following += 1
    finally:
        left = [future for future in futures if future is not None and not future.done()]
        with contextlib.suppress(Exception):
            if left:
                client.cancel(left, asynchronous=False)
        if owned:
            with contextlib.suppress(Exception):
                client.close(timeout=GRACE)


def _in_cluster_worker(function, item):
    """``function(item)`` on a cluster's worker, with BLAS at one thread."""
    if not _limited:
        one_thread()
        _limited.append(True)
    return function(item)


_limited = []
