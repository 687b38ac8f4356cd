"""Benchmark of the foundation's input and output: the X3P pipe stage and each format.

Run:  .venv/bin/python bench/bench_io.py [--size 4096] [--repeat 5] [--surfalize PYTHON [--x3p-only]]

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
    ``numpy.fromfile`` of as many bytes;
  - with ``--surfalize PYTHON`` (a Python with surfalize installed, e.g. a separate
    venv): reading a 1024² and a 2048² X3P file with ``rough.io.read``, which checks
    the data's MD5, against surfalize's ``Surface.load``, which checks none, each
    in its own process (surfalize's is started once and asked to read on each turn,
    so neither start-up is timed), the data member stored (as rough writes it) and
    deflated (as MountainsMap writes it), at least 15 paired runs; and the MD5 of the
    data alone against the same surfalize read (the floor of any reader that checks
    it). ``--x3p-only`` runs only these.

``rough convert`` runs as ``python -m rough`` with this interpreter and environment,
so ``PYTHONPATH=. .venv/bin/python bench/bench_io.py`` measures the checkout and
plain ``.venv/bin/python bench/bench_io.py`` the installed package (the header says
which). Start-up time is measured by ``bench/bench_startup.py``.

In-process peak memory is the growth of the resident set during the call (Linux's
``VmHWM`` after resetting it), which counts anonymous memory that tracemalloc does
not see, such as the buffer a stream is read into.
"""

import argparse
import hashlib
import importlib.util
import os
import pathlib
import shlex
import subprocess
import sys
import tempfile
import time
import zipfile

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


X3P_SIDES = (1024, 2048)
X3P_REPEAT = 15  # at least this many paired runs: a read takes milliseconds on a shared machine
PEER_READER = """
import sys, time
from surfalize import Surface
for line in sys.stdin:
    wall, cpu = time.perf_counter(), time.process_time()
    Surface.load(line.strip())
    print(time.perf_counter() - wall, time.process_time() - cpu, flush=True)
"""


class PeerReader:
    """surfalize reading files in its own interpreter, timed there: each call asks it
    to read ``path`` once and returns its :class:`timing.Child` figures."""

    def __init__(self, python):
        self.process = subprocess.Popen(
            [python, "-c", PEER_READER], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
        )

    def reader(self, path):
        def run():
            self.process.stdin.write(f"{path}\n")
            self.process.stdin.flush()
            answer = self.process.stdout.readline().split()
            if len(answer) != 2:
                raise RuntimeError(f"surfalize could not read {path}")
            return Child((float(answer[0]), float(answer[1]), None))

        return run

    def close(self):
        self.process.stdin.close()
        self.process.wait()


def x3p_against_surfalize(folder, python, repeat):
    """rough's X3P read (MD5 checked) against surfalize's (none checked), stored and deflated."""
    peer = PeerReader(python)
    repeat = max(repeat, X3P_REPEAT)
    try:
        for side in X3P_SIDES:
            heights = np.random.default_rng(side).standard_normal((side, side)) * 1e-6
            stored = os.path.join(folder, f"stored-{side}.x3p")
            rough.Surface(heights, (1e-6, 1e-6)).write(stored)
            deflated = os.path.join(folder, f"deflated-{side}.x3p")
            with zipfile.ZipFile(stored) as source, zipfile.ZipFile(deflated, "w", zipfile.ZIP_DEFLATED) as target:
                for name in source.namelist():
                    target.writestr(name, source.read(name))
                member = source.read("bindata/data.bin")
            for label, path in (("stored", stored), ("deflated", deflated)):
                compare(
                    f"X3P read {side}² {label}, MD5 checked",
                    in_process(lambda path=path: read(path)),
                    peer.reader(path),
                    "surfalize, no MD5",
                    repeat=repeat,
                    goal="≤ 1× surfalize's",
                )
            compare(
                f"  the MD5 of data.bin alone, {side}²",
                in_process(lambda member=member: hashlib.md5(member).hexdigest()),
                peer.reader(stored),
                "surfalize, stored",
                repeat=repeat,
                record=False,
            )
    finally:
        peer.close()


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=int, default=4096, help="side of the square test map (default 4096)")
    parser.add_argument("--repeat", type=int, default=5, help="paired runs per comparison (default 5)")
    parser.add_argument("--surfalize", metavar="PYTHON", help="a Python with surfalize: X3P reads against it")
    parser.add_argument("--x3p-only", action="store_true", help="only the X3P reads against surfalize")
    options = parser.parse_args()
    if options.surfalize:
        print(f"rough {rough.__version__} from {pathlib.Path(rough.__file__).parent}, {os.cpu_count()} CPUs")
        with tempfile.TemporaryDirectory(dir=os.environ.get("TMPDIR")) as folder:
            x3p_against_surfalize(folder, options.surfalize, options.repeat)
        if options.x3p_only:
            return
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
