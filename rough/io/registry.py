"""The format registry: every format module declares its facts once, in ``FORMAT``.

A format module (``rough/io/<module>.py``) holds ``FORMAT = Format(...)`` and a
``read(data, options)`` that turns a whole file's bytes into a :class:`~rough.Surface`;
it may add ``read_path(path, options)`` (formats read piecewise from disk, such as
GeoTIFF windows) and ``write(surface, stream)``. :data:`MODULES` lists the built-in
modules in sniffing order. The sniffer, the readers and writers table, the ``-f``
choices, ``rough formats``, the docs' format table and the error messages all come
from :func:`formats`.

Plugins: another package adds a format with a module laid out the same way, named
by an entry point of the group ``rough.formats`` (:func:`rough.plugins.entry_points`).
The sniffer asks the plugins after the built-in formats of :data:`MODULES` and before
the generic fallbacks of :data:`FALLBACKS` (text, which takes any plain text), in the
order of their entry-point names. A built-in name wins over a plugin's; a plugin that
fails to import, or declares no ``FORMAT`` and ``read``, is left out with a one-line
warning naming it.
"""

import dataclasses
import functools
import importlib
import importlib.util
import logging
import os
import re

from ..errors import FormatError
from ..plugins import entry_points

log = logging.getLogger("rough")

#: Built-in format modules, in the order the sniffer asks them (specific magic before generic).
MODULES = (
    "xlsx",
    "nmm",
    "npz",
    "x3p",
    "exr",
    "gsf",
    "npy",
    "sdf",
    "al3d",
    "gwy",
    "sur",
    "mnt",
    "frt",
    "tmd",
    "metropro",
    "opd",
    "opdx",
    "nms",
    "zon",
    "di",
    "bcr",
    "mi",
    "nid",
    "wsxm",
    "hdf5",
    "netcdf",
    "jpk",
    "ps",
    "geotiff",
    "ibw",
    "plu",
)

#: Built-in modules that take what no other format claims, asked last (after plugins).
FALLBACKS = ("text",)

#: What a format can carry, as ``Format.carries`` names it.
CARRIES = {
    "spacing": "lateral spacing",
    "exact-grid": "exact spacing and origin",
    "units": "units",
    "metadata": "instrument metadata",
    "time": "acquisition time",
    "channels": "several channels",
    "layers": "several layers",
    "mask": "invalid-point mask",
    "history": "rough's history",
    "crs": "coordinate reference system",
    "tiles": "maps read a window at a time (larger than memory)",
}

#: What names a height channel, in any reader's channel names or titles: a height,
#: topography, a z axis or sensor, a surface (not a Kelvin probe's surface potential) or
#: elevation (model), or ``z`` as a word (split at anything not a letter: ``Z``,
#: ``Z_grid``, ``z-data``).
HEIGHT_NAME = re.compile(
    r"height|topo|z[- ]?axis|z[- ]?sensor|surface(?![- _]?potential)|elevation|(?<![a-z])(z|dem)(?![a-z])",
    re.IGNORECASE,
)

#: Vendor extensions rough does not read: name → instrument or program.
UNREAD_EXTENSIONS = {
    ".vk4": "Keyence VK4",
    ".vk6": "Keyence VK6",
    ".vk3": "Keyence VK3",
    ".lext": "Olympus LEXT",
    ".oir": "Olympus OIR",
    ".poir": "Olympus POIR",
    ".os3d": "Olympus OS3D",
    ".zmg": "Zygo ZMG",
    ".sxm": "Nanonis SXM",
    ".sm4": "RHK SM4",
    ".mpp": "Nanonis/Createc",
    ".datx": "Zygo DATX",
    ".plux": "Sensofar PLUX",
    ".lsm": "Zeiss LSM",
}


@dataclasses.dataclass(frozen=True)
class Format:
    """The facts of one file format.

    Attributes
    ----------
    name : str
        The short key (``-f`` choice, ``Surface.source_format``).
    title : str
        What people call it (``"Digital Surf SUR"``).
    extensions : tuple of str
        File name endings, lower case with the dot; the first is the one written.
    magic : tuple
        Byte strings a file starts with; ``(offset, bytes)`` pairs for magic further in.
    probe : callable, optional
        ``probe(head) -> bool`` on the first :data:`HEAD` bytes, for formats whose magic
        is shared or absent (it is asked after the magic matched, if there is one).
    by_extension : bool
        The format has no reliable magic and is also chosen by its extension.
    writes : bool
        rough writes it.
    writes_profiles : bool
        rough writes profiles in it too, not only maps.
    height_type : str
        The type a written file holds its heights in (``"float32"``: they come back
        rounded to float32).
    carries : tuple of str
        Keys of :data:`CARRIES`.
    read_library, write_library : str or None
        The module reading (writing) needs beyond rough's core, if any (an extra of
        rough's, :data:`rough.extras.EXTRAS`).
    binary : bool
        A written file is binary (refused on a terminal).
    """

    name: str
    title: str
    extensions: tuple = ()
    magic: tuple = ()
    probe: object = None
    by_extension: bool = False
    writes: bool = False
    writes_profiles: bool = True
    height_type: str = "float64"
    carries: tuple = ()
    read_library: str = None
    write_library: str = None
    binary: bool = True

    def matches(self, head):
        if self.magic and not any(_starts(head, magic) for magic in self.magic):
            return False
        if self.probe is not None:
            return bool(self.probe(head))
        return bool(self.magic)


HEAD = 1 << 16


def _starts(head, magic):
    offset, magic = magic if isinstance(magic, tuple) else (0, magic)
    return head[offset : offset + len(magic)] == magic


@functools.cache
def _built_in():
    """``{format name: module}`` of :data:`MODULES` then :data:`FALLBACKS`: what a file
    a built-in format claims needs, without looking for plugins."""
    return {format_module.FORMAT.name: format_module for format_module in map(module, (*MODULES, *FALLBACKS))}


@functools.cache
def _modules():
    """``{format name: module}`` in sniffing order: :data:`MODULES`, the plugins,
    :data:`FALLBACKS`."""
    first = [module(name) for name in MODULES]
    last = [module(name) for name in FALLBACKS]
    taken = set(_built_in())
    plugins = []
    for point, value in entry_points("rough.formats").items():
        plugin = _plugin(point, value)
        if plugin is not None and plugin.FORMAT.name in taken:
            owner = "rough has" if plugin.FORMAT.name in _built_in() else "an earlier plugin has"
            log.warning("format plugin %s (%s) left out: %s a format named %r", point, value, owner, plugin.FORMAT.name)
        elif plugin is not None:
            taken.add(plugin.FORMAT.name)
            plugins.append(plugin)
    return {format_module.FORMAT.name: format_module for format_module in (*first, *plugins, *last)}


def _plugin(point, value):
    """The module a ``rough.formats`` entry point names, or None (with a one-line
    warning) when it fails to import or is not laid out as a format module."""
    try:
        plugin = importlib.import_module(value.partition(":")[0])
    except Exception as error:  # noqa: BLE001 -- any failure of a third-party import leaves the plugin out
        log.warning("format plugin %s (%s) left out: %s: %s", point, value, type(error).__name__, error)
        return None
    if not isinstance(getattr(plugin, "FORMAT", None), Format) or not callable(getattr(plugin, "read", None)):
        log.warning("format plugin %s (%s) left out: it declares no FORMAT = Format(...) and read()", point, value)
        return None
    return plugin


@functools.cache
def formats():
    """Every format, ``{name: Format}`` in sniffing order."""
    return {name: format_module.FORMAT for name, format_module in _modules().items()}


def module_of(name):
    """The module that reads and writes format ``name``; KeyError for an unknown name."""
    return _built_in()[name] if name in _built_in() else _modules()[name]


def module(module_name):
    return importlib.import_module(f"rough.io.{module_name}")


def writable():
    return tuple(name for name, facts in formats().items() if facts.writes)


def extensions():
    """``{extension: format name}`` for the formats rough writes."""
    table = {}
    for name, facts in formats().items():
        for extension in facts.extensions if facts.writes else ():
            table.setdefault(extension, name)
    return table


def sniff(head, name=None):
    """The format name of a file from its first bytes (and, for formats without a
    magic number, its name's extension). Raises FormatError naming what rough reads."""
    head, extension = bytes(head[:HEAD]), _extension(name)
    built_in = (module(module_name).FORMAT for module_name in MODULES)
    matched = next((facts for facts in built_in if facts.matches(head)), None)
    if matched is None:  # plugins come after the built-ins: looked for only now
        table = formats().values()
        matched = next((facts for facts in table if facts.matches(head)), None)
    if matched is None:
        matched = next((facts for facts in table if facts.by_extension and extension in facts.extensions), None)
    if matched is not None and extension in UNREAD_EXTENSIONS and extension not in matched.extensions:
        # a zip, HDF5 or TIFF container holding a vendor's format: only a plugin may read it
        matched = next((facts for facts in formats().values() if _claims(facts, head, extension)), None)
    if matched is None:
        raise FormatError(unrecognised(name))
    return matched.name


def _claims(facts, head, extension):
    return extension in facts.extensions and (facts.by_extension or facts.matches(head))


def unrecognised(name=None):
    """The message for a file no format claims."""
    extension = _extension(name)
    if extension in UNREAD_EXTENSIONS:
        return (
            f"{UNREAD_EXTENSIONS[extension]} ({extension}) is not a format rough reads yet; "
            "convert it with Gwyddion (gwyddion --convert-to-gwy) and read the .gwy"
        )
    return (
        f"not a surface file rough can read (unrecognised binary data); rough reads {', '.join(sorted(formats()))} "
        "(rough formats describes them), and Gwyddion's other formats once converted (gwyddion --convert-to-gwy)"
    )


def _extension(name):
    if not name or name in ("-", "<stdin>", "<bytes>", "<stream>"):
        return ""
    base = os.path.basename(os.fspath(name)).lower()
    if base.endswith(".gz"):
        base = base[:-3]
    return os.path.splitext(base)[1]


def choose_channel(names, wanted, default=0):
    """Index of the channel ``wanted`` (a name, or a number counted from 0) among
    ``names``; ``default`` when nothing is wanted. Raises FormatError listing the
    channels when there is no such channel.

    >>> choose_channel(["ZSensor", "Phase", "Height"], "height")
    2
    >>> choose_channel(["ZSensor", "Phase"], "1")
    1
    """
    if wanted is None:
        return default
    text = str(wanted).strip()
    if text.lstrip("-").isdigit():
        index = int(text)
        if 0 <= index < len(names):
            return index
    else:
        folded = [name.casefold() for name in names]
        if text.casefold() in folded:
            return folded.index(text.casefold())
    raise FormatError(f"no channel {wanted!r}; the file holds {channel_list(names)}")


def names_height(name):
    """Whether a channel's name or title says it holds heights (:data:`HEIGHT_NAME`).

    >>> [names_height(name) for name in ("ZSensor", "Z_grid", "Topography", "Phase", "Surface potential")]
    [True, True, True, False, False]
    """
    return bool(HEIGHT_NAME.search(name or ""))


def channel_list(names):
    """``"0 'ZSensor', 1 'Phase'"``: channels as ``info`` and messages list them."""
    return ", ".join(f"{index} {name!r}" for index, name in enumerate(names))


def channel_metadata(names, index):
    """The metadata a multi-channel reader records: the channel read and all of them."""
    return {"channel": names[index], "channels": channel_list(names)}


def describe(format_name):
    """What people call a format (``"Digital Surf SUR"``), from its key."""
    built_in = _built_in().get(format_name)
    facts = built_in.FORMAT if built_in else formats().get(format_name)
    return facts.title if facts else format_name


def table():
    """Every format as a dict: ``name``, ``title``, ``extensions``, ``read`` (always
    True), ``write``, ``carries`` (keys of :data:`CARRIES`), ``read_library`` and
    ``write_library`` (the modules reading and writing need beyond rough's core, or
    None) and whether they are ``installed``.

    >>> rows = {row["name"]: row for row in table()}
    >>> rows["x3p"]["write"], rows["x3p"]["extensions"]
    (True, ['.x3p'])
    >>> rows["gwy"]["read_library"], rows["gwy"]["write_library"]
    (None, 'gwyfile')
    """
    return [
        {
            "name": facts.name,
            "title": facts.title,
            "extensions": list(facts.extensions),
            "read": True,
            "write": facts.writes,
            "carries": list(facts.carries),
            "read_library": facts.read_library,
            "write_library": facts.write_library,
            "installed": all(_installed(library) for library in (facts.read_library, facts.write_library)),
        }
        for facts in formats().values()
    ]


def _installed(library):
    return library is None or importlib.util.find_spec(library) is not None
