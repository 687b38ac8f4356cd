"""rough convert: from any readable format to any writable one."""

import click

from ..io import registry
from .options import crop_option, surface_input, surface_output
from .work_options import jobs_option


class WritesCommand(click.Command):
    """A command whose help ends with the formats rough writes, from the registry (read
    when the help is shown: the format modules load numpy)."""

    @property
    def epilog(self):
        titles = [registry.formats()[name].title for name in registry.writable()]
        return f"Writes {', '.join(titles[:-1])} and {titles[-1]}; reads every format of 'rough formats'."

    @epilog.setter
    def epilog(self, value):
        pass


@click.command(cls=WritesCommand, short_help="Convert between the formats rough reads and writes.")
@surface_input
@jobs_option
@crop_option
@surface_output
def convert(surface, input, output):
    """Read INPUT (default: standard input) in any format rough reads, and write it
    in the format given by -f or the output file's extension (X3P on standard
    output). Heights, spacing, origin, units, metadata and history are kept as far
    as the output format can hold them ('rough formats' says what each carries).

    \b
    Examples:
        rough convert dektak.csv -o scan.x3p
        cat scan.x3p | rough convert -f exr -o scan.exr
        rough convert scan.x3p -f tsv | gnuplot -e "plot '-' using 1:2 with lines"
        rough convert --crop 100m:300m,0:200m big.tif -o part.x3p
    """
    output.write(surface.derive("convert", {"input": input, "format": output.format}))
