"""Benchmark of the foundation: start-up, the X3P pipe stage, and per-format I/O.

Run:  .venv/bin/python bench/bench_io.py [--size 4096] [--repeat 3]

Every figure is a ratio against a baseline measured in the same run on the same
machine, with the absolute times alongside:
  - ``rough --help`` against ``python -c pass`` (interpreter start-up);
  - ``cat map.x3p | rough convert | cat`` against ``cat map.x3p | cat`` (a raw pipe),
    in MB/s of X3P moved;
  - reading and writing each format against ``ndarray.tofile``/``numpy.fromfile`` of
    the same float64 map (a raw memory dump).
"""

import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np
from timing import median_time

import rough
from rough.io import read

HERE = os.path.dirname(os.path.abspath(__file__))
ROUGH = [sys.executable, "-m", "rough"]


def shell(command):
    subprocess.run(command, shell=True, check=True, stdout=subprocess.DEVNULL)


def startup(repeat):
    rough_cli = os.path.join(os.path.dirname(sys.executable), "rough")
    help_time = median_time(lambda: subprocess.run([rough_cli, "--help"], check=True, capture_output=True), repeat * 5)
    bare = median_time(lambda: subprocess.run([sys.executable, "-c", "pass"], check=True), repeat * 5)
    print(
        f"start-up   rough --help {help_time * 1e3:7.1f} ms   python -c pass {bare * 1e3:6.1f} ms   "
        f"ratio {help_time / bare:5.2f}×   (goal ≤ 150 ms)"
    )


def pipe(path, repeat):
    megabytes = os.path.getsize(path) / 1e6
    raw = median_time(lambda: shell(f"cat {path} | cat > /dev/null"), repeat)
    stage = median_time(lambda: shell(f"cat {path} | {' '.join(ROUGH)} convert | cat > /dev/null"), repeat)
    print(
        f"X3P pipe   rough convert {megabytes / stage:7.0f} MB/s ({stage:.3f} s)   raw cat {megabytes / raw:7.0f} MB/s "
        f"({raw:.3f} s)   rough costs {stage / raw:5.1f}× a raw pipe   (goal ≥ 1000 MB/s)"
    )


def formats(surface, folder, repeat):
    raw_path = os.path.join(folder, "raw.f8")
    write_raw = median_time(lambda: surface.heights.tofile(raw_path), repeat)
    read_raw = median_time(lambda: np.fromfile(raw_path), repeat)
    print(
        f"raw dump   write {write_raw:7.3f} s   read {read_raw:7.3f} s   "
        f"({surface.heights.nbytes / 1e6:.0f} MB float64)"
    )
    for fmt in ("x3p", "exr", "gsf", "npy", "tsv"):
        path = os.path.join(folder, f"map.{fmt}")
        times = 1 if fmt == "tsv" else repeat
        written = median_time(lambda path=path: surface.write(path), times)
        spacing = {"spacing": surface.spacing} if fmt == "npy" else {}
        loaded = median_time(lambda path=path, spacing=spacing: read(path, **spacing), times)
        print(
            f"{fmt:<10} write {written:7.3f} s ({written / write_raw:6.1f}× raw)   read {loaded:7.3f} s "
            f"({loaded / read_raw:6.1f}× raw)   file {os.path.getsize(path) / 1e6:7.1f} MB"
        )


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=int, default=4096, help="side of the square test map (default 4096)")
    parser.add_argument("--repeat", type=int, default=3, help="runs per measurement; the median is reported")
    options = parser.parse_args()
    heights = np.random.default_rng(0).standard_normal((options.size, options.size)) * 1e-6
    surface = rough.Surface(heights, (1e-6, 1e-6))
    print(
        f"rough {rough.__version__}, {options.size}×{options.size} map, median of {options.repeat} runs, "
        f"{os.cpu_count()} CPUs"
    )
    with tempfile.TemporaryDirectory(dir=os.environ.get("TMPDIR")) as folder:
        startup(options.repeat)
        surface.write(os.path.join(folder, "pipe.x3p"))
        pipe(os.path.join(folder, "pipe.x3p"), options.repeat)
        formats(surface, folder, options.repeat)


if __name__ == "__main__":
    main()
