"""What ``rough report`` costs against the commands a user would otherwise run by hand.

The report of the two samples (the map filled, and the profile) against, for each, the
separate commands that give the same content: ``features``, ``fit-fractal --plot``,
``show --plot`` and, for the map, ``rose --plot`` (SVG figures and a PNG map, as the
report embeds them). Then the PDF against the HTML of the same report (the cost of
WeasyPrint). Pairs are interleaved (bench/timing.py); the lines give the ratio, min
and median over the pairs.

    python bench/bench_report.py [--repeat 5]
"""

import argparse
import shlex
import sys
import tempfile

from timing import command, compare

from rough import sample


def separate_commands(folder, inputs):
    rough = f"{shlex.quote(sys.executable)} -m rough"
    lines = []
    for index, name in enumerate(inputs):
        out = f"{folder}/{index}"
        fill = "--fill" if name.endswith(".x3p") else ""
        lines += [
            f"{rough} features {name} > {out}.txt",
            f"{rough} fit-fractal {fill} --plot {out}-spectrum.svg {name}",
            f"{rough} show --plot {out}-surface.png {name}",
        ]
        if fill:
            lines.append(f"{rough} rose --fill --plot {out}-rose.svg {name}")
    return " && ".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    options = parser.parse_args()
    inputs = [str(sample("rock-map.x3p")), str(sample("rock-profile.tsv"))]
    rough = [sys.executable, "-m", "rough", "report", "--fill", *inputs, "-o"]
    with tempfile.TemporaryDirectory() as folder:
        html = command([*rough, f"{folder}/report.html"])
        by_hand = command(separate_commands(folder, inputs), shell=True)
        compare("report, 2 samples, HTML", html, by_hand, "the same by separate commands", options.repeat)
        pdf = command([*rough, f"{folder}/report.pdf"])
        compare("report, 2 samples, PDF", pdf, html, "the same report as HTML", options.repeat)


if __name__ == "__main__":
    main()
