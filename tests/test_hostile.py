"""The hostile corpus (tests/hostile, made by make_corpus.py): every crafted file is
refused with exit status 2 and one line that names the file and the problem, with no
traceback and no output file, inside an address-space limit and a time limit."""

import csv
import os
import pathlib
import resource
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

import pytest

from conftest import children_cpu_seconds

HOSTILE = pathlib.Path(__file__).resolve().parent / "hostile"
with open(HOSTILE / "MANIFEST.tsv", newline="") as manifest:
    MANIFEST = list(csv.DictReader(manifest, delimiter="\t"))
ADDRESS_SPACE = 2 << 30  # bytes a reader may map, numpy and scipy included
SECONDS = 20


def _limited():
    resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE, ADDRESS_SPACE))


def _refusal(row, folder):
    path = HOSTILE / row["file"]
    output = folder / f"{row['file']}.out.x3p"
    started = children_cpu_seconds()
    result = subprocess.run(
        [sys.executable, "-m", "rough", "convert", str(path), "-o", str(output)],
        capture_output=True,
        timeout=60,
        preexec_fn=_limited,
        check=False,
        env={**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"},
    )
    elapsed = children_cpu_seconds() - started  # CPU time: a loaded machine does not inflate it
    stderr = result.stderr.decode(errors="replace")
    problems = []
    if result.returncode != 2:
        problems.append(f"exit status {result.returncode}")
    if len(stderr.strip().splitlines()) != 1 or "Traceback" in stderr:
        problems.append("not one line")
    if result.stdout:
        problems.append(f"wrote to stdout: {result.stdout[:80]!r}")
    if str(path) not in stderr:
        problems.append("file not named")
    if row["fragment"] not in stderr:
        problems.append(f"no {row['fragment']!r}")
    if output.exists() or [p for p in folder.iterdir() if p.name.startswith(".rough-")]:
        problems.append("left a file")
    if elapsed > SECONDS:
        problems.append(f"took {elapsed:.1f} s of CPU")
    return row["file"], problems, stderr.strip()


def test_the_corpus_is_large_and_covers_every_reader():
    assert len(MANIFEST) >= 60
    families = {row["file"].split("-")[0].split(".")[0] for row in MANIFEST}
    assert {"x3p", "exr", "gsf", "text", "npy", "sdf", "al3d", "gzip"} <= families
    assert all((HOSTILE / row["file"]).is_file() for row in MANIFEST)


def test_every_hostile_file_is_refused_cleanly(tmp_path):
    with ThreadPoolExecutor(max(2, os.cpu_count() or 1)) as pool:
        outcomes = list(pool.map(lambda row: _refusal(row, tmp_path), MANIFEST))
    failures = [f"{name}: {', '.join(problems)} -- {stderr[:200]}" for name, problems, stderr in outcomes if problems]
    assert not failures, "\n".join(failures)
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024
    assert peak < ADDRESS_SPACE // 2, f"a reader used {peak >> 20} MB"


@pytest.mark.parametrize(
    "name",
    [
        "x3p-zip-bomb.x3p",
        "x3p-member-size-lie.x3p",
        "gzip-bomb.txt.gz",
        "x3p-entity-bomb.x3p",
        "gsf-absurd-size.gsf",
        "npy-absurd-shape.npy",
        "al3d-absurd-size.al3d",
        "sur-absurd-size.sur",
        "sur-zlib-bomb.sur",
        "ibw-note-size.ibw",
        "gwy-array-past-end.gwy",
        "hdf5-sparse-bomb.h5",
    ],
)
def test_bombs_and_absurd_sizes_are_refused_before_allocation(name):
    """In-process, with tracemalloc: refusing costs little more than the file itself."""
    import tracemalloc

    from rough.errors import InputError
    from rough.io import read

    size = (HOSTILE / name).stat().st_size
    tracemalloc.start()
    try:
        with pytest.raises(InputError):
            read(HOSTILE / name)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 4 * size + (160 << 20), f"{peak >> 20} MB for a {size >> 10} kB file"
