"""Speed of the haptic loop: the simulated loop with its trace written, by CPU time, as
a multiple of real time (goal ≥ 500×),
and a real-time run's period jitter (goal p99 ≤ 50 µs, no deadline missed by more than
1 ms on an idle core).

    python bench/bench_render.py               # 60 s real-time run
    python bench/bench_render.py --seconds 10  # shorter
"""

import argparse
import os
import statistics
import tempfile
import time

from timing import Comparison

from rough import __version__
from rough.fractal import synthesize_map, synthesize_profile
from rough.fractal.resampling import resample
from rough.render import (
    DynamicStylus,
    GradientField,
    MapTrack,
    QuasiStatic,
    Settings,
    Track,
    simulate,
    write_trace,
)
from rough.render.friction import parse_friction


def rock():
    profile = synthesize_profile(round(400e-3 / 30.9e-6), 30.9e-6, 1.275, rq=0.2781e-3, seed=1)
    return Track.from_surface(resample(profile, 0.1545e-3))


def bedding_plane():
    """A 1025² anisotropic map at 0.1 mm (102.4 mm square), felt as a map."""
    heights = synthesize_map((1025, 1025), (0.1e-3, 0.1e-3), None, anisotropy=(2.3, 1e-6, 2.3, 10e-6, 0.5), seed=1)
    return MapTrack.from_surface(heights)


def simulated(track, surface, folder):
    """Each model's simulated run with its trace written to TSV, by CPU time (and wall
    time) against the simulated time: the ratio is the share of real time the work
    takes (goal ≤ 1/500). The map is stroked back and forth for 20 s."""
    cases = [
        ("quasi-static", track, QuasiStatic(), None),
        ("dynamic stylus", track, DynamicStylus(), None),
        ("quasi-static + karnopp", track, QuasiStatic(), "karnopp:static=0.8N,coulomb=0.5N,band=2mm/s"),
        ("dynamic + dahl", track, DynamicStylus(), "dahl:stiffness=1N/mm,coulomb=0.3N"),
        ("map, gradient field, back and forth", surface, GradientField(), None),
    ]
    for name, where, model, friction in cases:
        walls, cpus = [], []
        settings = Settings(realtime=False, duration=20.0 if where is surface else None)
        for _ in range(3):
            wall, cpu = time.perf_counter(), time.process_time()
            result = simulate(where, 0.02, model, parse_friction(friction), settings)
            write_trace(result, os.path.join(folder, "trace.tsv"))
            simulated_time = result.timing()["simulated_time"]
            walls.append((time.perf_counter() - wall) / simulated_time)
            cpus.append((time.process_time() - cpu) / simulated_time)
        comparison = Comparison(
            f"render, simulated: {name}, trace written",
            "real time",
            walls,
            cpus,
            statistics.median(walls) * simulated_time,
            simulated_time,
            goal="≤ 0.002× (≥ 500× real time) by CPU",
        )
        print(f"{comparison.line()}   = {1 / statistics.median(cpus):.0f}× real time by CPU", flush=True)
        comparison.record()


def realtime(track, seconds):
    result = simulate(track, 0.02, QuasiStatic(), None, Settings(duration=seconds, realtime=True))
    timing = result.timing()
    late = timing["max_lateness"] * 1e3
    print(
        f"real time {seconds:g} s at 1 kHz ({timing['scheduling']}): rate {timing['rate']:.2f} Hz, "
        f"period jitter p50 {timing['jitter_p50'] * 1e6:.1f} µs, "
        f"p99 {timing['jitter_p99'] * 1e6:.1f} µs, max {timing['jitter_max'] * 1e6:.1f} µs; "
        f"missed deadlines {timing['missed_deadlines']}, latest tick {late:.3f} ms late   goal p99 ≤ 50 "
        f"µs, lateness ≤ 1 ms"
    )


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=60.0, help="length of the real-time run")
    arguments = parser.parse_args()
    print(f"rough {__version__}, haptic loop, {os.cpu_count()} cores")
    track = rock()
    with tempfile.TemporaryDirectory() as folder:
        simulated(track, bedding_plane(), folder)
    realtime(track, arguments.seconds)


if __name__ == "__main__":
    main()
