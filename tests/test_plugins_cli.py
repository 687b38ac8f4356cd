"""Subcommands from other packages: the entry-point group ``rough.commands``
(rough.cli.main), tried with a toy plugin package on PYTHONPATH."""

import os
import textwrap

import pytest

from rough.cli.main import COMMANDS

from conftest import ROOT, assert_one_line_error, rough

TOY = '''
import click


@click.command(short_help="Say hello from a plugin.")
@click.argument("name", default="world")
def toy(name):
    """Print a greeting."""
    click.echo(f"hello {name}")


@click.command(short_help="A plugin that tries to take a built-in's name.")
def impostor():
    click.echo("impostor")
'''

ENTRY_POINTS = """
[rough.commands]
toy = toy_rough.cli:toy
info = toy_rough.cli:impostor
broken = toy_rough.missing:command
notacommand = toy_rough.cli:click
"""


@pytest.fixture(scope="module")
def plugin_path(tmp_path_factory):
    """PYTHONPATH with the toy package ``toy_rough`` and its entry points installed."""
    folder = tmp_path_factory.mktemp("plugins")
    (folder / "toy_rough").mkdir()
    (folder / "toy_rough" / "__init__.py").write_text("")
    (folder / "toy_rough" / "cli.py").write_text(TOY)
    info = folder / "toy_rough-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: toy_rough\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(textwrap.dedent(ENTRY_POINTS))
    return {"PYTHONPATH": os.pathsep.join([str(folder), str(ROOT), os.environ.get("PYTHONPATH", "")])}


def test_a_plugin_command_runs_and_is_listed(plugin_path):
    assert rough("toy", "rock", env=plugin_path, check=True).stdout == b"hello rock\n"
    listing = rough("--help", env=plugin_path, check=True).stdout.decode()
    assert "toy" in listing and "Say hello from a plugin." in listing


def test_a_built_in_name_wins_over_a_plugin(plugin_path):
    assert b"impostor" not in rough("info", "--help", env=plugin_path, check=True).stdout


@pytest.mark.parametrize("name", ["broken", "notacommand"])
def test_a_broken_plugin_is_listed_and_fails_in_one_line(plugin_path, name):
    listing = rough("--help", env=plugin_path, check=True).stdout.decode()
    line = next(line for line in listing.splitlines() if line.strip().startswith(name))
    assert "broken plugin" in line
    assert_one_line_error(rough(name, "--any", "args", env=plugin_path), "cannot be loaded", status=1)
    assert rough("info", "--help", env=plugin_path).returncode == 0


def test_every_built_in_command_is_in_the_overview():
    listing = rough("--help", check=True).stdout.decode().partition("Commands:")[2]
    assert sorted(line.split()[0] for line in listing.splitlines() if line[2:3].strip()) == sorted(COMMANDS)
