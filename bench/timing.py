"""Shared by the benchmark scripts: paired, interleaved timing against a baseline.

These machines are shared and noisy, so no figure is a bare number of seconds: each
repetition runs the baseline and the subject back to back (alternating which goes
first) and keeps their ratio, and the report gives the minimum and median of the
wall-time ratios, the median of the CPU-time ratios (all threads of this process, or
of the child process and what it waited for), and the peak memory.

Peak memory is tracemalloc's peak for a call in this process (every numpy array is
traced; scratch space inside compiled libraries is not) and the child's maximum
resident set for a command, each as a multiple of a reference size (the map's
float64 bytes).

With ROUGH_BENCH_RESULTS set to a file, every comparison is also appended to it as a
JSON line; ``bench/table.py`` turns those lines into the README's table.
"""

import dataclasses
import json
import os
import statistics
import subprocess
import time
import tracemalloc


@dataclasses.dataclass
class Comparison:
    """Ratios subject/baseline over paired repetitions."""

    name: str
    baseline: str
    wall: list
    cpu: list
    seconds: float  # the subject's median wall time
    baseline_seconds: float
    peak: float = None  # × the reference size
    goal: str = None

    def line(self):
        cpu = f"   CPU {statistics.median(self.cpu):6.2f}×" if self.cpu else ""
        peak = f"   peak {self.peak:5.1f}× map" if self.peak is not None else ""
        goal = f"   (goal {self.goal})" if self.goal else ""
        ratios = f"{min(self.wall):7.2f}× (median {statistics.median(self.wall):7.2f}×)"
        baseline = f"{self.baseline} ({self.baseline_seconds * 1e3:.1f} ms)"
        return f"{self.name:<44} {self.seconds:8.3f} s = {ratios} {baseline}{cpu}{peak}{goal}"

    def record(self):
        path = os.environ.get("ROUGH_BENCH_RESULTS")
        if path:
            row = dataclasses.asdict(self) | {"wall_min": min(self.wall), "wall_median": statistics.median(self.wall)}
            row["cpu_median"] = statistics.median(self.cpu) if self.cpu else None
            with open(path, "a", encoding="utf-8") as stream:
                stream.write(json.dumps(row, ensure_ascii=False) + "\n")


class Child(tuple):
    """(wall seconds, CPU seconds, peak resident bytes) of a child process."""


def command(argv, shell=False):
    """A callable running a command (its output discarded) that returns the
    :class:`Child` figures of the child and what it waited for."""

    def run():
        started = time.perf_counter()
        child = subprocess.Popen(argv, shell=shell, stdout=subprocess.DEVNULL)
        _, status, usage = os.wait4(child.pid, 0)
        child.returncode = os.waitstatus_to_exitcode(status)
        if child.returncode:
            raise subprocess.CalledProcessError(child.returncode, argv)
        return Child((time.perf_counter() - started, usage.ru_utime + usage.ru_stime, usage.ru_maxrss * 1024))

    return run


def compare(name, subject, baseline, baseline_name, repeat=5, reference_bytes=None, goal=None, record=True):
    """Run ``subject`` and ``baseline`` (callables) ``repeat`` times each, interleaved,
    print and record the comparison. Callables made by :func:`command` report their
    own times and peak memory; others are clocked here, and their peak memory is
    traced in one extra run when ``reference_bytes`` is given."""
    walls, cpus, subject_walls, baseline_walls, peaks = [], [], [], [], []
    for index in range(repeat):
        order = (baseline, subject) if index % 2 == 0 else (subject, baseline)
        measured = {id(action): _measure(action) for action in order}
        (b_wall, b_cpu, _), (s_wall, s_cpu, s_peak) = measured[id(baseline)], measured[id(subject)]
        walls.append(s_wall / b_wall)
        cpus.append(s_cpu / b_cpu if b_cpu > 0 else float("nan"))
        subject_walls.append(s_wall)
        baseline_walls.append(b_wall)
        if s_peak is not None:
            peaks.append(s_peak)
    peak = None
    if reference_bytes:
        peak = (max(peaks) if peaks else traced_peak(subject)) / reference_bytes
    comparison = Comparison(
        name,
        baseline_name,
        walls,
        cpus,
        statistics.median(subject_walls),
        statistics.median(baseline_walls),
        peak,
        goal,
    )
    print(comparison.line(), flush=True)
    if record:  # for the README's table (detail rows pass False)
        comparison.record()
    return comparison


def _measure(action):
    wall, cpu = time.perf_counter(), time.process_time()
    result = action()
    if isinstance(result, Child):  # a command: the child's own figures
        return result
    return time.perf_counter() - wall, time.process_time() - cpu, None


def traced_peak(action):
    """Peak bytes allocated through Python's allocators (numpy arrays included) during one call."""
    tracemalloc.start()
    try:
        tracemalloc.reset_peak()
        base = tracemalloc.get_traced_memory()[0]
        action()
        return tracemalloc.get_traced_memory()[1] - base
    finally:
        tracemalloc.stop()


def median_time(action, repeat):
    """Median wall time in seconds of ``repeat`` calls of ``action()`` (for figures
    that are not ratios, such as a profile of where time goes)."""
    return statistics.median(_measure(action)[0] for _ in range(repeat))
