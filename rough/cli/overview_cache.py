"""The overview that ``rough``, ``rough -h`` and ``rough --help`` print, kept in the
user's cache (``$XDG_CACHE_HOME/rough``, else ``~/.cache/rough``).

It is click's own text for the group (:func:`rough.cli.main.overview`), which lists the
built-in commands and the plugins' (``rough.commands`` entry points). Making it costs
click, the command modules and the entry-point scan, several times the start-up of
Python itself, so it is stored under a key that changes whenever the answer could:
rough's version, the interpreter, the width of the text, the modification time of every
folder on ``sys.path`` (installing or removing a package changes its site-packages
folder) and of the command modules (a change in a source checkout). Any failure to read
or write the cache only means the text is made again.
"""

import os
import sys
import zlib

from .. import __version__

KEPT = 32  # stored overviews kept per user, newest first (one per environment and width)


def stored_overview():
    """The overview stored for this environment and width, or None."""
    key = _key()
    try:
        with open(_path(key), encoding="utf-8") as stored:
            stored_key, _, text = stored.read().partition("\n")
    except (OSError, UnicodeError):
        return None
    return text if stored_key == key else None


def store_overview(text):
    """Keep ``text`` as the overview of this environment and width (quietly not, where
    the cache cannot be written)."""
    key = _key()
    path = _path(key)
    try:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        temporary = f"{path}.{os.getpid()}.tmp"
        with open(temporary, "w", encoding="utf-8") as stream:
            stream.write(f"{key}\n{text}")
        os.replace(temporary, path)
        _prune(os.path.dirname(path))
    except OSError:
        return


def _key():
    folders = [(folder, _modified(folder)) for folder in sys.path]
    here = os.path.dirname(__file__)
    commands = sorted((entry.name, entry.stat().st_mtime_ns) for entry in os.scandir(here) if entry.is_file())
    return repr((__version__, sys.executable, width(), folders, commands))


def _modified(folder):
    try:
        return os.stat(folder or ".").st_mtime_ns
    except OSError:
        return None


def _path(key):
    cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(cache, "rough", f"overview-{zlib.crc32(key.encode()):08x}")


def _prune(folder):
    stored = [entry for entry in os.scandir(folder) if entry.name.startswith("overview-")]
    for entry in sorted(stored, key=lambda entry: entry.stat().st_mtime_ns, reverse=True)[KEPT:]:
        os.unlink(entry.path)


def width():
    """The columns click formats the overview in: the terminal's (``COLUMNS`` first), at
    most 80, as click's ``HelpFormatter`` takes them."""
    try:
        columns = int(os.environ.get("COLUMNS", 0)) or os.get_terminal_size(sys.__stdout__.fileno()).columns
    except (AttributeError, ValueError, OSError):
        columns = 80
    return min(columns, 80)
