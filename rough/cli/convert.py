"""rough convert: from any readable format to any writable one."""

import click

from .options import surface_input, surface_output


@click.command(short_help="Convert between X3P, OpenEXR, GSF, TSV and NPY.")
@surface_input
@surface_output
def convert(surface, input, output):
    """Read INPUT (default: standard input) in any format rough reads, and write it
    in the format given by -f or the output file's extension (X3P on standard
    output). Heights, spacing, origin, units, metadata and history are kept as far
    as the output format can hold them (NPY keeps heights only; GSF and EXR store
    float32 heights).

    \b
    Examples:
        rough convert dektak.csv -o scan.x3p
        cat scan.x3p | rough convert -f exr -o scan.exr
        rough convert scan.x3p -f tsv | gnuplot -e "plot '-' using 1:2 with lines"
    """
    output.write(surface.derive("convert", {"input": input, "format": output.format}))
