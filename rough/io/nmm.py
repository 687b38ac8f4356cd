"""SIOS / TU Ilmenau nanomeasuring machine (NMM) line scans: a zip of a ``.dsc`` and a ``.dat`` file, read only.

The ``.dsc`` file describes the columns of the ``.dat`` file, one line each between dashed lines:
``index : date time : name : points : description`` (e.g. ``10 : 11-Jan-2024 23:49:11 : -Lz+Az : 20001 : Surface
height (-LZ+AZ)``). The ``.dat`` file holds one whitespace-separated row of numbers per point, one column per
``.dsc`` line, lengths in metres. rough reads the heights from ``-Lz+Az`` and the position along the scan from
``XY vector`` (the distance travelled in the xy plane, so a diagonal scan has its true length), or from ``Lx``
when that column is absent. The positions are not evenly spaced, so the profile is refused without ``--regrid``.
The first line's date is the acquisition time. Members whose names start with ``.`` or ``_`` (``__MACOSX``) are
ignored. Layout as in SurfaceTopography's ``NMM.py`` (commit 574e0f3) and Gwyddion's ``nmmxyz.c``; the newer
2-D "Scan procedure description file" layout is not read.
"""

import datetime
import io
import posixpath
import zipfile

import numpy as np

from ..errors import FormatError
from ..surface import Units
from . import limits, regrid
from .header import zip_names
from .registry import Format

FORMAT = Format(
    "nmm",
    "Nanomeasuring machine (SIOS NMM) profile",
    (".zip",),
    magic=(b"PK\x03\x04",),
    probe=lambda head: _probe(head),
    carries=("units", "metadata", "time"),
)

HEIGHT, POSITION, TABLE_X = "-Lz+Az", "XY vector", "Lx"
ZIP_ERRORS = (zipfile.BadZipFile, zipfile.LargeZipFile, NotImplementedError, RuntimeError, OSError, EOFError)


def _probe(head):
    """A zip whose member names (those the head reaches) include a ``.dsc`` file, or whose first member is a
    ``.dat`` file and no X3P ``main.xml`` is in sight."""
    names = [posixpath.basename(name).lower() for name in zip_names(head)]
    names = [name for name in names if name and not name.startswith((".", "_"))]
    if any(name.endswith(".dsc") for name in names):
        return True
    return bool(names) and names[0].endswith(".dat") and not any(name.endswith("main.xml") for name in names)


def read(data, options):
    try:
        archive = zipfile.ZipFile(io.BytesIO(bytes(data)))
        dsc_name, dat_name = _members(archive)
        dsc = _text(archive, dsc_name, len(data))
        dat = _text(archive, dat_name, len(data))
    except ZIP_ERRORS as error:
        raise FormatError(f"not a readable NMM zip archive ({error})") from None
    columns, date = _description(dsc)
    if any(column["index"] >= len(columns) for column in columns.values()):
        raise FormatError(f"NMM .dsc numbers a column past its {len(columns)} columns")
    table = _table(dat, len(columns))
    if table.shape[0] != columns[HEIGHT]["points"]:
        raise FormatError(f"NMM .dsc declares {columns[HEIGHT]['points']} points but the .dat holds {table.shape[0]}")
    position = POSITION if POSITION in columns else TABLE_X
    if position not in columns:
        raise FormatError(f"NMM .dsc names no position column ({POSITION!r} or {TABLE_X!r})")
    x, z = table[:, columns[position]["index"]], table[:, columns[HEIGHT]["index"]]
    if position == TABLE_X and x[-1] < x[0]:
        x = x[0] - x
    metadata = {"instrument": "Nanomeasuring machine (NMM)", "nmm_position": position}
    if date:
        metadata["date"] = date
    return regrid.profile_from_points(x - x.min(), z, options, units=Units("m", "m"), metadata=metadata)


def _members(archive):
    names = [name for name in archive.namelist() if not posixpath.basename(name).startswith((".", "_"))]
    dsc = [name for name in names if name.lower().endswith(".dsc")]
    dat = [name for name in names if name.lower().endswith(".dat")]
    if len(dsc) != 1 or len(dat) != 1:
        raise FormatError(f"an NMM zip holds one .dsc and one .dat file, not {len(dsc)} and {len(dat)}")
    return dsc[0], dat[0]


def _text(archive, name, packed):
    size = archive.getinfo(name).file_size
    if size > limits.cap("MAX_TEXT_BYTES"):
        raise FormatError(f"NMM member {name} is {limits.human(size)} of text, more than rough parses")
    limits.Budget(packed, name).add(size)
    return archive.read(name).decode("latin-1")


def _description(text):
    """``{name: {"index", "points"}}`` from the .dsc lines, and the first line's date in ISO 8601."""
    columns, date = {}, None
    for line in text.splitlines():
        parts = [part.strip() for part in line.split(" : ")]
        if len(parts) < 4 or not parts[0].isdigit():
            continue
        if not parts[3].isdigit():
            raise FormatError(f"NMM .dsc line {line.strip()[:60]!r} gives no point count")
        columns[parts[2]] = {"index": int(parts[0]), "points": int(parts[3])}
        date = date or _iso(parts[1])
    if HEIGHT not in columns:
        if "Scan procedure description file" in text:
            raise FormatError("NMM 2-D scan-procedure files are not supported; rough reads NMM line scans")
        raise FormatError(f"NMM .dsc names no height column {HEIGHT!r}")
    return columns, date


def _iso(text):
    try:
        return datetime.datetime.strptime(text, "%d-%b-%Y %H:%M:%S").isoformat()
    except ValueError:
        return None


def _table(text, count):
    try:
        values = np.array(text.split(), dtype=np.float64)
    except ValueError:
        raise FormatError("NMM .dat holds something other than numbers") from None
    if values.size % count:
        raise FormatError(f"NMM .dat holds {values.size} numbers, not a whole number of {count}-column rows")
    return values.reshape(-1, count)
