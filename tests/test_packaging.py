"""The package as users install it: the wheel ships every subpackage and the samples,
the distribution has its own name, every command has help, the top-level API is
complete and lazy, and a missing optional package is reported in one line."""

import email.parser
import importlib.metadata
import os
import pathlib
import re
import subprocess
import sys
import zipfile

import pytest

import rough

from conftest import ROOT, assert_one_line_error

DISTRIBUTION = "rough-metrology"


def source_modules():
    """Every module of the source tree, as a path inside the package (``rough/io/x3p.py``);
    ``rough/sample_profiles`` is data (a link to ``sample_profiles/``), not code."""
    package = ROOT / "rough"
    return {
        path.relative_to(ROOT).as_posix()
        for path in package.rglob("*.py")
        if "__pycache__" not in path.parts and "sample_profiles" not in path.relative_to(package).parts
    }


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    if not (ROOT / "setup.cfg").is_file():
        pytest.skip("the source tree (setup.cfg) is not beside these tests")
    folder = tmp_path_factory.mktemp("wheel")
    built = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--quiet", "--no-deps", "--no-build-isolation", "-w", str(folder), "."],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
        timeout=300,
    )
    assert built.returncode == 0, built.stderr
    (path,) = folder.glob("rough_metrology-*.whl")
    return path


def test_the_wheel_ships_every_module_of_the_source_tree(wheel):
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
    missing = source_modules() - names
    assert not missing, f"left out of the wheel: {sorted(missing)}"
    folders = {pathlib.PurePosixPath(name).parent for name in source_modules()}
    assert all(f"{folder}/__init__.py" in names for folder in folders), "a package folder without __init__.py"
    assert {"rough/sample_profiles/rock-profile.tsv", "rough/sample_profiles/rock-map.x3p"} <= names


def test_the_wheel_names_its_own_distribution_and_the_rough_command(wheel):
    with zipfile.ZipFile(wheel) as archive:
        info = next(name for name in archive.namelist() if name.endswith(".dist-info/METADATA"))
        metadata = email.parser.Parser().parsestr(archive.read(info).decode())
        entry_points = archive.read(info.replace("METADATA", "entry_points.txt")).decode()
        licence = [name for name in archive.namelist() if name.endswith("LICENSE")]
    assert metadata["Name"] == DISTRIBUTION
    assert metadata["Version"] == rough.__version__
    assert re.search(r"^rough = rough\.cli\.launch:main$", entry_points, re.MULTILINE)
    assert licence, "LICENSE is not in the wheel"
    core = [r for r in metadata.get_all("Requires-Dist") if "extra ==" not in r]
    assert not any(name in " ".join(core) for name in ("matplotlib", "hidapi", "statsmodels")), core


def test_the_installed_copy_is_complete():
    """Where rough runs from an installed (not editable) distribution, its files hold
    every module of the source tree."""
    try:
        files = importlib.metadata.files(DISTRIBUTION)
    except importlib.metadata.PackageNotFoundError:
        pytest.skip(f"{DISTRIBUTION} is not installed as a distribution")
    installed = {file.as_posix() for file in files or ()}
    if not any(name.startswith("rough/") for name in installed):
        pytest.skip(f"{DISTRIBUTION} is installed editable: its files are the source tree")
    missing = source_modules() - installed
    assert not missing, f"missing from the installed copy: {sorted(missing)}"


def test_the_changelog_names_this_version():
    changelog = (ROOT / "CHANGELOG.md").read_text()
    newest = re.search(r"^## \[(\d+\.\d+\.\d+)\]", changelog, re.MULTILINE)[1]
    assert newest == rough.__version__


def commands():
    from rough.cli.main import COMMANDS

    yield from ((name,) for name in COMMANDS)
    yield from (("experiment", sub) for sub in ("design", "run", "analyze"))


@pytest.mark.parametrize("command", list(commands()), ids=" ".join)
def test_every_command_has_help_with_examples(run, command):
    result = run(*command, "--help", check=True)
    text = result.stdout.decode()
    assert text.startswith(f"Usage: rough {' '.join(command)}")
    assert not result.stderr


def test_the_api_is_listed_complete_and_loaded_lazily():
    for name in rough.__all__:
        assert getattr(rough, name) is not None
    assert set(rough.__all__) <= set(dir(rough))
    fresh = subprocess.run(
        [sys.executable, "-c", "import rough, sys; dir(rough); print('numpy' in sys.modules)"],
        capture_output=True,
        text=True,
        check=True,
    )
    assert fresh.stdout.strip() == "False", "import rough (or dir) loaded numpy"


def test_the_experiment_commands_run_from_the_package(run, tmp_path):
    run(
        "experiment",
        "design",
        "--preset",
        "costa2000",
        "--subjects",
        "2",
        "--seed",
        "1",
        tmp_path / "study",
        check=True,
    )
    assert (tmp_path / "study" / "study.json").is_file()


SAMPLE = "rock-profile.tsv"


@pytest.mark.parametrize(
    ("args", "hidden", "extra"),
    [
        (["fit-fractal", "--plot", "psd.png", SAMPLE], ["matplotlib"], "plot"),
        (["render", "--device", "hid", SAMPLE], ["hidraw", "hidtools"], "haptics"),
        (["experiment", "analyze", "study"], ["statsmodels"], "experiment"),
    ],
)
def test_a_missing_extra_is_named_in_one_line(tmp_path, args, hidden, extra):
    """With the optional package hidden, the command stops before any work and says
    what to install."""
    args = [str(rough.sample(SAMPLE)) if arg == SAMPLE else arg for arg in args]
    code = f"import sys; sys.modules.update(dict.fromkeys({hidden!r})); import rough.cli.main as m; m.main({args!r})"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, cwd=tmp_path, check=False)
    assert_one_line_error(result, f"pip install '{DISTRIBUTION}[{extra}]'", status=1)
    assert os.listdir(tmp_path) == []


def test_every_command_has_a_generated_docs_page():
    from rough.cli.main import COMMANDS

    folder = ROOT / "docs" / "cli"
    if not folder.is_dir():
        pytest.skip("the docs/ folder is not beside these tests")
    index = (folder / "index.rst").read_text()
    for name, target in COMMANDS.items():
        page = folder / f"{name}.rst"
        assert page.is_file(), f"docs/cli/{name}.rst is missing"
        assert f".. click:: {target}" in page.read_text()
        assert f"   {name}\n" in index
