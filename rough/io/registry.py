"""The format registry: every format module declares its facts once, in ``FORMAT``.

A format module (``rough/io/<module>.py``) holds ``FORMAT = Format(...)`` and a
``read(data, options)`` that turns a whole file's bytes into a :class:`~rough.Surface`;
it may add ``read_path(path, options)`` (formats read piecewise from disk, such as
GeoTIFF windows) and ``write(surface, stream)``. :data:`MODULES` lists the modules in
sniffing order. The sniffer, the readers and writers table, the ``-f`` choices,
``rough formats``, the docs' format table and the error messages all come from here.
"""

import dataclasses
import functools
import importlib
import os

from ..errors import FormatError

#: Format modules, in the order the sniffer asks them (specific magic before generic).
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
    "text",
)

#: What a format can carry, as ``Format.carries`` names it.
CARRIES = {
    "spacing": "lateral spacing",
    "units": "units",
    "metadata": "instrument metadata",
    "time": "acquisition time",
    "channels": "several channels",
    "layers": "several layers",
    "mask": "invalid-point mask",
    "history": "rough's history",
    "crs": "coordinate reference system",
}

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

    name: the short key (``-f`` choice, ``Surface.source_format``).
    title: what people call it (``"Digital Surf SUR"``).
    extensions: file name endings, lower case with the dot; the first is the one written.
    magic: byte strings a file starts with; ``(offset, bytes)`` pairs for magic further in.
    probe: ``probe(head) -> bool`` on the first :data:`HEAD` bytes, for formats whose
        magic is shared or absent (it is asked after the magic matched, if there is one).
    by_extension: the format has no reliable magic and is also chosen by its extension.
    writes: rough writes it.
    carries: keys of :data:`CARRIES`.
    library: the PyPI distribution its reader needs, if any (an extra of rough's).
    binary: a written file is binary (refused on a terminal).
    """

    name: str
    title: str
    extensions: tuple = ()
    magic: tuple = ()
    probe: object = None
    by_extension: bool = False
    writes: bool = False
    carries: tuple = ()
    library: str = None
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
def _modules():
    """``{format name: module}`` in sniffing order."""
    table = {}
    for module_name in MODULES:
        format_module = module(module_name)
        table[format_module.FORMAT.name] = format_module
    return table


@functools.cache
def formats():
    """Every format, ``{name: Format}`` in sniffing order."""
    return {name: format_module.FORMAT for name, format_module in _modules().items()}


def module_of(name):
    """The module that reads and writes format ``name``; KeyError for an unknown name."""
    return _modules()[name]


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
    table = formats().values()
    matched = next((facts for facts in table if facts.matches(head)), None)
    if matched is None:
        matched = next((facts for facts in table if facts.by_extension and extension in facts.extensions), None)
    if matched is None or (extension in UNREAD_EXTENSIONS and extension not in matched.extensions):
        raise FormatError(unrecognised(name))  # a zip, HDF5 or TIFF holding a format rough does not read
    return matched.name


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


def channel_list(names):
    """``"0 'ZSensor', 1 'Phase'"``: channels as ``info`` and messages list them."""
    return ", ".join(f"{index} {name!r}" for index, name in enumerate(names))


def channel_metadata(names, index):
    """The metadata a multi-channel reader records: the channel read and all of them."""
    return {"channel": names[index], "channels": channel_list(names)}


def table():
    """Every format as a dict: ``name``, ``title``, ``extensions``, ``read`` (always
    True), ``write``, ``carries`` (keys of :data:`CARRIES`), ``library`` and whether that
    library is ``installed``.

    >>> rows = {row["name"]: row for row in table()}
    >>> rows["x3p"]["write"], rows["x3p"]["extensions"]
    (True, ['.x3p'])
    """
    import importlib.util

    return [
        {
            "name": facts.name,
            "title": facts.title,
            "extensions": list(facts.extensions),
            "read": True,
            "write": facts.writes,
            "carries": list(facts.carries),
            "library": facts.library,
            "installed": facts.library is None or importlib.util.find_spec(facts.library) is not None,
        }
        for facts in formats().values()
    ]
