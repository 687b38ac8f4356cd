"""Damaged files never pass as data (tests/damaged_files.py makes them): every seed cut
at every byte near its end (and every 7th before), its data block shifted by 1-16 bytes
or replaced by random bytes, and heights of ±1e308. No internal error; a cut file is
refused or reads the values it held; a shifted data block (every reader checks the file's
length, or what follows the data, against its header), a random float block and huge
heights are refused. Random integer counts are refused only where the header states
their range; the formats that state none are listed in :data:`RANDOM_COUNTS_PASS`
(docs/formats.rst, "Damaged files")."""

import collections
import io
import logging
import pathlib
import random

import numpy as np
import pytest

from rough import Surface
from rough.errors import FormatError
from rough.io import ReadOptions, read_bytes

from conftest import assert_one_line_error
from damaged_files import HEIGHTS, measured_seeds, outcome, tally, variants, written_huge
from seed_files import seeds

KINDS = ("truncated", "shifted", "random", "huge")
# integer data whose header states no range (or none rough can hold them to): random counts read as counts
RANDOM_COUNTS_PASS = {
    "binary.sdf",
    "map.bcr",
    "map.dat",
    "map.frt",
    "map.mi",
    "map.nid",
    "map.nms",
    "map.spm",
    "park.tiff",
}
SPACED = ReadOptions(spacing=(1e-6, 1e-6))
HOSTILE = pathlib.Path(__file__).resolve().parent / "hostile"


@pytest.fixture(scope="module")
def results():
    logging.getLogger("rough").propagate = False
    try:
        return tally(KINDS)
    finally:
        logging.getLogger("rough").propagate = True


def test_no_damaged_file_makes_an_internal_error(results):
    counts, bad = results
    assert sum(sum(counter.values()) for counter in counts.values()) > 8000
    internal = [row for row in bad if row[3].startswith("internal")]
    assert not internal, internal[:10]


def test_a_file_cut_short_is_refused_or_reads_the_values_it_held(results):
    counts, bad = results
    changed = [row for row in bad if row[1] == "truncated" and row[3] == "changed"]
    assert not changed, changed[:10]
    shorter = {row[0] for row in bad if row[1] == "truncated" and row[3] in ("shorter", "warned")}
    assert shorter <= {"columns.csv", "dektak.csv", "gwyddion.txt"}  # text with no count: cut at a line end


def test_rough_tsv_cut_anywhere_is_refused(results):
    counts, _ = results
    for name in ("map.tsv", "profile.tsv", "map.tsv.gz"):
        assert set(counts[name, "truncated"]) == {"refused"}, (name, counts[name, "truncated"])


def test_shifted_or_random_float_data_are_refused(results):
    counts, bad = results
    floats = sorted(measured_seeds())
    assert len(floats) >= 8
    for name in floats:
        for kind in ("shifted", "random"):
            assert set(counts[name, kind]) == {"refused"}, (name, kind, counts[name, kind])


def test_a_shifted_data_block_is_refused_by_every_reader(results):
    """Issue 31: 1-7 bytes put in before the data block (or taken from before it) read as
    other heights in 14 binary readers (49 of the shifted copies); each now checks the
    file's length, or what follows the data, against its header. 3, 4, 7, 8 or 16
    bytes put in read in OpenEXR (the library trusts a chunk's packed size) until its
    chunks were checked to fill the file."""
    counts, bad = results
    shifted = [row for row in bad if row[1] == "shifted"]
    assert not shifted, shifted[:10]
    assert len({name for name, kind in counts if kind == "shifted"}) >= 30


def test_random_counts_are_refused_where_the_header_states_their_range(results):
    """SUR (zmin … zmax) and WSxM (Minimum … Maximum) state the counts' range; random
    counts fall outside it. The formats of :data:`RANDOM_COUNTS_PASS` state none."""
    counts, _ = results
    seeds_with_blocks = {name for name, kind in counts if kind == "random"}
    assert RANDOM_COUNTS_PASS < seeds_with_blocks and {"map.sur", "map.top"} <= seeds_with_blocks
    for name in sorted(seeds_with_blocks - RANDOM_COUNTS_PASS):
        assert set(counts[name, "random"]) == {"refused"}, (name, counts[name, "random"])


@pytest.mark.parametrize(
    ("name", "count", "words"),
    [
        ("sur-3.sur", np.array(6992351, "<i4"), "outside the header's zmin … zmax, 0 … 6992350"),
        ("top-1.top", np.array(6901, "<i2"), "outside the header's Minimum … Maximum, 5927 … 6900"),
    ],
)
def test_a_count_outside_the_range_the_header_states_is_refused(shared_data, name, count, words):
    """The last point, one count above the stated maximum (the counts' own maximum in both files)."""
    data = (shared_data / "SurfaceTopography" / name).read_bytes()
    with pytest.raises(FormatError, match=words):
        read_bytes(data[: -count.nbytes] + count.tobytes(), name=name)


REAL_DATA_END_THE_FILE = [
    "bcrf-1.bcrf",
    "metropro-1.dat",
    "frt-1.frt",
    "frt-2.frt",
    "mi-1.mi",
    "nid-1.nid",
    "nms-1.nms",
    "di-1.di",
    "di-3.di",
    "di-5.di",
    "sur-2.sur",
    "sur-3.sur",
    "top-1.top",
    "stp-1.stp",
    "tmd-1.tmd",
]


@pytest.mark.parametrize("name", REAL_DATA_END_THE_FILE)
@pytest.mark.parametrize("extra", [b"\0", b"\0" * 7])
def test_a_real_file_with_bytes_after_its_data_is_refused(shared_data, name, extra):
    data = (shared_data / "SurfaceTopography" / name).read_bytes()
    read_bytes(data, name=name)
    with pytest.raises(FormatError, match=f"{len(data) + len(extra):,} bytes"):
        read_bytes(data + extra, name=name)


def test_asylum_thumbnails_after_an_igor_wave_read_but_other_bytes_do_not(shared_data):
    """spot_1-1000nm.ibw ends with 8 thumbnails whose list starts them where the wave
    ends (HeightTraceFileStart:2112969); a byte put in the wave's data or between the
    thumbnails is refused."""
    data = (shared_data / "SurfaceTopography" / "spot_1-1000nm.ibw").read_bytes()
    assert b"HeightTraceFileStart:2112969;" in data
    assert read_bytes(data, name="spot.ibw").heights.shape == (256, 256)
    for at in (1000, 2112969, 2200000, len(data) - 600):
        with pytest.raises(FormatError, match="not Asylum's thumbnails starting where it ends"):
            read_bytes(data[:at] + b"\0" + data[at:], name="spot.ibw")


def test_a_plu_file_may_carry_its_colour_image_and_more_but_not_a_few_bytes(shared_data):
    data = (shared_data / "SurfaceTopography" / "plu-1.plu").read_bytes()
    layers_end = 500 + 8 + 576 * 768 * 4 + 8
    assert len(data) - layers_end == 576 * 768 * 3 + 133133  # the colour image, then bytes of unknown layout
    read_bytes(data[:layers_end], name="p.plu")
    with pytest.raises(FormatError, match="3 bytes after its layers"):
        read_bytes(data[: layers_end + 3], name="p.plu")


def test_heights_of_1e308_are_refused_by_every_reader(results):
    counts, _ = results
    huge = {name: counter for (name, kind), counter in counts.items() if kind == "huge"}
    assert {"huge.x3p", "huge.npy", "huge.gwy", "huge.tsv", "huge.h5", "offset.x3p"} <= set(huge)
    assert all(set(counter) == {"refused"} for counter in huge.values()), huge


def test_the_damage_reaches_every_float_and_text_reader():
    kinds = collections.Counter()
    for name, blob in {**seeds(), **measured_seeds()}.items():
        for kind, _, _ in variants(name, blob, random.Random(0)):
            kinds[kind] += 1
    assert kinds["shifted"] >= 7 * 20 and kinds["random"] >= 4 * 20 and kinds["huge"] >= 9
    assert len(written_huge()) >= 5
    assert HEIGHTS.std() > 0


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        (b"x z\n0 -4.67e-07\n1 -4.6e-07\n2 -4.67", "the last number, '-4.67', is printed unlike"),
        (b"x z\n0 -4.67e-07\n1 -4.6e-07\n2 -4.67e-0", "the last number, '-4.67e-0', is printed unlike"),
        (b"1.25 2.50 3.75 4.00\n5.00 6.25 7.50 8.75\n9.00 1.25 2.50 3.7", "the last number, '3.7'"),
        (b"1 2 3 4\n5 6 7 8\n9 10", "line 3: the last line has 2 values where the line before has 4"),
        (b"1 2 3 4\n5 6 7 8\n9 10\n", "line 3: 2 values where the first row has 4 (a row cut short?)"),
        (b"x z\n0 1\n1\n2 3\n", "line 3: 1 value where the first row has 2"),
        (b"# Width: 12 um\n# Height: 8 um\n1e-09 2e-09 3e-09 4e-09 5e-09 6e-0", "line 3: the last number, '6e-0'"),
    ],
)
def test_text_cut_inside_its_last_line_is_refused_naming_the_line(text, fragment):
    with pytest.raises(FormatError, match="cut short") as refusal:
        read_bytes(text, SPACED)
    assert fragment in str(refusal.value)


def test_text_that_ends_without_a_line_end_but_reads_as_a_whole_warns(caplog):
    """'2.2' may be all of the number or the start of '2.25': nothing tells, so the
    read goes on and says so."""
    with caplog.at_level(logging.WARNING, logger="rough"):
        scan = read_bytes(b"x z\n0 1.5\n1 2.5\n2 2.2", SPACED)
    assert scan.heights.size == 3
    assert "no line end after its last value, '2.2': if it was cut short" in caplog.text


def test_the_same_text_with_a_line_end_reads_without_a_word(caplog):
    with caplog.at_level(logging.WARNING, logger="rough"):
        read_bytes(b"x z\n0 -4.67e-07\n1 -4.6e-07\n2 -4.67\n")
    assert caplog.text == ""


def test_rough_tsv_cut_mid_number_is_refused_not_read_as_metres(tmp_path):
    """The issue's case: a TSV written by rough, cut inside its last height (-4.67e-07 →
    -4.67), read as -4.67 m: Sq 1 µm became 117.58 mm."""
    import numpy as np

    from rough import Surface

    surface = Surface(np.random.default_rng(5).normal(size=200) * 1e-6, (1e-6,))
    surface.write(tmp_path / "p.tsv")
    data = (tmp_path / "p.tsv").read_bytes()
    cut = data[: data.rindex(b"e-")]
    with pytest.raises(FormatError, match="cut short"):
        read_bytes(cut)
    for end in range(len(data) - 30, len(data)):  # every cut in the last line, the line end included
        with pytest.raises(FormatError, match="cut short"):
            read_bytes(data[:end])
    assert outcome("p.tsv", read_bytes(data), data) == "same"


def test_rough_tsv_cut_at_a_line_end_is_refused_by_its_point_count(tmp_path):
    import numpy as np

    from rough import Surface

    surface = Surface(np.arange(12.0).reshape(3, 4) * 1e-6, (1e-6, 1e-6))
    surface.write(tmp_path / "m.tsv")
    data = (tmp_path / "m.tsv").read_bytes()
    assert b"# points: 4 3\n" in data
    rows = data.split(b"\n\n")
    with pytest.raises(FormatError, match="header says 4 3 points, the data hold 4 2"):
        read_bytes(b"\n\n".join(rows[:2]) + b"\n\n")


@pytest.mark.parametrize("fmt", ["x3p", "npy", "gwy", "h5"])
def test_features_on_heights_of_1e308_is_a_refusal_not_an_internal_error(fmt, run, tmp_path):
    """Issue 31: ``features`` on ±1e308 heights (X3P, NPY, GWY, HDF5) exited 1 with
    "internal error"; now the read refuses them, exit status 2, naming the height."""
    blob = written_huge()[f"huge.{fmt}"]
    path = tmp_path / f"huge.{fmt}"
    path.write_bytes(blob)
    result = run("features", "--spacing", "1um", path)
    assert_one_line_error(result, str(path), "a height of ", "is beyond ±100 km", "their unit (m) is wrong")


def test_a_refused_file_prints_one_line_even_after_a_warning(run, tmp_path):
    """A GeoTIFF with no CRS warns that its lengths are taken as metres; cut in its
    pixels, the refusal that follows is the only line."""
    result = run("info", HOSTILE / "geotiff-no-crs-cut.tif")
    assert_one_line_error(result, "IReadBlock")


def _x3p(heights, spacing):
    buffer = io.BytesIO()
    Surface(heights, (spacing, spacing)).write(buffer, "x3p")
    return buffer.getvalue()


@pytest.mark.parametrize("spacing", [1e-6, 100.0, 1e4])
def test_one_height_past_100_km_is_refused_whatever_the_width(spacing):
    heights = np.zeros((10, 10))
    heights[3, 4] = -1.5e5
    with pytest.raises(FormatError, match=r"a height of -150000 m \(at point 4, 3\) is beyond ±100 km"):
        read_bytes(_x3p(heights, spacing))


def test_an_elevation_model_from_the_trench_to_everest_reads_without_a_word(caplog):
    heights = np.linspace(-10994.0, 8849.0, 100).reshape(10, 10)
    with caplog.at_level(logging.WARNING, logger="rough"):
        scan = read_bytes(_x3p(heights, 1000.0))
    assert scan.heights.max() == 8849.0 and caplog.text == ""


def test_heights_at_the_limit_read_and_past_it_do_not():
    edge = np.full((3, 4), 1e5)
    np.testing.assert_array_equal(read_bytes(_x3p(edge, 1e3)).heights, edge)
    with pytest.raises(FormatError, match="beyond"):
        read_bytes(_x3p(np.nextafter(edge, np.inf), 1e3))


def test_heights_spanning_more_than_a_thousand_widths_warn_of_the_unit(caplog):
    heights = np.array([[0.0, 1.0], [2.0, 15.0]])  # 15 m over 20 µm: micrometres read as metres?
    with caplog.at_level(logging.WARNING, logger="rough"):
        read_bytes(_x3p(heights, 1e-5))
    assert "the heights span 15 m, 7.5e+05 times the surface's 20 µm width: is their unit (m) right?" in caplog.text


@pytest.mark.parametrize("extra", [1, 4, 8])
def test_an_npy_file_with_bytes_after_its_array_is_refused(extra):
    """numpy writes the array right after the header and nothing after it: more bytes
    than the header declares mean the data block moved (bytes put in before it)."""
    buffer = io.BytesIO()
    np.save(buffer, HEIGHTS)
    blob = buffer.getvalue()
    np.testing.assert_array_equal(read_bytes(blob, SPACED).heights, HEIGHTS)
    start = len(blob) - HEIGHTS.nbytes
    for damaged in (blob + bytes(extra), blob[:start] + bytes(extra) + blob[start:]):
        with pytest.raises(FormatError, match="declares 12×16 values"):
            read_bytes(damaged, SPACED)


def _exr(heights, compression="ZIP_COMPRESSION", tiles=None, **header):
    import OpenEXR

    header = {"compression": getattr(OpenEXR, compression), "type": OpenEXR.scanlineimage, **header}
    if tiles is not None:
        description = OpenEXR.TileDescription()
        description.xSize, description.ySize = tiles[:2]
        description.mode, description.roundingMode = OpenEXR.LevelMode(tiles[2]), OpenEXR.LevelRoundingMode(tiles[3])
        header.update(type=OpenEXR.tiledimage, tiles=description)
    buffer = io.BytesIO()
    OpenEXR.File(header, {"Y": heights}).write(buffer)
    return buffer.getvalue()


def _shifted(blob, start, shift):
    """``shift`` bytes (of float32 heights, as a measurement's) put in at ``start``, or
    taken from before it."""
    return (
        blob[:start] + HEIGHTS.astype("<f4").tobytes()[:shift] + blob[start:]
        if shift > 0
        else blob[: start + shift] + blob[start:]
    )


SHIFTS = [-16, -8, -4, -3, -1, 1, 3, 4, 8, 16]


@pytest.mark.parametrize("shift", SHIFTS)
def test_an_exr_with_bytes_put_in_or_taken_from_before_its_pixels_is_refused(shift):
    """Issue 31: the OpenEXR library trusts a chunk's packed size, so 4, 8 or 16 bytes put
    in before the pixels of a file rough wrote read as other heights (the bytes put in
    first, the rest moved by 1, 2 or 4 points, the last ones dropped); rough now checks
    that the chunks fill the file from the offset table to its end."""
    buffer = io.BytesIO()
    Surface(HEIGHTS, (1e-6, 1e-6)).write(buffer, "exr")
    blob = buffer.getvalue()
    start = blob.index(HEIGHTS.astype("<f4").tobytes())  # stored as is: ZIP does not shrink these mantissas
    np.testing.assert_array_equal(read_bytes(blob).heights, HEIGHTS.astype("f4"))
    with pytest.raises(FormatError, match="EXR chunk") as refusal:
        read_bytes(_shifted(blob, start, shift))
    assert "\n" not in str(refusal.value)


@pytest.mark.parametrize("shift", SHIFTS)
def test_an_exr_chunk_moved_within_the_file_is_refused(shift):
    """Twelve one-row chunks (no compression): bytes put in before the sixth chunk move it
    away from where the offset table says it is (the library refuses these too; this
    holds rough's own check to them)."""
    heights = HEIGHTS.astype("f4")
    blob = _exr(heights, "NO_COMPRESSION")
    start = blob.index(heights[5].tobytes()) - 8  # its scanline number and packed size first
    with pytest.raises(FormatError, match="EXR chunk"):
        read_bytes(_shifted(blob, start, shift), SPACED)


@pytest.mark.parametrize(
    "compression",
    [
        "NO_COMPRESSION",
        "RLE_COMPRESSION",
        "ZIPS_COMPRESSION",
        "ZIP_COMPRESSION",
        "PIZ_COMPRESSION",
        "PXR24_COMPRESSION",
        "B44_COMPRESSION",
        "B44A_COMPRESSION",
        "DWAA_COMPRESSION",
        "DWAB_COMPRESSION",
        "HTJ2K256_COMPRESSION",
        "HTJ2K32_COMPRESSION",
        "LJ2K_COMPRESSION",
        "ZSTD_COMPRESSION",
    ],
)
@pytest.mark.parametrize("rows", [1, 17, 300])
def test_exr_files_of_every_compression_and_layout_still_read(compression, rows):
    """The chunk check refuses no file OpenEXR's bindings write: scanlines in either
    order, tiles (of one level: their mipmaps and ripmaps leave the reduced levels out,
    which the library does not read either)."""
    import OpenEXR

    heights = np.random.default_rng(rows).normal(size=(rows, 5)).astype("f4")
    layouts = [{"lineOrder": OpenEXR.INCREASING_Y}, {"lineOrder": OpenEXR.DECREASING_Y}]
    layouts += [{"tiles": (8, 3, 0, rounding)} for rounding in range(2)]
    for layout in layouts:
        surface = read_bytes(_exr(heights, compression, **layout), SPACED)
        assert surface.heights.shape == heights.shape[1:] if rows == 1 else heights.shape
        if compression in ("NO_COMPRESSION", "RLE_COMPRESSION", "ZIPS_COMPRESSION", "ZIP_COMPRESSION"):
            np.testing.assert_array_equal(surface.heights, heights[0] if rows == 1 else heights)


@pytest.mark.parametrize("fmt", ["gsf", "gwy"])
@pytest.mark.parametrize("shift", SHIFTS)
def test_a_gsf_or_gwy_with_a_shifted_data_block_is_refused(fmt, shift):
    """GSF: XRes·YRes float32 exactly after the NUL padding; GWY: the data's byte count
    is stored before it. Both refused every shift of ±1…±16 bytes before the data."""
    buffer = io.BytesIO()
    Surface(HEIGHTS, (1e-6, 1e-6)).write(buffer, fmt)
    blob = buffer.getvalue()
    start = blob.index(HEIGHTS.astype("<f4" if fmt == "gsf" else "<f8").tobytes())
    with pytest.raises(FormatError):
        read_bytes(_shifted(blob, start, shift))


def _all_levels(blob, rounding):
    """A ripmap or mipmap written by the bindings (full-resolution tiles only, the other
    offsets 0) with every tile of the reduced levels added, uncompressed, in the order of
    OpenEXR's TileOffsets: levels by y then x, tiles by row."""
    from rough.io.exr import _attributes, _tiles

    attributes, at = _attributes(blob, 8)
    xmin, ymin, xmax, ymax = np.frombuffer(attributes["dataWindow"], "<i4").tolist()
    tiles = _tiles(attributes["tiles"], xmax - xmin + 1, ymax - ymin + 1, 10**6)
    offsets = np.frombuffer(blob, "<u8", count=len(tiles), offset=at)
    chunks = []
    for offset, (dx, dy, lx, ly) in zip(offsets.tolist(), tiles.tolist()):
        if offset:
            chunks.append(blob[offset : offset + 20 + int.from_bytes(blob[offset + 16 : offset + 20], "little")])
            continue
        width, height = (max(1, -(-n >> level) if rounding else n >> level) for n, level in ((5, lx), (17, ly)))
        pixels = np.full(min(8, width - 8 * dx) * min(3, height - 3 * dy), 7.0, "<f4").tobytes()
        chunks.append(np.array([dx, dy, lx, ly, len(pixels)], "<i4").tobytes() + pixels)
    starts = at + 8 * len(tiles) + np.cumsum([0] + [len(chunk) for chunk in chunks[:-1]])
    return blob[:at] + starts.astype("<u8").tobytes() + b"".join(chunks)


@pytest.mark.parametrize("mode", [1, 2])
@pytest.mark.parametrize("rounding", [0, 1])
def test_an_exr_mipmap_or_ripmap_with_all_its_levels_reads_and_shifted_does_not(mode, rounding):
    """The offset table's order checked against a file the library reads (as rough did
    before the check); bytes moved in the last tile of the smallest level are refused,
    though the library, reading the full-resolution level only, never looks there."""
    heights = np.arange(85, dtype="f4").reshape(17, 5)
    blob = _all_levels(_exr(heights, "NO_COMPRESSION", tiles=(8, 3, mode, rounding)), rounding)
    np.testing.assert_array_equal(read_bytes(blob, SPACED).heights, heights)
    for shift in (-4, 4):
        with pytest.raises(FormatError, match="EXR chunk"):
            read_bytes(_shifted(blob, len(blob) - 8, shift), SPACED)
