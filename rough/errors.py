"""The exceptions rough raises on purpose, and the exit status each one means."""


class RoughError(Exception):
    """A failure that is reported in one line; exit status 1.

    The base class of every exception rough raises on purpose. The command line
    prints its message as ``rough COMMAND: problem`` (no traceback) and exits with
    :attr:`exit_code`.

    Attributes
    ----------
    exit_code : int
        The command line's exit status for this failure: 1.

    See Also
    --------
    InputError : Bad input (exit status 2).

    Examples
    --------
    >>> import rough
    >>> rough.RoughError.exit_code
    1
    >>> issubclass(rough.InputError, rough.RoughError)
    True
    """

    exit_code = 1


class InputError(RoughError):
    """Bad input: an unreadable, malformed or unsuitable file or value; exit status 2.

    Raised for anything the user can fix by changing the input: a missing or
    malformed file, a surface that does not suit the operation (a map where a profile
    is needed, invalid points where the spectrum needs gap-free data), or a value out
    of range.

    Parameters
    ----------
    message : str
        What is wrong, in one line.
    filename : str, optional
        The output the message is about, where it is not the input (the command line
        then puts no input name in front of the message).

    Attributes
    ----------
    exit_code : int
        The command line's exit status for bad input: 2.
    filename : str or None
        As given.

    See Also
    --------
    rough.errors.FormatError : A file that does not follow its format.

    Examples
    --------
    >>> import rough
    >>> try:
    ...     rough.read("no-such-file.x3p")
    ... except rough.InputError as error:
    ...     print(error, "| exit status", error.exit_code)
    no-such-file.x3p: no such file | exit status 2
    """

    exit_code = 2

    def __init__(self, message, filename=None):
        super().__init__(message)
        self.filename = filename


class FormatError(InputError):
    """A file that does not follow its format.

    Readers raise it without the file name; :func:`rough.io.read` adds the name. It
    is an :class:`InputError`, so the command line exits with status 2.

    Attributes
    ----------
    exit_code : int
        2, as for every :class:`InputError`.

    Examples
    --------
    >>> import rough
    >>> from rough.errors import FormatError
    >>> try:
    ...     rough.read(b"\\x00\\x01 not a surface")
    ... except FormatError as error:
    ...     print(error)
    <bytes>: not a surface file rough can read (unrecognised binary data); rough reads al3d, bcr, di, ...
    """
