"""The Examples in rough's docstrings, run against the installed package."""

import doctest
import importlib
import pkgutil

import pytest

import rough

FINDER = doctest.DocTestFinder(exclude_empty=True)


def examples(name):
    return [test for test in FINDER.find(importlib.import_module(name), name) if test.examples]


def modules_with_examples():
    names = ["rough"] + [
        info.name
        for info in pkgutil.walk_packages(rough.__path__, "rough.")
        if ".sample_profiles" not in info.name and info.name != "rough.__main__"  # __main__ exits on import
    ]
    return sorted(name for name in names if examples(name))


def test_the_public_functions_have_examples():
    assert {"rough", "rough.io", "rough.metrology", "rough.fractal.fit", "rough.render"} <= set(modules_with_examples())


@pytest.mark.parametrize("name", modules_with_examples())
def test_docstring_examples(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    tests = examples(name)
    runner = doctest.DocTestRunner(verbose=False, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    report = []
    for test in tests:
        runner.run(test, out=report.append)
    assert not report, "".join(report)
