"""Issue 15: one format registry from which the sniffer, the readers and writers, ``-f``,
``rough formats``, the docs and the error messages come; every third-party example file
recognised as its format; the error-path files refused in one line."""

import importlib
import io
import json
import sys

import click
import numpy as np
import pytest
from plugin_package import install_plugin

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


def test_the_docs_have_a_section_for_every_built_in_format():
    page = (ROOT / "docs" / "formats.rst").read_text()
    for module_name in registry.MODULES + registry.FALLBACKS:
        facts = registry.module(module_name).FORMAT
        assert f"{facts.title} (``{facts.name}``)" in page and f"automodule:: rough.io.{module_name}" in page, (
            facts.name
        )


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
    assert_one_line_error(run("info", "--regrid", "250", input=uneven), "--regrid 250: give a unit, e.g. 250mm")
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


# A format plugin as a package lays it out: the module of docs/design.rst's "add a format".
TOY_FORMAT = '''"""Toy: a tiny text format, heights one row a line after a line of spacing and one of origin."""

import numpy as np

from rough import Surface
from rough.io.registry import Format

FORMAT = Format("toy", "Toy text grid", (".toy",), magic=(b"TOY1\\n",), writes=True, carries=("spacing",), binary=False)


def read(data, options):
    _, spacing, origin, *rows = bytes(data).decode("ascii").splitlines()
    spacing, origin = (tuple(map(float, line.split())) for line in (spacing, origin))
    heights = np.array([[float(value) for value in row.split()] for row in rows])
    return Surface(heights[0] if len(spacing) == 1 else heights, spacing, origin)


def write(surface, stream):
    lines = ["TOY1", *(" ".join(map(repr, values)) for values in (surface.spacing, surface.origin))]
    lines += [" ".join(map(repr, row.tolist())) for row in np.atleast_2d(surface.heights)]
    stream.write(("\\n".join(lines) + "\\n").encode("ascii"))
'''


@pytest.fixture
def plugins(monkeypatch, tmp_path):
    """Install plugin modules in this process: ``plugins({entry name: module text})``;
    the registry is read afresh, and again after the test."""

    def install(modules):
        for index, (point, text) in enumerate(modules.items()):
            (tmp_path / f"plugin_{index}.py").write_text(text)
        points = {point: f"plugin_{index}" for index, point in enumerate(modules)}
        for name in points.values():
            monkeypatch.delitem(sys.modules, name, raising=False)
        importlib.invalidate_caches()
        monkeypatch.setattr(registry, "entry_points", lambda group: points if group == "rough.formats" else {})
        registry._modules.cache_clear()
        registry.formats.cache_clear()

    monkeypatch.syspath_prepend(str(tmp_path))
    yield install
    monkeypatch.undo()
    registry._modules.cache_clear()
    registry.formats.cache_clear()


def test_a_plugin_format_is_sniffed_after_the_built_ins_and_before_text(plugins):
    plugins({"toy": TOY_FORMAT})
    order = list(registry.formats())
    assert order[-2:] == ["toy", "tsv"]
    assert order[:-2] == [registry.module(name).FORMAT.name for name in registry.MODULES]
    text = b"TOY1\n1e-06 2e-06\n0.0 0.5\n1.0 2.0\n3.0 nan\n"
    assert registry.sniff(text) == "toy"
    surface = read_bytes(text)
    assert surface.source_format == "toy" and surface.spacing == (1e-6, 2e-6) and surface.origin == (0.0, 0.5)
    assert np.array_equal(surface.heights, [[1.0, 2.0], [3.0, np.nan]], equal_nan=True)
    buffer = io.BytesIO()
    surface.write(buffer, "toy")
    assert buffer.getvalue() == text
    assert "toy" in registry.writable() and registry.extensions()[".toy"] == "toy"


@pytest.mark.parametrize(
    "module, warning",
    [
        ("raise ImportError('no module toy_dependency')", "format plugin broken (plugin_0) left out: ImportError"),
        ("FORMAT = None", "format plugin broken (plugin_0) left out: it declares no FORMAT"),
        (TOY_FORMAT.replace('Format("toy"', 'Format("x3p"'), "format plugin broken (plugin_0) left out: rough has"),
    ],
)
def test_a_broken_or_clashing_plugin_is_left_out_with_one_line(plugins, caplog, module, warning):
    plugins({"broken": module})
    with caplog.at_level("WARNING", logger="rough"):
        table = registry.formats()
    assert "toy" not in table and table["x3p"].title == "X3P (ISO 25178-72)"
    assert [record.getMessage().splitlines() for record in caplog.records] == [[caplog.records[0].getMessage()]]
    assert caplog.records[0].getMessage().startswith(warning)


def test_of_two_plugins_with_one_name_the_first_is_kept_and_the_second_named(plugins, caplog):
    plugins({"first": TOY_FORMAT, "second": TOY_FORMAT})
    with caplog.at_level("WARNING", logger="rough"):
        assert "toy" in registry.formats()
    assert [record.getMessage() for record in caplog.records] == [
        "format plugin second (plugin_1) left out: an earlier plugin has a format named 'toy'"
    ]


# A vendor format inside a container rough reads (Zygo DATX is HDF5): only a plugin reads it.
DATX = TOY_FORMAT.replace(
    'Format("toy", "Toy text grid", (".toy",), magic=(b"TOY1\\n",),',
    'Format("datx", "Zygo DATX (a plugin)", (".datx",), magic=(b"\\x89HDF\\r\\n\\x1a\\n",),',
)


def test_a_plugin_reads_a_vendor_format_inside_a_container_rough_reads(plugins):
    head = b"\x89HDF\r\n\x1a\n" + bytes(100)
    with pytest.raises(FormatError, match="Zygo DATX .* is not a format rough reads yet"):
        registry.sniff(head, "scan.datx")
    plugins({"datx": DATX})
    assert registry.sniff(head, "scan.datx") == "datx"
    assert registry.sniff(head, "scan.h5") == "hdf5"


def test_a_kelvin_probe_surface_potential_is_not_a_height():
    names = ["Surface potential", "SurfacePotential", "surface_potential", "Surface", "surface height", "Z_grid"]
    assert [registry.names_height(name) for name in names] == [False, False, False, True, True, True]


def test_an_installed_plugin_appears_in_rough_formats_and_reads(run, tmp_path):
    env = install_plugin(tmp_path, {"toy_format.py": TOY_FORMAT}, "[rough.formats]\ntoy = toy_rough.toy_format\n")
    listing = json.loads(run("formats", "--json", env=env, check=True).stdout)["formats"]
    assert {"name": "toy", "write": True, "extensions": [".toy"]}.items() <= next(
        row for row in listing if row["name"] == "toy"
    ).items()
    scan = tmp_path / "scan.toy"
    scan.write_bytes(b"TOY1\n1e-06\n0.0\n1.0 2.0 4.0\n")
    info = json.loads(run("info", "--json", scan, env=env, check=True).stdout)
    assert "toy" in json.dumps(info).lower()
