"""Many inputs in one call against one call per input: what a batch saves.

One ``rough COMMAND --tsv`` over N copies of a sample against N separate
``rough COMMAND --tsv`` processes, run interleaved (pair by pair) and repeated; the
figures are the ratio separate / one call (min and median over the pairs), so the
machine's load cancels out. The outputs are checked to be the same table.

    python bench/bench_batch.py                 # info and features over 20 files
    python bench/bench_batch.py --files 50 --repeat 5
"""

import argparse
import pathlib
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

from rough import __version__, sample


def timed(commands):
    started = time.perf_counter()
    outputs = [subprocess.run(command, capture_output=True, check=True).stdout for command in commands]
    return time.perf_counter() - started, b"".join(outputs)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--files", type=int, default=20)
    parser.add_argument("--repeat", type=int, default=3)
    options = parser.parse_args()
    rough = [sys.executable, "-m", "rough"]
    with tempfile.TemporaryDirectory() as folder:
        names = []
        for index in range(options.files):
            name = pathlib.Path(folder) / f"map{index:03d}.x3p"
            shutil.copy(sample("rock-map.x3p"), name)
            names.append(str(name))
        print(f"rough {__version__}: {options.files} files of 128 × 96 points, {options.repeat} interleaved pairs")
        for command in (["info", "--tsv"], ["features", "--tsv"]):
            ratios, together, apart = [], [], []
            for _ in range(options.repeat):
                one, table = timed([rough + command + names])
                many, tables = timed([rough + command + [name] for name in names])
                assert table == tables, "one call and separate calls must print the same table"
                ratios.append(many / one)
                together.append(one)
                apart.append(many)
            print(
                f"{command[0]:<9} one call {statistics.median(together):6.2f} s, separate calls "
                f"{statistics.median(apart):6.2f} s: separate / one = {min(ratios):.1f}× min, "
                f"{statistics.median(ratios):.1f}× median"
            )


if __name__ == "__main__":
    main()
