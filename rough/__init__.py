"""rough: surface metrology on the command line and in notebooks.

    >>> import rough
    >>> scan = rough.read("scan.x3p")          # any supported format, sniffed from content
    >>> scan.heights.shape, scan.spacing        # metres; NaN marks invalid points
    >>> scan.write("scan.gsf")                  # format from the extension

The package imports numpy only when a surface is first touched, so that the
command line starts quickly.
"""

__version__ = "0.1.0"

__all__ = ["Surface", "Units", "__version__", "read"]


def __getattr__(name):
    if name in ("Surface", "Units"):
        from . import surface

        return getattr(surface, name)
    if name == "read":
        from .io import read

        return read
    raise AttributeError(f"module 'rough' has no attribute {name!r}")
