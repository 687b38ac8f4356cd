"""Issue 31, readers: the right numbers or a clear refusal (channel choice by physical quantity, non-height data
refused, exact WSxM values, MNT sizes, sur-3 decided, regridding that does not eat Rq, JPK and SDF 2.0 read, a
unitless GWY with --unit, truncated files refused). Values from ../shared/data/INDEX.md and reference_values.json;
files that the shared data lack are built here like the instruments write them."""

import io
import json
import struct

import numpy as np
import pytest
from peer_statistics import rq, sq

from rough.errors import FormatError
from rough.io import ReadOptions, read_bytes, registry
from rough.io.regrid import regrid

from conftest import assert_one_line_error

NM, UM = 1e-9, 1e-6


def load(shared_data, name, **options):
    return read_bytes((shared_data / "SurfaceTopography" / name).read_bytes(), ReadOptions(**options), name=name)


def expectations(shared_data):
    return json.loads((shared_data / "reference_values.json").read_text())["SurfaceTopography_file_expectations"]


# --- Nanosurf NID: the height channel is chosen by quantity, not by unit -------------------------------------


def lateral_force_nid(shared_data):
    """nid-1.nid (a lateral-force scan) with its deflection calibrated in metres, as contact-mode files carry it:
    then the first data set in a length unit is a deflection, not a height."""
    return (shared_data / "SurfaceTopography" / "nid-1.nid").read_bytes().replace(b"Dim2Unit=N", b"Dim2Unit=m")


def test_nid_deflection_in_metres_is_not_the_height_channel(shared_data):
    data = lateral_force_nid(shared_data)
    scan = read_bytes(data, name="lateral-force.nid")
    assert scan.metadata["channel"] == "Scan forward (Z-Axis)"
    assert scan.metadata["channels"].startswith("0 'Scan forward (Deflection)', 1 'Scan forward (Z-Axis)'")
    for channel in expectations(shared_data)["nid-1.nid"]["channels"]:
        heights = read_bytes(data, ReadOptions(channel=channel["name"]), name="x.nid").heights
        np.testing.assert_allclose(sq(heights), channel["rms_height_from_area"], rtol=1e-6)
    deflection = read_bytes(data, ReadOptions(channel="Scan forward (Deflection)"), name="x.nid")
    assert sq(deflection.heights) < 1e-9  # asked for by name: read, and far from the 240 nm of the height


def test_nid_without_a_height_channel_is_refused_unless_one_is_named(shared_data, run, tmp_path):
    path = tmp_path / "deflection-only.nid"
    path.write_bytes(lateral_force_nid(shared_data).replace(b"Dim2Name=Z-Axis", b"Dim2Name=Amplitude"))
    assert_one_line_error(run("info", path), "no height channel", "give --channel")
    assert run("info", "--channel", "0", path).returncode == 0


# --- Digital Surf SUR: images are refused; sur-3 decided -----------------------------------------------------


def sur_object(shared_data, kind, z_unit):
    """sur-2.sur with its studiable type (offset 18) and z unit (offset 212) changed."""
    header = bytearray((shared_data / "SurfaceTopography" / "sur-2.sur").read_bytes())
    header[18:20] = struct.pack("<h", kind)
    header[212:228] = z_unit.ljust(16, b"\0")
    return bytes(header)


@pytest.mark.parametrize(("kind", "unit"), [(12, b""), (10, b""), (3, b""), (2, b""), (2, b"V")])
def test_sur_images_and_values_that_are_not_lengths_are_refused(shared_data, run, tmp_path, kind, unit):
    path = tmp_path / "image.sur"
    path.write_bytes(sur_object(shared_data, kind, unit))
    assert_one_line_error(run("info", path), "--unit" if (kind, unit) == (2, b"") else "not heights")


def test_sur_rgb_image_of_the_issue_is_refused(shared_data):
    with pytest.raises(FormatError, match="SUR object 'Z' is a RGB image, not heights"):
        read_bytes(sur_object(shared_data, 12, b""), name="rgb.sur")


def test_sur_without_z_unit_reads_with_unit_given(shared_data):
    scan = read_bytes(sur_object(shared_data, 2, b""), ReadOptions(unit="mm"), name="x.sur")
    np.testing.assert_array_equal(scan.heights, load(shared_data, "sur-2.sur").heights)


def test_sur3_sq_is_that_of_the_measured_points(shared_data):
    """Gwyddion 2.62 gives 1.9200491394179295 mm, SurfaceTopography's old test 1.92 mm: both keep the 233,009
    points that the non-measured flag marks (-2 counts, below every measured point) as heights. On the measured
    points Gwyddion's heights equal rough's exactly; SurfaceTopography 1.27.1 masks them and gives rough's value."""
    scan = load(shared_data, "sur-3.sur")
    assert int(np.isnan(scan.heights).sum()) == 233009
    np.testing.assert_allclose(sq(scan.heights), 1.1131994265859693e-3, rtol=1e-12)


# --- WSxM: float data are taken as stored ------------------------------------------------------------------


def wsxm(values, kind, amplitude="13.7008 nm", extremes=("12.8379", "-0.862931"), channel="Topography"):
    ny, nx = values.shape
    header = (
        f"[Control]\r\n    X Amplitude: 600 nm\r\n    Y Amplitude: 600 nm\r\n[General Info]\r\n"
        f"    Acquisition channel: {channel}\r\n    Image Data Type: {kind}\r\n    Number of columns: {nx}\r\n"
        f"    Number of rows: {ny}\r\n    Z Amplitude: {amplitude}\r\n[Miscellaneous]\r\n"
        f"    Maximum: {extremes[0]}\r\n    Minimum: {extremes[1]}\r\n[Header end]\r\n"
    )
    head = f"WSxM file copyright UAM\r\nSxM Image file\r\nImage header size: {len(header) + 70}\r\n"
    dtype = {"double": "<f8", "float": "<f4", "short": "<i2"}[kind]
    return (head + header).encode() + np.asarray(values, dtype).tobytes()


def test_wsxm_double_data_are_the_stored_heights(shared_data):
    """SurfaceTopography's test asserts 1.6541594 nm (its old rescaling gave 1.654156)."""
    raw = (shared_data / "SurfaceTopography" / "stp-1.stp").read_bytes()
    start = raw.index(b"\n", raw.index(b"[Header end]")) + 1
    stored = np.frombuffer(raw, "<f8", 256 * 256, start).reshape(256, 256)
    scan = load(shared_data, "stp-1.stp")
    np.testing.assert_array_equal(scan.heights, stored[::-1, ::-1] * NM)
    np.testing.assert_allclose(sq(scan.heights) / NM, 1.6541594, rtol=1e-6)
    np.testing.assert_allclose(sq(load(shared_data, "top-1.top").heights) / NM, 3.153099, rtol=1e-6)


@pytest.mark.parametrize("kind", ["double", "float"])
def test_wsxm_float_heights_are_not_rescaled_by_six_digit_header_values(kind):
    values = np.array([[-0.8629313034883381, 12.8378757297439], [1.0, 2.5]])
    scan = read_bytes(wsxm(values, kind), name="x.stp")
    np.testing.assert_array_equal(scan.heights, values.astype(kind[0]).astype(float)[::-1, ::-1] * NM)


def test_wsxm_integer_counts_are_scaled_to_the_z_amplitude():
    scan = read_bytes(wsxm(np.array([[0, 100], [50, 25]]), "short", "20 nm", ("100", "0")), name="x.top")
    np.testing.assert_allclose(scan.heights, [[5 * NM, 10 * NM], [20 * NM, 0.0]], rtol=1e-15)


def test_wsxm_channel_that_is_not_a_height_is_refused(run, tmp_path):
    path = tmp_path / "phase.top"
    path.write_bytes(wsxm(np.ones((2, 2)), "double", channel="Normal force"))
    assert_one_line_error(run("info", path), "'Normal force' channel, not heights")
    assert run("info", "--channel", "Normal force", path).returncode == 0


# --- MountainsMap MNT: the size is MountainsMap's extent -----------------------------------------------------


def test_mnt_sizes_equal_the_bcr_export_of_the_same_measurement(shared_data):
    mnt, bcr = load(shared_data, "mnt-1.mnt"), load(shared_data, "bcrf-1.bcrf")
    np.testing.assert_allclose(mnt.size, (1777404 * NM, 1110878 * NM), rtol=1e-12)
    np.testing.assert_allclose(mnt.spacing, bcr.spacing, rtol=1e-12)
    np.testing.assert_allclose(mnt.heights, bcr.heights, rtol=0, atol=1e-13)


def test_mnt2_size_is_surfacetopography_s(shared_data):
    scan = load(shared_data, "mnt-2.mnt")
    np.testing.assert_allclose(np.array(scan.size) / UM, (95.77, 71.81), atol=0.005)  # its test: 2 decimals
    np.testing.assert_allclose(np.array(scan.size) / UM, (95.77176348102515, 71.8101025631768), rtol=1e-9)


# --- Regridding: one jittered x does not eat Rq -----------------------------------------------------------


@pytest.mark.parametrize("method", ["linear", "bandlimited"])
def test_one_jittered_x_barely_changes_rq(shared_data, method):
    """mitutoyo_nonuniform_mock.xlsx in SurfaceTopography is mitutoyo_mock with one x shifted by 0.1 µm."""
    from rough.io import read

    profile = read(shared_data / "SurfaceTopography" / "mitutoyo_mock.xlsx")
    heights, step = profile.heights, profile.spacing[0]
    x = np.arange(heights.size) * step
    x[heights.size // 2] += 0.1 * UM
    regridded = regrid(x, heights, step, method)
    assert abs(rq(regridded) / rq(heights) - 1) < 1e-3


def test_the_command_line_regrid_keeps_rq_of_a_jittered_profile(shared_data, run, tmp_path):
    """SurfaceTopography's Rq of mitutoyo_mock.xlsx is 0.16866328079293708 µm; `--regrid 0.5um` took 17 % off."""
    from rough.io import read

    profile = read(shared_data / "SurfaceTopography" / "mitutoyo_mock.xlsx")
    x = np.arange(profile.heights.size) * profile.spacing[0]
    x[480] += 0.1 * UM
    path = tmp_path / "jittered.txt"
    path.write_text("x z\n" + "".join(f"{float(a)!r} {float(b)!r}\n" for a, b in zip(x, profile.heights)))
    for value in ("0.5um", "0.5um:bandlimited", "0.5um:linear"):
        facts = json.loads(run("info", "--json", "--regrid", value, path, check=True).stdout)
        np.testing.assert_allclose(facts["Rq"], 0.16866328079293708 * UM, rtol=1e-3)


def test_the_default_regrid_method_is_linear():
    x = np.array([0.0, 1.0, 2.1, 3.0])
    np.testing.assert_array_equal(
        read_bytes(b"x z\n0 0\n1 1\n2.1 5\n3 3\n", ReadOptions(regrid=1.0)).heights[:2], [0, 1]
    )
    assert ReadOptions(regrid=1.0).regrid == (1.0, "linear")
    assert regrid(x, x**2, 1.0).tolist() == regrid(x, x**2, 1.0, "linear").tolist()


def test_band_limited_regridding_keeps_a_profile_sampled_at_the_new_spacing():
    heights = np.random.default_rng(3).normal(size=1001)
    x = np.arange(1001.0)
    x[500] += 0.2
    kept = regrid(x, heights, 1.0, "bandlimited")
    mask = np.ones(1001, bool)
    mask[499:502] = False
    np.testing.assert_array_equal(kept[mask], heights[mask])


# --- ISO 25178-71 SDF, revision 2.0 ----------------------------------------------------------------------


def test_sdf_aiso_2_reads_like_aiso_1(shared_data):
    text = (shared_data / "SurfaceTopography" / "sdf-1.sdf").read_bytes()
    revised = read_bytes(text.replace(b"aISO-1.0", b"aISO-2.0", 1), name="x.sdf")
    assert revised.source_format == "sdf"
    np.testing.assert_array_equal(revised.heights, load(shared_data, "sdf-1.sdf").heights)
    np.testing.assert_allclose(revised.size, (7 * UM, 4 * UM), rtol=1e-12)


def test_sdf_biso_2_has_32_bit_point_counts():
    body = np.arange(70000 * 2, dtype="<i2") % 1000
    header = struct.pack(
        "<8s10s12s12sIIddddBBB", b"bISO-2.0", b"TEST", b"010120201200", b"010120201200", 70000, 2,
        1e-6, 2e-6, 1e-9, 1e-9, 0, 5, 0,
    )  # fmt: skip
    scan = read_bytes(header + body.tobytes())
    assert scan.heights.shape == (2, 70000)
    np.testing.assert_array_equal(scan.heights.ravel(), body * 1e-9)


def test_sdf_cut_inside_its_data_is_refused(shared_data):
    text = (shared_data / "SurfaceTopography" / "sdf-1.sdf").read_bytes()
    cut = text[: text.index(b"0.97986 0.97862 0.97491 0.96874 0.96012 0.94907 0.97986") + 54]  # "0.9798" for 0.97986
    with pytest.raises(FormatError, match="not closed by a"):
        read_bytes(cut, name="x.sdf")


# --- Gwyddion GWY without units ---------------------------------------------------------------------------


def unitless_gwy(tmp_path):
    from gwyfile.objects import GwyContainer, GwyDataField

    container = GwyContainer()
    container["/0/data"] = GwyDataField(np.arange(12.0).reshape(3, 4), xreal=4.0, yreal=3.0)
    container["/0/data/title"] = "Height"
    path = tmp_path / "unitless.gwy"
    container.tofile(str(path))
    return path


def test_a_unitless_gwy_reads_with_unit(run, tmp_path):
    path = unitless_gwy(tmp_path)
    assert_one_line_error(run("info", path), "no unit", "--unit")
    assert run("info", "--unit", "m", path).returncode == 0
    scan = read_bytes(path.read_bytes(), ReadOptions(unit="nm"))
    np.testing.assert_allclose(scan.heights, np.arange(12.0).reshape(3, 4) * NM, rtol=1e-15)
    np.testing.assert_allclose(scan.spacing, (NM, NM), rtol=1e-15)


def test_gwy_default_channel_is_a_height_by_title(tmp_path):
    from gwyfile.objects import GwyContainer, GwyDataField

    container = GwyContainer()
    for number, (title, unit) in enumerate([("Deflection forward", "m"), ("Z-Axis forward", "m")]):
        container[f"/{number}/data"] = GwyDataField(np.full((2, 2), number + 1.0), si_unit_xy="m", si_unit_z=unit)
        container[f"/{number}/data/title"] = title
    buffer = io.BytesIO()
    container.tofile(buffer)
    scan = read_bytes(buffer.getvalue())
    assert scan.metadata["channel"] == "Z-Axis forward" and scan.heights[0, 0] == 2.0


# --- JPK image scans ----------------------------------------------------------------------------------------


def jpk(channels, size=(2e-6, 1e-6), reflect=0):
    """A JPK image scan as JPK writes one (Gwyddion's jpkscan.c, SurfaceTopography's JPK.py): a big-endian TIFF
    whose thumbnail carries the scan's tags and whose further pages are channels with scaling slots."""
    import tifffile

    def slot(number, name, unit, multiply, offset):
        base = 0x8090 + 0x30 * number
        return [
            (base, "s", 0, name, True),
            (base + 0x12, "s", 0, unit, True),
            (base + 0x13, "s", 0, "LinearScaling", True),
            (base + 0x14, "d", 1, multiply, True),
            (base + 0x15, "d", 1, offset, True),
        ]

    buffer = io.BytesIO()
    with tifffile.TiffWriter(buffer, byteorder=">") as tiff:
        scan = [(0x8042, "d", 1, size[0], True), (0x8043, "d", 1, size[1], True), (0x8050, "s", 0, "height", True)]
        scan.append((0x8003, "s", 0, "2024-05-06 07:08:09", True))
        tiff.write(np.zeros((8, 8, 3), np.uint8), photometric="rgb", extratags=scan)
        for channel, fancy, raw, unit, multiply, offset in channels:
            tags = [(0x8050, "s", 0, channel, True), (0x8051, "H", 1, 0, True), (0x8052, "s", 0, fancy, True)]
            tags += [(0x8080, "H", 1, 2, True), (0x8081, "s", 0, "nominal", True), (0x8045, "H", 1, reflect, True)]
            tags += slot(0, "raw", "V", 1.0, 0.0) + slot(1, "nominal", unit, multiply, offset)
            tiff.write(raw, photometric="minisblack", extratags=tags)
    return buffer.getvalue()


RAW = np.arange(12, dtype=">i4").reshape(3, 4)
DEFLECTION = ("vDeflection", "Vertical Deflection", RAW, "m", 1e-9, 0.0)
HEIGHT = ("height", "Height", RAW, "m", 2e-9, 5e-9)


def test_jpk_height_channel_scaling_size_and_orientation():
    """Gwyddion 2.62 shows these files with the stored lines reversed (GridReflect 0) or as stored (1)."""
    data = jpk([DEFLECTION, ("phase", "Phase", RAW, "deg", 1.0, 0.0), HEIGHT])
    assert registry.sniff(data) == "jpk" and registry.sniff(data, "scan.jpk") == "jpk"
    scan = read_bytes(data, name="scan.jpk")
    assert scan.metadata["channel"] == "Height"
    assert scan.metadata["channels"] == "0 'Vertical Deflection', 1 'Height'"
    np.testing.assert_allclose(scan.heights, (RAW[::-1] * 2e-9 + 5e-9), rtol=1e-15)
    np.testing.assert_allclose(scan.size, (2e-6, 1e-6), rtol=1e-15)
    assert scan.units.z == "m" and scan.metadata["jpk_start_date"] == "2024-05-06 07:08:09"
    reflected = read_bytes(jpk([HEIGHT], reflect=1))
    np.testing.assert_allclose(reflected.heights, RAW * 2e-9 + 5e-9, rtol=1e-15)
    nanometres = read_bytes(jpk([("height", "Height", RAW.astype(">u2"), "nm", 0.5, 1.0)]))
    np.testing.assert_allclose(nanometres.heights, (RAW[::-1] * 0.5 + 1.0) * NM, rtol=1e-15)


def test_jpk_deflection_alone_is_refused_unless_named(run, tmp_path):
    path = tmp_path / "deflection.jpk"
    path.write_bytes(jpk([DEFLECTION]))
    assert_one_line_error(run("info", path), "no height channel", "give --channel")
    assert run("info", "--channel", "Vertical Deflection", path).returncode == 0


def test_a_truncated_jpk_is_refused(run, tmp_path):
    data = jpk([HEIGHT])
    for cut in (len(data) - 4, len(data) // 2, 200):
        path = tmp_path / f"cut-{cut}.jpk"
        path.write_bytes(data[:cut])
        assert_one_line_error(run("info", path))


# --- Truncated files ----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "name", ["nid-1.nid", "sur-2.sur", "sur-3.sur", "stp-1.stp", "top-1.top", "mnt-1.mnt", "mnt-2.mnt"]
)
def test_a_file_cut_short_is_refused(shared_data, name):
    """(An SDF cut in its trailer keeps its data whole and reads; one cut in its data is refused, above.)"""
    data = (shared_data / "SurfaceTopography" / name).read_bytes()
    for cut in (len(data) - 1, len(data) - 9, len(data) * 3 // 4):
        with pytest.raises(FormatError):
            read_bytes(data[:cut], name=name)


def test_a_gwy_cut_short_is_refused(tmp_path):
    data = unitless_gwy(tmp_path).read_bytes()
    for cut in (len(data) - 1, len(data) - 9, len(data) * 3 // 4, 200):
        with pytest.raises(FormatError):
            read_bytes(data[:cut], ReadOptions(unit="m"))
