"""Units chosen for the data (docs/output.rst, "Text"): every number rough prints with
a unit has a mantissa in [0.1, 1000), for surfaces from 1 nm to 1 km; a DEM prints
metres and per-metre values, an AFM scan nanometres; rounding noise prints as 0; a
file that states no unit says "assumed"; ``--tsv`` has numbers only in its value
column.

The property test reads the text table through a parser that cannot skip a number:
each is followed by a unit :func:`rough.units.scale_for` makes (then checked), or is
a pure number where the table says so, or stands in a listed unitless context (a
count, an ISO number, ``D = …``); anything else fails the test.
"""

import io
import json
import math
import re

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

import rough
from rough.cli.main import cli
from rough.units import LENGTH_POWERS, format_length, format_quantity, scale_for

#: Every unit label rough prints for a quantity of a length power.
KNOWN = {scale_for(10.0**e, unit)[1] for unit in LENGTH_POWERS for e in np.arange(-60, 40, 0.25)}
#: The table's units of a pure number (TSV unit column).
PURE = {"1", "%", "deg", "points"}
NUMBER = re.compile(r"(?<![\w.·/^–-])[+-]?(?:\d+\.?\d*|\.\d+)(?:e[+-]?\d+)?(?![\w.·])")
#: Unitless numbers in these contexts are counts, names, exponents or pure values.
BEFORE = re.compile(r"(\b(D|Ds|H|p|Ds - 1) =|±|ISO|of|flat|→|L\^|\d+ ×)\s*$")
AFTER = re.compile(
    r"^(°|\s?%|\s(of|for|points|frequencies|sectors|scales|sampling|bins|windows|profiles|edition|isotropic|"
    r"directional|neighbours|log10)\b|\s[+×]\s|–|-\d|\))"
)
#: A frequency as ``--band`` takes it, in a hint: ``33.47/km:226.5/km``.
PASTEABLE = re.compile(r"^(/[^\s:;,)]+)")
#: A range in one unit: ``0.53 to 3.2 /mm``.
RANGE = re.compile(r"^ to [+-]?(?:\d+\.?\d*|\.\d+)(?:e[+-]?\d+)? (\S+)")
#: Rows whose text is words (or numbers rough does not scale: dates in the history);
#: the spectrum's prefactor is in SI, its unit a power of the metre that depends on D.
TEXT_ROWS = re.compile(r"^(file|format|kind|units|method|metadata\..*|history\..*|scale_dependent|psd_prefactor)$")


def mantissas(label, text, unit):
    """The numbers of one table row that carry a scaled unit; AssertionError for a
    number the parser cannot place. ``unit`` is the row's TSV unit: a pure one makes
    the first number pure; in the rows of ``fit-fractal``'s scale table (``λ = …``)
    the second, the RMS slope."""
    words = label != "verdict" and text.startswith(("none", "no ", "not detected"))  # a verdict's hint has numbers
    if TEXT_ROWS.match(label) or text in ("undefined",) or words:
        return []
    found = []
    pure = 1 if label.startswith("λ = ") else 0 if unit in PURE else None
    for index, match in enumerate(NUMBER.finditer(text)):
        rest, before = text[match.end() :], text[: match.start()]
        token = (rest[1:].split() or [""])[0].rstrip(",;:") if rest.startswith(" ") else ""
        token = token if token in KNOWN else token.rstrip(")")
        token = PASTEABLE.match(rest).group(1) if PASTEABLE.match(rest) else token
        shared = RANGE.match(rest)
        if token in KNOWN or shared and shared.group(1).rstrip(",;:)") in KNOWN:
            found.append((float(match.group()), token if token in KNOWN else shared.group(1).rstrip(",;:)")))
        elif index == pure or AFTER.match(rest) or BEFORE.search(before):
            continue
        else:
            raise AssertionError(f"unplaced number {match.group()!r} in {label}: {text!r}")
    return found


def check_table(output, units):
    """Every scaled number of a text table in [0.1, 1000) (zero and non-finite apart)."""
    lines = output.splitlines()
    column = re.match(r"file\s+", lines[0]).end()  # where the value column starts
    for line in lines:
        label, text = line[:column].strip(), line[column:].strip()
        unit = units.get(label, next((units[key] for key in units if key.startswith(f"{label}.")), None))
        found = mantissas(label, text, unit) + mantissas("", label, "label")
        for value, token in found:
            if value and math.isfinite(value):
                assert 0.1 <= abs(value) < 1000, f"{value} {token} in {line!r}"
    return output


def run(*args):
    result = CliRunner().invoke(cli, [str(a) for a in args], catch_exceptions=False)
    assert result.exit_code == 0, result.output
    return result.stdout


def tsv_units(*args):
    """key → unit (or text) of the ``--tsv`` table."""
    return {row.split("\t")[1]: row.split("\t")[3] for row in run(*args, "--tsv").splitlines()}


def scaled(surface, factor, path):
    """``surface`` with heights, spacing and origin times ``factor``, written to ``path``."""
    rough.Surface(
        surface.heights * factor, tuple(d * factor for d in surface.spacing), tuple(o * factor for o in surface.origin)
    ).write(path)
    return path


MAP = rough.read(rough.sample("rock-map.x3p"))
PROFILE = rough.read(rough.sample("rock-profile.tsv"))
COMMANDS = (("info",), ("features",), ("fit-fractal", "--fill"), ("rose", "--fill", "--angle-step", "45"))


def exponent(surface):
    """The k of 10^k scalings that make ``surface``'s longer side 1 nm to 1 km long
    (or its spacing 2 pm, near rough's limit, for the 2048-point profile)."""
    return st.floats(*powers(surface))


def powers(surface):
    least = max(1e-9 / max(surface.size), 2e-12 / min(surface.spacing))
    return math.log10(least), math.log10(1e3 / max(surface.size))


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(map_power=exponent(MAP), profile_power=exponent(PROFILE))
def test_every_printed_quantity_fits_from_a_nanometre_to_a_kilometre(tmp_path, map_power, profile_power):
    for surface, power in ((MAP, map_power), (PROFILE, profile_power)):
        path = scaled(surface, 10.0**power, tmp_path / "scaled.x3p")
        for command in COMMANDS:
            if command[0] == "rose" and surface.is_profile:
                continue
            arguments = [*command[:1], *(a for a in command[1:] if not surface.is_profile or a != "--fill"), path]
            check_table(run(*arguments), tsv_units(*arguments))


@pytest.mark.parametrize(
    "line",
    ["η = 1e+06 µm", "C = 4.3e-06 /mm", "z 6.4e-05 pm", "Sha 5000 µm²"],
)
def test_the_parser_catches_what_the_issue_found(line):
    with pytest.raises(AssertionError):
        check_table(f"file  x\nkey   {line}", {})


def test_the_parser_refuses_a_number_it_cannot_place():
    with pytest.raises(AssertionError, match="unplaced"):
        check_table("file  x\nSa    12 furlongs", {"Sa": "m"})


def test_prefixes_fit_every_quantity():
    assert format_quantity(1.48e-7, "m3/m2") == "148 nm³/nm²"
    assert format_quantity(1.48e-6, "m3/m2") == "1.48 µm³/µm²"
    assert format_quantity(4.3e-3, "1/m") == "4.3 /km" and format_quantity(250.0, "1/m") == "250 /m"
    assert format_quantity(4.2e5, "1/m2") == "0.42 /mm²"
    assert format_quantity(2.5e-9, "m2") == "2.5 mm·µm" and format_quantity(7.8e-7, "m2") == "0.78 mm²"
    assert format_quantity(1.76e-12, "m3") == "1.76 mm²·µm"
    assert format_length(999.9999e-6) == "1 mm" and format_length(-2.5e-14) == "-25 fm"


@given(st.floats(allow_nan=False, allow_infinity=False), st.sampled_from(["m", "m2", "m3", "1/m", "1/m2", "m3/m2"]))
@example(5e-324, "m")
@example(-1.7976931348623157e308, "1/m2")
def test_every_finite_value_prints(value, unit):
    """Down to the smallest subnormal (a crop bound of 5e-324 m divided by zero)."""
    assert isinstance(format_quantity(value, unit), str)


def test_rounding_noise_prints_as_zero(tmp_path):
    assert format_length(6.4e-17, scale=1e-3) == "0 mm" and format_length(6.4e-12, scale=1e-3) == "6.4 pm"
    path = tmp_path / "shifted.x3p"
    rough.Surface(np.zeros((8, 8)), (1e-6, 1e-6), origin=(6.4e-17, 2e-6)).write(path)
    assert re.search(r"^origin\s+0 µm, 2 µm$", run("info", path), re.MULTILINE)


def test_an_origin_far_away_keeps_its_step(tmp_path):
    """A DEM corner 564 km east is printed to the metre its 1 m spacing resolves."""
    path = tmp_path / "dem.x3p"
    rough.Surface(np.zeros((8, 8)), (1.0, 1.0), origin=(564123.0, 146007.0)).write(path)
    assert re.search(r"^origin\s+564.123 km, 146.007 km$", run("info", path), re.MULTILINE)


def test_an_afm_scan_prints_nanometres(tmp_path):
    heights = np.random.default_rng(3).normal(0, 2e-9, (64, 64))
    path = tmp_path / "afm.x3p"
    rough.Surface(heights, (5e-9, 5e-9)).write(path)
    text = check_table(run("features", path), tsv_units("features", path))
    assert re.search(r"^Sq\s+\S+ nm ", text, re.MULTILINE)
    assert re.search(r"^Sal\s+\S+ nm ", text, re.MULTILINE)


def test_a_dem_prints_metres_and_per_metre_values(shared_data, tmp_path):
    dem = rough.read(shared_data / "dem" / "TM1_564_146.tif")
    path = tmp_path / "dem.x3p"
    rough.Surface(dem.heights[:256, :256], dem.spacing).write(path)
    rose = check_table(run("rose", "--angle-step", "30", path), tsv_units("rose", "--angle-step", "30", path))
    assert re.search(r"^band\s+\S+ to \S+ /(km|m) ", rose, re.MULTILINE), rose
    assert "C at η = 1 m" in rose
    spectrum = check_table(run("fit-fractal", path), tsv_units("fit-fractal", path))
    assert re.search(r"^resolution\s+η = 1 m ", spectrum, re.MULTILINE), spectrum
    assert re.search(r"^band\s+\S+ (/km )?to \S+ /(km|m) \(wavelengths \S+ (m )?to \S+ m\)", spectrum, re.MULTILINE)


def test_a_dem_rose_plot_has_no_negative_radius(shared_data, tmp_path):
    pytest.importorskip("matplotlib")
    dem = rough.read(shared_data / "dem" / "TM1_564_146.tif")
    surface = rough.Surface(dem.heights[:256, :256], dem.spacing)
    figure = rough.plot.rose_figure(rough.fractal.rose(surface, 30.0))
    amplitude = figure.axes[0]
    assert amplitude.get_ylim()[0] == 0 and amplitude.get_title().startswith("C(θ) (")
    assert "η = 1 m" in amplitude.get_title()


def test_a_file_without_units_says_assumed(tmp_path):
    path = tmp_path / "heights.npy"
    np.save(path, np.zeros((4, 5)))
    facts = json.loads(run("info", "--spacing", "1um", "--json", path))
    assert facts["units"] == {"xy": "m", "z": "m", "assumed": ["xy", "z"]}
    assert "assumed: the source file stated no unit" in run("info", "--spacing", "1um", path)
    bare = tmp_path / "bare.txt"
    bare.write_text("0 1e-6\n1e-6 2e-6\n2e-6 0\n")
    assert rough.read(bare).units.assumed == ("xy", "z")
    named = tmp_path / "named.txt"
    named.write_text("x[mm] z\n0 1e-3\n1 2e-3\n2 0\n")
    assert rough.read(named).units.assumed == ("z",)
    assert rough.read(rough.sample("rock-map.x3p")).units.assumed == ()
    assert "(as the file states)" in run("info", rough.sample("rock-map.x3p"))


def test_tsv_loads_into_pandas_with_numeric_values():
    pandas = pytest.importorskip("pandas")
    text = run("features", "--tsv", rough.sample("rock-map.x3p"))
    table = pandas.read_csv(
        io.StringIO(text),
        sep="\t",
        names=["file", "key", "value", "unit"],
        keep_default_na=False,
    )
    readme = pandas.read_csv(io.StringIO(text), sep="\t", names=["file", "key", "value", "unit"])
    assert readme["value"].dtype == float  # README's recipe: text rows and nan alike NaN
    numbers = table[table["value"] != ""].astype({"value": float})  # docs/output.rst's recipe
    wide = numbers.pivot(index="file", columns="key", values="value")
    assert math.isclose(wide["Sq"].mean(), 1.0002e-4, rel_tol=1e-3)
    basis = table.set_index("key").loc["evaluation.basis"]
    assert basis["value"] == "" and basis["unit"] == "data as given, mean removed"


def test_info_says_the_unit_it_read_an_unstated_axis_in(tmp_path):
    column = tmp_path / "column.txt"
    column.write_text("".join(f"{i}\n" for i in range(1, 9)))
    line = next(
        line
        for line in run("info", "--unit", "um", "--spacing", "1um", column).splitlines()
        if line.startswith("units")
    )
    assert line.endswith("stated no unit for xy or z; numbers read xy in um, z in um)"), line


def test_hdf5_and_geotiff_without_a_height_unit_say_z_is_assumed(shared_data):
    assert rough.read(
        shared_data / "SurfaceTopography" / "multiple_data_sets.h5", spacing=(1e-6, 1e-6)
    ).units.assumed == ("z",)
    assert "numbers read z in m)" in run(
        "info", "--spacing", "1um", shared_data / "SurfaceTopography" / "multiple_data_sets.h5"
    )
    dem = shared_data / "dem" / "TM1_564_146.tif"
    assert rough.read(dem).units.assumed == ("z",)  # xy in the CRS's metres, stated
    assert rough.io.open_tiles(dem).units.assumed == ("z",)


def test_a_band_hint_fits_its_data_and_pastes_back(shared_data):
    dem = shared_data / "dem" / "TM1_564_146.tif"
    crop = ("--crop", "564000m:564127m,146000m:146127m")
    text = check_table(run("fit-fractal", *crop, dem), tsv_units("fit-fractal", *crop, dem))
    band = re.search(r"try --band (\S+)$", text, re.MULTILINE).group(1)
    assert band == "33.47/km:226.5/km", text
    fitted = json.loads(run("fit-fractal", *crop, "--band", band, "--json", dem))
    low, high = fitted["band"]  # the band used: the frequencies of the periodogram within the one asked for
    assert 0.03347 <= low < high <= 0.2265, fitted["band"]


def test_the_figure_names_the_form_removed_from_a_profile_a_line():
    pytest.importorskip("matplotlib")
    assert rough.plot.surface(PROFILE, order=1).axes[0].get_title().endswith("\nleast-squares line removed")
    assert rough.plot.surface(MAP, order=1).axes[0].get_title().endswith("\nleast-squares plane removed")
