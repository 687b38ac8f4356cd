"""Plugins: what other packages add to rough's registries through entry points.

A package adds a format, a device or a command by declaring an entry point in one of
:data:`GROUPS` (in its ``setup.cfg`` or ``pyproject.toml``), as rasterio's ``rio``
takes subcommands from ``rasterio.rio_commands``::

    [options.entry_points]
    rough.formats =
        toy = toy_rough.toy_format
    rough.devices =
        toy = toy_rough.toy_device
    rough.commands =
        toy = toy_rough.cli:toy

A format's value names a module laid out as ``rough/io``'s format modules are, a
device's a module laid out as ``rough/render``'s backends, a command's a click command
(``module:attribute``). Built-in names win over a plugin's.
"""

import functools

#: Entry-point group → what a plugin adds through it.
GROUPS = {
    "rough.formats": "a file format",
    "rough.devices": "a render device",
    "rough.commands": "a subcommand",
}


@functools.cache
def entry_points(group):
    """The entry points of ``group`` installed in this environment, ``{name: value}``
    sorted by name (``value`` as written: ``'module'`` or ``'module:attribute'``).

    >>> entry_points("rough.formats")   # none installed with rough itself
    {}
    """
    import importlib.metadata  # deferred, 30-40 ms: rough --help's overview, a text or unknown input, -f

    if group not in GROUPS:
        raise KeyError(f"unknown entry-point group {group!r}")
    found = importlib.metadata.entry_points(group=group)
    return {point.name: point.value for point in sorted(found, key=lambda point: point.name)}
