"""Every command example of the README and the docs runs as written (issue 35).

The examples are collected from the sources of the pages a reader sees: the code blocks
of ``README.md``, of ``docs/*.rst`` and ``docs/cli/*.rst`` (literal blocks and
``command-output`` directives), and the ``\\b`` blocks of every click command's help,
which sphinx_click puts on the command pages (taken from ``rough.cli.main.COMMANDS``,
so a new command's examples are run too). A line is an example when it runs ``rough
COMMAND`` (in a block with ``$`` prompts: every ``$`` line). Each runs through ``bash
-c`` in a folder of its own block, holding the inputs the examples name, after the
block's earlier lines (a block is one session, as in a terminal), with ``rough`` on
PATH. It must exit 0 (every stage of a pipe 0, or 141 when a later stage such as
``head`` closed it), or the status a ``# exit status N`` comment on its line or the
next one says. Examples that need what a test machine has not (a joystick, a display,
a cluster) are in :data:`NOT_RUNNABLE`; a program that is not installed (``jq``,
``gnuplot``) skips its examples with a reason.
"""

import html
import io
import os
import pathlib
import pty
import re
import select
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import click
import numpy
import pytest

import rough
from rough import fractal
from rough.cli import main

ROOT = pathlib.Path(__file__).resolve().parent.parent
EPOCH = "1767225600"
EXIT_STATUS = re.compile(r"#\s*exit status (\d+)\s*$")
NAMES = "|".join(map(re.escape, sorted(main.COMMANDS, key=len, reverse=True)))
RUNS_ROUGH = re.compile(rf"(?:^|[\s|;&(])rough(?:\s+-\S+)*\s+(?:{NAMES})(?=\s|$)")

#: (pattern, why): examples that cannot run on a test machine, each for a stated reason.
NOT_RUNNABLE = [
    (r"--scheduler tcp://", "needs a Dask scheduler at the reader's own address"),
    (r"--device (hid|evdev)", "needs a force-feedback joystick"),
    (r"\| display$", "needs an X display"),
    (r"scan\.vk4", "needs a Keyence VK4 scan, which rough cannot make"),
    (r"\$SLURM_ARRAY_TASK_ID|\"\$scan\"", "a line of a Slurm job script (sbatch sets its variables)"),
]
UNLOADED = {}  # command -> why its module did not import (test_every_command_is_collected)
SHELL_WORDS = {"export", "cd", "echo", "eval", "for", "do", "done", "if", "then", "fi", "set", "test", "["}


class Example:
    """One command line of a page, the lines of its block before it, and the exit
    status it should end with."""

    def __init__(self, source, line, command, status, before, block):
        self.source, self.line, self.command, self.status = source, line, command, status
        self.before, self.block = before, block  # earlier lines of the block; all its lines

    @property
    def name(self):
        return f"{self.source}:{self.line}"


def block_commands(source, lines):
    """The examples of one code block: ``lines`` are (line number, text) pairs."""
    prompted = any(text.lstrip().startswith("$ ") for _, text in lines)
    commands = []
    for index, (number, text) in enumerate(lines):
        text = text.strip()
        if commands and commands[-1][1].endswith("\\"):
            commands[-1][1] += "\n" + text
            continue
        if prompted:
            if not text.startswith("$ "):
                continue
            text = text[2:]
        elif not RUNS_ROUGH.search(text):
            continue
        following = lines[index + 1][1] if index + 1 < len(lines) else ""
        mark = EXIT_STATUS.search(text) or EXIT_STATUS.match(following.strip())
        commands.append([number, text, int(mark.group(1)) if mark else 0])
    examples = []
    for position, (number, text, status) in enumerate(commands):
        if prompted or RUNS_ROUGH.search(text):
            before = [earlier for _, earlier, _ in commands[:position]]
            block = "\n".join(text for _, text, _ in commands)
            examples.append(Example(source, number, text, status, before, block))
    return examples


def markdown_blocks(path):
    """(line number, text) lists of the shell code blocks of a Markdown file."""
    markdown_it = pytest.importorskip("markdown_it", reason="markdown-it-py (the docs extra) reads the README")
    text = path.read_text(encoding="utf-8")
    lines = text.splitlines()
    for token in markdown_it.MarkdownIt("commonmark").parse(text):
        if token.type in ("code_block", "fence") and token.info.strip() in ("", "console", "shell", "sh", "bash"):
            start, end = token.map
            body = range(start + 1, end - 1) if token.type == "fence" else range(start, end)
            yield [(number + 1, lines[number]) for number in body]


def rst_blocks(path):
    """(line number, text) lists of the literal blocks and ``command-output``
    directives of a reStructuredText file."""
    lines = path.read_text(encoding="utf-8").splitlines()
    number = 0
    while number < len(lines):
        line = lines[number]
        output = re.match(r"\s*\.\. command-output:: (.*)", line)
        if output:
            yield [(number + 1, output.group(1))]
        if re.match(r"\s*\.\. (code-block|code|sourcecode)::", line) or (
            line.rstrip().endswith("::") and not line.lstrip().startswith("..")
        ):
            indent = len(line) - len(line.lstrip())
            block, number = [], number + 1
            while number < len(lines) and (not lines[number].strip() or _indent(lines[number]) > indent):
                if lines[number].strip() and not re.match(r"\s*:[\w-]+:", lines[number]) or block:
                    block.append((number + 1, lines[number]))
                number += 1
            yield block
            continue
        number += 1


def _indent(line):
    return len(line) - len(line.lstrip())


def help_blocks(command, prog):
    """(line number, text) lists of the ``\\b`` blocks of a click command's help and of
    its subcommands' (the command pages show them as written)."""
    lines = (command.help or "").splitlines()
    for number, line in enumerate(lines):
        if line.strip() == "\b":
            block = []
            for offset, text in enumerate(lines[number + 1 :], number + 2):
                if not text.strip():
                    break
                block.append((offset, text))
            yield prog, block
    for name, sub in getattr(command, "commands", {}).items():
        yield from help_blocks(sub, f"{prog} {name}")


def command_help_blocks():
    context = click.Context(main.cli)
    yield from help_blocks(main.cli, "rough")
    for name in main.COMMANDS:
        try:
            command = main.cli.get_command(context, name)
        except ImportError as error:
            UNLOADED[name] = str(error)
            continue
        yield from help_blocks(command, f"rough {name}")


def examples():
    found = []
    for block in markdown_blocks(ROOT / "README.md"):
        found += block_commands("README.md", block)
    for path in sorted([*(ROOT / "docs").glob("*.rst"), *(ROOT / "docs" / "cli").glob("*.rst")]):
        for block in rst_blocks(path):
            found += block_commands(str(path.relative_to(ROOT)), block)
    for prog, block in command_help_blocks():
        found += block_commands(f"{prog} --help", block)
    return found


EXAMPLES = examples()


def missing_program(command):
    """The first program the command runs that is not installed, if any."""
    lexer = shlex.shlex(command.replace("\\\n", " "), posix=True, punctuation_chars=True)
    lexer.whitespace_split = True
    starts, expect = [], True
    for token in lexer:
        if expect and not re.match(r"\w+=", token):
            starts.append(token)
        expect = token in ("|", "||", "&&", ";", "&", "(", "$(")
    for program in starts:
        if program not in SHELL_WORDS and program != "rough" and shutil.which(program) is None:
            return program
    return None


@pytest.fixture(scope="module")
def bin_folder(tmp_path_factory):
    """A folder with the ``rough`` to test: the installed one beside this Python (make
    test), or, run from the source tree, a script that runs it with this Python."""
    installed = shutil.which("rough", path=os.path.dirname(sys.executable))
    if installed and pathlib.Path(rough.__file__).parent != ROOT / "rough":
        return os.path.dirname(installed)
    folder = tmp_path_factory.mktemp("bin")
    script = folder / "rough"
    source = pathlib.Path(rough.__file__).parent.parent
    python = shlex.quote(sys.executable)
    script.write_text(f'#!/bin/sh\nPYTHONPATH={shlex.quote(str(source))} exec {python} -m rough "$@"\n')
    script.chmod(0o755)
    return str(folder)


def environment(bin_folder):
    return {
        **os.environ,
        "PATH": bin_folder + os.pathsep + os.environ["PATH"],
        "SOURCE_DATE_EPOCH": EPOCH,
        "COLUMNS": "100",
        "MPLBACKEND": "Agg",
        "GNUTERM": "dumb",
    }


def run(command, folder, bin_folder):
    """Exit statuses of the last pipeline's stages, and standard error, of the command
    run with a terminal as standard output, as when it is pasted into one."""
    status_file = folder / ".pipestatus"
    script = f'{command}\necho "${{PIPESTATUS[@]}}" > {shlex.quote(str(status_file))}\n'
    terminal, screen = pty.openpty()
    with tempfile.TemporaryFile() as stderr:
        process = subprocess.Popen(
            ["bash", "-c", script],
            cwd=folder,
            env=environment(bin_folder),
            stdin=subprocess.DEVNULL,
            stdout=screen,
            stderr=stderr,
            start_new_session=True,
        )
        os.close(screen)
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            if select.select([terminal], [], [], 1)[0]:
                try:
                    if not os.read(terminal, 65536):
                        break
                except OSError:  # EIO: every writer closed the terminal
                    break
        os.close(terminal)
        try:
            process.wait(timeout=max(1, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            raise
        stderr.seek(0)
        errors = stderr.read().decode(errors="replace")
    statuses = [int(word) for word in status_file.read_text().split()] if status_file.exists() else [process.returncode]
    return statuses, errors


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """Small files under the names the examples use, made in this process: scans are
    gap-free maps of 128 × 96 points (the sample map has invalid points, which the
    spectrum refuses), profiles are the sample profile or short synthetic ones."""
    folder = tmp_path_factory.mktemp("inputs")
    (folder / "scans").mkdir()
    maps = ["scan", "a", "b", "c", "fault", "bore", "bedding-plane", "map", "scans/a", "scans/b"]
    for seed, name in enumerate(maps):
        fractal.synthesize_map((128, 96), (50e-6, 50e-6), 2.3, rq=10e-6, seed=seed).write(folder / f"{name}.x3p")
    for seed, name in enumerate(["rough", "smooth", "stylus-scan", "fossil"]):
        fractal.synthesize_profile(1000, 20e-6, 1.3, rq=10e-6, seed=seed).write(folder / f"{name}.x3p")
    anisotropy = (2.2, 1e-6, 2.5, 3e-6, 30.0)
    fractal.synthesize_map((128, 128), (10e-6, 10e-6), None, seed=6, anisotropy=anisotropy).write(folder / "lay.x3p")
    profile = rough.read(ROOT / "sample_profiles" / "rock-profile.tsv")
    for name in ["rock.x3p", "rock.tsv", "profile.tsv", "dektak.csv", "scan.csv"]:
        profile.write(folder / name, format="tsv" if name.endswith(".csv") else None)
    rough.read(folder / "scan.x3p").write(folder / "scan.gwy")
    for size, name in [(512, "dem.tif"), (512, "big.tif"), (1024, "national-dem.tif")]:
        fractal.synthesize_map((size, size), (1.0, 1.0), 2.3, rq=5.0, seed=size).write(folder / name)
    fault = fractal.synthesize_map((64, 64), (5.7e-3, 5.7e-3), 2.3, rq=1e-3, seed=9)  # as a LiDAR grid comes
    numpy.savez(folder / "fault.npz", z=fault.heights, dx=fault.spacing[0])
    (folder / "lab.html.j2").write_text('{% extends "report.html.j2" %}\n')
    return folder


_sessions = {}  # (source, the block's lines) -> [its folder, how many of its lines ran there]


def session(example, inputs, bin_folder, tmp_path_factory):
    """The folder of the example's block, with the block's earlier lines run in it
    (each once, when the examples run in order)."""
    key = (example.source, example.block)
    if key not in _sessions or _sessions[key][1] != len(example.before):
        folder = tmp_path_factory.mktemp("example")
        shutil.copytree(ROOT / "sample_profiles", folder / "sample_profiles")
        for entry in inputs.iterdir():  # the files the block names, so that *.x3p is what it says
            if re.search(rf"(^|[\s/'\"=]){re.escape(entry.name)}($|[\s/'\"])", example.block):
                copy = shutil.copytree if entry.is_dir() else shutil.copy
                copy(entry, folder / entry.name)
        for earlier in example.before:
            if not_runnable(earlier) is None:
                run(earlier, folder, bin_folder)
        _sessions[key] = [folder, len(example.before)]
    _sessions[key][1] += 1
    return _sessions[key][0]


def not_runnable(command):
    """Why the command cannot run here, or None."""
    for pattern, why in NOT_RUNNABLE:
        if re.search(pattern, command, re.M):
            return why
    program = missing_program(command)
    return f"needs {program}, which is not installed" if program else None


def test_every_command_is_collected():
    assert not UNLOADED, f"commands whose examples could not be collected: {UNLOADED}"


def test_an_error_shown_on_purpose_is_marked():
    shown = [(1, "$ rough info missing.x3p"), (2, "# exit status 2"), (3, "$ rough info scan.x3p  # exit status 0")]
    assert [example.status for example in block_commands("page", shown)] == [2, 0]


def test_examples_come_from_every_page():
    sources = {example.source for example in EXAMPLES}
    assert {"README.md", "docs/getting-started.rst", "docs/conventions.rst", "docs/cluster.rst"} <= sources
    assert {f"rough {name} --help" for name in main.COMMANDS if name not in UNLOADED} <= sources


def commands():
    """(prog, click command) of every command and subcommand that loads."""
    context = click.Context(main.cli)
    found = [("rough", main.cli)]
    for name in main.COMMANDS:
        if name not in UNLOADED:
            found.append((f"rough {name}", main.cli.get_command(context, name)))
    for prog, command in found:
        found += [(f"{prog} {name}", sub) for name, sub in getattr(command, "commands", {}).items()]
    return found


def test_command_pages_keep_examples_verbatim():
    """Each command page's text, as sphinx_click writes it from the help and docutils
    reads it with the docs' smartquotes setting, shows every example character for
    character: ``--cutoff`` stays two hyphens, quotes stay straight, and no glob or
    backslash is taken for markup."""
    sphinx_click = pytest.importorskip("sphinx_click.ext", reason="sphinx-click (the docs extra) makes the pages")
    from docutils.core import publish_parts

    conf = {"__file__": str(ROOT / "docs" / "conf.py")}
    exec((ROOT / "docs" / "conf.py").read_text(encoding="utf-8"), conf)
    for prog, command in commands():
        page = "\n".join(sphinx_click._format_description(click.Context(command, info_name=prog)))
        warnings = io.StringIO()
        settings = {"smart_quotes": conf.get("smartquotes", True), "warning_stream": warnings}
        body = publish_parts(page, writer="html", settings_overrides=settings)["body"]
        text = html.unescape(re.sub(r"<[^>]+>", "", body))
        assert not warnings.getvalue(), (prog, warnings.getvalue())
        for example in EXAMPLES:
            if example.source == f"{prog} --help":
                assert example.command in text, (prog, example.command)


@pytest.mark.slow  # about 160 processes of rough: two minutes of CPU
@pytest.mark.parametrize("example", EXAMPLES, ids=[example.name for example in EXAMPLES])
def test_example_runs_as_written(example, inputs, bin_folder, tmp_path_factory):
    folder = session(example, inputs, bin_folder, tmp_path_factory)
    why = not_runnable(example.command)
    if why:
        pytest.skip(why)
    statuses, stderr = run(example.command, folder, bin_folder)
    assert "Traceback" not in stderr, stderr
    *upstream, last = statuses
    assert last == example.status and all(status in (0, 141) for status in upstream), (statuses, stderr)
