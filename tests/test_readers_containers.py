"""Container formats: Gwyddion GWY (read and write), HDF5, NetCDF, Mitutoyo Excel and NMM zip profiles, against the
example files in ../shared/data and their projects' expectations (INDEX.md §2b)."""

import io
import shutil
import subprocess
import zipfile

import numpy as np
import pytest
from peer_statistics import rq

from rough import Surface, read
from rough.errors import FormatError, InputError
from rough.io import ReadOptions, read_bytes, registry

from conftest import shared_data_path

DATA = shared_data_path()  # ../shared/data, or $ROUGH_SHARED/data
ST = DATA / "SurfaceTopography"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason="needs ../shared/data")
needs_gwyddion = pytest.mark.skipif(
    shutil.which("gwyddion") is None, reason="Gwyddion is not installed (apt-get install gwyddion)"
)


def reader_ready(path, **options):
    """The surface, or a skip when another format's reader (mi, opd) is not written yet."""
    try:
        return read(path, **options)
    except FormatError as error:
        if "not written yet" in str(error):
            pytest.skip(f"{path.name}: {error}")
        raise


# --- NetCDF -------------------------------------------------------------------------------------------------------


@needs_data
def test_netcdf_reads_surfacetopography_layout():
    surface = read(ST / "nc-1.nc")
    assert surface.source_format == "netcdf"
    assert surface.points == (5, 10)
    assert surface.size == pytest.approx((5e-9, 10e-9), rel=1e-12)
    assert surface.units.xy == "nm" and surface.units.z == "nm"
    expected = np.array([9, 7, 5, 3, 1, -1, -3, -5, -7, -9]) * 1e-9
    for column in surface.heights.T:  # the file's rows (fixed x) are rough's columns
        np.testing.assert_allclose(column, expected, rtol=1e-12)


def _netcdf(tmp_path, heights, mask=None, length=None, unit="um", nonuniform_x=None):
    from scipy.io import netcdf_file

    path = tmp_path / "t.nc"
    with netcdf_file(path, "w", version=2) as nc:
        nc.json = '{"acquisition_time": "2021-03-04T05:06:07"}'
        if nonuniform_x is not None:
            nc.createDimension("n", len(heights))
            x = nc.createVariable("x", "f8", ("n",))
            x[:] = nonuniform_x
            x.unit = unit
            nc.createVariable("heights", "f8", ("n",))[:] = heights
            return path
        nc.createDimension("x", heights.shape[0])
        nc.createDimension("y", heights.shape[1])
        h = nc.createVariable("heights", "f8", ("x", "y"))
        h[:] = heights
        h.unit = unit
        for name, count in zip("xy", heights.shape):
            variable = nc.createVariable(name, "f8", (name,))
            variable[:] = np.arange(count)
            if length:
                variable.length = length[name == "y"]
            variable.unit = unit
        if mask is not None:
            nc.createVariable("mask", "b", ("x", "y"))[:] = mask
    return path


def test_netcdf_mask_date_and_transpose(tmp_path):
    heights = np.arange(12.0).reshape(3, 4)
    mask = np.zeros((3, 4), np.int8)
    mask[1, 2] = 1
    surface = read(_netcdf(tmp_path, heights, mask, length=(6.0, 2.0)))
    assert surface.heights.shape == (4, 3)
    assert np.isnan(surface.heights[2, 1]) and np.isnan(surface.heights).sum() == 1
    np.testing.assert_allclose(surface.heights[0], heights[:, 0] * 1e-6)
    assert surface.spacing == pytest.approx((2e-6, 0.5e-6))
    assert surface.metadata["date"] == "2021-03-04T05:06:07"


def test_netcdf_without_sizes_needs_spacing(tmp_path):
    path = _netcdf(tmp_path, np.ones((3, 4)))
    with pytest.raises(FormatError, match="--spacing"):
        read(path)
    assert read(path, spacing=1e-6).spacing == (1e-6, 1e-6)


def test_netcdf_with_an_empty_dimension_is_refused(tmp_path):
    """A dimension of length 0 (found by the fuzz test): one line, not a division by zero."""
    path = _netcdf(tmp_path, np.ones((0, 4)), length=(6.0, 2.0))
    with pytest.raises(FormatError, match="holds no points"):
        read(path)


def test_netcdf_nonuniform_profile_needs_regrid(tmp_path):
    path = _netcdf(tmp_path, np.array([0.0, 1.0, 3.0, 2.0]), nonuniform_x=[0.0, 1.0, 3.0, 4.0])
    with pytest.raises(FormatError, match="--regrid"):
        read(path)
    assert read(path, regrid=(1e-6, "linear")).points == (5,)


# --- HDF5 ---------------------------------------------------------------------------------------------------------


@needs_data
def test_hdf5_refuses_without_spacing_with_a_hint():
    with pytest.raises(FormatError, match="--spacing"):
        read(ST / "multiple_data_sets.h5")


@needs_data
def test_hdf5_channels_and_shapes():
    first = read(ST / "multiple_data_sets.h5", spacing=1e-6, unit="um")
    assert first.heights.shape == (256, 256)
    assert first.metadata["channels"] == "0 'dataset1', 1 'dataset2'"
    assert first.units.z == "um"
    second = read(ST / "multiple_data_sets.h5", spacing=1e-6, unit="mm", channel="dataset2")
    assert second.heights.shape == (640, 480)  # SurfaceTopography's (nx, ny) = (640, 480), stored x first
    assert second.metadata["channel"] == "dataset2"
    with pytest.raises(FormatError, match="no channel 2"):
        read(ST / "multiple_data_sets.h5", spacing=1e-6, channel=2)


@needs_data
def test_hdf5_dataset1_is_mi1_topography():
    mi = reader_ready(ST / "mi-1.mi")
    h5 = read(ST / "multiple_data_sets.h5", spacing=mi.spacing, unit="um")
    # the HDF5 array is SurfaceTopography's (nx, ny): rough's z[y, x] transposed; equal up to the µm → m rounding
    np.testing.assert_allclose(h5.heights.T, mi.heights, rtol=1e-12, atol=0)


@needs_data
def test_hdf5_dataset2_is_opd1_heights():
    opd = reader_ready(ST / "opd-1.opd")
    h5 = read(ST / "multiple_data_sets.h5", spacing=opd.spacing, unit="mm", channel=1)
    z = h5.heights.T  # the HDF5 array is (nx, ny)
    assert z.shape == opd.heights.shape
    valid = ~np.isnan(opd.heights)
    np.testing.assert_allclose(z[valid], opd.heights[valid], rtol=1e-6)


def test_hdf5_units_attribute_and_default_channel(tmp_path):
    h5py = pytest.importorskip("h5py")
    path = tmp_path / "t.h5"
    with h5py.File(path, "w") as handle:
        handle["phase"] = np.zeros((3, 4))
        handle.create_group("scan")["Height"] = np.arange(12.0).reshape(3, 4)
        handle["scan/Height"].attrs["units"] = "nm"
        handle["coords"] = np.arange(4.0)
    surface = read(path, spacing=1e-6)
    assert surface.metadata["channel"] == "scan/Height"
    assert surface.units.z == "nm"
    assert surface.heights[2, 3] == pytest.approx(11e-9)


# --- Mitutoyo Excel -----------------------------------------------------------------------------------------------


@needs_data
def test_mitutoyo_mock():
    surface = read(ST / "mitutoyo_mock.xlsx")
    assert surface.source_format == "xlsx"
    assert surface.points == (960,)
    assert surface.spacing[0] == pytest.approx(0.5e-6, rel=1e-9)
    assert surface.size[0] == pytest.approx(480.0e-6, rel=1e-9)
    assert rq(surface.heights) == pytest.approx(0.16866328079293708e-6, rel=1e-9)
    assert surface.metadata["date"] == "2022-10-10"
    assert surface.metadata["vendor"] == "Mitutoyo"
    assert surface.metadata["mitutoyo_cut_off"] == "0.08mm"
    instrument = {key: surface.metadata[f"mitutoyo_{key}"] for key in ("Ra", "Rq", "Rz", "Rpk", "Rvk")}
    assert instrument == {"Ra": "0.018 µm", "Rq": "0.027 µm", "Rz": "0.191 µm", "Rpk": "0.052 µm", "Rvk": "0.489 µm"}


@needs_data
def test_mitutoyo_2_mock():
    surface = read(ST / "mitutoyo_2_mock.xlsx")
    assert surface.points == (6664,)
    assert surface.spacing[0] == pytest.approx(1.5e-6, rel=1e-9)
    assert surface.size[0] == pytest.approx(9996.0e-6, rel=1e-9)
    assert rq(surface.heights) == pytest.approx(3.96889742e-6, rel=1e-8)
    assert surface.metadata["date"] == "2023-06-20"
    instrument = [key for key in surface.metadata if key.startswith(("mitutoyo_R", "mitutoyo_M", "mitutoyo_A"))]
    assert len(instrument) == 23  # the instrument's own results, all of them
    assert surface.metadata["mitutoyo_Rsk"] == "-0.144"
    assert surface.metadata["mitutoyo_Mr2"] == "92.617 %"
    assert surface.metadata["mitutoyo_RSm"] == "419.9 µm"


# --- NMM ----------------------------------------------------------------------------------------------------------


@needs_data
def test_nmm_is_sniffed_from_its_head():
    head = (ST / "nmm-1.zip").read_bytes()[: registry.HEAD]
    assert b".dsc" not in head  # the .dsc member lies beyond the head
    assert registry.sniff(head, "nmm-1.zip") == "nmm"


@needs_data
def test_nmm_nonuniform_is_refused_without_regrid():
    with pytest.raises(FormatError, match="--regrid"):
        read(ST / "nmm-1.zip")


@needs_data
def test_nmm_regridded():
    surface = read(ST / "nmm-1.zip", regrid=(1e-8, "linear"))
    assert surface.metadata["date"] == "2024-01-11T23:49:11"
    assert surface.history[-1]["parameters"]["points_read"] == 20001
    # Rq of SurfaceTopography (the piecewise-linear profile) is 1.135232e-06 m; sampling it every 10 nm comes close
    assert rq(surface.heights) == pytest.approx(1.135232e-06, rel=2e-4)
    # the length along the diagonal scan path; SurfaceTopography's 0.7071105772375498 mm is its projection on x
    assert surface.size[0] == pytest.approx(0.0007071105772375498 * np.sqrt(2), rel=1e-4)


@needs_data
def test_nmm_columns_match_the_reference_projection():
    with zipfile.ZipFile(ST / "nmm-1.zip") as archive:
        table = np.array(archive.read("profile.dat").split(), dtype=float).reshape(-1, 12)
    assert abs(table[-1, 0] - table[0, 0]) == pytest.approx(0.0007071105772375498, rel=1e-12)
    assert table.shape[0] == 20001


# --- Gwyddion GWY -------------------------------------------------------------------------------------------------


@pytest.fixture
def scan():
    heights = np.cumsum(np.random.default_rng(3).normal(size=(20, 32)), axis=1) * 1e-7
    heights[4, 7] = np.nan
    surface = Surface(heights, (1.5e-6, 2.5e-6), (1e-5, -2e-5), metadata={"title": "scan", "operator": "A"})
    return surface.derive("level", {"method": "plane"})


def test_gwy_write_reads_back_in_gwyfile(scan, tmp_path):
    gwyfile = pytest.importorskip("gwyfile")
    scan.write(tmp_path / "scan.gwy")
    container = gwyfile.load(str(tmp_path / "scan.gwy"))
    field, mask = container["/0/data"], container["/0/mask"]
    valid = ~np.isnan(scan.heights)
    np.testing.assert_array_equal(field.data[valid], scan.heights[valid])
    assert np.isfinite(field.data).all()
    np.testing.assert_array_equal(mask.data, (~valid).astype(float))
    assert (field.xreal, field.yreal, field.xoff, field.yoff) == pytest.approx((48e-6, 50e-6, 1e-5, -2e-5))
    assert field.si_unit_xy.unitstr == "m" and field.si_unit_z.unitstr == "m"
    assert container["/0/data/title"] == "scan"
    assert '"operator": "A"' in container["/0/meta"]["rough.metadata"]


def test_gwy_round_trip_in_rough(scan, tmp_path):
    scan.write(tmp_path / "scan.gwy")
    again = read(tmp_path / "scan.gwy")
    assert again.source_format == "gwy"
    np.testing.assert_array_equal(again.heights, scan.heights)
    assert again.spacing == scan.spacing and again.origin == scan.origin
    assert again.metadata["operator"] == "A" and again.metadata["title"] == "scan"
    assert [entry["command"] for entry in again.history] == ["level"]


def test_gwy_profile_round_trip(tmp_path):
    profile = Surface(np.sin(np.arange(50) / 5.0) * 1e-6, (2e-6,))
    profile.heights[3] = np.nan
    profile.write(tmp_path / "p.gwy")
    again = read(tmp_path / "p.gwy")
    assert again.is_profile
    np.testing.assert_array_equal(again.heights, profile.heights)
    assert again.spacing == (2e-6,)


def test_gwy_channels_units_and_graph(tmp_path):
    gwyfile = pytest.importorskip("gwyfile")
    objects = gwyfile.objects
    container = objects.GwyContainer()
    container["/0/data"] = objects.GwyDataField(np.ones((2, 3)), 6.0, 4.0, si_unit_xy="µm", si_unit_z="V")
    container["/0/data/title"] = "Amplitude"
    container["/1/data"] = objects.GwyDataField(np.arange(6.0).reshape(2, 3), 6.0, 4.0, si_unit_xy="µm", si_unit_z="nm")
    container["/1/data/title"] = "Height"
    container.tofile(str(tmp_path / "two.gwy"))
    surface = read(tmp_path / "two.gwy")
    assert surface.metadata["channel"] == "Height"
    assert surface.spacing == pytest.approx((2e-6, 2e-6))
    assert surface.heights[1, 2] == pytest.approx(5e-9)
    assert surface.units.xy == "µm" and surface.units.z == "nm"
    with pytest.raises(FormatError, match="not a length"):
        read(tmp_path / "two.gwy", channel=0)

    curve = objects.GwyObject("GwyGraphCurveModel", {"xdata": np.arange(5.0), "ydata": np.arange(5.0) ** 2})
    graph = objects.GwyObject(
        "GwyGraphModel", {"title": "Profile", "x_unit": objects.GwySIUnit(unitstr="mm"), "curves": [curve]}
    )
    graph["y_unit"] = objects.GwySIUnit(unitstr="um")
    graph.typecodes["curves"] = "O"
    only_graph = objects.GwyContainer({"/0/graph/graph/1": graph})
    buffer = io.BytesIO()
    only_graph.tofile(buffer)
    profile = read_bytes(buffer.getvalue())
    assert profile.is_profile and profile.spacing == pytest.approx((1e-3,))
    assert profile.heights[-1] == pytest.approx(16e-6)


def gwyddion(*args):
    return subprocess.run(["gwyddion", *map(str, args)], check=False, capture_output=True, text=True, timeout=120)


@needs_gwyddion
def test_gwyddion_checks_and_resaves_rough_gwy(scan, tmp_path):
    scan.write(tmp_path / "scan.gwy")
    result = gwyddion("--check", tmp_path / "scan.gwy")
    assert "fail" not in (result.stdout + result.stderr).lower(), result.stderr
    gwyddion(f"--convert-to-gwy={tmp_path / 'again.gwy'}", tmp_path / "scan.gwy")
    again = read(tmp_path / "again.gwy")
    np.testing.assert_array_equal(again.heights, scan.heights)
    assert again.spacing == pytest.approx(scan.spacing, rel=1e-12)


@needs_gwyddion
@pytest.mark.parametrize("fmt,rtol", [("x3p", 0.0), ("gsf", 0.0)])
def test_gwyddion_converted_rough_files_read_back(scan, tmp_path, fmt, rtol):
    scan.write(tmp_path / f"scan.{fmt}")
    written = read(tmp_path / f"scan.{fmt}")  # GSF is float32: compare with what the file holds
    gwyddion(f"--convert-to-gwy={tmp_path / 'converted.gwy'}", tmp_path / f"scan.{fmt}")
    converted = read(tmp_path / "converted.gwy")
    np.testing.assert_allclose(converted.heights, written.heights, rtol=rtol, atol=0)
    assert np.array_equal(np.isnan(converted.heights), np.isnan(scan.heights))
    assert converted.size == pytest.approx(scan.size, rel=1e-6)


@needs_gwyddion
def test_gwyddion_profile_graph_reads_back(tmp_path):
    profile = Surface(np.sin(np.arange(300) / 7.0) * 1e-6, (2e-6,))
    profile.write(tmp_path / "profile.x3p")
    gwyddion(f"--convert-to-gwy={tmp_path / 'profile.gwy'}", tmp_path / "profile.x3p")
    again = read(tmp_path / "profile.gwy")
    np.testing.assert_array_equal(again.heights, profile.heights)
    assert again.spacing == pytest.approx((2e-6,), rel=1e-9)


# --- damaged files ------------------------------------------------------------------------------------------------


def _examples():
    if not DATA.is_dir():
        return []
    names = ["nc-1.nc", "multiple_data_sets.h5", "mitutoyo_mock.xlsx", "nmm-1.zip"]
    return [ST / name for name in names]


def _gwy_example():
    buffer = io.BytesIO()
    Surface(np.arange(24.0).reshape(4, 6) * 1e-7, (1e-6,)).write(buffer, format="gwy")
    return buffer.getvalue()


OPTIONS = ReadOptions(spacing=(1e-6,), regrid=(1e-7, "linear"))


def _survives(data):
    try:
        assert isinstance(read_bytes(data, OPTIONS), Surface)
    except InputError as error:
        assert "\n" not in str(error)


@pytest.mark.parametrize("fraction", [0.0, 0.01, 0.1, 0.5, 0.9, 0.999])
def test_truncated_gwy(fraction):
    data = _gwy_example()
    _survives(data[: max(5, int(len(data) * fraction))])


@pytest.mark.parametrize("seed", range(40))
def test_corrupted_gwy(seed):
    data = bytearray(_gwy_example())
    rng = np.random.default_rng(seed)
    for position in rng.integers(4, 400, size=3):
        data[position] = rng.integers(256)
    _survives(bytes(data))


def test_gwy_string_without_terminator_is_refused():
    body = b"/a\0sabc"
    data = b"GWYPGwyContainer\0" + len(body).to_bytes(4, "little") + body
    with pytest.raises(FormatError):
        read_bytes(data)


@needs_data
@pytest.mark.parametrize("path", _examples(), ids=lambda path: path.name)
@pytest.mark.parametrize("fraction", [0.05, 0.5, 0.95])
def test_truncated_examples(path, fraction):
    data = path.read_bytes()
    _survives(data[: int(len(data) * fraction)])


@needs_data
@pytest.mark.parametrize("path", _examples(), ids=lambda path: path.name)
@pytest.mark.parametrize("seed", range(4))
def test_corrupted_example_headers(path, seed):
    data = bytearray(path.read_bytes())
    rng = np.random.default_rng(seed)
    for position in rng.integers(8, min(len(data), 2048), size=4):
        data[position] ^= 0xFF
    _survives(bytes(data))


@needs_data
@pytest.mark.parametrize(
    "name", ["SurfaceTopography/x3p-2.x3p", "x3ptools/csafe-logo.x3p", "opengps/ISO5436-sample1.x3p"]
)
def test_x3p_zips_are_not_taken_for_nmm(name):
    assert registry.sniff((DATA / name).read_bytes()[: registry.HEAD], name) == "x3p"
