"""rough.compiled: a compiled call leaves the caller free to be interrupted."""

import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from rough.compiled import compiled

from conftest import ROOT

# A stand-in for numba's compiler: three seconds of Python inside a ctypes callback,
# which swallows a KeyboardInterrupt raised there ("Exception ignored on calling ctypes
# callback function") and returns as if nothing happened.
SCRIPT = """
import ctypes, sys, time
from rough.compiled import _waited

busy = ctypes.CFUNCTYPE(None)(lambda: [time.sleep(0.01) for _ in range(300)])


class Compiling:
    __name__ = "compiling"

    def __call__(self):
        busy()


call = _waited if sys.argv[1] == "waited" else (lambda dispatcher: dispatcher())
print("started", flush=True)
try:
    call(Compiling())
except KeyboardInterrupt:
    print("interrupted", flush=True)
    sys.exit(130)
print("finished", flush=True)
"""


def interrupted(how):
    process = subprocess.Popen(
        [sys.executable, "-c", SCRIPT, how],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env={"PYTHONPATH": str(ROOT)},
    )
    assert process.stdout.readline() == b"started\n"
    time.sleep(0.3)
    process.send_signal(signal.SIGINT)
    out, _ = process.communicate(timeout=30)
    return process.returncode, out.decode().split()


def test_ctrl_c_during_a_compilation_reaches_the_caller():
    assert interrupted("direct") == (0, ["finished"])  # called directly, the interrupt is lost
    assert interrupted("waited") == (130, ["interrupted"])  # the caller stops; the call is dropped


def test_a_compiled_call_returns_its_result_and_raises_its_errors():
    def first_negative(values):
        for i in range(values.size):
            if values[i] < 0:
                return i
        raise ValueError("no negative value")

    kernel = compiled(first_negative)
    assert kernel(np.array([3.0, 1.0, -2.0])) == 2
    with pytest.raises(ValueError, match="no negative value"):
        kernel(np.array([1.0]))


def test_a_call_from_another_thread_runs_in_that_thread():
    import threading

    from rough.compiled import _waited

    class Where:
        __name__ = "where"

        def __call__(self):
            return threading.current_thread()

    seen = []
    worker = threading.Thread(target=lambda: seen.append((threading.current_thread(), _waited(Where()))))
    worker.start()
    worker.join()
    assert seen[0][0] is seen[0][1] is worker
    assert _waited(Where()) is not threading.main_thread()  # from the main thread: a worker runs it
