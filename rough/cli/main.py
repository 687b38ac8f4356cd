"""The ``rough`` command: a click group with one small module per subcommand.

:data:`COMMANDS` is the registry of built-in subcommands; a package adds one through
the entry-point group ``rough.commands`` (:func:`rough.plugins.entry_points`). A
subcommand's module is imported only when it is needed, and imports the library's
packages, which load their modules on first use, so ``rough --help`` starts without
numpy. Errors end in one
line on stderr (``rough COMMAND: FILE: problem``) and an exit status: 0 success, 2 bad
usage or bad input, 1 any other failure, 130 interrupted (Ctrl-C), 143 terminated
(SIGTERM), 129 hung up (SIGHUP); a closed downstream pipe ends the command quietly
(141, as a SIGPIPE death would).
"""

import contextlib
import errno
import importlib
import logging
import os
import signal
import sys
import traceback
import warnings

import click

from .. import __version__, errors, plugins, progress
from . import overview_cache
from .report import printable

#: The built-in subcommands: name -> ``module:attribute`` of a click command.
COMMANDS = {
    "info": "rough.cli.info:info",
    "convert": "rough.cli.convert:convert",
    "formats": "rough.cli.formats:formats",
    "detrend": "rough.cli.detrend:detrend",
    "features": "rough.cli.features:features",
    "synth": "rough.cli.synth:synth",
    "fit-fractal": "rough.cli.fit_fractal:fit_fractal",
    "resample": "rough.cli.resample:resample",
    "rose": "rough.cli.rose:rose",
    "show": "rough.cli.show:show",
    "render": "rough.cli.render:render",
    "experiment": "rough.cli.experiment:experiment",
    "map": "rough.cli.map:map_command",
    "report": "rough.cli.reports:report",
}

log = logging.getLogger("rough")
# OSErrors that say a name given on the command line is unusable: bad input, status 2
_BAD_NAME = {errno.ENAMETOOLONG, errno.ELOOP, errno.ENOTDIR, errno.EISDIR, errno.ENOENT, errno.ENXIO}
_invoked = []
_debug = [False]
current_input = []  # the input being worked on, when a command was given several


class PipeClosed(Exception):
    """The reader of standard output went away (raised instead of BrokenPipeError,
    which click would turn into exit status 1)."""


class Interrupted(Exception):
    """Ctrl-C during a command (raised instead of KeyboardInterrupt, which click answers
    with a blank line on standard error)."""


class Stopped(BaseException):
    """SIGTERM or SIGHUP, raised in the main thread so that temporary files are cleaned
    up on the way out, as after Ctrl-C (a BaseException: no ``except Exception`` stops it)."""

    def __init__(self, signum):
        super().__init__(signum)
        self.signum = signum


def _stop(signum, frame):
    raise Stopped(signum)


class LazyGroup(click.Group):
    """A group whose subcommands are imported on first use."""

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except BrokenPipeError as error:
            raise PipeClosed() from error
        except KeyboardInterrupt as error:  # past click, which would print a blank line first
            raise Interrupted() from error

    def get_help(self, ctx):
        text = super().get_help(ctx)
        overview_cache.store_overview(f"{text}\n")  # as click.echo prints it
        return text

    def list_commands(self, ctx):
        return sorted({*COMMANDS, *plugins.entry_points("rough.commands")})

    def get_command(self, ctx, name):
        if name in COMMANDS:
            return _take_global_options(_load(COMMANDS[name]))
        plugin = plugins.entry_points("rough.commands").get(name)
        if plugin is None:
            return None
        try:
            command = _load(plugin)
        except Exception as error:  # noqa: BLE001 -- any failure of a plugin's import leaves the rest working
            return BrokenCommand(name, plugin, f"{type(error).__name__}: {error}")
        if not isinstance(command, click.Command):
            return BrokenCommand(name, plugin, f"{type(command).__name__} is not a click command")
        return _take_global_options(command)

    def resolve_command(self, ctx, args):
        name, command, rest = super().resolve_command(ctx, args)
        _invoked.append(name)
        return name, command, rest


def _load(value):
    """The object that ``module:attribute`` names."""
    module, _, attribute = value.partition(":")
    return getattr(importlib.import_module(module), attribute)


class BrokenCommand(click.Command):
    """A plugin's subcommand that could not be loaded (as rasterio's ``BrokenCommand``):
    listed in ``rough --help`` as broken; run, it says why in one line and exits 1."""

    def __init__(self, name, value, reason):
        super().__init__(
            name,
            short_help=f"(broken plugin {value}: run it to see why)",
            add_help_option=False,
            context_settings={"ignore_unknown_options": True, "allow_extra_args": True},
        )
        self.reason = f"the plugin {value} cannot be loaded: {reason}"

    def invoke(self, ctx):
        raise click.ClickException(self.reason)


#: The options the group takes before a command's name and every command after it:
#: ``rough info -q scan.x3p`` is ``rough -q info scan.x3p``.
GLOBAL_OPTIONS = (
    (("-q", "--quiet"), {"is_flag": True, "help": "Print errors only, no warnings or notes."}),
    (("-v", "--verbose"), {"count": True, "help": "Print notes on what is done (-vv: more)."}),
    (("--debug",), {"is_flag": True, "help": "Show a traceback with every error."}),
)
_said = {"quiet": False, "verbose": 0, "debug": False}  # what the group and the command were given


def _take_global_options(command):
    """``command`` (and, for a group, its subcommands) taking :data:`GLOBAL_OPTIONS`
    after its name too, adding to what the group was given: each once, and none whose
    name the command (a plugin's) uses for something else."""
    taken = {name for param in command.params for name in param.opts}
    command.params += [
        click.Option(names, expose_value=False, callback=_said_after, **settings)
        for names, settings in GLOBAL_OPTIONS
        if not taken & set(names)
    ]
    for sub in getattr(command, "commands", {}).values():
        _take_global_options(sub)
    return command


def _said_after(ctx, param, value):
    if value:
        _said[param.name] = _said[param.name] + value if param.name == "verbose" else True
        configure(**_said)
    return value


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, "--version", prog_name="rough", message="%(prog)s %(version)s")
@click.option(*GLOBAL_OPTIONS[0][0], **GLOBAL_OPTIONS[0][1])
@click.option(*GLOBAL_OPTIONS[1][0], **GLOBAL_OPTIONS[1][1])
@click.option(*GLOBAL_OPTIONS[2][0], **GLOBAL_OPTIONS[2][1])
def cli(quiet, verbose, debug):
    """Surface metrology for rock, worn and machined surfaces.

    Every command reads a profile or height map from a file or standard input and
    writes to a file or standard output, so commands chain in pipes:

    \b
        rough convert scan.csv -o scan.x3p
        cat scan.x3p | rough info
        rough info --json scan.x3p | jq .valid_points

    Lengths, frequencies and forces name their unit (0.1545mm, 30.9um, 0.2/mm,
    1N); a number in a file that names no unit is in metres. Options -q, -v and
    --debug may also follow the command's name. Invalid points are NaN throughout.
    """
    _said.update(quiet=quiet, verbose=verbose, debug=debug)
    configure(quiet, verbose, debug)


def configure(quiet=False, verbose=0, debug=False):
    """Set what reaches standard error: errors only (``quiet``), notes (``verbose``
    1 or 2), tracebacks (``debug``); progress bars unless ``quiet``."""
    level = logging.ERROR if quiet else (logging.WARNING, logging.INFO, logging.DEBUG)[min(verbose, 2)]
    handler = logging.StreamHandler(sys.stderr) if sys.stderr else logging.NullHandler()
    handler.setFormatter(_Formatter())
    handler.setLevel(level)
    log.handlers[:] = [handler]
    log.setLevel(min(level, logging.WARNING))  # warnings reach --json's "warnings" even with -q
    log.propagate = False
    progress.configure(not quiet)
    _debug[0] = _debug[0] or debug


def _warn_in_one_line(message, category, filename, lineno, file=None, line=None):
    """A library's Python warning, as one 'warning:' line like rough's own."""
    log.warning(str(message).splitlines()[0] if str(message) else category.__name__)


class _Formatter(logging.Formatter):
    def format(self, record):
        kind = "warning: " if record.levelno >= logging.WARNING else ""
        return printable(f"{_prefix()}: {kind}{record.getMessage()}")


def _prefix():
    command = f"rough {_invoked[-1]}" if _invoked else "rough"
    return f"{command}: {current_input[0]}" if current_input else command


def main(args=None):
    """Entry point: run the command line and exit with its status."""
    args = sys.argv[1:] if args is None else list(args)
    sys.exit(run(args))


def _help():
    """Bare ``rough``: the overview on standard output, status 0."""
    click.echo(overview())
    return 0


def overview():
    """The text of ``rough --help`` (at the terminal's width, up to 78 columns)."""
    with click.Context(cli, info_name="rough", **cli.context_settings) as ctx:
        return cli.get_help(ctx)


def run(args):
    """Run the command line with ``args``; return the exit status. SIGTERM and SIGHUP
    end it as Ctrl-C does, cleaning up (status 143 and 129)."""
    _open_standard_descriptors()
    previous = {}
    for signum in {signal.SIGTERM, getattr(signal, "SIGHUP", signal.SIGTERM)}:
        with contextlib.suppress(ValueError):  # not the main thread: leave the signals alone
            if signal.getsignal(signum) == signal.SIG_DFL:  # nohup's SIG_IGN stays
                previous[signum] = signal.signal(signum, _stop)
    try:
        return _run(args) if args or "_ROUGH_COMPLETE" in os.environ else _help()
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def _run(args):
    debug = _debug[0] = "--debug" in args
    # numpy's RuntimeWarnings (invalid value, overflow, mean of empty slice) are noise on a
    # command line: rough announces the NaN and infinities it produces itself
    warnings.filterwarnings("ignore", category=RuntimeWarning)
    warnings.showwarning = _warn_in_one_line
    try:
        result = cli.main(args=args, prog_name="rough", standalone_mode=False)
        _flush_stdout()
        return result if isinstance(result, int) else 0
    except Stopped as stopped:
        say("hung up" if stopped.signum == getattr(signal, "SIGHUP", None) else "terminated")
        return 128 + stopped.signum
    except click.exceptions.Exit as done:
        return done.exit_code
    except click.UsageError as error:
        command = f" {_invoked[-1]}" if _invoked else ""
        say(f"{error.format_message()} (see 'rough{command} --help')")
        return 2
    except click.ClickException as error:
        say(error.format_message())
        return error.exit_code
    except (click.Abort, KeyboardInterrupt, Interrupted):
        say("interrupted")
        return 130
    except (PipeClosed, BrokenPipeError):
        _silence_stdout()
        return 141
    except Exception as error:  # noqa: BLE001 -- the last resort: say what failed, in one line
        message, status = failure(error, debug)
        say(message)
        return status


def failure(error, debug=None):
    """``(message, exit status)`` for an exception that ends a command (or, with several
    inputs, one input's work); with ``debug`` the traceback goes to standard error."""
    if _debug[0] if debug is None else debug:
        traceback.print_exception(error, file=sys.stderr)
    if isinstance(error, errors.RoughError):
        return str(error), error.exit_code
    if isinstance(error, MemoryError):
        return "out of memory: the surface is too large for this machine (crop it, or resample it coarser)", 1
    if isinstance(error, OSError):
        where = f"{error.filename}: " if error.filename else ""
        return f"{where}{error.strerror or error}", 2 if error.filename and error.errno in _BAD_NAME else 1
    return f"internal error: {type(error).__name__}: {error} (run with --debug for details)", 1


def note(message):
    """Print ``rough COMMAND: message`` on standard error, unless ``-q``."""
    if not _said["quiet"]:
        say(message)


def say(message):
    """Print ``rough COMMAND: message`` on standard error."""
    if sys.stderr is None:  # closed: the message is lost, but never sent to standard output
        return
    try:
        print(printable(f"{_prefix()}: {message}"), file=sys.stderr, flush=True)
    except (OSError, ValueError):
        pass


def _open_standard_descriptors():
    """Point closed descriptors 0-2 at /dev/null, so that no file rough opens takes their
    number and receives what a library writes there (sys.stdin/stdout/stderr stay None)."""
    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
        except OSError:
            with contextlib.suppress(OSError):
                opened = os.open(os.devnull, os.O_RDWR)
                if opened != fd:
                    os.dup2(opened, fd)
                    os.close(opened)


def _flush_stdout():
    """A failure to write the last of the output is the command's failure."""
    try:
        if sys.stdout is not None:
            sys.stdout.flush()
    except BrokenPipeError:
        raise
    except OSError as error:
        raise OSError(error.errno, error.strerror, "standard output") from error


def _silence_stdout():
    """After EPIPE, point stdout at /dev/null so that the interpreter's final flush
    does not print a second error."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass
