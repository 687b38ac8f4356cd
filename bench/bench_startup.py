"""Start-up: what a short command costs against starting Python itself, paired and
interleaved (bench/timing.py), each a child process (wall, CPU and peak memory).

Run:  .venv/bin/python bench/bench_startup.py [--repeat 20]

  - ``rough --help`` against ``python -c pass`` (goal ≤ 2×);
  - ``rough features`` on the small sample map and profile against
    ``python -c "import numpy, scipy"`` (goal ≤ 1.5×);
  - ``rough synth --rq`` of a small map against the same.
"""

import argparse
import os
import sys

from timing import command, compare

import rough

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=20)
    repeat = parser.parse_args().repeat
    cli = os.path.join(os.path.dirname(sys.executable), "rough")
    cli = [cli] if os.path.exists(cli) else [sys.executable, "-m", "rough"]
    print(f"rough {rough.__version__}: {' '.join(cli)}")
    bare = command([sys.executable, "-c", "pass"])
    libraries = command([sys.executable, "-c", "import numpy, scipy"])
    compare("rough --help", command([*cli, "--help"]), bare, "python -c pass", repeat, goal="≤ 2×")
    for sample in ("rock-map.x3p", "rock-profile.tsv"):
        compare(
            f"rough features {sample}",
            command([*cli, "features", rough.sample(sample)]),
            libraries,
            "import numpy, scipy",
            repeat,
            goal="≤ 1.5×",
        )
    synth = [*cli, "synth", "--size", "128x96", "--step", "10um", "--dimension", "2.3", "--rq", "1um", "--seed", "1"]
    compare("rough synth --size 128x96 --rq 1um", command(synth), libraries, "import numpy, scipy", repeat)


if __name__ == "__main__":
    main()
