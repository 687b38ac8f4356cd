"""Maps read a window at a time from disk (rough.io.open_tiles: GeoTIFF/COG/VRT through rasterio, NPY through a
memory map, binary X3P stored or deflated): every window, and the whole view, equal the whole-file reader's
heights bit for bit (NaN where it has NaN), with its spacing, origin, units, metadata and history; a tiled
surface pickles and reads in another process; damaged, cut-short and changed files are refused in one line."""

import hashlib
import io
import logging
import os
import pickle
import subprocess
import sys
import zipfile

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rough
from rough.errors import InputError
from rough.io import open_surface, open_tiles, read, registry, x3pdata

from conftest import ROOT

rasterio = pytest.importorskip("rasterio")
from rasterio.transform import Affine  # noqa: E402

WINDOWS = [
    (slice(None), slice(None)),
    (slice(0, 1), slice(0, 3)),
    (slice(250, 520), slice(17, 300)),
    (slice(-9, None), slice(-40, None)),
]


def same(tiled, whole):
    """A tiled view equal to the whole read: every window, the whole view and the provenance."""
    for rows, cols in WINDOWS:
        assert np.array_equal(tiled.read(rows, cols), whole.heights[rows, cols], equal_nan=True), (rows, cols)
    surface = tiled.whole()
    assert surface.heights.dtype == np.float64 and surface.heights.shape == whole.heights.shape
    assert np.array_equal(np.isnan(surface.heights), np.isnan(whole.heights))
    assert (surface.spacing, surface.origin, surface.units) == (whole.spacing, whole.origin, whole.units)
    assert surface.metadata == whole.metadata
    assert surface.history == whole.history
    assert tiled.source_format == whole.source_format


def same_crop(path, crop, **options):
    """A crop of the tiled view equals the whole reader's crop (its heights and place; the whole read records
    the crop in its history)."""
    tiled, whole = open_tiles(path, crop=crop, **options), read(path, crop=crop, **options)
    surface = tiled.whole()
    assert np.array_equal(surface.heights, whole.heights, equal_nan=True)
    assert (surface.spacing, surface.origin) == (whole.spacing, whole.origin)


def heights(rows=537, cols=419, seed=0):
    """Odd-sized Gaussian heights (µm) with a few NaN and an infinite one."""
    z = np.random.default_rng(seed).standard_normal((rows, cols)) * 1e-6
    z[3, 5] = z[rows - 1, cols - 1] = np.nan
    z[100, :7] = np.nan
    z[200, 9] = np.inf
    return z


# -- NPY -------------------------------------------------------------------------------


@pytest.mark.parametrize("dtype", ["<f8", ">f4", "<i2", "<f8-fortran"])
def test_npy_windows_equal_the_whole_read(tmp_path, dtype):
    z = heights()
    if dtype == "<i2":
        z = np.nan_to_num(z * 1e10, posinf=0).astype("<i2")
    fortran = dtype.endswith("fortran")
    array = np.asfortranarray(z) if fortran else z.astype(dtype.removesuffix("-fortran"))
    path = tmp_path / "map.npy"
    np.save(path, array)
    same(open_tiles(path, spacing=(2e-6, 3e-6)), read(path, spacing=(2e-6, 3e-6)))
    same_crop(path, ((1e-4, 5e-4), (3e-5, 9e-4)), spacing=(2e-6, 3e-6))


def test_npy_refusals_are_those_of_the_whole_reader(tmp_path):
    path = tmp_path / "map.npy"
    np.save(path, heights())
    with pytest.raises(InputError, match="carry no spacing"):
        open_tiles(path)
    data = path.read_bytes()
    path.write_bytes(data[:-8])
    with pytest.raises(InputError, match=r"map\.npy: NPY header declares .* the file holds"):
        open_tiles(path, spacing=1e-6)
    np.save(path, np.zeros(10))  # a profile is read whole
    assert open_tiles(path, spacing=1e-6) is None


# -- GeoTIFF ----------------------------------------------------------------------------


TILED = {"driver": "GTiff", "tiled": True, "blockxsize": 256, "blockysize": 256, "compress": "deflate"}


def make_tiff(path, z, transform, crs="EPSG:32633", nodata=-9999.0, **profile):
    """A tiled, deflated GeoTIFF of ``z`` (rows × columns, or bands × rows × columns)."""
    bands = np.asarray(z).reshape(-1, *np.shape(z)[-2:])
    count, height, width = bands.shape
    grid = {"transform": transform, "crs": crs, "nodata": nodata, "dtype": bands.dtype}
    with rasterio.open(path, "w", width=width, height=height, count=count, **grid, **TILED, **profile) as dataset:
        dataset.write(bands)


def dem(rows=537, cols=419):
    z = (np.random.default_rng(1).standard_normal((rows, cols)) * 3 + 300).astype("float32")
    z[10, 20] = z[0, 0] = z[rows - 1, 7] = -9999.0
    z[50, 60] = np.inf
    return z


@pytest.mark.parametrize(
    "transform",
    [Affine(2, 0, 500000, 0, -2, 4100000), Affine(2, 0, 500000, 0, 2, 4100000), Affine(-1.5, 0, 500000, 0, -2.5, 0)],
    ids=["north-up", "south-up", "flipped x"],
)
def test_geotiff_windows_equal_the_whole_read(tmp_path, transform):
    path = tmp_path / "dem.tif"
    make_tiff(path, dem(), transform)
    tiled, whole = open_tiles(path), read(path)
    same(tiled, whole)
    assert tiled.geo == {"crs": whole.metadata["crs"]} == {"crs": "EPSG:32633"}
    x0, y0 = whole.origin
    same_crop(path, ((x0 + 101.3, x0 + 517), (y0 + 33, y0 + 711.2)))


def test_geotiff_scale_unit_band_and_no_crs(tmp_path):
    path = tmp_path / "bands.tif"
    z = np.stack([dem(), dem()[::-1] * 2]).astype("float32")
    make_tiff(path, z, Affine(1, 0, 0, 0, -1, 600), crs=None)
    with rasterio.open(path, "r+") as dataset:
        dataset.scales, dataset.offsets = (0.5, 2.0), (10.0, -3.0)
        dataset.units = ("ft", "cm")
        dataset.descriptions = ("surface", "other")
    for channel in (None, "other", 1):
        tiled, whole = open_tiles(path, channel=channel), read(path, channel=channel)
        same(tiled, whole)
        assert tiled.geo is None and whole.metadata["crs"] == "unknown"


def test_a_vrt_is_sniffed_and_read_in_windows(tmp_path):
    make_tiff(tmp_path / "dem.tif", dem(), Affine(2, 0, 500000, 0, -2, 4100000))
    with rasterio.open(tmp_path / "dem.tif") as dataset:
        crs = dataset.crs.to_wkt()
    vrt = tmp_path / "mosaic.vrt"
    vrt.write_text(
        f'<VRTDataset rasterXSize="419" rasterYSize="537"><SRS>{crs}</SRS>'
        "<GeoTransform>500000, 2, 0, 4100000, 0, -2</GeoTransform>"
        '<VRTRasterBand dataType="Float32" band="1"><NoDataValue>-9999</NoDataValue><SimpleSource>'
        '<SourceFilename relativeToVRT="1">dem.tif</SourceFilename><SourceBand>1</SourceBand>'
        "</SimpleSource></VRTRasterBand></VRTDataset>"
    )
    assert registry.sniff(vrt.read_bytes(), str(vrt)) == "geotiff"
    tiled, whole = open_tiles(vrt), read(vrt)
    same(tiled, whole)
    assert np.array_equal(whole.heights, read(tmp_path / "dem.tif").heights, equal_nan=True)
    with pytest.raises(InputError, match="give its path, not its bytes"):
        read(vrt.read_bytes())


def test_a_damaged_geotiff_tile_is_refused_when_read(tmp_path):
    path = tmp_path / "dem.tif"
    make_tiff(path, dem(1024, 1024), Affine(2, 0, 500000, 0, -2, 4100000), predictor=3)
    with rasterio.open(path) as dataset:
        offset = int(dataset.get_tag_item("BLOCK_OFFSET_1_1", "TIFF", bidx=1))
    data = bytearray(path.read_bytes())
    data[offset + 20 : offset + 400] = bytes(380)
    path.write_bytes(bytes(data))
    tiled = open_tiles(path)
    assert tiled.read(slice(0, 10), slice(0, 10)).shape == (10, 10)  # a block far from the damage
    with pytest.raises(InputError) as refused:
        tiled.read(slice(700, 800), slice(300, 400))
    assert str(path) in str(refused.value) and "\n" not in str(refused.value)


def test_a_cut_short_geotiff_is_refused(tmp_path):
    path = tmp_path / "dem.tif"
    make_tiff(path, dem(), Affine(2, 0, 500000, 0, -2, 4100000))
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(InputError) as refused:
        tiled = open_tiles(path)
        for start, _ in tiled.strips(100):
            pass
    assert "\n" not in str(refused.value)


# -- X3P -------------------------------------------------------------------------------


def x3p(path, raw, code="D", increment=1.0, offset=0.0, layers=1, valid=None, compression=zipfile.ZIP_STORED):
    """An X3P file of ``raw`` values (layers × rows × columns, or rows × columns) with the given CZ type,
    Increment and Offset, an optional valid-point mask and the data member stored or deflated."""
    raw = np.asarray(raw).reshape(layers, -1, np.shape(raw)[-1])
    data = raw.astype({"I": "<i2", "L": "<i4", "F": "<f4", "D": "<f8"}[code]).tobytes()
    mask = "" if valid is None else np.packbits(np.asarray(valid).ravel(), bitorder="little").tobytes()
    mask_xml = (
        f"<ValidPointsLink>bindata/valid.bin</ValidPointsLink>"
        f"<MD5ChecksumValidPoints>{hashlib.md5(mask).hexdigest()}</MD5ChecksumValidPoints>"
        if mask
        else ""
    )
    document = (
        '<?xml version="1.0" encoding="UTF-8"?><p:ISO5436_2 xmlns:p="http://www.opengps.eu/2008/ISO5436_2">'
        "<Record1><Revision>ISO5436 - 2000</Revision><FeatureType>SUR</FeatureType><Axes>"
        "<CX><AxisType>I</AxisType><DataType>D</DataType><Increment>2e-6</Increment><Offset>1e-5</Offset></CX>"
        "<CY><AxisType>I</AxisType><DataType>D</DataType><Increment>3e-6</Increment><Offset>-4e-6</Offset></CY>"
        f"<CZ><AxisType>A</AxisType><DataType>{code}</DataType><Increment>{increment!r}</Increment>"
        f"<Offset>{offset!r}</Offset></CZ></Axes></Record1>"
        "<Record2><Date>2024-01-01T00:00:00</Date><Instrument><Manufacturer>test</Manufacturer>"
        "<Model>m</Model><Serial>s</Serial><Version>1</Version></Instrument>"
        "<CalibrationDate>2024-01-01T00:00:00</CalibrationDate>"
        "<ProbingSystem><Type>Software</Type><Identification>t</Identification></ProbingSystem></Record2>"
        f"<Record3><MatrixDimension><SizeX>{raw.shape[2]}</SizeX><SizeY>{raw.shape[1]}</SizeY>"
        f"<SizeZ>{layers}</SizeZ></MatrixDimension><DataLink><PointDataLink>bindata/data.bin</PointDataLink>"
        f"<MD5ChecksumPointData>{hashlib.md5(data).hexdigest()}</MD5ChecksumPointData>{mask_xml}</DataLink>"
        "</Record3><Record4><ChecksumFile>md5checksum.hex</ChecksumFile></Record4></p:ISO5436_2>"
    ).encode()
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("main.xml", document)
        archive.writestr("md5checksum.hex", f"{hashlib.md5(document).hexdigest()} *main.xml\n")
        archive.writestr("bindata/data.bin", data, compress_type=compression)
        if mask:
            archive.writestr("bindata/valid.bin", mask, compress_type=compression)
    return path


def deflated_copy(source, target):
    """The same X3P file with every member deflated."""
    with zipfile.ZipFile(source) as old, zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as new:
        for name in old.namelist():
            new.writestr(name, old.read(name))
    return target


@pytest.mark.parametrize("compression", ["stored", "deflated"])
def test_x3p_written_by_rough_reads_the_same_in_windows(tmp_path, compression):
    surface = rough.Surface(heights(), (2e-6, 3e-6), origin=(1e-3, -2e-3), metadata={"comment": "tiles"})
    path = tmp_path / "map.x3p"
    surface.write(path)
    if compression == "deflated":
        path = deflated_copy(path, tmp_path / "deflated.x3p")
    tiled, whole = open_tiles(path), read(path)
    same(tiled, whole)
    assert tiled.metadata["comment"] == "tiles" and tiled.geo is None
    same_crop(path, ((1.1e-3, 1.5e-3), (-1.9e-3, -0.9e-3)))


@pytest.mark.parametrize("compression", [zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED], ids=["stored", "deflated"])
@pytest.mark.parametrize("code", ["I", "L", "F"])
def test_x3p_types_scale_layers_and_mask(tmp_path, code, compression):
    raw = np.random.default_rng(2).integers(-3000, 3000, (3, 301, 203))
    valid = np.random.default_rng(3).random(raw.shape) > 0.05
    path = x3p(tmp_path / "layers.x3p", raw, code, 1e-9, -5e-7, 3, valid, compression)
    for layer in (None, 0, 2):
        tiled, whole = open_tiles(path, layer=layer), read(path, layer=layer)
        same(tiled, whole)
        assert tiled.metadata["layers"] == "3"


def test_deflated_x3p_strips_with_a_halo_and_windows_out_of_order(tmp_path):
    surface = rough.Surface(heights(), (1e-6, 1e-6))
    path = deflated_copy(surface.write(tmp_path / "a.x3p") or tmp_path / "a.x3p", tmp_path / "b.x3p")
    whole, tiled = read(path), open_tiles(path)
    for start, strip in tiled.strips(50, halo=2):
        assert np.array_equal(strip, whole.heights[start : start + 52], equal_nan=True)
    for rows in (slice(400, 420), slice(10, 30), slice(15, 500), slice(536, 537)):
        assert np.array_equal(tiled.read(rows), whole.heights[rows], equal_nan=True)


@pytest.mark.parametrize("compression", [zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED], ids=["stored", "deflated"])
def test_x3p_checksums_are_checked_when_opened(tmp_path, compression, caplog):
    path = x3p(tmp_path / "map.x3p", heights(), compression=compression)
    with zipfile.ZipFile(path) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    damaged = bytearray(members["bindata/data.bin"])
    damaged[1000] ^= 1
    with zipfile.ZipFile(path, "w") as archive:
        for name, content in members.items():
            archive.writestr(name, bytes(damaged) if name == "bindata/data.bin" else content, compress_type=compression)
    with pytest.raises(
        InputError, match=r"map\.x3p: bindata/data\.bin checksum mismatch .*--ignore-checksums"
    ) as refused:
        open_tiles(path)
    assert "\n" not in str(refused.value)
    with caplog.at_level(logging.WARNING, logger="rough"):
        tiled = open_tiles(path, verify=False)
    assert "checksum mismatch" in caplog.text
    same(tiled, read(path, verify=False))


@pytest.mark.parametrize("compression", [zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED], ids=["stored", "deflated"])
def test_open_surface_checks_the_data_once(tmp_path, compression, monkeypatch):
    """A map that fits the budget is checked by its whole read alone (no second pass
    over the data member); one read in tiles is checked once, before its first tile;
    and a damaged one is refused either way."""
    path = x3p(tmp_path / "map.x3p", heights(), compression=compression)
    passes = []
    digests = x3pdata._member_digests
    monkeypatch.setattr(x3pdata, "_member_digests", lambda *a: passes.append(1) or digests(*a))
    assert isinstance(open_surface(path), rough.Surface) and passes == []
    assert isinstance(open_surface(path, memory=1000), rough.io.TiledSurface) and passes == [1]
    with zipfile.ZipFile(path) as archive:
        members = {name: archive.read(name) for name in archive.namelist()}
    damaged = bytearray(members["bindata/data.bin"])
    damaged[-8] ^= 1
    with zipfile.ZipFile(path, "w") as archive:
        for name, content in members.items():
            archive.writestr(name, bytes(damaged) if name == "bindata/data.bin" else content, compress_type=compression)
    for memory in (None, 1000):
        with pytest.raises(InputError, match=r"map\.x3p: bindata/data\.bin checksum mismatch"):
            open_surface(path, memory=memory)


def test_damaged_and_cut_short_x3p_are_refused(tmp_path):
    surface = rough.Surface(heights(), (1e-6, 1e-6))
    path = tmp_path / "map.x3p"
    surface.write(path)
    data = path.read_bytes()
    deflated = deflated_copy(path, tmp_path / "deflated.x3p").read_bytes()
    for name, content in {"cut": data[: len(data) - 3000], "deflate cut": deflated[:-2000]}.items():
        (tmp_path / "bad.x3p").write_bytes(content)
        with pytest.raises(InputError) as refused:
            open_tiles(tmp_path / "bad.x3p")
        assert "\n" not in str(refused.value), name
    middle = bytearray(deflated)
    at = len(deflated) // 2
    middle[at : at + 64] = bytes(64)
    (tmp_path / "bad.x3p").write_bytes(bytes(middle))
    with pytest.raises(InputError):
        open_tiles(tmp_path / "bad.x3p")


@pytest.fixture(scope="module")
def deflated_map(tmp_path_factory):
    folder = tmp_path_factory.mktemp("deflated")
    valid = np.random.default_rng(4).random((3, 97, 61)) > 0.1
    raw = np.random.default_rng(5).integers(-99, 99, (3, 97, 61))
    path = x3p(folder / "map.x3p", raw, "I", 1e-8, 0.0, 3, valid, zipfile.ZIP_DEFLATED)
    return open_tiles(path, layer=1), read(path, layer=1).heights


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 96), st.integers(1, 97), st.integers(0, 60), st.integers(1, 61)), max_size=8))
def test_deflated_windows_in_any_order_are_the_whole_reads(deflated_map, windows):
    """Windows before, inside, overlapping and after the last one read (the stream restarts or goes on)."""
    tiled, whole = deflated_map
    for top, height, left, width in windows:
        rows, cols = slice(top, top + height), slice(left, left + width)
        assert np.array_equal(tiled.read(rows, cols), whole[rows, cols], equal_nan=True)


def test_x3p_read_whole_where_windows_cannot_be_read(tmp_path):
    rough.Surface(heights()[0], (1e-6,)).write(tmp_path / "profile.x3p")
    assert open_tiles(tmp_path / "profile.x3p") is None


# -- every format --------------------------------------------------------------------


def maps(tmp_path):
    """A file of each format that reads windows."""
    z = heights()
    np.save(tmp_path / "map.npy", z)
    make_tiff(tmp_path / "map.tif", dem(), Affine(2, 0, 500000, 0, -2, 4100000))
    rough.Surface(z, (1e-6, 1e-6)).write(tmp_path / "map.x3p")
    deflated_copy(tmp_path / "map.x3p", tmp_path / "deflated.x3p")
    return {name: {"spacing": 1e-6} if name.endswith(".npy") else {} for name in os.listdir(tmp_path)}


def test_tiled_surfaces_pickle_and_read_in_another_process(tmp_path):
    files = maps(tmp_path)
    tiled = [open_tiles(tmp_path / name, **options) for name, options in files.items()]
    for one in tiled:
        one.read(slice(5, 9))  # opened in this process: the handle must not travel
        again = pickle.loads(pickle.dumps(one))
        assert np.array_equal(
            again.read(slice(30, 90), slice(3, 70)), one.read(slice(30, 90), slice(3, 70)), equal_nan=True
        )
    script = (
        "import pickle, sys, numpy as np\n"
        "views = pickle.load(sys.stdin.buffer)\n"
        "np.save(sys.stdout.buffer, np.stack([v.read(slice(30, 90), slice(3, 70)) for v in views]))\n"
    )
    environment = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = subprocess.run(
        [sys.executable, "-c", script], input=pickle.dumps(tiled), capture_output=True, env=environment, timeout=60
    )
    assert done.returncode == 0, done.stderr.decode()
    windows = np.load(io.BytesIO(done.stdout))
    for one, window in zip(tiled, windows):
        assert np.array_equal(window, one.read(slice(30, 90), slice(3, 70)), equal_nan=True)


def test_a_file_changed_after_it_was_opened_is_refused(tmp_path):
    files = maps(tmp_path)
    for name, options in files.items():
        tiled = open_tiles(tmp_path / name, **options)
        tiled.read(slice(0, 2))
        travelled = pickle.loads(pickle.dumps(tiled))
        os.utime(tmp_path / name, ns=(1, 1))
        for view in (tiled, travelled):
            with pytest.raises(InputError, match="has changed since it was opened"):
                view.read(slice(0, 2))


def test_open_surface_reads_tiles_over_the_memory_budget(tmp_path, caplog):
    files = maps(tmp_path)
    for name, options in files.items():
        with caplog.at_level(logging.INFO, logger="rough"):
            caplog.clear()
            tiled = open_surface(tmp_path / name, memory=1 << 20, **options)
        assert isinstance(tiled, rough.io.TiledSurface), name
        assert "read in tiles" in caplog.text
        assert isinstance(open_surface(tmp_path / name, memory=1 << 40, **options), rough.Surface)


def test_rough_formats_says_which_formats_read_windows():
    tiles = {name for name, facts in registry.formats().items() if "tiles" in facts.carries}
    assert tiles == {"geotiff", "npy", "x3p"}
    assert "tiles" in registry.CARRIES


# -- the real files of ../shared/data --------------------------------------------------


def test_shared_geotiffs_and_x3p_read_the_same_in_windows(shared_data):
    paths = sorted((shared_data / "dem").glob("*.tif")) + sorted(shared_data.rglob("*.x3p"))
    compared = 0
    for path in paths:
        try:
            whole = read(path)
        except InputError:
            continue
        tiled = open_tiles(path)
        if tiled is not None:
            same(tiled, whole)
            compared += 1
    assert compared >= 10
    assert open_tiles(shared_data / "opengps" / "ISO5436-sample1.x3p") is None  # an inline DataList: read whole
