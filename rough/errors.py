"""The exceptions rough raises on purpose, and the exit status each one means."""


class RoughError(Exception):
    """A failure that is reported in one line; exit status 1."""

    exit_code = 1


class InputError(RoughError):
    """Bad input: an unreadable, malformed or unsuitable file or value; exit status 2."""

    exit_code = 2


class FormatError(InputError):
    """A file that does not follow its format. Readers raise it without the file name;
    :func:`rough.io.read` adds the name."""
