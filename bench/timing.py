"""Shared by the benchmark scripts: the median wall time of repeated runs."""

import statistics
import time


def median_time(action, repeat):
    """Median wall time in seconds of ``repeat`` calls of ``action()``."""
    times = []
    for _ in range(repeat):
        started = time.perf_counter()
        action()
        times.append(time.perf_counter() - started)
    return statistics.median(times)
