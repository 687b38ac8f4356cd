"""Benchmark of the foundation's input and output: the X3P pipe stage and each format.

Run:  .venv/bin/python bench/bench_io.py [--size 4096] [--repeat 5]

Every figure comes from ``bench/timing.py``'s paired harness: the subject and its
baseline run back to back, alternately first, ``--repeat`` times, and the line gives
the subject's median time, the minimum and median of the time ratios, the CPU ratio
and the peak memory (× the map's float64 bytes):
  - ``cat map.x3p | rough convert | cat > /dev/null`` against ``cat map.x3p | cat >
    /dev/null`` (a raw pipe), with the MB/s of X3P each moves; the goal is at least
    half the raw pipe's throughput (at most twice its time);
  - writing and reading each format against ``ndarray.tofile`` and ``numpy.fromfile``
    of the same float64 map (a raw memory dump); TSV on a 1024×1024 corner, as the
    text of the whole map is past what rough parses;
  - a window of a GeoTIFF against the whole file (``--crop`` reads only the window);
  - each instrument file of ``../shared/data`` (when present) against
    ``numpy.fromfile`` of as many bytes.

``rough convert`` runs as ``python -m rough`` with this interpreter and environment,
so ``PYTHONPATH=. .venv/bin/python bench/bench_io.py`` measures the checkout and
plain ``.venv/bin/python bench/bench_io.py`` the installed package (the header says
which). Start-up time is measured by ``bench/bench_startup.py``.

In-process peak memory is the growth of the resident set during the call (Linux's
``VmHWM`` after resetting it), which counts anonymous memory that tracemalloc does
not see, such as the buffer a stream is read into.
"""

import argparse
import importlib.util
import os
import pathlib
import shlex
import sys
import tempfile
import time

import numpy as np
from timing import Child, command, compare

import rough
from rough.io import read

PIPE_GOAL = "≤ 2× the raw pipe's time, i.e. ≥ 0.5× its throughput"  # no "|": the README's table splits on it
TSV_SIDE = 1024  # the text of a 4096² map (~800 MB) is past what rough parses


def in_process(action):
    """``action`` as a callable whose run reports its own :class:`timing.Child`
    figures: wall and CPU time (all threads) and the growth of the resident set."""

    def run():
        start = _resident("VmRSS", reset=True)
        wall, cpu = time.perf_counter(), time.process_time()
        action()
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        peak = _resident("VmHWM")
        return Child((wall, cpu, None if start is None or peak is None else max(peak - start, 0)))

    return run


def _resident(field, reset=False):
    """Bytes of ``field`` in /proc/self/status (None off Linux); ``reset`` first makes
    the peak (VmHWM) the current resident size."""
    try:
        if reset:
            with open("/proc/self/clear_refs", "w") as stream:
                stream.write("5")
        with open("/proc/self/status") as stream:
            line = next(line for line in stream if line.startswith(f"{field}:"))
        return int(line.split()[1]) * 1024
    except (OSError, StopIteration, ValueError):
        return None


def pipe(path, repeat, reference):
    megabytes = os.path.getsize(path) / 1e6
    source = shlex.quote(str(path))
    stage = " ".join(map(shlex.quote, (sys.executable, "-m", "rough", "convert")))
    result = compare(
        "X3P pipe stage: cat, rough convert, cat",
        command(f"cat {source} | {stage} | cat > /dev/null", shell=True),
        command(f"cat {source} | cat > /dev/null", shell=True),
        "raw pipe: cat, cat",
        repeat=repeat,
        reference_bytes=reference,
        goal=PIPE_GOAL,
    )
    print(
        f"{'':<4} rough convert {megabytes / result.seconds:6.0f} MB/s, raw pipe "
        f"{megabytes / result.baseline_seconds:6.0f} MB/s ({megabytes:.0f} MB of X3P): {1 / min(result.wall):.2f}× "
        f"(median {1 / np.median(result.wall):.2f}×) the raw pipe's throughput"
    )


def formats(surface, folder, repeat):
    libraries = {"gwy": "gwyfile", "geotiff": "rasterio"}
    optional = [fmt for fmt, library in libraries.items() if importlib.util.find_spec(library)]
    for fmt in ("x3p", "exr", "gsf", "npy", *optional):
        one_format(fmt, surface, folder, repeat)
    # the text of the whole map would pass rough's cap on parsed text (limits.MAX_TEXT_BYTES): a corner of it
    side = min(TSV_SIDE, *surface.heights.shape)
    corner = rough.Surface(surface.heights[:side, :side].copy(), surface.spacing, metadata=surface.metadata)
    one_format("tsv", corner, folder, 1, f" ({side}×{side})")


def one_format(fmt, surface, folder, repeat, label=""):
    """Writing and reading ``fmt`` against a raw dump of the same heights."""
    heights = surface.heights
    raw_path = os.path.join(folder, f"raw-{fmt}.f8")
    heights.tofile(raw_path)
    path = os.path.join(folder, f"map.{ {'geotiff': 'tif'}.get(fmt, fmt) }")
    compare(
        f"{fmt} write{label}",
        in_process(lambda: surface.write(path)),
        in_process(lambda: heights.tofile(raw_path)),
        "tofile",
        repeat=repeat,
        reference_bytes=heights.nbytes,
    )
    spacing = {"spacing": surface.spacing} if fmt == "npy" else {}
    compare(
        f"{fmt} read{label} ({os.path.getsize(path) / 1e6:.0f} MB file)",
        in_process(lambda: read(path, **spacing)),
        in_process(lambda: np.fromfile(raw_path)),
        "fromfile",
        repeat=repeat,
        reference_bytes=heights.nbytes,
    )
    os.remove(raw_path)


def geotiff_window(surface, folder, repeat):
    if not importlib.util.find_spec("rasterio"):
        return
    path = os.path.join(folder, "window.tif")
    surface.write(path)
    x1, y1 = (0.1 * surface.points[0] * surface.spacing[0], 0.1 * surface.points[1] * surface.spacing[1])
    compare(
        "GeoTIFF read of a 10 %×10 % window",
        in_process(lambda: read(path, crop=((0.0, x1), (0.0, y1)))),
        in_process(lambda: read(path)),
        "the whole map",
        repeat=repeat,
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
        compare(
            f"{path.name} ({os.path.getsize(path) / 1e6:.2f} MB)",
            in_process(lambda path=path: read(path)),
            in_process(lambda path=path: np.fromfile(path, np.uint8)),
            "fromfile",
            repeat=repeat,
            record=False,
        )


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=int, default=4096, help="side of the square test map (default 4096)")
    parser.add_argument("--repeat", type=int, default=5, help="paired runs per comparison (default 5)")
    options = parser.parse_args()
    heights = np.random.default_rng(0).standard_normal((options.size, options.size)) * 1e-6
    surface = rough.Surface(heights, (1e-6, 1e-6), metadata={"crs": "EPSG:32633"})  # UTM 33N, for GeoTIFF
    print(
        f"rough {rough.__version__} from {pathlib.Path(rough.__file__).parent}, {options.size}×{options.size} map "
        f"({heights.nbytes / 1e6:.0f} MB), {options.repeat} paired runs, {os.cpu_count()} CPUs"
    )
    with tempfile.TemporaryDirectory(dir=os.environ.get("TMPDIR")) as folder:
        surface.write(os.path.join(folder, "pipe.x3p"))
        pipe(os.path.join(folder, "pipe.x3p"), options.repeat, heights.nbytes)
        formats(surface, folder, options.repeat)
        geotiff_window(surface, folder, options.repeat)
    instrument_files(options.repeat)


if __name__ == "__main__":
    main()
