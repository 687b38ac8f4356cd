"""``--jobs 2`` against ``--jobs 1``: what a second core saves over many files.

``rough features --tsv`` over N small maps made by ``rough synth`` in a temporary
folder, with ``--jobs 1`` and with ``--jobs 2``, run interleaved (pair by pair,
alternating which goes first) and repeated. The figure is the speed-up, the wall time
of ``--jobs 1`` over that of ``--jobs 2`` (min and median over the pairs; issue 34's
goal: at least 1.6 on 2 cores); the CPU ratio says how much work the workers add.
As the ceiling the machine allows at the moment, the same speed-up is measured for
two independent ``--jobs 1`` processes over half the files each, run at once.
The two tables are checked to be the same, byte for byte. The load average is
printed before and after: these machines are shared.

    python bench/bench_jobs.py                      # 40 maps of 256 × 256 points
    python bench/bench_jobs.py --files 80 --size 128 --repeat 7
"""

import argparse
import os
import pathlib
import shlex
import subprocess
import sys
import tempfile

from timing import command, compare

from rough import __version__
from rough.cli.pool import cores

ROUGH = [sys.executable, "-m", "rough"]


def main():
    options = _arguments()
    with tempfile.TemporaryDirectory() as folder:
        names = [_synthesise(folder, index, options.size) for index in range(options.files)]
        base = [*ROUGH, "-q", "features", "--tsv"]  # -q: the maps' warnings are not the point
        one = [*base, "--jobs", "1", *names]
        many = [*base, "--jobs", str(options.jobs), *names]
        tables = [subprocess.run(argv, capture_output=True, check=True).stdout for argv in (one, many)]
        assert tables[0] == tables[1], "--jobs 1 and --jobs N must print the same table"
        print(
            f"rough {__version__}: {options.files} maps of {options.size}², {options.repeat} interleaved pairs, "
            f"{cores()} cores; load average {_load()}"
        )
        print(f"ratio = --jobs 1 time / --jobs {options.jobs} time (the speed-up)")
        compare(
            f"features --jobs 1 over {options.files} files",
            command(one),
            command(many),
            f"--jobs {options.jobs}",
            repeat=options.repeat,
            goal="≥ 1.6 on 2 cores",
        )
        half = len(names) // 2
        halves = [shlex.join([*base, *names[:half]]), shlex.join([*base, *names[half:]])]
        compare(
            "ceiling: two processes over half the files each",
            command(one),
            command(f"{halves[0]} > /dev/null & {halves[1]} > /dev/null; wait", shell=True),
            "both at once",
            repeat=options.repeat,
            record=False,
        )
        print(f"load average after: {_load()}")


def _arguments():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    for flag, default, meaning in (
        ("--files", 40, "how many maps"),
        ("--size", 256, "points along each side of a map"),
        ("--repeat", 5, "interleaved pairs"),
        ("--jobs", 2, "the processes compared with one"),
    ):
        parser.add_argument(flag, type=int, default=default, help=meaning)
    return parser.parse_args()


def _synthesise(folder, seed, size):
    """A fractal map of ``size``² points in ``folder``: its file name."""
    name = str(pathlib.Path(folder) / f"map{seed:03d}.x3p")
    shape = ["--size", f"{size}x{size}", "--step", "1um", "--dimension", "2.3", "--amplitude", "1um"]
    subprocess.run([*ROUGH, "synth", *shape, "--seed", str(seed), "-o", name], check=True)
    return name


def _load():
    return " ".join(f"{value:.2f}" for value in os.getloadavg())


if __name__ == "__main__":
    main()
