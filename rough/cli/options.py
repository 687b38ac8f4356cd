"""Options shared by the subcommands, as decorators (in the manner of rasterio's rio).

``surface_input`` adds INPUT… (default ``-``) and the read options and calls the
command once per input with a :class:`~rough.Surface`; ``surface_output`` adds
``-o/--output`` and ``-f/--format`` and hands it an :class:`Output` that writes a
surface there; ``report_format`` adds ``--json``/``--tsv``. A command made with
``cls=Command`` answers an option spelling that rough 0.14 removed (:data:`RENAMED`)
with a usage error that names the new one.

Lengths, frequencies and physical quantities name their unit (``0.1545mm``,
``0.2/mm``, ``20mm/s``); zero needs none. rough 0.12 and 0.13 read a bare number in
the option's old default unit (mm, per mm, the quantity's), with a warning; since
rough 0.14 it is refused, in one line that shows the unit (:func:`bare_number`).

Every number an option takes is range-checked here, by its type: it must be finite
(NaN and infinities refused), positive where the option says so, and of a plausible
size for what it measures (:data:`LENGTHS`, :data:`QUANTITIES`), so that no later
square, reciprocal or grid of points overflows, underflows or asks for more memory
than exists. A new option gets these checks by using these types
(:class:`FloatRange`, not click's, which lets NaN through).
"""

import dataclasses
import functools
import logging
import math
import os
import sys

import click
from click.shell_completion import CompletionItem

from .. import errors, extras, fractal, io, metrology, units
from ..io import registry
from . import work_options
from .batch import check_inputs, read_named, run_each, stem_name
from .targets import FIGURE, TABLE, TRACE, check_target, side_file  # noqa: F401 -- the commands' options

log = logging.getLogger("rough")
#: The last release that read a bare number in the option's old unit (with a warning);
#: rough 0.14 refuses it.
READ_UNTIL = "0.13"

#: The smallest and largest length (metres) an option takes: 1 pm (below an atom's
#: size) and 10 000 km (a planet's elevation model, a UTM northing); zero where an
#: option allows it.
LENGTHS = (1e-12, 1e7)
#: The smallest and largest sampling interval, as a surface takes (rough.surface.SPACING_RANGE).
SPACINGS = (1e-12, 1e6)
#: The smallest (non-zero) and largest magnitude, in SI units, of each quantity.
QUANTITIES = {
    "force": (1e-6, 1e4),  # 1 µN … 10 kN
    "stiffness": (1e-3, 1e9),  # 1 N/km … 1 N/nm
    "damping": (1e-9, 1e6),  # N·s/m
    "mass": (1e-9, 1e3),  # 1 µg … 1 t
    "speed": (1e-9, 1e3),  # 1 nm/s … 1 km/s
    "time": (1e-6, 1e6),  # 1 µs … 11.6 days
    "rate": (1e-3, 1e6),  # Hz
}


def _refuse_outside(type_, number, bounds, value, param, ctx, what, show, zero=False):
    """Fail unless ``number`` is finite and ``bounds[0] <= |number| <= bounds[1]``
    (or zero, where ``zero`` allows it)."""
    if number == 0 and zero:
        return number
    if not (math.isfinite(number) and bounds[0] <= abs(number) <= bounds[1]):
        kind = "be 0 or lie" if zero else "be positive, and lie" if number <= 0 else "lie"
        type_.fail(f"{value!r}: {what} must {kind} between {show(bounds[0])} and {show(bounds[1])}", param, ctx)
    return number


def _length(metres):
    return units.format_length(metres, 6)


def _frequency(per_metre):
    return units.format_quantity(per_metre, "1/m", 6)


def bare_number(value, flag, unit):
    """Refuse ``value`` if it is a number that names no unit (zero needs none): rough
    0.12 and 0.13 read it in the option ``flag``'s old default ``unit`` (``mm``,
    ``/mm``, ``mm/s`` …), with a warning; since 0.14 it is a one-line usage error (exit
    status 2) that shows the unit to write."""
    if units.is_bare(value) and float(value) != 0:
        number = str(value).strip()
        said = f"per {unit[1:]}" if unit.startswith("/") else unit
        raise click.UsageError(
            f"{f'{flag} ' if flag else ''}{number}: give a unit, e.g. {number}{unit} "
            f"(bare numbers were read as {said} until rough {READ_UNTIL})"
        )


def _flag(param):
    """The option's longest name, as people type it (None for no option)."""
    return param.opts[-1] if param is not None and param.opts else None


#: Option spellings that rough 0.12 renamed and 0.14 removed, and resample's
#: ``--input-spacing``, which 0.14 made ``--spacing`` as on every other command:
#: (command, old spelling) → (new spelling, the release that renamed it).
RENAMED = {
    ("synth", "--spacing"): ("--step", "0.12"),
    ("synth", "--rolloff"): ("--rolloff-wavelength", "0.12"),
    ("resample", "--input-spacing"): ("--spacing", "0.14"),
    ("experiment design", "--spacing"): ("--step", "0.12"),
    ("experiment design", "--synthesis-spacing"): ("--synthesis-step", "0.12"),
    ("rose", "--step"): ("--angle-step", "0.12"),
    ("show", "-o"): ("--plot", "0.12"),
    ("show", "--output"): ("--plot", "0.12"),
}


class Command(click.Command):
    """A click command that answers an old spelling of :data:`RENAMED` with one usage
    line naming the new one (``--spacing was renamed --step in rough 0.12``) instead of
    click's bare "No such option" (``@click.command(cls=Command)``)."""

    def parse_args(self, ctx, args):
        try:
            return super().parse_args(ctx, args)
        except click.NoSuchOption as error:
            names, context = [], ctx
            while context.parent is not None:  # the command's path below ``rough``
                names.insert(0, context.info_name)
                context = context.parent
            new = RENAMED.get((" ".join(names) or ctx.info_name, error.option_name))
            if new is None:
                raise
            message = f"{error.option_name} was renamed {new[0]} in rough {new[1]}"
            raise click.NoSuchOption(error.option_name, message, ctx=ctx) from None


class FloatRange(click.FloatRange):
    """click's FloatRange, refusing NaN (which passes every comparison) and infinities."""

    def convert(self, value, param, ctx):
        number = super().convert(value, param, ctx)
        if not math.isfinite(number):
            self.fail(f"{value!r} is not a finite number", param, ctx)
        return number


def plot_option(help):
    """``--plot FILE``; checks that matplotlib (the ``plot`` extra) is installed and
    that the figure can be written there (:func:`check_target`) before any work starts."""

    def needs_matplotlib(ctx, param, value):
        if value is not None:
            extras.require("matplotlib")
            check_target(value, param, FIGURE)
        return value

    return click.option("--plot", metavar="FILE", callback=needs_matplotlib, help=help)


class LengthType(click.ParamType):
    """A length with a unit (``0.1545mm``, ``30.9um``, ``2e-3m``) → metres; a position,
    of either sign, up to 10 000 km from the origin."""

    name = "LENGTH"

    def convert(self, value, param, ctx):
        if isinstance(value, float):
            return value
        bare_number(value, _flag(param), "mm")
        try:
            length = units.parse_length(value)
        except errors.InputError as error:
            self.fail(str(error), param, ctx)
        return self.checked(length, value, param, ctx)

    def checked(self, length, value, param, ctx):
        """``length`` if it is in this type's range; a failure otherwise."""
        if not (abs(length) <= LENGTHS[1] and (length == 0 or abs(length) >= LENGTHS[0])):
            near, far = _length(LENGTHS[0]), _length(LENGTHS[1])
            self.fail(f"{value!r}: a position must be 0 or lie between {near} and {far} from the origin", param, ctx)
        return length


class PositiveLengthType(LengthType):
    """A length that must be positive (a spacing, cut-off, size, resolution …), from
    1 pm to 10 000 km (:data:`LENGTHS`)."""

    what, bounds = "a length", LENGTHS

    def checked(self, length, value, param, ctx):
        if not length > 0:
            self.fail(f"{value!r}: {self.what} must be positive", param, ctx)
        return _refuse_outside(self, length, self.bounds, value, param, ctx, self.what, _length)


class SpacingType(PositiveLengthType):
    """``DX`` or ``DX,DY`` → a tuple of metres, each within :data:`SPACINGS`."""

    name = "DX[,DY]"
    what, bounds = "a spacing", SPACINGS

    def convert(self, value, param, ctx):
        if isinstance(value, tuple):
            return value
        parts = str(value).split(",")
        if len(parts) > 2:
            self.fail(f"{value!r}: give one or two positive lengths, e.g. 1um or 1um,2um", param, ctx)
        return tuple(super(SpacingType, self).convert(part, param, ctx) for part in parts)


class QuantityType(click.ParamType):
    """A physical quantity with a unit (``1.28N/mm``, ``20mm/s``, ``1.85g``) → SI; a
    bare number is refused (until rough 0.13 it was in ``default_unit``). Zero (unless
    ``positive``) or a magnitude within :data:`QUANTITIES` for its kind (and at most
    ``most``, if given)."""

    def __init__(self, kind, default_unit, positive=False, most=None):
        self.kind, self.default_unit, self.positive = kind, default_unit, positive
        self.bounds = (QUANTITIES[kind][0], QUANTITIES[kind][1] if most is None else most)
        self.name = kind.upper()

    def convert(self, value, param, ctx):
        if isinstance(value, float):
            return value
        bare_number(value, _flag(param), self.default_unit)
        try:
            quantity = units.parse_quantity(value, self.kind)
        except errors.InputError as error:
            self.fail(str(error), param, ctx)
        if quantity < 0:
            self.fail(f"{value!r}: must not be negative", param, ctx)
        what = f"a {self.kind}"
        return _refuse_outside(self, quantity, self.bounds, value, param, ctx, what, self.show, not self.positive)

    def show(self, quantity):
        """``quantity`` (SI) in this option's unit."""
        return units.format_unit(quantity, self.kind, 6)


#: The names of rough.metrology.PRESETS (the tip presets), kept here so that --help does
#: not load numpy (tests/test_option_ranges.py checks the two agree).
TIP_PRESETS = ("needle", "fingernail", "fingertip")


class TipType(PositiveLengthType):
    """A tip radius: a length, or a preset of :data:`rough.metrology.PRESETS`
    (``needle`` 0.05 mm, ``fingernail`` 0.5 mm, ``fingertip`` 8 mm) → metres."""

    name = "|".join(("RADIUS", *TIP_PRESETS))
    what = "a tip radius"

    def shell_complete(self, ctx, param, incomplete):
        return [CompletionItem(name) for name in TIP_PRESETS if name.startswith(incomplete)]

    def convert(self, value, param, ctx):
        if isinstance(value, str) and value.strip().lower() in TIP_PRESETS:
            return metrology.PRESETS[value.strip().lower()]
        return super().convert(value, param, ctx)


class DirectionType(click.ParamType):
    """A direction in the map's plane: ``x`` (along the rows), ``y`` (along the columns),
    or an angle counter-clockwise from +x in degrees (``30``, ``30deg``, ``-45°``) →
    ``"x"``, ``"y"`` or radians in [0, π)."""

    name = "x|y|ANGLE"

    def convert(self, value, param, ctx):
        if not isinstance(value, str):
            return value
        text = value.strip().lower()
        if text in ("x", "y"):
            return text
        number = text.removesuffix("°").removesuffix("deg").strip()
        try:
            degrees = float(number)
        except ValueError:
            self.fail(f"{value!r}: give x, y or an angle in degrees (e.g. 30 or 30deg)", param, ctx)
        if not math.isfinite(degrees) or abs(degrees) > 360:
            self.fail(f"{value!r}: an angle must be finite and within ±360°", param, ctx)
        return math.radians(degrees % 180)


class CropType(click.ParamType):
    """``X0:X1`` or ``X0:X1,Y0:Y1`` (lengths; an empty end is open) → ((x0, x1), (y0, y1) or None)."""

    name = "X0:X1[,Y0:Y1]"

    def convert(self, value, param, ctx):
        if isinstance(value, tuple):
            return value
        ranges = []
        for part in str(value).split(","):
            ends = part.split(":")
            if len(ends) != 2:
                self.fail(f"{value!r}: write a range as X0:X1, e.g. 468um:733um (an empty end is open)", param, ctx)
            low, high = (None if not end.strip() else POSITION.convert(end, param, ctx) for end in ends)
            if low is not None and high is not None and low >= high:
                self.fail(f"{value!r}: the range {part} ends before it starts (give X0 < X1)", param, ctx)
            ranges.append((low, high))
        if len(ranges) > 2:
            self.fail(f"{value!r}: at most two ranges, X0:X1,Y0:Y1", param, ctx)
        return (ranges + [None])[:2]


class FrequencyRangeType(click.ParamType):
    """``FMIN:FMAX`` spatial frequencies (``0.1/mm:20/mm``; an empty end is open) →
    (fmin or None, fmax or None) in 1/m. A bare number is refused (until rough 0.13 it
    was per mm)."""

    name = "FMIN:FMAX"

    def convert(self, value, param, ctx):
        if isinstance(value, tuple):
            return value
        ends = str(value).split(":")
        if len(ends) != 2:
            self.fail(f"{value!r}: write a band as FMIN:FMAX, e.g. 0.1/mm:20/mm", param, ctx)
        for end in ends:
            bare_number(end, _flag(param), "/mm")
        try:
            low, high = (None if not end.strip() else units.parse_frequency(end) for end in ends)
        except errors.InputError as error:
            self.fail(str(error), param, ctx)
        if any(end is not None and end <= 0 for end in (low, high)):
            self.fail(f"{value!r}: frequencies must be positive", param, ctx)
        bounds = (1 / LENGTHS[1], 1 / LENGTHS[0])  # the wavelengths an option may take
        for end in (low, high):
            if end is not None:
                _refuse_outside(self, end, bounds, value, param, ctx, "a frequency", _frequency)
        if low is not None and high is not None and low >= high:
            self.fail(f"{value!r}: FMIN must be below FMAX, e.g. 0.05/mm:5/mm", param, ctx)
        return low, high


class RatioType(click.ParamType):
    """A material ratio in per cent, ``10`` or ``10%``, between 0 and 100 → float."""

    name = "PERCENT"

    def convert(self, value, param, ctx):
        if isinstance(value, float):
            return value
        try:
            ratio = float(str(value).strip().removesuffix("%"))
        except ValueError:
            self.fail(f"{value!r} is not a percentage (write e.g. 10 or 10%)", param, ctx)
        if not 0 <= ratio <= 100:
            self.fail(f"{value!r}: a material ratio lies between 0 and 100 %", param, ctx)
        return ratio


class RatioPairType(RatioType):
    """Two increasing material ratios, ``10:80`` (per cent) → (10.0, 80.0)."""

    name = "MR1:MR2"

    def convert(self, value, param, ctx):
        if isinstance(value, tuple):
            return value
        ends = str(value).split(":")
        if len(ends) != 2:
            self.fail(f"{value!r}: write two material ratios as MR1:MR2, e.g. 10:80", param, ctx)
        low, high = (RatioType.convert(self, end, param, ctx) for end in ends)
        if not low < high:
            self.fail(f"{value!r}: the first material ratio must be below the second", param, ctx)
        return low, high


POSITION = LengthType()
LENGTH = PositiveLengthType()
TIP = TipType()
SPACING = SpacingType()
CROP = CropType()
DIRECTION = DirectionType()
BAND = FrequencyRangeType()
RATIO = RatioType()
RATIOS = RatioPairType()


def crop_option(command):
    """``--crop X0:X1[,Y0:Y1]``: read only this range (the input options pass it to
    :func:`rough.read`, which reads only that window of a GeoTIFF). The range includes
    the samples nearest to its ends."""
    return click.option(
        "--crop",
        type=CROP,
        help="Work on X0:X1 only (and Y0:Y1 for maps), e.g. 468um:733um; positions include the origin. "
        "A GeoTIFF is read only in this window.",
    )(command)


def gaps_option(command):
    """``--gaps longest|fill``: how profiles taken from a map treat its invalid points."""
    return click.option(
        "--gaps",
        type=RegistryChoice(lambda: fractal.GAPS),
        default="longest",
        show_default=True,
        help="With --profiles: keep each profile's longest run of valid points, or fill its gaps linearly.",
    )(command)


def model_options(command):
    """The spectral model's options, shared by ``fit-fractal`` and ``rose``: ``--no-noise``,
    ``--rolloff``, the goodness-of-fit diagnostic's ``--level`` and ``--tip-radius``."""
    for option in reversed(
        (
            click.option(
                "--noise/--no-noise",
                default=True,
                show_default=True,
                help="Fit a white noise floor along with the power law (kept when the likelihood ratio finds it).",
            ),
            click.option(
                "--rolloff", is_flag=True, help="Also fit a Gaussian short-wavelength roll-off (tip, optics)."
            ),
            click.option(
                "--level",
                type=FloatRange(0, 1, min_open=True, max_open=True),
                default=0.01,
                show_default=True,
                help="Level of the χ² goodness-of-fit diagnostic (logged with -v); the band is chosen by effect "
                "size: the widest band of a decade or more where the local exponent keeps within 0.1 in H.",
            ),
            click.option(
                "--tip-radius",
                type=TIP,
                help="Leave out the scales a tip of this radius cannot follow (the curvature criterion).",
            ),
        )
    ):
        command = option(command)
    return command


class RegridType(SpacingType):
    """``SPACING`` or ``SPACING:linear|bandlimited`` → (metres, method)."""

    name = "SPACING[:METHOD]"

    def convert(self, value, param, ctx):
        if isinstance(value, tuple):
            return value
        length, _, method = str(value).partition(":")
        method = method.strip().lower() or "linear"
        if method not in ("linear", "bandlimited"):
            self.fail(f"{value!r}: the method is linear or bandlimited, e.g. 0.5um:linear", param, ctx)
        return LengthType.convert(self, length, param, ctx), method


def input_options(spacing_flag="--spacing", together=None, tiles=False, split=False):
    """INPUT… plus ``--spacing`` (under ``spacing_flag``), ``--unit``,
    ``--ignore-checksums``, ``--channel``, ``--layer`` and ``--regrid``. The command
    is called once per input with ``surface`` (the surface read) and ``input`` (the
    name given), and returns a :class:`~rough.cli.report.Report` or None (see
    :mod:`rough.cli.batch`). With ``together`` = N it takes up to N inputs at once
    instead, as the lists ``surfaces`` and ``inputs``. With ``tiles`` the command also
    takes ``--memory`` and is given a :class:`~rough.io.TiledSurface` for a map too
    large for that budget (:func:`rough.io.open_surface`), and ``work``: the keywords
    ``budget``, ``jobs`` and ``scheduler`` of the library's tiled functions. With
    ``split`` (a command that cuts any map into pieces: ``map``) one input's pieces go
    to ``--scheduler``'s cluster too, not the input whole."""

    def decorate(command):
        @functools.wraps(command)
        def wrapper(*args, input, spacing, unit, ignore_checksums, channel, layer, regrid, **kwargs):
            options = dict(
                spacing=spacing,
                unit=unit,
                verify=not ignore_checksums,
                channel=channel,
                layer=layer,
                crop=kwargs.pop("crop", None),
                regrid=regrid,
            )
            names = list(input or ("-",))
            if tiles:
                options["memory"] = kwargs.pop("memory")
                kwargs["work"] = _pieces_work(options["memory"], names, kwargs, split)
            if "output" in kwargs:  # surface_output's, made an Output here to name one per input
                kwargs["output"] = Output(kwargs.pop("output"), kwargs.pop("format"))
            if together:
                return _together(functools.partial(command, *args), names, options, together, kwargs)

            def work(name, **rest):
                return command(*args, surface=read_named(name, options), input=name, **rest)

            return run_each(work, names, kwargs)

        paths = click.Path(dir_okay=False, allow_dash=True)
        decorators = [
            click.argument("input", nargs=-1, type=paths, metavar="[INPUT]..."),
            click.option(
                spacing_flag,
                "spacing",
                type=SPACING,
                help="Spacing of input data that carry none (NPY, a column of heights), e.g. 1um or "
                "1um,2um; overrides a file's own, with a warning.",
            ),
            click.option(
                "--unit", metavar="UNIT", help="Length unit of text values that name none (default m, not mm)."
            ),
            click.option(
                "--ignore-checksums", is_flag=True, help="Read X3P files whose MD5 checksums fail, with a warning."
            ),
            click.option(
                "--channel",
                metavar="NAME|N",
                help="The channel of a multi-channel file (AFM, HDF5, ...), by name or number from 0; "
                "default the height channel (rough info lists them).",
            ),
            click.option(
                "--layer", type=click.IntRange(0), help="The layer of a multi-layer X3P file, from 0 (default 0)."
            ),
            click.option(
                "--regrid",
                type=RegridType(),
                help="Interpolate unevenly spaced data (stylus exports, irregular X3P) onto this spacing, "
                "e.g. 0.5um (linear: cannot ring) or 0.5um:bandlimited (for coarsening); recorded in the history. "
                "Without it they are refused.",
            ),
        ]
        if tiles:
            decorators.append(
                click.option(
                    "--memory",
                    type=work_options.MemoryType(),
                    help="Memory budget, e.g. 4GB: a map that would need more is read in tiles "
                    "(default: half the machine's memory, or ROUGH_MEMORY).",
                )
            )
        for decorator in reversed(decorators):
            wrapper = decorator(wrapper)
        return wrapper

    return decorate


def _together(command, names, options, most, kwargs):
    """Inputs that one run uses together (render's surfaces, switched by the trigger):
    one report, under the first input's name."""
    if len(names) > most:
        raise click.UsageError(f"give at most {most} inputs, not {len(names)}")
    check_inputs(names)

    def work(name, **rest):
        return command(surfaces=[read_named(each, options) for each in names], inputs=names, **rest)

    return run_each(work, names[:1], kwargs)


surface_input = input_options()
#: The input of commands that work on a map larger than memory, a tile at a time.
tiled_input = input_options(tiles=True)
#: The input of ``map``, which cuts any map into bands of windows: one input's bands go to
#: ``--jobs`` and ``--scheduler``.
split_input = input_options(tiles=True, split=True)


def _pieces_work(budget, names, kwargs, split):
    """``--jobs`` goes to the inputs when there are several, and to the pieces (tiles,
    strips, bands of windows) of the one input otherwise. ``--scheduler`` sends the
    inputs to the cluster (each worker then works on its input's pieces in turn), or,
    with ``split`` and one input, that input's pieces."""
    if len(names) > 1 or "jobs" not in kwargs:
        return {"budget": budget, "jobs": 1, "scheduler": None}
    work = {"budget": budget, "jobs": kwargs["jobs"], "scheduler": kwargs["scheduler"] if split else None}
    kwargs.update(jobs=1, scheduler=None if split else kwargs["scheduler"])
    return work


class RegistryChoice(click.Choice):
    """A choice among the names of a registry of the library, ``names()``, read when
    first needed: the library's modules load numpy (and a registry with plugins scans
    the installed packages), which ``rough --help`` must not."""

    def __init__(self, names):
        self.names, self.case_sensitive = names, True

    @functools.cached_property
    def choices(self):
        return tuple(self.names())


def surface_output(command):
    """``-o/--output`` (default ``-``) and ``-f/--format``; the command receives
    ``output``, an :class:`Output`."""

    @functools.wraps(command)
    def wrapper(*args, output, format=None, **kwargs):
        output = output if isinstance(output, Output) else Output(check_target(output, "--output"), format)
        output.check()
        return command(*args, output=output, **kwargs)

    wrapper = click.option(
        "-f",
        "--format",
        type=RegistryChoice(registry.writable),
        default=None,
        help="Output format (default: from the output file's extension; X3P on standard output).",
    )(wrapper)
    wrapper = click.option(
        "-o",
        "--output",
        default="-",
        type=click.Path(allow_dash=True),
        metavar="FILE|DIR/",
        show_default=True,
        help="Output file, written atomically; - is standard output; with several inputs a directory.",
    )(wrapper)
    return wrapper


@dataclasses.dataclass(frozen=True)
class Output:
    """Where a command's surface goes: a file (written atomically), standard output
    (X3P unless told otherwise; binary output to a terminal is refused), or, for
    several inputs, a directory (``out/``) where each keeps its name with the output
    format's extension."""

    path: str = "-"
    requested_format: str = None

    @property
    def is_directory(self):
        return self.path != "-" and (self.path.endswith(os.sep) or os.path.isdir(self.path))

    def check_directory(self, names):
        """With several inputs: ``-o`` must be a directory, and no two inputs may land
        on the same output file."""
        if not self.is_directory:
            raise click.UsageError("with several inputs, -o names a directory (e.g. -o out/)")
        targets = [self.for_input(name).path for name in names]
        clash = next((target for target in targets if targets.count(target) > 1), None)
        if clash is not None:
            raise click.UsageError(f"two inputs would both be written to {clash}")

    def for_input(self, name):
        """The output of input ``name``: in the directory, the input's stem with the
        output format's extension; otherwise this output itself."""
        if not self.is_directory:
            return self
        if name == "-":
            raise errors.InputError("standard input has no name to write under: give -o FILE", filename=self.path)
        os.makedirs(self.path, exist_ok=True)
        format_name = self.requested_format or "x3p"
        extension = registry.formats()[format_name].extensions[0]
        return Output(os.path.join(self.path, stem_name("{stem}", name) + extension), format_name)

    def check(self):
        """Refuse, before any work, an output file that cannot be written
        (:func:`check_target`) or whose format cannot be told; the format (None for a
        directory, whose files' format is chosen per input)."""
        if self.is_directory:
            return None
        check_target(self.path, "--output")
        self._refuse_binary_on_terminal()
        return self.format

    @property
    def format(self):
        if self.requested_format:
            return self.requested_format
        try:
            return "x3p" if self.path == "-" else io.format_for_path(self.path)
        except errors.InputError as error:
            error.filename = self.path  # names the output: no input name in front
            raise

    def _refuse_binary_on_terminal(self):
        on_terminal = (
            io.standard_output() and sys.stdout.isatty() if self.path == "-" else io.names_a_terminal(self.path)
        )
        if self.format in io.BINARY and on_terminal:
            raise errors.InputError(
                f"refusing to write binary {self.format.upper()} to a terminal: use -o FILE, a pipe, or -f tsv",
                filename=self.path,
            )

    def write(self, surface):
        self._refuse_binary_on_terminal()
        if self.path != "-":
            io.write(surface, self.path, format=self.format)
            return
        with io.atomic_output("-") as stream:
            io.write(surface, stream, format=self.format)


def report_format(command):
    """``--json`` (one JSON object, SI units) and ``--tsv`` (file, key, value, unit rows):
    the output contract of :mod:`rough.cli.report`."""
    command = click.option(
        "--tsv", "as_tsv", is_flag=True, help="Print tab-separated rows: file, key, value, unit (SI units, no header)."
    )(command)
    return click.option(
        "--json", "as_json", is_flag=True, help="Print one JSON object (SI units); several inputs: JSON Lines."
    )(command)
