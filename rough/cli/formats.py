"""rough formats: the file formats rough reads and writes."""

import click

from .options import report_format
from .report import Report, emit


@click.command(short_help="The file formats rough reads and writes, and what each carries.")
@report_format
def formats(as_json, as_tsv):
    """List every format: its key (for -f), the extensions, read/write, what it
    carries (spacing, units, metadata, acquisition time, channels, layers, mask,
    rough's history, CRS) and the library it needs, if any.

    Input formats are recognised from the content; the extension decides only for
    the few formats without a magic number (PLU, NMS, IBW). Other instruments' files
    reach rough through Gwyddion: gwyddion --convert-to-gwy FILE, then read the .gwy.

    \b
    Examples:
        rough formats
        rough formats --json | jq -r '.formats[] | select(.write) | .name'
    """
    from ..io.registry import CARRIES, table

    listing = sorted(table(), key=lambda row: row["title"].casefold())
    title_width = max(len(row["title"]) for row in listing)
    extension_width = max(len(" ".join(row["extensions"])) for row in listing)
    rows = [
        (
            f"formats.{index}",
            row,
            "",
            f"{row['title']:<{title_width}}  {' '.join(row['extensions']):<{extension_width}}  "
            f"{'read/write' if row['write'] else 'read':<10}  "
            + (", ".join(CARRIES[key] for key in row["carries"]) or "heights only")
            + (f"  [needs {row['library']}{'' if row['installed'] else ', not installed'}]" if row["library"] else ""),
            row["name"],
        )
        for index, row in enumerate(listing)
    ]
    emit(Report(rows, {"formats": listing}), as_json, as_tsv)
