"""Fixtures shared by the tests: the third-party data folder, running ``rough`` as a
separate process exactly as a shell user would, and surfalize's seeded test data."""

import atexit
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile

# what `import rough` sets when numpy is not loaded yet (docs/design.rst, "Threads"); test
# modules import numpy first
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
# `rough --help` keeps its text in the user's cache (rough/cli/launch.py): the suite uses its own
os.environ["XDG_CACHE_HOME"] = tempfile.mkdtemp(prefix="rough-tests-cache-")
atexit.register(shutil.rmtree, os.environ["XDG_CACHE_HOME"], ignore_errors=True)

import pytest  # noqa: E402
from hypothesis import settings  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent

# Hypothesis profiles: $HYPOTHESIS_PROFILE names one; else "ci" where $CI is set (as CI
# services set it), else hypothesis's "default", whose example database is .hypothesis/
# (or $HYPOTHESIS_STORAGE_DIRECTORY). "ci" explores afresh on every run: no database, so
# no failure saved by an earlier run replays, and random, not derandomised, examples.
# "thorough" is "ci" with 5000 examples, for the property tests that take
# max(1000, the profile's max_examples).
settings.register_profile("ci", settings.get_profile("ci"), database=None, derandomize=False)
settings.register_profile("thorough", settings.get_profile("ci"), max_examples=5000)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE") or ("ci" if os.environ.get("CI") else "default"))


def pytest_report_header():
    import rough

    return f"rough {rough.__version__} from {pathlib.Path(rough.__file__).parent}"


def shared_folder():
    """``../shared`` beside the checkout (or $ROUGH_SHARED), or None."""
    candidate = pathlib.Path(os.environ.get("ROUGH_SHARED", ROOT.parent / "shared"))
    return candidate if (candidate / "data" / "INDEX.md").is_file() else None


def shared_data_path():
    """Where the third-party data are (``shared/data`` of :func:`shared_folder`), whether
    or not they are there: for module-level skip marks."""
    return (shared_folder() or ROOT.parent / "shared") / "data"


@pytest.fixture(scope="session")
def shared_data():
    folder = shared_folder()
    if folder is None:
        pytest.skip("../shared/data (third-party reference files) is not beside this checkout")
    return folder / "data"


def surfalize_heights():
    """surfalize's seeded test surface (its tests/conftest.py): 700 × 1000 points,
    meant at a step of 0.1 (µm, as surfalize's steps are)."""
    import numpy as np

    np.random.seed(0)
    x, y = np.meshgrid(np.arange(1000), np.arange(700))
    z = np.sin(x / 200 * 2 * np.pi)
    z += 0.5 * (np.sin((x - 200 / 2) / 200 * 2 * np.pi) + 1) * 0.3 * np.sin((np.sin(y / 10) + x) / 10 * 2 * np.pi)
    return z + np.random.normal(size=z.shape) / 5


def children_cpu_seconds():
    """CPU seconds used so far by this process's finished child processes: a cost that a
    loaded machine does not inflate, unlike wall time."""
    import resource

    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def cpu_seconds_of(pid):
    """CPU seconds a running process has used so far (all its threads), from /proc."""
    fields = pathlib.Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def rough(*args, input=None, check=False, env=None, timeout=120):
    """Run ``python -m rough ARGS``; returns the CompletedProcess (bytes output)."""
    environment = {**os.environ, **(env or {})}
    result = subprocess.run(
        [sys.executable, "-m", "rough", *map(str, args)],
        check=False,
        input=input,
        capture_output=True,
        env=environment,
        timeout=timeout,
    )
    if check and result.returncode != 0:
        raise AssertionError(f"rough {' '.join(map(str, args))} failed ({result.returncode}): {result.stderr.decode()}")
    return result


@pytest.fixture
def run():
    return rough


def assert_one_line_error(result, *fragments, status=2):
    """A failure as the command-line contract wants it (docs/conventions.rst): the status, one line on stderr that says
    what went wrong, and no traceback."""
    stderr = result.stderr.decode()
    assert result.returncode == status, stderr
    assert "Traceback" not in stderr, stderr
    assert len(stderr.strip().splitlines()) == 1, stderr
    for fragment in fragments:
        assert fragment in stderr, stderr
