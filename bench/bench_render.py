"""Speed of the haptic loop: the simulated loop as a multiple of real time (goal ≥ 500×),
and a real-time run's period jitter (goal p99 ≤ 50 µs, no deadline missed by more than
1 ms on an idle core).

    python bench/bench_render.py               # 60 s real-time run
    python bench/bench_render.py --seconds 10  # shorter
"""

import argparse
import os

from rough import __version__
from rough.fractal.resample import resample
from rough.fractal.synth import synthesize_profile
from rough.render import DynamicStylus, QuasiStatic, Settings, Track, simulate
from rough.render.friction import parse_friction


def rock():
    profile = synthesize_profile(round(400e-3 / 30.9e-6), 30.9e-6, 1.275, rq=0.2781e-3, seed=1)
    return Track.from_surface(resample(profile, 0.1545e-3))


def simulated(track):
    cases = [
        ("quasi-static", QuasiStatic(), None),
        ("dynamic stylus", DynamicStylus(), None),
        ("quasi-static + karnopp", QuasiStatic(), "karnopp:static=0.8N,coulomb=0.5N,band=2mm/s"),
        ("dynamic + dahl", DynamicStylus(), "dahl:stiffness=1N/mm,coulomb=0.3N"),
    ]
    for name, model, friction in cases:
        factors = []
        for _ in range(3):
            result = simulate(track, 0.02, model, parse_friction(friction))
            factors.append(result.timing()["realtime_factor"])
        best = sorted(factors)[1]
        per_tick = 1e6 / (best * 1000)
        print(
            f"sim {name:<24} {result.ticks} ticks: {best:6.0f}× real time ({per_tick:.2f} µs per 1 ms "
            f"tick)   goal ≥ 500×"
        )


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
    simulated(track)
    realtime(track, arguments.seconds)


if __name__ == "__main__":
    main()
