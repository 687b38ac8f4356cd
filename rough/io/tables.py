"""The registry's tables as constants, for code that wants a value rather than a call:
every format with its title, the formats rough writes, the binary ones among them, and
the extensions that choose a written format. Derived from :func:`rough.io.registry.formats`
(plugins included) when first used.

>>> from rough.io import EXTENSIONS, WRITABLE
>>> "x3p" in WRITABLE, EXTENSIONS[".x3p"]
(True, 'x3p')
"""

from . import registry

#: Every format: ``{key: title}``, in sniffing order.
FORMATS = {name: facts.title for name, facts in registry.formats().items()}
#: The formats rough writes.
WRITABLE = registry.writable()
#: The written formats that are binary (refused on a terminal).
BINARY = tuple(name for name in WRITABLE if registry.formats()[name].binary)
#: ``{extension: key}`` of the written formats.
EXTENSIONS = registry.extensions()
