"""Readers of profilometer formats (Digital Surf SUR and MountainsMap MNT, Sensofar PLU,
FRT MicroProf, TrueMap TMD) against the expectations of the projects their example
files come from (../shared/data/INDEX.md §2, §2b), and their error paths."""

import struct
import zlib

import numpy as np
import pytest
from peer_statistics import rq, sq

from rough.errors import InputError
from rough.io import ReadOptions, read_bytes

from conftest import shared_data_path

DATA = shared_data_path()  # ../shared/data, or $ROUGH_SHARED/data
EXAMPLES = DATA / "SurfaceTopography"
pytestmark = pytest.mark.skipif(not DATA.is_dir(), reason="needs ../shared/data")

FILES = ("sur-2.sur", "sur-3.sur", "plu-1.plu", "frt-1.frt", "frt-2.frt", "tmd-1.tmd", "mnt-1.mnt", "mnt-2.mnt")


def load(name, **options):
    return read_bytes((EXAMPLES / name).read_bytes(), ReadOptions(**options), name=name)


def test_sur3_matches_surfacetopography():
    scan = load("sur-3.sur")
    assert scan.source_format == "sur" and scan.heights.shape == (512, 512)
    np.testing.assert_allclose(scan.size, (0.151319552, 0.151319552), rtol=1e-6)
    assert scan.units.xy == "nm" and scan.units.z == "m"
    assert scan.metadata["date"] == "2023-06-22T10:08:53"
    invalid = np.isnan(scan.heights)
    assert invalid.sum() == 233009
    # SurfaceTopography keeps the non-measured marker (zmin - 2 = -2 counts) as a height.
    raw = (EXAMPLES / "sur-3.sur").read_bytes()
    dz, z_offset = struct.unpack_from("<f", raw, 128)[0], struct.unpack_from("<f", raw, 474)[0]
    unmasked = np.where(invalid, -2 * dz + z_offset, scan.heights)
    np.testing.assert_allclose(sq(unmasked), 0.0019200491394179297, rtol=1e-6)
    np.testing.assert_allclose(sq(scan.heights), 0.0011131994265859693, rtol=1e-9)  # rough's, valid points only


def test_sur2_reads_with_its_non_measured_points():
    scan = load("sur-2.sur")
    assert scan.heights.shape == (484, 563) and int(np.isnan(scan.heights).sum()) == 117
    np.testing.assert_allclose(scan.spacing, (3.484e-6, 3.484e-6), rtol=1e-6)
    assert scan.units.xy == "mm" and "date" not in scan.metadata


def _compressed(raw, streams=2):
    """sur-3 rewritten as a DSCOMPRESSED file of ``streams`` zlib streams."""
    points = raw[512:]
    cut = np.linspace(0, len(points), streams + 1).astype(int)
    parts = [points[a:b] for a, b in zip(cut[:-1], cut[1:])]
    packed = [zlib.compress(part) for part in parts]
    sizes = b"".join(struct.pack("<II", len(part), len(blob)) for part, blob in zip(parts, packed))
    body = struct.pack("<I", streams) + sizes + b"".join(packed)
    header = bytearray(raw[:512])
    header[:12] = b"DSCOMPRESSED"
    header[324:328] = struct.pack("<I", len(body))
    return bytes(header) + body


def test_sur_compressed_variant_reads_like_the_plain_file():
    """Self-consistency only: no DSCOMPRESSED example file exists."""
    raw = (EXAMPLES / "sur-3.sur").read_bytes()
    compressed = read_bytes(_compressed(raw), name="x.sur")
    np.testing.assert_array_equal(compressed.heights, load("sur-3.sur").heights)


def test_sur_objects_are_channels():
    joined = (EXAMPLES / "sur-2.sur").read_bytes() + (EXAMPLES / "sur-3.sur").read_bytes()
    second = read_bytes(joined, ReadOptions(channel="1"), name="x.sur")
    np.testing.assert_array_equal(second.heights, load("sur-3.sur").heights)
    assert second.metadata["channels"] == "0 'Z', 1 'Z'"
    assert read_bytes(joined, name="x.sur").heights.shape == (484, 563)


def test_plu1_matches_surfacetopography():
    scan = load("plu-1.plu")
    assert scan.heights.shape == (576, 768)
    np.testing.assert_allclose(np.array(scan.size) * 1e6, (1274.880066, 956.160049), rtol=1e-6)
    np.testing.assert_allclose(sq(scan.heights) * 1e6, 2.834391, rtol=1e-6)
    np.testing.assert_allclose(rq(scan.heights) * 1e6, 2.833895, rtol=1e-6)
    assert scan.metadata["date"] == "2023-03-10T15:35:59+00:00"  # the file's text says 16:35:59 local time
    assert scan.units.z == "um" and not np.isnan(scan.heights).any()


@pytest.mark.parametrize(
    "name, shape, size, invalid, date",
    [
        ("frt-1.frt", (500, 500), (0.012, 0.012), 76456, "2023-03-10T15:57:20+00:00"),
        ("frt-2.frt", (300, 150), (0.03, 0.06), 12314, "2023-06-26T16:22:25+00:00"),
    ],
)
def test_frt_grid_size_and_undefined_points(name, shape, size, invalid, date):
    scan = load(name)
    assert scan.heights.shape == shape
    np.testing.assert_allclose(scan.size, size, rtol=1e-6)
    assert int(np.isnan(scan.heights).sum()) == invalid  # SurfaceTopography: has undefined data
    assert scan.metadata["channels"] == "0 'Topography', 1 'Intensity'"
    assert scan.metadata["date"] == date and scan.units.z == "m"


def test_frt_single_image_block_equals_the_topography_channel():
    raw = (EXAMPLES / "frt-1.frt").read_bytes()
    start = raw.index(b"\x0b\x00" + struct.pack("<I", 500 * 500 * 2)) + 6
    counts = np.frombuffer(raw, "<u2", 500 * 500, start).reshape(500, 500)[::-1]  # first stored row: the bottom
    scan = load("frt-1.frt")
    np.testing.assert_array_equal(np.isnan(scan.heights), counts == 1)
    np.testing.assert_allclose(scan.heights[counts != 1], counts[counts != 1] * 9.765923032319103e-09, rtol=1e-15)
    intensity = load("frt-1.frt", channel="Intensity")
    assert intensity.units.z == "1" and np.nanmax(intensity.heights) > 1


def test_tmd1_matches_surfacetopography():
    scan = load("tmd-1.tmd")
    assert scan.heights.shape == (300, 300)
    np.testing.assert_allclose(np.array(scan.size) * 1e6, (18.9566, 18.9566), rtol=1e-3)
    assert scan.metadata["vendor"] == "TrueMap" and scan.metadata["comment"] == "Created by TrueMap v6"


def test_mnt1_equals_bcrf1_in_micrometres():
    """mnt-1 is bcrf-1's measurement; bcrf-1's values (nm) are SurfaceTopography's test expectations."""
    scan = load("mnt-1.mnt")
    assert scan.heights.shape == (600, 960) and not np.isnan(scan.heights).any()
    # rough's size (n steps) is MountainsMap's extent; SurfaceTopography asserts it to 2 decimals (µm).
    np.testing.assert_allclose(np.array(scan.size) * 1e6, (1777.404, 1110.878), atol=0.005)
    np.testing.assert_allclose(sq(scan.heights), 24.560207201442292e-9, rtol=1e-6)
    np.testing.assert_allclose(rq(scan.heights), 24.009754961959388e-9, rtol=1e-6)
    np.testing.assert_allclose(rq(scan.heights.T), 24.134045799796326e-9, rtol=1e-6)
    np.testing.assert_allclose(scan.origin, (10.3595e-3, 156.152e-3), rtol=1e-9)  # bcrf-1's xoffset, yoffset
    assert scan.units.z == "µm"


def test_mnt2_validity_image_and_height_range():
    scan = load("mnt-2.mnt")
    assert scan.heights.shape == (960, 1280)
    np.testing.assert_allclose(np.array(scan.size) * 1e6, (95.77, 71.81), atol=0.05)
    invalid = int(np.isnan(scan.heights).sum())
    assert 40000 < invalid < 50000 and invalid == 45405  # SurfaceTopography 1.27.1 also masks 45405
    micrometres = scan.heights * 1e6
    assert -150 < np.nanmin(micrometres) and np.nanmax(micrometres) < 100
    np.testing.assert_allclose((np.nanmin(micrometres), np.nanmax(micrometres)), (-0.369, 3.355), atol=5e-4)


@pytest.mark.parametrize("value", (0x00, 0xFF, 0x7F))
@pytest.mark.parametrize("name", FILES)
def test_truncated_and_corrupted_files_raise_one_line_errors(name, value):
    raw = (EXAMPLES / name).read_bytes()
    variants = [raw[:cut] for cut in (16, 100, 511, 600, len(raw) // 2, len(raw) - 1)] if value == 0 else []
    tree = raw.find(b"\x04X\x00")  # MNT: the X axis record, inside the tree of entries
    near_tree = range(max(tree - 400, 0), tree + 400, 23) if tree > 0 and name.endswith(".mnt") else ()
    random = np.random.default_rng(value).integers(0, len(raw), 6)
    for position in [*range(12, 520, 37), *near_tree, *random]:
        corrupted = bytearray(raw)
        corrupted[position] = value
        variants.append(bytes(corrupted))
    for variant in variants:
        try:
            surface = read_bytes(variant, name=name)
        except InputError as error:
            assert "\n" not in str(error)
        else:
            assert surface.heights.ndim in (1, 2)
