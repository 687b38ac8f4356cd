"""Run ``rough COMMAND [SUBCOMMAND] --help`` for every command of the installed rough
(found from its click group, so a new command is covered without editing this file).
Usage: python help_all.py PATH/TO/rough"""

import subprocess
import sys

import click

from rough.cli.main import cli


def command_paths(group, context, prefix=()):
    for name in group.list_commands(context):
        command = group.get_command(context, name)
        yield (*prefix, name)
        if isinstance(command, click.Group):
            yield from command_paths(command, context, (*prefix, name))


def main(executable):
    context = click.Context(cli)
    failures = 0
    paths = [(), *command_paths(cli, context)]
    for path in paths:
        result = subprocess.run([executable, *path, "--help"], capture_output=True, text=True, check=False)
        ok = result.returncode == 0 and "Usage:" in result.stdout and not result.stderr
        failures += not ok
        print(f"{'ok  ' if ok else 'FAIL'} rough {' '.join(path)} --help".rstrip(), result.stderr.strip()[:200])
    if failures:
        sys.exit(f"{failures} of {len(paths)} help pages failed")
    print(f"all {len(paths)} help pages")


if __name__ == "__main__":
    main(sys.argv[1])
