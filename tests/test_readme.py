"""The README's tour and batch recipes run as written: every ``$ command`` of the tour
is run with the installed ``rough`` on PATH, and its output must be the lines shown
(a line ``...`` stands for any number of lines, ``...`` within a line for any
text). The Makefile recipe is run with ``make -j2`` on the sample files."""

import os
import pathlib
import re
import shutil
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text(encoding="utf-8")
EPOCH = "1767225600"  # 2026-01-01, as the tour says


def section(title):
    start = README.index(f"\n## {title}\n")
    end = README.find("\n## ", start + 1)
    return README[start:end]


def tour_steps():
    """(command, expected lines) for each ``$`` line of the tour's console blocks."""
    steps = []
    for line in section("A 60-second tour").splitlines():
        if line.startswith("    $ "):
            steps.append((line[6:], []))
        elif steps and line.startswith("    ") and steps[-1] is not None:
            steps[-1][1].append(line[4:])
        elif steps and not line.strip():
            steps.append(None)
    return [step for step in steps if step is not None]


def matches(expected, actual):
    """Whether ``actual`` lines fit ``expected`` (with the ``...`` wildcards)."""
    if not expected:
        return not actual
    head, rest = expected[0], expected[1:]
    if head == "...":
        return any(matches(rest, actual[skip:]) for skip in range(len(actual) + 1))
    if not actual:
        return False
    pattern = ".*".join(map(re.escape, head.split("...")))
    return re.fullmatch(pattern, actual[0]) is not None and matches(rest, actual[1:])


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    if shutil.which("rough", path=os.path.dirname(sys.executable)) is None:
        pytest.skip("rough is not installed beside this Python (run make test)")
    folder = tmp_path_factory.mktemp("tour")
    (folder / "sample_profiles").symlink_to(ROOT / "sample_profiles")
    return folder


def environment():
    return {
        **os.environ,
        "PATH": os.path.dirname(sys.executable) + os.pathsep + os.environ["PATH"],
        "SOURCE_DATE_EPOCH": EPOCH,
        "COLUMNS": "100",
    }


def test_the_tour_has_commands_with_outputs():
    steps = tour_steps()
    assert len(steps) >= 6 and sum(bool(expected) for _, expected in steps) >= 4


@pytest.mark.parametrize("number", range(len(tour_steps())))
def test_the_tour_runs_as_written(workdir, number):
    command, expected = tour_steps()[number]
    result = subprocess.run(
        ["bash", "-c", command],
        cwd=workdir,
        env=environment(),
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert result.returncode == 0 and not result.stderr, result.stderr
    actual = result.stdout.rstrip("\n").splitlines()
    assert matches(expected, actual), "\n".join(["expected:", *expected, "got:", *actual])


def test_the_makefile_recipe_makes_one_table(workdir, tmp_path):
    block = re.search(r"```make\n(.*?)```", section("Many files at once"), re.S).group(1)
    (tmp_path / "Makefile").write_text(block)
    scans = tmp_path / "scans"
    scans.mkdir()
    shutil.copy(ROOT / "sample_profiles" / "rock-map.x3p", scans)
    convert = ["rough", "convert", ROOT / "sample_profiles" / "rock-profile.tsv", "-o", scans / "profile.x3p"]
    subprocess.run(convert, env=environment(), check=True)
    result = subprocess.run(
        ["make", "-j2"], cwd=tmp_path, env=environment(), capture_output=True, text=True, check=False
    )
    assert result.returncode == 0, result.stderr
    rows = [line.split("\t") for line in (tmp_path / "features.tsv").read_text().splitlines()]
    assert {row[0] for row in rows} == {"scans/rock-map.x3p", "scans/profile.x3p"}
    assert all(len(row) == 4 for row in rows)


def test_the_pandas_recipe_gives_numbers(workdir, tmp_path, monkeypatch):
    """The recipe of "Many files at once" on a real table: ``Sa`` comes out numeric even
    though text-valued rows (``evaluation.basis``, ``format``) share the table."""
    pandas = pytest.importorskip("pandas", reason="pandas is not installed (rough does not need it)")
    recipe = re.search(r"```python\n(import pandas.*?)```", section("Many files at once"), re.S).group(1)
    sample = ROOT / "sample_profiles"
    scans = [sample / "rock-map.x3p", sample / "rock-profile.tsv", tmp_path / "map.x3p"]
    synth = ["rough", "synth", "--size", "64x48", "--step", "10um", "--dimension", "2.3", "--rq", "1um", "--seed", "1"]
    subprocess.run([*synth, "-o", scans[2]], env=environment(), check=True)
    with open(tmp_path / "features.tsv", "w") as table:
        subprocess.run(["rough", "features", "--tsv", *scans], env=environment(), stdout=table, check=True)
    *lines, last = recipe.strip().splitlines()
    namespace = {}
    monkeypatch.chdir(tmp_path)
    exec("\n".join(lines), namespace)
    mean = eval(last, namespace)
    wide = namespace["wide"]
    assert pandas.api.types.is_float_dtype(wide["Sa"]) and isinstance(mean, float)
    assert wide["Sa"].count() == 2 and 0 < mean < 1e-3  # two maps; metres
