"""rough formats: the file formats rough reads and writes."""

import click

from .. import io
from .options import report_format
from .report import Report, emit


@click.command(short_help="The file formats rough reads and writes, and what each carries.")
@report_format
def formats(as_json, as_tsv):
    """List every format (those of installed plugins too): its key (for -f), the
    extensions, read/write, what it carries (spacing, units, metadata, acquisition
    time, channels, layers, mask, rough's history, CRS) and the library reading or
    writing it needs, if any.

    Input formats are recognised from the content; the extension decides only for
    the few formats without a magic number (PLU, NMS, IBW). Other instruments' files
    reach rough through Gwyddion: gwyddion --convert-to-gwy FILE, then read the .gwy.

    \b
    Examples:
        rough formats
        rough formats --json | jq -r '.formats[] | select(.write) | .name'
    """
    listing = sorted(io.registry.table(), key=lambda row: row["title"].casefold())
    title_width = max(len(row["title"]) for row in listing)
    extension_width = max(len(" ".join(row["extensions"])) for row in listing)
    rows = [
        (
            f"formats.{index}",
            row,
            "",
            f"{row['title']:<{title_width}}  {' '.join(row['extensions']):<{extension_width}}  "
            f"{'read/write' if row['write'] else 'read':<10}  "
            + (", ".join(io.registry.CARRIES.get(key, key) for key in row["carries"]) or "heights only")
            + _needs(row),
            row["name"],
        )
        for index, row in enumerate(listing)
    ]
    emit(Report(rows, {"formats": listing}), as_json, as_tsv)


def _needs(row):
    """``"  [needs h5py]"``, ``"  [writing needs gwyfile, not installed]"``: the library
    reading or writing needs, if any, and whether it is missing."""
    read, write = row["read_library"], row["write_library"]
    if read is None and write is None:
        return ""
    missing = "" if row["installed"] else ", not installed"
    if read is None:
        return f"  [writing needs {write}{missing}]"
    if write not in (None, read):
        return f"  [needs {read}, writing {write}{missing}]"
    return f"  [needs {read}{missing}]"
