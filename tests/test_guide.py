"""The contributor guide (docs/design.rst) is held to the code: every name and path it
cites exists, and its worked examples — a toy format, a toy device and a toy command,
added as a plugin package exactly as the guide writes them — run and appear in help,
``rough formats``, the docs' table and the round-trip and device tests with no other
edit."""

import importlib
import os
import pathlib
import re
import subprocess
import sys

import pytest

import rough
from rough import plugins

ROOT = pathlib.Path(__file__).resolve().parent.parent
GUIDE = ROOT / "docs" / "design.rst"
TEXT = GUIDE.read_text() if GUIDE.exists() else ""
pytestmark = pytest.mark.skipif(not TEXT, reason="docs/design.rst is not in this tree (an installed copy)")


PLACEHOLDERS = {"NAME", "MODULE", "FUNCTION"}


def cited_names():
    """Dotted names the guide cites in literals or roles (``rough.io.registry.MODULES``),
    leaving out the entry-point groups and the placeholders of its recipes."""
    names = set(re.findall(r"(?<![\w./])(rough(?:\.\w+)+)", TEXT)) - set(plugins.GROUPS)
    return sorted(name for name in names if not PLACEHOLDERS & set(name.split(".")))


def cited_paths():
    """Files and folders of the tree the guide cites: ``rough/io/registry.py``, ``tests/...``."""
    found = re.findall(r"``((?:rough|tests|bench|docs|\.ci)/[\w./-]*)``", TEXT)
    return sorted({path.rstrip("/") for path in found if "NAME" not in path})


def resolve(dotted):
    """The object a dotted name stands for, importing as much of it as is a module."""
    parts = dotted.split(".")
    for split in range(len(parts), 0, -1):
        try:
            value = importlib.import_module(".".join(parts[:split]))
        except ModuleNotFoundError:
            continue
        for attribute in parts[split:]:
            value = getattr(value, attribute)
        return value
    raise ModuleNotFoundError(dotted)


def test_the_guide_cites_only_names_that_exist():
    assert len(cited_names()) > 20
    missing = []
    for dotted in cited_names():
        try:
            resolve(dotted)
        except (ImportError, AttributeError):
            missing.append(dotted)
    assert not missing, f"docs/design.rst cites names the code does not have: {missing}"


def test_the_guide_cites_only_files_that_exist():
    assert len(cited_paths()) > 10
    missing = [path for path in cited_paths() if not (ROOT / path).exists()]
    assert not missing, f"docs/design.rst cites files the tree does not have: {missing}"


def worked_example_files():
    """``{relative path: text}`` of the guide's code blocks captioned with a file name."""
    blocks = re.finditer(
        r"^\.\. code-block:: \w+\n   :caption: (?P<path>\S+)\n\n(?P<body>(?:(?:   .*)?\n)+)", TEXT, re.MULTILINE
    )
    return {
        match["path"]: "\n".join(line[3:] for line in match["body"].rstrip().splitlines()) + "\n" for match in blocks
    }


@pytest.fixture(scope="module")
def plugin(tmp_path_factory):
    """The guide's toy package, written where Python finds it; the environment to run in."""
    folder = tmp_path_factory.mktemp("plugin")
    files = worked_example_files()
    assert any(path.endswith("entry_points.txt") for path in files), "the guide shows no entry points"
    for path, text in files.items():
        (folder / path).parent.mkdir(parents=True, exist_ok=True)
        (folder / path).write_text(text)
    for info in folder.glob("*.dist-info"):
        name, version = info.name.removesuffix(".dist-info").split("-")
        (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: {version}\n")
    environment = dict(os.environ)
    source = pathlib.Path(rough.__file__).parent.parent
    environment["PYTHONPATH"] = os.pathsep.join([str(folder), str(source), environment.get("PYTHONPATH", "")])
    return folder, environment


def run(environment, *args, cwd=None):
    return subprocess.run(
        [sys.executable, "-m", "rough", *args], env=environment, cwd=cwd, capture_output=True, text=True, timeout=300
    )


def test_a_plugin_format_is_listed_read_and_written(plugin, tmp_path):
    folder, environment = plugin
    listing = run(environment, "formats")
    assert listing.returncode == 0, listing.stderr
    assert re.search(r"^\s*toy\b", listing.stdout, re.MULTILINE), listing.stdout
    assert "toy" in run(environment, "convert", "--help").stdout
    target = tmp_path / "map.toy"
    converted = run(environment, "convert", str(rough.sample("rock-map.x3p")), "-o", str(target))
    assert converted.returncode == 0, converted.stderr
    info = run(environment, "info", "--json", str(target))
    assert info.returncode == 0, info.stderr
    assert '"format": "toy"' in info.stdout


def test_a_plugin_device_renders(plugin):
    folder, environment = plugin
    assert "toy" in run(environment, "render", "--help").stdout
    rendered = run(
        environment, "render", "--device", "toy", "--duration", "0.05s", str(rough.sample("rock-profile.tsv"))
    )
    assert rendered.returncode == 0, rendered.stderr


def test_a_plugin_command_runs(plugin):
    folder, environment = plugin
    assert re.search(r"^\s+rq\b", run(environment, "--help").stdout, re.MULTILINE)
    answer = run(environment, "rq", str(rough.sample("rock-profile.tsv")))
    assert answer.returncode == 0, answer.stderr
    assert answer.stdout.strip()


@pytest.mark.parametrize("test_file, registry", [("test_roundtrip.py", "format"), ("test_devices.py", "device")])
def test_the_registry_tests_take_the_plugin_in(plugin, test_file, registry):
    folder, environment = plugin
    tests = ROOT / "tests" / test_file
    outcome = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-k", "toy", str(tests)],
        env=environment,
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert outcome.returncode == 0, outcome.stdout[-2000:]
    assert re.search(r"\b[1-9]\d* passed", outcome.stdout), (
        f"no {registry} test ran for the toy: {outcome.stdout[-500:]}"
    )
