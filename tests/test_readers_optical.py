"""Optical-profiler and stylus readers against their example files: Zygo MetroPro, Wyko OPD,
Bruker OPDx, Nanofocus NMS and Keyence ZON (values from ../shared/data/INDEX.md §2, §2b, §2c)."""

import numpy as np
import pytest
from peer_statistics import rq, sq

import rough
from rough.errors import FormatError, InputError
from rough.io import ReadOptions, read_bytes, registry

from conftest import shared_data_path

DATA = shared_data_path()  # ../shared/data, or $ROUGH_SHARED/data
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason="needs ../shared/data")

METROPRO = DATA / "SurfaceTopography" / "metropro-1.dat"
OPD = DATA / "SurfaceTopography" / "opd-1.opd"
OPDX = DATA / "SurfaceTopography" / "opdx-3.opdx"
NMS = DATA / "SurfaceTopography" / "nms-1.nms"
ZON = DATA / "surfalize" / "test_1.zon"
FILES = {"metropro": METROPRO, "opd": OPD, "opdx": OPDX, "nms": NMS, "zon": ZON}


@needs_data
@pytest.mark.parametrize("name", FILES)
def test_the_format_is_sniffed_from_the_content(name):
    assert registry.sniff(FILES[name].read_bytes()[: registry.HEAD]) == name


@needs_data
def test_metropro_matches_surfacetopography():
    scan = rough.read(METROPRO)
    assert scan.source_format == "metropro"
    assert scan.heights.shape == (480, 640)
    np.testing.assert_allclose(scan.size, (7.028812979115173e-4, 5.27160973433638e-4), rtol=1e-6)
    np.testing.assert_allclose(sq(scan.heights), 7.528822204734589e-08, rtol=1e-6)
    np.testing.assert_allclose(rq(scan.heights), 7.524071e-08, rtol=1e-6)
    assert not np.isnan(scan.heights).any()
    assert scan.metadata["vendor"] == "Zygo"
    assert scan.metadata["date"] == "2011-07-23T16:49:36+00:00"
    assert scan.metadata["metropro_objective"] == "20X  Mirau"


@needs_data
def test_metropro_invalid_phase_is_nan():
    data = bytearray(METROPRO.read_bytes())
    phase = 834 + 2 * 640 * 480  # header, then one intensity bucket
    data[phase + 4 * 5 : phase + 4 * 6] = (2147483647).to_bytes(4, "big")
    heights = read_bytes(bytes(data)).heights
    assert np.isnan(heights).sum() == 1 and np.isnan(heights[0, 5])


@needs_data
def test_opd_matches_surfacetopography():
    scan = rough.read(OPD)
    assert scan.source_format == "opd"
    assert scan.heights.shape == (480, 640)
    np.testing.assert_allclose(scan.size, (0.125909140e-3, 0.094431855e-3), rtol=1e-6)
    assert np.isnan(scan.heights).sum() == 116
    assert scan.metadata["channel"] == "Raw"
    assert scan.metadata["channels"] == "0 'Raw', 1 'SecArr_0', 2 'Image'"
    assert scan.metadata["date"] == "2015-07-07T16:19:48"
    assert scan.metadata["opd_wavelength"] == "577.295 nm"
    # SurfaceTopography's Sq of a masked map divides by all points; its value pins the heights
    z = scan.heights[~np.isnan(scan.heights)] * 1e3  # mm
    biased_mean = z.sum() / scan.heights.size
    np.testing.assert_allclose(np.sqrt(np.sum((z - biased_mean) ** 2) / scan.heights.size), 8.355505688524562e-06)
    np.testing.assert_allclose(sq(scan.heights), 8.356451162720973e-09, rtol=1e-9)


@needs_data
def test_opd_equals_the_hdf5_copy_of_its_heights():
    h5py = pytest.importorskip("h5py")
    with h5py.File(DATA / "SurfaceTopography" / "multiple_data_sets.h5") as file:
        copy = file["dataset2"][...].astype(np.float64).T * 1e-3  # SurfaceTopography's z[x, y] in mm
    heights = rough.read(OPD).heights
    valid = ~np.isnan(heights)
    np.testing.assert_allclose(heights[valid], copy[valid], rtol=0, atol=1e-13)


@needs_data
def test_an_opd_intensity_channel_is_refused_by_name():
    data = OPD.read_bytes()
    assert read_bytes(data, ReadOptions(channel="raw")).metadata["channel"] == "Raw"
    with pytest.raises(FormatError, match="'Image' is an intensity image"):
        read_bytes(data, ReadOptions(channel="Image"))


@needs_data
def test_opdx_equals_its_text_export():
    scan = rough.read(OPDX)
    x, z = np.loadtxt(DATA / "SurfaceTopography" / "opdx-3.txt", unpack=True)  # metres
    assert scan.source_format == "opdx"
    assert scan.heights.shape == (3001,)
    np.testing.assert_allclose(scan.heights, z, rtol=1e-7)
    np.testing.assert_allclose(scan.positions(), x, rtol=1e-7, atol=1e-15)  # the text has 8 digits
    np.testing.assert_allclose(scan.spacing, (49.966688862798314e-6 / 3000,), rtol=1e-9)  # Extent / (n - 1)
    assert scan.metadata["instrument"] == "Dektak Profiler"
    assert scan.metadata["vendor"] == "Bruker"
    assert scan.metadata["date"] == "2021-11-02T15:39:13+00:00"  # FILETIME; the locale's Date says 2/11/2021
    assert scan.units == rough.Units(xy="um", z="um")


@needs_data
def test_nms_reads_nanometre_pixels():
    scan = rough.read(NMS)
    assert scan.source_format == "nms"
    assert scan.heights.shape == (512, 512)
    np.testing.assert_allclose(scan.spacing, (312.4999911618964e-9,) * 2)
    np.testing.assert_allclose(scan.size, (160e-6, 160e-6), rtol=1e-7)
    assert np.isfinite(scan.heights).all()
    np.testing.assert_allclose(
        (scan.heights.min(), scan.heights.max()), (2.689124584197998e-6, 6.007402420043945e-6), rtol=1e-12
    )
    # SurfaceTopography's Sq (µm) with its 1/65534 raw step, scaled to ours (1/65535)
    np.testing.assert_allclose(sq(scan.heights), 0.718718598411047e-6 * 65534 / 65535, rtol=1e-9)
    assert scan.metadata["date"] == "2022-02-09T13:25:00"
    assert scan.metadata["title"] == "Confocal Height Image"


@needs_data
def test_nms_without_its_format_name_is_read_by_extension():
    data = bytearray(NMS.read_bytes())
    data[32:38] = b"XXXXXX"
    assert read_bytes(bytes(data), name="scan.nms").heights.shape == (512, 512)


@needs_data
def test_zon_applies_its_mask():
    scan = rough.read(ZON)
    assert scan.source_format == "zon"
    assert scan.heights.shape == (769, 1024)
    np.testing.assert_allclose(scan.spacing, (2.36311288524538e-05,) * 2, rtol=1e-15)
    assert np.isnan(scan.heights).sum() == 2048
    np.testing.assert_allclose(sq(scan.heights), 0.0005696934660786111, rtol=1e-12)
    assert scan.metadata["instrument"] == "VR-6100"
    assert scan.metadata["vendor"] == "Keyence"
    assert scan.metadata["date"] == "2025-12-18T12:47:39-06:00"


def _damaged(data, seed):
    """Truncations at fixed fractions and 24 single-byte flips in the first 4 KiB."""
    rng = np.random.default_rng(seed)
    for fraction in (0.001, 0.01, 0.1, 0.3, 0.5, 0.9, 0.999):
        yield data[: max(1, int(len(data) * fraction))]
    for position in rng.integers(0, min(len(data), 4096), 24):
        flipped = bytearray(data)
        flipped[position] ^= 0xFF
        yield bytes(flipped)


@needs_data
@pytest.mark.parametrize("name", FILES)
def test_damaged_files_are_read_or_refused_in_one_line(name):
    data = FILES[name].read_bytes()
    for damaged in _damaged(data, seed=len(data)):
        try:
            surface = read_bytes(damaged, name=FILES[name].name)
        except InputError as error:
            assert "\n" not in str(error)
        else:
            assert isinstance(surface, rough.Surface)


@needs_data
@pytest.mark.parametrize(
    "name, offset, value, message",
    [
        ("metropro", 70, b"\xff\xff", "runs past the end"),
        ("metropro", 218, b"\x00\x07", "phase_res 7"),
        ("opd", 18 + 2, b"\xff\xff\xff\x7f", "runs past the end"),
        ("opdx", 12, b"\xff\xff\xff\x7f", "runs past the end"),
        ("nms", 1368, b"\x00\x40\x00\x00", "runs past the end"),
        ("nms", 1376, b"\x00" * 8, "not a pixel size"),
    ],
)
def test_corrupted_header_fields_are_named(name, offset, value, message):
    data = bytearray(FILES[name].read_bytes())
    data[offset : offset + len(value)] = value
    with pytest.raises(FormatError, match=message):
        read_bytes(bytes(data), name=FILES[name].name)


def _vca(name, kind, payload):
    """One OPDx item: name, type byte, value (see rough.io.opdx)."""
    raw = name.encode()
    return len(raw).to_bytes(4, "little") + raw + bytes([kind]) + payload


def _sized(payload):
    return b"\x04" + len(payload).to_bytes(4, "little") + payload


def _text(text):
    raw = text.encode()
    return len(raw).to_bytes(4, "little") + raw


def _container(name, *children):
    return _vca(name, 0x7D, _sized(b"".join(children) + _vca("", 0x7F, b"") + b"\0\0"))


def _quantity(value, symbol):
    return _sized(np.float64(value).tobytes() + _text("unit") + _text(symbol))


def test_a_synthetic_opdx_map_is_read_row_by_row():
    """No example map exists: this only pins the layout as SurfaceTopography reads it."""
    rows, columns = 3, 4
    values = np.arange(rows * columns, dtype="<f4")
    matrix = _text("float") + (0).to_bytes(4, "little") + _text("m")
    matrix += _sized(rows.to_bytes(4, "little") + columns.to_bytes(4, "little") + values.tobytes())
    data = b"VCA DATA\x01\x00\x00\x55" + b"".join(
        [
            _container(
                "2D_Data",
                _container(
                    "Height",
                    _vca("Dimension1Points", 0x07, rows.to_bytes(4, "little")),
                    _vca("Dimension2Points", 0x07, columns.to_bytes(4, "little")),
                    _vca("Dimension1Extent", 0x13, _quantity(2.0, "µm")),
                    _vca("Dimension2Extent", 0x13, _quantity(3.0, "µm")),
                    _vca("DataScale", 0x13, _quantity(0.5, "nm")),
                    _vca("Matrix", 0x00, matrix),
                ),
            ),
            _container(
                "MetaData",
                _vca("DataKind", 0x12, b"\x01\x0eSurface Height"),
                _vca("PrimaryData2D", 0x12, b"\x01\x06Height"),
            ),
            _vca("", 0x7F, b""),
        ]
    )
    scan = read_bytes(data)
    assert scan.heights.shape == (rows, columns)
    np.testing.assert_allclose(scan.heights, values.reshape(rows, columns) * 0.5e-9)
    np.testing.assert_allclose(scan.spacing, (1e-6, 1e-6))
    assert scan.units == rough.Units(xy="um", z="nm")
