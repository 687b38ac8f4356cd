"""The README's performance table, from the JSON lines that ``make bench`` collects
(bench/timing.py writes one per comparison when ROUGH_BENCH_RESULTS names a file).

Run:  python bench/table.py build/bench.jsonl README.md

Replaces what lies between the README's ``<!-- bench:start -->`` and
``<!-- bench:end -->`` lines; prints the table when no README is given. A measure
given twice (a benchmark run again, appended) keeps its first place and its last figures.
"""

import json
import pathlib
import platform
import statistics
import sys

START, END = "<!-- bench:start -->", "<!-- bench:end -->"


def table(rows):
    lines = [
        f"Measured by `make bench` on {platform.machine()} with {_cores()} cores; each ratio is against the "
        "baseline run alternately with it in the same process (wall time: least and median of the pairs; "
        "CPU time: median), peak memory a multiple of the map's float64 size.",
        "",
        "| measure | median time | baseline (median) | wall ratio, least / median | CPU ratio | peak memory | goal |",
        "|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        peak = f"{row['peak']:.1f}×" if row.get("peak") is not None else ""
        cpu = _ratio(row["cpu_median"]) if row.get("cpu_median") is not None else ""
        baseline = f"{row['baseline']} ({_seconds(row['baseline_seconds'])})"
        ratios = f"{_ratio(row['wall_min'])} / {_ratio(row['wall_median'])}"
        lines.append(
            f"| {row['name'].strip()} | {_seconds(row['seconds'])} | {baseline} | {ratios} | {cpu} | {peak} "
            f"| {row.get('goal') or ''} |"
        )
    return "\n".join(lines)


def _ratio(value):
    """Three significant digits, so that a small ratio (a share of real time) still shows."""
    return f"{value:.3g}×"


def _seconds(value):
    return f"{value * 1e3:.1f} ms" if value < 1 else f"{value:.2f} s"


def _cores():
    import os

    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()


def main():
    measures = {}  # a later row of the same measure replaces the earlier one, in its place
    for line in pathlib.Path(sys.argv[1]).read_text().splitlines():
        if line.strip():
            row = json.loads(line)
            measures[row["name"]] = row
    rows = list(measures.values())
    for row in rows:
        row.setdefault("wall_min", min(row["wall"]))
        row.setdefault("wall_median", statistics.median(row["wall"]))
    text = table(rows)
    if len(sys.argv) < 3:
        print(text)
        return
    readme = pathlib.Path(sys.argv[2])
    before, rest = readme.read_text().split(START, 1)
    after = rest.split(END, 1)[1]
    readme.write_text(f"{before}{START}\n{text}\n{END}{after}")
    print(f"{readme}: {len(rows)} benchmark rows")


if __name__ == "__main__":
    main()
