"""``rough --help`` from the stored overview: the same text as click's, made again
whenever the environment changes (a plugin installed, another width), never a wrong or
missing answer when the cache cannot be used."""

import os
import subprocess
import sys

from plugin_package import install_plugin

# run as the `rough` script does, reporting on stderr whether click was loaded
LAUNCH = (
    "import sys\n"
    "from rough.cli import launch\n"
    "sys.argv = ['rough', *sys.argv[1:]]\n"
    "try:\n"
    "    launch.main()\n"
    "except SystemExit as end:\n"
    "    print('click' in sys.modules, file=sys.stderr)\n"
    "    raise\n"
)
COMMAND = '''
import click

from rough.cli.report import Report


@click.command(short_help="A plugin's command.")
def toy():
    """A plugin's command."""
    return Report([], {})
'''


def launch(cache, *args, path=(), columns="100"):
    """``rough ARGS`` through the entry point, with its cache in ``cache``, from a working
    folder of its own (a folder on ``sys.path``: its changes would change the key)."""
    work = cache.parent / "work"
    work.mkdir(exist_ok=True)
    environment = {
        **os.environ,
        "XDG_CACHE_HOME": str(cache),
        "COLUMNS": columns,
        "PYTHONPATH": search_path(path),
    }
    return subprocess.run(
        [sys.executable, "-c", LAUNCH, *args], env=environment, capture_output=True, text=True, timeout=120, cwd=work
    )


def search_path(folders):
    """PYTHONPATH with ``folders`` first: the rough the suite tests, plus plugins."""
    return os.pathsep.join([*map(str, folders), os.environ.get("PYTHONPATH", "")])


def click_text(columns="100", path=()):
    environment = {**os.environ, "COLUMNS": columns, "PYTHONPATH": search_path(path)}
    code = "from rough.cli.main import overview; print(overview())"
    return subprocess.run([sys.executable, "-c", code], env=environment, capture_output=True, text=True).stdout


def test_the_second_help_comes_from_the_cache_without_click_and_says_the_same(tmp_path):
    cache = tmp_path / "cache"
    first, second = launch(cache, "--help"), launch(cache, "--help")
    assert first.returncode == second.returncode == 0
    assert first.stderr.strip() == "True" and second.stderr.strip() == "False"
    assert first.stdout == second.stdout == click_text()
    assert launch(cache).stdout == launch(cache, "-h").stdout == click_text()


def test_a_plugin_installed_since_is_listed(tmp_path):
    plugins = tmp_path / "site"
    plugins.mkdir()
    before = launch(tmp_path / "cache", "--help", path=[plugins])
    assert "toy" not in before.stdout
    install_plugin(plugins, {"cli.py": COMMAND}, "[rough.commands]\ntoy = toy_rough.cli:toy\n")
    after = launch(tmp_path / "cache", "--help", path=[plugins])
    assert after.stderr.strip() == "True"  # the folder changed: the text is made again
    assert "A plugin's command." in after.stdout
    assert after.stdout == click_text(path=[plugins])


def test_each_width_has_its_own_text(tmp_path):
    for columns in ("60", "100", "60"):
        assert launch(tmp_path / "cache", "--help", columns=columns).stdout == click_text(columns)


def test_an_unwritable_cache_costs_nothing_but_time(tmp_path):
    blocked = tmp_path / "a file"
    blocked.write_text("")
    for _ in range(2):
        answer = launch(blocked, "--help")
        assert answer.returncode == 0 and answer.stdout == click_text()
        assert answer.stderr.strip() == "True"


def test_a_damaged_or_foreign_cache_file_is_made_again(tmp_path):
    launch(tmp_path / "cache", "--help")
    (stored,) = (tmp_path / "cache" / "rough").iterdir()
    stored.write_text("another key\nnot rough's help\n")
    answer = launch(tmp_path / "cache", "--help")
    assert answer.stdout == click_text() and answer.stderr.strip() == "True"


def test_old_overviews_are_pruned(tmp_path):
    folder = tmp_path / "cache" / "rough"
    folder.mkdir(parents=True)
    for number in range(40):
        (folder / f"overview-{number:08x}").write_text("old\n")
    launch(tmp_path / "cache", "--help")
    assert len(list(folder.iterdir())) == 32
