"""Benchmark of the foundation: start-up, the X3P pipe stage, and per-format I/O.

Run:  .venv/bin/python bench/bench_io.py [--size 4096] [--repeat 3]

Every figure is a ratio against a baseline measured in the same run on the same
machine, with the absolute times alongside:
  - ``rough --help`` against ``python -c pass`` (interpreter start-up);
  - ``cat map.x3p | rough convert | cat`` against ``cat map.x3p | cat`` (a raw pipe),
    in MB/s of X3P moved;
  - reading and writing each format against ``ndarray.tofile``/``numpy.fromfile`` of
    the same float64 map (a raw memory dump);
  - a window of a GeoTIFF against the whole file (``--crop`` reads only the window);
  - each instrument file of ``../shared/data`` (when present) against ``numpy.fromfile``
    of as many bytes, alternating the two (min and median of the ratio).
"""

import argparse
import importlib.util
import os
import pathlib
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
    libraries = {"gwy": "gwyfile", "geotiff": "rasterio"}
    optional = [fmt for fmt, library in libraries.items() if importlib.util.find_spec(library)]
    for fmt in ("x3p", "exr", "gsf", "npy", "tsv", *optional):
        path = os.path.join(folder, f"map.{ {'geotiff': 'tif'}.get(fmt, fmt) }")
        times = 1 if fmt == "tsv" else repeat
        written = median_time(lambda path=path: surface.write(path), times)
        spacing = {"spacing": surface.spacing} if fmt == "npy" else {}
        loaded = median_time(lambda path=path, spacing=spacing: read(path, **spacing), times)
        print(
            f"{fmt:<10} write {written:7.3f} s ({written / write_raw:6.1f}× raw)   read {loaded:7.3f} s "
            f"({loaded / read_raw:6.1f}× raw)   file {os.path.getsize(path) / 1e6:7.1f} MB"
        )


def geotiff_window(surface, folder, repeat):
    if not importlib.util.find_spec("rasterio"):
        return
    path = os.path.join(folder, "window.tif")
    surface.write(path)
    x1, y1 = (0.1 * surface.points[0] * surface.spacing[0], 0.1 * surface.points[1] * surface.spacing[1])
    ratios = []
    for _ in range(repeat):
        whole = median_time(lambda: read(path), 1)
        window = median_time(lambda: read(path, crop=((0.0, x1), (0.0, y1))), 1)
        ratios.append(window / whole)
    print(
        f"GeoTIFF    a 10 %×10 % window costs {min(ratios):.3f}× (min) {np.median(ratios):.3f}× (median) the whole map"
    )


def instrument_files(repeat):
    """Every example instrument file read against a raw read of as many bytes."""
    shared = pathlib.Path(__file__).resolve().parents[2] / "shared" / "data" / "SurfaceTopography"
    if not shared.is_dir():
        print("instrument files: ../shared/data is absent, skipped")
        return
    for path in sorted(shared.iterdir()):
        try:
            read(path)
        except rough.InputError:
            continue
        ratios = []
        for _ in range(repeat):
            loaded = median_time(lambda path=path: read(path), 1)
            raw = median_time(lambda path=path: np.fromfile(path, np.uint8), 1)
            ratios.append(loaded / raw)
        print(
            f"{path.name:<40} {os.path.getsize(path) / 1e6:7.2f} MB   read {loaded * 1e3:8.1f} ms   "
            f"{min(ratios):8.0f}× (min) {np.median(ratios):8.0f}× (median) a raw read"
        )


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=int, default=4096, help="side of the square test map (default 4096)")
    parser.add_argument("--repeat", type=int, default=3, help="runs per measurement; the median is reported")
    options = parser.parse_args()
    heights = np.random.default_rng(0).standard_normal((options.size, options.size)) * 1e-6
    surface = rough.Surface(heights, (1e-6, 1e-6), metadata={"crs": "EPSG:32633"})  # UTM 33N, for GeoTIFF
    print(
        f"rough {rough.__version__}, {options.size}×{options.size} map, median of {options.repeat} runs, "
        f"{os.cpu_count()} CPUs"
    )
    with tempfile.TemporaryDirectory(dir=os.environ.get("TMPDIR")) as folder:
        startup(options.repeat)
        surface.write(os.path.join(folder, "pipe.x3p"))
        pipe(os.path.join(folder, "pipe.x3p"), options.repeat)
        formats(surface, folder, options.repeat)
        geotiff_window(surface, folder, options.repeat)
    instrument_files(options.repeat)


if __name__ == "__main__":
    main()
