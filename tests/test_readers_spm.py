"""Scanning-probe readers against their example files: Bruker Nanoscope, BCR-STM, Agilent MI, Nanosurf NID,
WSxM, Igor IBW and Park Systems TIFF (values from ../shared/data/INDEX.md §2, §2b and reference_values.json)."""

import numpy as np
import pytest
from peer_statistics import rq, sq

from rough.errors import FormatError, InputError
from rough.io import ReadOptions, read_bytes, registry

from conftest import shared_data_path

DATA = shared_data_path()  # ../shared/data, or $ROUGH_SHARED/data
ST = DATA / "SurfaceTopography"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason="needs ../shared/data")

FILES = {
    "di-1.di": "di",
    "di-3.di": "di",
    "di-5.di": "di",
    "bcrf-1.bcrf": "bcr",
    "mi-1.mi": "mi",
    "nid-1.nid": "nid",
    "stp-1.stp": "wsxm",
    "top-1.top": "wsxm",
    "spot_1-1000nm.ibw": "ibw",
    "10x10-one_channel_without_name.ibw": "ibw",
    "example_ps.tiff": "ps",
}
NM, UM = 1e-9, 1e-6


def read(name, **options):
    return read_bytes((ST / name).read_bytes(), ReadOptions(**options), name=name)


@needs_data
@pytest.mark.parametrize("name", FILES)
def test_the_format_is_sniffed_from_the_content(name):
    assert registry.sniff((ST / name).read_bytes()[: registry.HEAD]) == FILES[name]


@needs_data
def test_di1_height_channels_date_and_orientation():
    scan = read("di-1.di")
    assert scan.heights.shape == (512, 512)
    np.testing.assert_allclose(scan.size, (500 * NM, 500 * NM), rtol=1e-12)
    assert scan.metadata["channels"] == "0 'Height', 1 'Height', 2 'Phase', 3 'AmplitudeError'"
    assert scan.metadata["channel"] == "Height"
    assert (scan.metadata["date"], scan.metadata["instrument"], scan.metadata["vendor"]) == (
        "2016-01-12T09:57:48",
        "Dimension V",
        "Bruker",
    )
    assert sq(scan.heights) / NM == pytest.approx(9.9459868005603909, abs=1e-7)
    assert sq(read("di-1.di", channel=1).heights) / NM == pytest.approx(114.01328027385664, abs=1e-7)
    # SurfaceTopography's h[x, y] corners [0,0], [0,-1], [-1,0], [-1,-1] are z[0,0], z[-1,0], z[0,-1], z[-1,-1]
    corners = np.array([scan.heights[0, 0], scan.heights[-1, 0], scan.heights[0, -1], scan.heights[-1, -1]])
    np.testing.assert_allclose(corners / NM, [6.060, 2.843, -9.740, -30.306], atol=1e-3)


@needs_data
def test_di1_phase_channel_is_listed_but_refused():
    with pytest.raises(FormatError, match="'Phase' holds values in º, not heights"):
        read("di-1.di", channel="Phase")


@needs_data
def test_di3_defaults_to_the_height_sensor():
    scan = read("di-3.di")
    assert scan.metadata["channels"] == "0 'ZSensor', 1 'AmplitudeError', 2 'Phase', 3 'Height'"
    assert scan.metadata["channel"] == "ZSensor"
    assert scan.heights.shape == (256, 256)
    np.testing.assert_allclose(scan.size, (10 * UM, 10 * UM), rtol=1e-12)
    assert sq(scan.heights) / NM == pytest.approx(226.42539668457405, abs=1e-7)
    assert sq(read("di-3.di", channel="Height").heights) / NM == pytest.approx(264.00285276203158, abs=1e-7)


@needs_data
def test_di5_four_byte_data():
    scan = read("di-5.di")
    np.testing.assert_allclose(sq(scan.heights) / NM, 5.831926, rtol=1e-7)
    assert scan.metadata["instrument"] == "Dimension Icon"


@needs_data
def test_di_corrupted_is_refused_in_one_line(run):
    with pytest.raises(FormatError) as refused:
        read("di_corrupted.di")
    assert "truncated" in str(refused.value) and "\n" not in str(refused.value)
    result = run("info", ST / "di_corrupted.di")
    assert result.returncode == 2 and len(result.stderr.decode().strip().splitlines()) == 1


@needs_data
def test_bcrf_matches_surfacetopography():
    scan = read("bcrf-1.bcrf")
    assert scan.heights.shape == (600, 960)
    np.testing.assert_allclose(scan.size, (1777404 * NM, 1110878 * NM), rtol=1e-12)
    assert not np.isnan(scan.heights).any()
    np.testing.assert_allclose(sq(scan.heights) / NM, 24.560207201442292, rtol=1e-6)
    np.testing.assert_allclose(rq(scan.heights) / NM, 24.009754961959388, rtol=1e-6)
    np.testing.assert_allclose(rq(scan.heights.T) / NM, 24.134045799796326, rtol=1e-6)


@needs_data
def test_mi_channels_units_and_first_height():
    scan = read("mi-1.mi")
    assert scan.metadata["channels"] == "0 'Topography', 1 'Deflection', 2 'Friction', 3 'Friction'"
    assert scan.heights.shape == (256, 256)
    np.testing.assert_allclose(scan.size, (2e-5, 2e-5), rtol=1e-12)  # the header's metres
    assert (scan.units.xy, scan.units.z) == ("m", "um")
    np.testing.assert_allclose(scan.heights[0, 0] / UM, -0.4986900329589844, rtol=1e-6)
    assert scan.metadata["date"] == "2014-02-18T15:00:51"
    with pytest.raises(FormatError, match="'Deflection' holds values in 'V'"):
        read("mi-1.mi", channel=1)


@needs_data
def test_mi_equals_the_hdf5_copy_of_its_topography():
    h5py = pytest.importorskip("h5py")
    with h5py.File(ST / "multiple_data_sets.h5") as copy:
        topography = copy["dataset1"][...]  # SurfaceTopography's h[x, y], µm
    np.testing.assert_allclose(read("mi-1.mi").heights / UM, topography.T, rtol=1e-12)


NID_SQ = {
    "Scan forward (Z-Axis)": 2.395896706764167e-07,
    "Scan forward (Z-AxisSensor)": 3.026701737129839e-07,
    "Scan backward (Z-Axis)": 2.3941867686171115e-07,
    "Scan backward (Z-AxisSensor)": 3.029781629305204e-07,
}


@needs_data
def test_nid_height_channels_match_surfacetopography():
    scan = read("nid-1.nid")
    assert scan.metadata["channels"] == ", ".join(f"{index} {name!r}" for index, name in enumerate(NID_SQ))
    assert scan.heights.shape == (256, 256)
    np.testing.assert_allclose(scan.size, (2e-5, 2e-5), rtol=1e-12)
    np.testing.assert_allclose(rq(scan.heights), 2.294702406191355e-07, rtol=1e-6)
    np.testing.assert_allclose(rq(scan.heights.T), 6.891854644154332e-08, rtol=1e-6)
    for name, expected in NID_SQ.items():
        np.testing.assert_allclose(sq(read("nid-1.nid", channel=name).heights), expected, rtol=1e-6)


@needs_data
@pytest.mark.parametrize(("name", "expected"), [("stp-1.stp", 1.6541594), ("top-1.top", 3.153099)])
def test_wsxm_matches_surfacetopography(name, expected):
    scan = read(name)
    assert scan.heights.shape == (256, 256)
    np.testing.assert_allclose(scan.size, (600 * NM, 600 * NM), rtol=1e-12)
    np.testing.assert_allclose(sq(scan.heights) / NM, expected, rtol=1e-6)


@needs_data
def test_ibw_kpfm_channels():
    scan = read("spot_1-1000nm.ibw")
    assert scan.metadata["channel"] == "HeightTrace"
    assert scan.metadata["channels"].count("'") == 16
    assert (scan.metadata["instrument"], scan.metadata["vendor"]) == ("Cypher", "Asylum Research")
    assert scan.heights.shape == (256, 256)
    np.testing.assert_allclose(scan.size, (2.007843137254902e-05,) * 2, rtol=1e-12)
    np.testing.assert_allclose(sq(scan.heights), 8.945481491256412e-08, rtol=1e-6)


@needs_data
def test_ibw_unnamed_channel_without_units():
    scan = read("10x10-one_channel_without_name.ibw")
    assert scan.metadata["channels"] == "0 'no name (1)'"
    assert scan.heights.shape == (10, 10)
    np.testing.assert_allclose(sq(scan.heights), 0.480049350063276, rtol=1e-6)


@needs_data
def test_ibw_is_recognised_by_its_checksum_without_extension():
    assert registry.sniff((ST / "spot_1-1000nm.ibw").read_bytes()[: registry.HEAD], name="scan.bin") == "ibw"


@needs_data
def test_park_systems_tiff():
    scan = read("example_ps.tiff")
    assert scan.metadata["channel"] == "Z Height"
    assert scan.heights.shape == (512, 512)
    np.testing.assert_allclose(scan.size, (UM, UM), rtol=1e-12)
    np.testing.assert_allclose(sq(scan.heights) / UM, 0.003933333499668988, rtol=1e-6)


def test_a_plain_tiff_is_not_taken_for_park_systems():
    header = b"II*\0" + (8).to_bytes(4, "little") + (1).to_bytes(2, "little")
    entry = (256).to_bytes(2, "little") + (4).to_bytes(2, "little") + (1).to_bytes(4, "little") + bytes(4)
    assert not registry.module("ps").probe(header + entry + bytes(4))


def damaged(data):
    """Truncations at fixed fractions and 24 single-byte flips in the first 4 KiB."""
    for fraction in (0.0005, 0.01, 0.1, 0.5, 0.999):
        yield data[: max(1, int(len(data) * fraction))]
    for position in np.random.default_rng(15).integers(0, min(len(data), 4096), 24):
        flipped = bytearray(data)
        flipped[position] ^= 0xFF
        yield bytes(flipped)


@needs_data
@pytest.mark.parametrize("name", [*FILES, "di_corrupted.di"])
def test_damaged_files_are_read_or_refused_in_one_line(name):
    for data in damaged((ST / name).read_bytes()):
        try:
            read_bytes(data, name=name)
        except InputError as error:
            assert "\n" not in str(error)


@needs_data
@pytest.mark.parametrize(
    ("name", "old", "new", "message"),
    [
        ("di-1.di", b"Samps/line: 512", b"Samps/line: 5x2", "Samps/line"),
        ("di-1.di", b"Data offset: 40960", b"Data offset: 9e999", "Data offset"),
        ("mi-1.mi", b"xPixels       256", b"xPixels       300", "runs past the end"),
        ("nid-1.nid", b"Points=256", b"Points=99999", "ends at byte"),
        ("stp-1.stp", b"Number of rows: 256", b"Number of rows: 65536", "runs past the end"),
        ("top-1.top", b"Image Data Type: short", b"Image Data Type: quad", "Image Data Type"),
    ],
)
def test_corrupted_header_fields_are_named(name, old, new, message):
    data = (ST / name).read_bytes()
    assert old in data
    with pytest.raises(FormatError, match=message):
        read_bytes(data.replace(old, new), name=name)


@needs_data
def test_bcr_header_size_past_the_end_is_refused():
    data = (ST / "bcrf-1.bcrf").read_bytes()
    old = "headersize = 2048".encode("utf-16-le")
    with pytest.raises(FormatError, match="headersize"):
        read_bytes(data.replace(old, "headersize = 9999999".encode("utf-16-le"), 1)[:8192], name="x.bcrf")


@needs_data
@pytest.mark.parametrize(("name", "keep"), [("spot_1-1000nm.ibw", 500000), ("example_ps.tiff", 3000)])
def test_library_log_messages_stay_off_the_terminal(run, tmp_path, name, keep):
    damaged_file = tmp_path / name
    damaged_file.write_bytes((ST / name).read_bytes()[:keep])
    result = run("info", damaged_file)
    assert result.returncode == 2
    assert len(result.stderr.decode().strip().splitlines()) == 1, result.stderr.decode()[:300]
