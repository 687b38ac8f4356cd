"""Issue 15: one format registry from which the sniffer, the readers and writers, ``-f``,
``rough formats``, the docs and the error messages come; every third-party example file
recognised as its format; the error-path files refused in one line."""

import io
import json

import click
import numpy as np
import pytest

from rough import Surface
from rough.errors import FormatError, InputError
from rough.io import FORMATS, WRITABLE, ReadOptions, read, read_bytes, registry, sniff

from conftest import ROOT, assert_one_line_error, shared_folder

SHARED = shared_folder()
needs_shared = pytest.mark.skipif(SHARED is None, reason="needs ../shared/data (third-party reference files)")

# every example file of ../shared/data → the format it must be recognised as
EXPECTED_FORMAT = {
    "SurfaceTopography/10x10-one_channel_without_name.ibw": "ibw",
    "SurfaceTopography/al3d-1.al3d": "al3d",
    "SurfaceTopography/bcrf-1.bcrf": "bcr",
    "SurfaceTopography/csv-1.csv": "tsv",
    "SurfaceTopography/dektak-1.csv": "tsv",
    "SurfaceTopography/di-1.di": "di",
    "SurfaceTopography/di-3.di": "di",
    "SurfaceTopography/di-5.di": "di",
    "SurfaceTopography/example-2d.npy": "npy",
    "SurfaceTopography/example_ps.tiff": "ps",
    "SurfaceTopography/frt-1.frt": "frt",
    "SurfaceTopography/frt-2.frt": "frt",
    "SurfaceTopography/hfm-1.hfm": "tsv",
    "SurfaceTopography/matrix-3.txt": "tsv",
    "SurfaceTopography/metropro-1.dat": "metropro",
    "SurfaceTopography/mi-1.mi": "mi",
    "SurfaceTopography/mitutoyo_mock.xlsx": "xlsx",
    "SurfaceTopography/mitutoyo_2_mock.xlsx": "xlsx",
    "SurfaceTopography/mnt-1.mnt": "mnt",
    "SurfaceTopography/mnt-2.mnt": "mnt",
    "SurfaceTopography/multiple_data_sets.h5": "hdf5",
    "SurfaceTopography/nc-1.nc": "netcdf",
    "SurfaceTopography/nid-1.nid": "nid",
    "SurfaceTopography/nmm-1.zip": "nmm",
    "SurfaceTopography/nms-1.nms": "nms",
    "SurfaceTopography/opd-1.opd": "opd",
    "SurfaceTopography/opdx-3.opdx": "opdx",
    "SurfaceTopography/plu-1.plu": "plu",
    "SurfaceTopography/sdf-1.sdf": "sdf",
    "SurfaceTopography/spot_1-1000nm.ibw": "ibw",
    "SurfaceTopography/stp-1.stp": "wsxm",
    "SurfaceTopography/sur-2.sur": "sur",
    "SurfaceTopography/sur-3.sur": "sur",
    "SurfaceTopography/tmd-1.tmd": "tmd",
    "SurfaceTopography/top-1.top": "wsxm",
    "SurfaceTopography/x3p-2.x3p": "x3p",
    "surfalize/test_1.zon": "zon",
    "dem/TM1_564_146.tif": "geotiff",
    "dem/coronaA_grids.npz": "npz",
    "dem/faultzone.tif": "geotiff",
    "opengps/KautschukInfiniteFocus.x3p": "x3p",
}


@needs_shared
@pytest.mark.parametrize("name", sorted(EXPECTED_FORMAT))
def test_every_example_file_is_recognised_as_its_format(name):
    path = SHARED / "data" / name
    with open(path, "rb") as stream:
        head = stream.read(registry.HEAD)
    assert sniff(head, path.name) == EXPECTED_FORMAT[name]


@needs_shared
@pytest.mark.parametrize(
    ("name", "fragment"),
    [
        ("di_corrupted.di", "Nanoscope"),
        ("wrongnpyfile.npy", ""),
        ("nonsense_txt_file.txt", ""),
    ],
)
def test_the_error_path_files_are_refused_in_one_line(run, name, fragment):
    path = SHARED / "data" / "SurfaceTopography" / name
    result = run("info", path)
    assert_one_line_error(result, name, fragment)


def test_the_registry_declares_every_format_once_with_its_facts():
    table = registry.formats()
    assert len(table) >= 30
    for name, facts in table.items():
        assert facts.name == name and facts.title and facts.extensions, name
        assert all(extension.startswith(".") and extension == extension.lower() for extension in facts.extensions)
        assert set(facts.carries) <= set(registry.CARRIES), name
        assert facts.magic or facts.probe or facts.by_extension, f"{name} cannot be recognised"
        module = registry.module_of(name)
        assert callable(module.read)
        assert hasattr(module, "write") == facts.writes, name
    assert FORMATS == {name: facts.title for name, facts in table.items()}
    assert set(WRITABLE) == {name for name, facts in table.items() if facts.writes}


def test_the_output_format_choices_come_from_the_registry():
    from rough.cli.main import cli

    convert = cli.get_command(click.Context(cli), "convert")
    choices = next(param for param in convert.params if param.name == "format").type.choices
    assert tuple(choices) == registry.writable()


def test_a_format_rough_reads_but_cannot_write_is_refused_in_one_line(tmp_path):
    from rough import Surface
    from rough.io import write

    with pytest.raises(InputError, match="rough reads Digital Surf SUR but does not write it"):
        write(Surface([1.0, 2.0, 3.0], 1e-6), tmp_path / "out.sur", format="sur")
    assert not (tmp_path / "out.sur").exists()


def test_rough_formats_lists_every_format(run):
    listing = json.loads(run("formats", "--json", check=True).stdout)["formats"]
    assert {row["name"] for row in listing} == set(FORMATS)
    table = run("formats", check=True).stdout.decode()
    for title in FORMATS.values():
        assert title in table
    assert "read/write" in table and "[needs rasterio" in table


@pytest.mark.parametrize(
    ("name", "fragment"),
    [
        ("scan.vk4", "Keyence VK4 (.vk4) is not a format rough reads yet; convert it with Gwyddion"),
        ("scan.bin", f"unrecognised binary data); rough reads {', '.join(sorted(FORMATS))} (rough formats describes"),
    ],
)
def test_an_unrecognised_file_names_what_rough_reads_or_points_to_gwyddion(run, tmp_path, name, fragment):
    path = tmp_path / name
    path.write_bytes(b"\x00\x01\x02\x03binary junk\x00" * 20)
    result = run("info", path)
    assert_one_line_error(result, name, fragment)
    assert "gwyddion --convert-to-gwy" in result.stderr.decode()


def test_magic_beats_the_extension():
    """A file is what its content says, whatever its name."""
    assert sniff(b"Gwyddion Simple Field 1.0\n", "scan.plu") == "gsf"
    assert sniff(b"\\*File list\r\n", "scan.txt") == "di"


@pytest.mark.parametrize("fmt", ["x3p", "gwy"])
def test_bytes_inside_the_data_never_decide_the_format(fmt):
    """Zip-based formats are told apart by their member names, found by walking the local
    headers: heights whose bytes spell another format's member names stay what they are."""
    decoy = b"PK\x03\x04" + bytes(22) + b"\x0b\x00\x00\x00profile.dsc xl/[Content_Types].xml"
    decoy += bytes(-len(decoy) % 8)
    heights = np.tile(np.frombuffer(decoy, "<f8"), (4, 1))
    surface = Surface(np.nan_to_num(heights, nan=0.0, posinf=0.0, neginf=0.0), (1e-6, 1e-6))
    buffer = io.BytesIO()
    surface.write(buffer, fmt)
    assert decoy in buffer.getvalue()
    assert sniff(buffer.getvalue()) == fmt


def test_formats_without_magic_are_chosen_by_extension_only_when_nothing_else_claims_them():
    junk = b"\x05\x00\x01\x02" + bytes(60)
    assert sniff(junk, "scan.ibw") == "ibw"
    with pytest.raises(FormatError, match="unrecognised binary data"):
        sniff(junk, "scan.xyz")
    with pytest.raises(FormatError):
        sniff(junk, "-")


def test_a_channel_is_chosen_by_name_or_number_and_a_wrong_one_lists_them():
    names = ["ZSensor", "AmplitudeError", "Phase", "Height"]
    assert registry.choose_channel(names, None, default=3) == 3
    assert registry.choose_channel(names, "phase") == 2
    assert registry.choose_channel(names, 0) == 0
    with pytest.raises(FormatError, match=r"no channel 'Friction'; the file holds 0 'ZSensor', 1 'AmplitudeError'"):
        registry.choose_channel(names, "Friction")
    with pytest.raises(FormatError, match="no channel '7'"):
        registry.choose_channel(names, "7")


def test_crop_reads_a_range_of_any_format_and_refuses_a_y_range_on_a_profile():
    text = b"x z\n0 1\n1 2\n2 3\n3 4\n4 5\n"
    assert read(text, crop=((1.0, 3.0), None)).heights.tolist() == [2.0, 3.0, 4.0]
    with pytest.raises(InputError, match="a profile has no y range"):
        read(text, crop=((1.0, 3.0), (0.0, 1.0)))


def test_regrid_applies_to_uneven_text_and_is_recorded():
    uneven = b"x z\n0 0\n1 1\n3 3\n4 4\n"
    with pytest.raises(FormatError, match="give --regrid SPACING"):
        read_bytes(uneven, ReadOptions())
    surface = read(uneven, regrid=(0.5, "linear"))
    assert surface.spacing == (0.5,) and surface.heights.tolist() == [0, 0.5, 1, 1.5, 2, 2.5, 3, 3.5, 4]
    assert surface.history[-1]["command"] == "regrid"


def test_the_docs_list_every_format():
    page = (ROOT / "docs" / "formats.rst").read_text()
    for name in FORMATS:
        assert f"``{name}``" in page, name


@pytest.mark.parametrize(
    "value, fragment",
    [(0.0, "positive length"), (-1e-6, "positive length"), ("abc", "positive length"), ((1e-6, "cubic"), "cubic")],
)
def test_a_bad_regrid_option_is_refused_whatever_the_format(value, fragment):
    """Checked once, where the read options are made, for every reader that regrids."""
    with pytest.raises(InputError, match=fragment):
        ReadOptions(regrid=value)
    with pytest.raises(InputError, match=fragment):
        read(b"x z\n0 0\n1 1\n3 3\n", regrid=value)


def test_the_cli_regrid_option_takes_a_length_and_a_method(run):
    uneven = b"x z\n0 0\n1 1\n3 3\n4 4\n"
    facts = json.loads(run("info", "--json", "--regrid", "0.5m:linear", input=uneven, check=True).stdout)
    assert facts["shape"] == [9] and facts["spacing"] == [0.5]
    facts = json.loads(run("info", "--json", "--regrid", "250", input=uneven, check=True).stdout)
    assert facts["spacing"] == [0.25]  # a bare number is in mm
    assert_one_line_error(run("info", "--regrid", "1um:cubic", input=uneven), "linear or bandlimited")


ALL_FILES = (
    []
    if SHARED is None
    else sorted(str(path.relative_to(SHARED / "data")) for path in (SHARED / "data").rglob("*") if path.is_file())
)
NEEDS_SPACING = (".npy", ".h5", "single_column.txt", "matrix-5.txt")


@needs_shared
@pytest.mark.parametrize("name", ALL_FILES if SHARED else [])
def test_every_shared_file_reads_or_is_refused_with_an_input_error(name):
    """Instrument files, licences and notes alike: a surface, or one line that names the file."""
    path = SHARED / "data" / name
    try:
        surface = read(path, spacing=1e-6 if name.endswith(NEEDS_SPACING) else None)
    except InputError as error:
        assert "\n" not in str(error) and str(error).startswith(str(path))
        return
    assert surface.heights.ndim in (1, 2) and surface.heights.dtype.kind == "f"
