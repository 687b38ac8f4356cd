"""The Python API equals the command line (docs/design.rst, "The layers"): every option
of every command is a keyword of a library function the command calls, as
``rough.cli.library`` declares them, with the same default; ``rough.parameters``
returns what ``rough features`` prints; ``fill`` does in Python what ``--fill`` does."""

import functools
import importlib
import inspect
import json
import math
import subprocess
import sys

import click
import numpy as np
import pytest

import rough
from rough import fractal, metrology
from rough.cli import library
from rough.cli.main import COMMANDS

from conftest import rough as run_rough

MAP = rough.sample("rock-map.x3p")
PROFILE = rough.sample("rock-profile.tsv")


def resolve(target):
    """The object ``module:attribute`` names (the attribute may be dotted)."""
    module, _, attribute = target.partition(":")
    return functools.reduce(getattr, attribute.split("."), importlib.import_module(module))


def keywords(function):
    """The keyword parameters of ``function`` (a class: of its constructor) → default."""
    return {
        name: parameter.default
        for name, parameter in inspect.signature(function).parameters.items()
        if parameter.kind in (parameter.POSITIONAL_OR_KEYWORD, parameter.KEYWORD_ONLY)
    }


def commands():
    """(name, click command) of every built-in command and ``experiment`` subcommand."""
    for name, target in COMMANDS.items():
        module, attribute = target.split(":")
        command = getattr(importlib.import_module(module), attribute)
        if isinstance(command, click.Group):
            yield from ((f"{name} {sub}", each) for sub, each in command.commands.items())
        else:
            yield name, command


COMMAND_LIST = dict(commands())


def options(command):
    """option name (the long flag without ``--``) → click Option."""
    found = {}
    for parameter in command.params:
        if isinstance(parameter, click.Option):
            long = [flag for flag in parameter.opts if flag.startswith("--")]
            found[long[0][2:]] = parameter
    return found


def library_keywords(name):
    merged = {}
    for dotted in library.LIBRARY[name]:
        merged = keywords(resolve(dotted)) | merged
    return merged


@pytest.mark.parametrize("name", sorted(COMMAND_LIST))
def test_every_option_is_a_keyword_of_the_library(name):
    known = library_keywords(name)
    declared = {*library.COMMAND_LINE, *library.keywords(name)}
    given = options(COMMAND_LIST[name])
    missing = [option for option in given if option not in declared and option.replace("-", "_") not in known]
    assert missing == sorted(library.NOT_YET.get(name, ())), (
        f"rough {name}: options that are no keyword of {', '.join(library.LIBRARY[name])}: {missing}"
    )


@pytest.mark.parametrize("name", sorted(COMMAND_LIST))
def test_an_option_has_its_keywords_default(name):
    """Where the option is the keyword, a default given on the command line is the
    library's, once parsed (units to SI)."""
    known = library_keywords(name)
    context = click.Context(COMMAND_LIST[name])
    differ = []
    for option, parameter in options(COMMAND_LIST[name]).items():
        keyword = option.replace("-", "_")
        default = parameter.get_default(context)
        unset = default is None or default is getattr(click.core, "UNSET", None)
        chosen = known.get(keyword) in (None, inspect.Parameter.empty)  # by the function, or given by the command
        if keyword not in known or option in library.keywords(name) or unset or chosen or parameter.multiple:
            continue
        given = parameter.type_cast_value(context, default)
        if given != known[keyword] and not _same_list(given, known[keyword]):
            differ.append(f"--{option} {given!r} against {keyword}={known[keyword]!r}")
    differ = [text for text in differ if text.split()[0][2:] not in library.DEFAULTS.get(name, {})]
    assert not differ, f"rough {name}: {differ}"


def _same_list(given, default):
    """A tuple option against a list or tuple default, or a comma-separated list against a tuple."""
    if isinstance(given, str) and isinstance(default, tuple):
        return given.split(",") == list(default)
    return isinstance(given, tuple) and isinstance(default, (list, tuple)) and list(given) == list(default)


def test_the_table_names_only_what_exists():
    assert set(library.LIBRARY) == set(COMMAND_LIST)
    for name, functions in library.LIBRARY.items():
        for dotted in functions:
            assert callable(resolve(dotted)), dotted
    every_option = {option for command in COMMAND_LIST.values() for option in options(command)}
    assert set(library.COMMAND_LINE) <= every_option
    for key in library.KEYWORDS:
        name, _, option = key.rpartition("--")
        name = name.strip()
        target, reason = library.keywords(name)[option]
        assert reason
        if name:
            assert option in options(COMMAND_LIST[name]), f"rough {name} has no --{option}"
        if ":" in target:
            assert callable(resolve(target)), target
        else:
            names = [name] if name else [n for n in COMMAND_LIST if option in options(COMMAND_LIST[n])]
            for each in names:
                assert target in library_keywords(each), f"rough {each} --{option}: no keyword {target}"


def test_the_table_loads_nothing():
    code = "import sys, rough.cli.library; print('numpy' in sys.modules, 'click' in sys.modules)"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.split() == ["False", "False"]


# -- rough.parameters is rough features -----------------------------------------------------------


def features_json(*args):
    result = run_rough("features", "--json", *args, check=True)
    return json.loads(result.stdout)


def same(one, other):
    return (one is None and math.isnan(other)) or one == other or (math.isnan(one) and math.isnan(other))


@pytest.mark.parametrize(
    ("path", "arguments", "keywords"),
    [
        (PROFILE, (), {}),
        (MAP, (), {}),
        (PROFILE, ("--cutoff", "0.8mm", "--height", "-20um", "--ratio", "20"), {"cutoff": 0.8e-3, "height": -20e-6}),
        (
            MAP,
            ("--volume-ratios", "5:85", "--pruning", "10", "--edge-features", "include", "--slope", "7point"),
            {"volume_ratios": (5.0, 85.0), "pruning": 10.0, "edge_features": "include", "slope": "7point"},
        ),
        (MAP, ("--along", "y", "--dc-ratios", "20:70"), {"along": "y", "dc_ratios": (20.0, 70.0)}),
    ],
    ids=["profile", "map", "profile-options", "map-options", "map-along"],
)
def test_parameters_are_the_numbers_features_prints(path, arguments, keywords):
    if "--ratio" in arguments:
        keywords = {**keywords, "ratio": 20.0}
    document = features_json(*arguments, path)
    values = rough.parameters(rough.read(path), **keywords)
    printed = {key: value for key, value in document.items() if isinstance(value, float) or value is None}
    printed.pop("feature_count", None)
    assert list(values) == [key for key in document if key in printed]
    unequal = {key: (values[key], printed[key]) for key in values if not same(printed[key], values[key])}
    assert not unequal


def test_parameters_of_chosen_families():
    profile, scan = rough.read(PROFILE), rough.read(MAP)
    assert list(rough.parameters(profile, families=["field"])) == list(metrology.PROFILE)
    assert list(rough.parameters(profile, families="functional")) == list(metrology.PROFILE_FUNCTIONAL)
    assert list(rough.parameters(scan, families=("feature",))) == list(metrology.FEATURE)
    everything = rough.parameters(scan)
    assert list(everything) == [*metrology.AREAL, *metrology.AREAL_FUNCTIONAL, *metrology.FEATURE]
    for families, fragment in (
        (["feature"], "need a map evaluated as a map"),
        (["height"], "unknown parameter families 'height'"),
    ):
        with pytest.raises(rough.InputError, match=fragment):
            rough.parameters(profile, families=families)


def test_parameters_of_a_map_with_gaps_are_those_of_its_valid_points():
    scan = rough.read(MAP)
    heights = scan.heights.copy()
    heights[10:14, 20:30] = np.nan
    holed = scan.derive("holes", {}, heights=heights)
    values = rough.parameters(holed, families=["field", "functional"])
    assert values["Sq"] == pytest.approx(np.nanstd(heights), rel=1e-12)
    assert all(math.isfinite(values[key]) for key in ("Sk", "Spk", "Svk", "Vmc", "Vvc"))


# -- fill= does what --fill does --------------------------------------------------------------------


def test_fit_fractal_fills_when_asked_and_says_how_when_not():
    scan = rough.read(MAP)
    with pytest.raises(rough.InputError, match=r"fill=True"):
        rough.fit_fractal(scan)
    filled = rough.fit_fractal(scan, fill=True)
    assert filled == fractal.fit_fractal(fractal.fill_invalid(scan))
    document = json.loads(run_rough("fit-fractal", "--fill", "--json", MAP, check=True).stdout)
    assert document["fractal_dimension"] == filled.fractal_dimension
    assert document["amplitude_coefficient"] == filled.amplitude_coefficient


def test_rose_fills_when_asked():
    scan = rough.read(MAP)
    with pytest.raises(rough.InputError, match=r"fill=True"):
        rough.rose(scan, step=30)
    filled = rough.rose(scan, step=30, fill=True)
    document = json.loads(run_rough("rose", "--fill", "--angle-step", "30", "--json", MAP, check=True).stdout)
    assert document["principal_direction"] == filled.principal_direction
    assert [sector["fractal_dimension"] for sector in document["sectors"]] == list(filled.fractal_dimension)
