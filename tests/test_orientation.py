"""One orientation for every reader, checked against Gwyddion and SurfaceTopography on every shared file they
read, and a drawing that agrees with the directions rough reports.

The convention (docs/conventions.rst, "Orientation"): a map is ``z[y, x]``, row j at ``y = y0 + j·dy``, so y
increases with the row index, as in X3P. A file that gives no y direction of its own has the (x, y) that Gwyddion
gives its points: Gwyddion's data field (row 0 the top row of its window) is rough's array unchanged, and
SurfaceTopography's ``heights()[x, y]`` is its transpose. A georeferenced raster has y pointing north, so its
rows are Gwyddion's in reverse (row 0 is the southern edge). ``show`` draws y upwards: row 0 at the bottom, a DEM
north up, and an angle counter-clockwise from +x (``rose``, Std) counter-clockwise on the page.

The reference points are recorded here (peers are never imported in tests), four points per file, chosen where
all four are valid and differ, so that any flip or transposition moves at least one:

* ``GWYDDION``: Gwyddion 2.62 (Debian 2.62-1), ``gwyddion --convert-to-gwy=out.gwy FILE``, the data field of the
  channel rough reads, opened with gwyfile: ``(row, column, data[row, column])`` in Gwyddion's indices and SI
  units (metres). Gwyddion puts the points Gwyddion masks (FRT's invalid counts) at interpolated heights; the
  points below are valid in both.
* ``SURFACETOPOGRAPHY``: SurfaceTopography 1.27.1, ``read_topography(FILE).heights()`` indexed ``[x, y]``:
  ``(x, y, value)`` in the topography's own unit (files Gwyddion 2.62 does not read).

Heights are compared up to a positive scale and an offset (the readers' unit and scale decisions are tested
elsewhere; SurfaceTopography's MNT scale, for one, differs): the four values, each set shifted to its minimum and
divided by its range, must agree.
"""

import math

import numpy as np
import pytest

import rough
from rough.fractal.synth_map import synthesize_map

from conftest import shared_data_path

DATA = shared_data_path()  # ../shared/data, or $ROUGH_SHARED/data
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason="needs ../shared/data")

# (file, channel or None for the default, [(Gwyddion row, Gwyddion column, height in metres), ...])
GWYDDION = [
    (
        "SurfaceTopography/al3d-1.al3d",
        None,
        [(0, 0, 0.0763581544161), (0, 199, 0.0763457044959), (295, 0, 0.0763367936015), (295, 199, 0.0763232037425)],
    ),
    (
        "SurfaceTopography/bcrf-1.bcrf",
        None,
        [
            (0, 0, 5.06283718103e-05),
            (0, 959, 5.06257968896e-05),
            (599, 0, 5.06285053247e-05),
            (599, 959, 5.05906902307e-05),
        ],
    ),
    (
        "SurfaceTopography/di-1.di",
        "Height",
        [
            (0, 0, 6.05998011118e-09),
            (0, 511, -9.7401786555e-09),
            (511, 0, 2.84315916694e-09),
            (511, 511, -3.03063748936e-08),
        ],
    ),
    (
        "SurfaceTopography/di-3.di",
        "ZSensor",
        [
            (0, 0, 5.64016302441e-07),
            (0, 255, 1.27148183787e-07),
            (255, 0, 6.43150486756e-08),
            (255, 255, -6.16476042605e-07),
        ],
    ),
    (
        "SurfaceTopography/di-5.di",
        "ZSensor",
        [
            (0, 0, -3.18730335548e-07),
            (0, 511, -3.19773487118e-07),
            (511, 0, -3.01807603415e-07),
            (511, 511, -3.02540903019e-07),
        ],
    ),
    (
        "SurfaceTopography/example_ps.tiff",
        "Z Height",
        [
            (0, 0, -2.01995107881e-09),
            (0, 511, 8.95068830975e-10),
            (511, 0, 3.83816732062e-09),
            (511, 511, 2.08363862149e-09),
        ],
    ),
    (
        "SurfaceTopography/frt-1.frt",
        "Topography",
        [
            (443, 56, 7.6760155034e-05),
            (443, 443, 8.11352885525e-05),
            (56, 56, 7.39671010468e-05),
            (56, 443, 7.86254463332e-05),
        ],
    ),
    (
        "SurfaceTopography/frt-2.frt",
        "Topography",
        [
            (240, 59, 7.38206122013e-05),
            (240, 90, 7.43089083529e-05),
            (59, 59, 7.02853480636e-05),
            (59, 90, 7.14865565966e-05),
        ],
    ),
    (
        "SurfaceTopography/metropro-1.dat",
        None,
        [
            (0, 0, 5.05753145603e-05),
            (0, 639, 5.08308995811e-05),
            (479, 0, 5.05675563816e-05),
            (479, 639, 5.0851886672e-05),
        ],
    ),
    (
        "SurfaceTopography/mi-1.mi",
        "Topography",
        [
            (0, 0, -4.98690032959e-07),
            (0, 255, -5.98162307739e-07),
            (255, 0, -5.12242355347e-07),
            (255, 255, -6.28987197876e-07),
        ],
    ),
    (
        "SurfaceTopography/nid-1.nid",
        "Scan forward (Z-Axis)",
        [
            (0, 0, -9.253918036e-07),
            (0, 255, -1.72022784582e-06),
            (255, 0, -1.23216537984e-06),
            (255, 255, -1.98257838057e-06),
        ],
    ),
    (
        "SurfaceTopography/opd-1.opd",
        "Raw",
        [
            (0, 0, -2.65506216149e-07),
            (0, 639, -2.56463289001e-07),
            (479, 0, -2.83992854659e-07),
            (479, 639, -2.73773812086e-07),
        ],
    ),
    (
        "SurfaceTopography/plu-1.plu",
        None,
        [
            (0, 0, -0.0001112265625),
            (0, 767, -0.00010144921875),
            (575, 0, -0.00011106640625),
            (575, 767, -0.00010121484375),
        ],
    ),
    (
        "SurfaceTopography/sdf-1.sdf",
        None,
        [(1, 1, 9.9748e-07), (1, 5, 9.6736e-07), (2, 1, 9.9369e-07), (2, 5, 9.6369e-07)],
    ),
    (
        "SurfaceTopography/spot_1-1000nm.ibw",
        "HeightTrace",
        [
            (0, 0, -3.99694698672e-07),
            (0, 255, -7.04592196143e-07),
            (255, 0, -3.31233451334e-07),
            (255, 255, -6.81755864207e-07),
        ],
    ),
    (
        "SurfaceTopography/sur-3.sur",
        None,
        [
            (225, 225, 0.00199985777418),
            (225, 286, 0.00187011977784),
            (286, 225, 0.00166838178355),
            (286, 286, 0.00177337978058),
        ],
    ),
    (
        "SurfaceTopography/top-1.top",
        None,
        [
            (0, 0, 1.15503833607e-07),
            (0, 255, 1.15387378726e-07),
            (255, 0, 1.2489786074e-07),
            (255, 255, 1.30972923741e-07),
        ],
    ),
    (
        "SurfaceTopography/x3p-2.x3p",
        None,
        [
            (0, 0, 6.57978134122e-08),
            (0, 649, -4.13331865878e-08),
            (649, 0, 9.59761134122e-08),
            (649, 649, -3.27691865878e-08),
        ],
    ),
    (
        "dem/TM1_564_146.tif",
        None,
        [(999, 0, 324.950012207), (999, 999, 275.029998779), (0, 0, 305.730010986), (0, 999, 299.369995117)],
    ),
    (
        "dem/TM1_564_146_nodata.tif",
        None,
        [(999, 0, 324.950012207), (999, 999, 275.029998779), (0, 0, 305.730010986), (0, 999, 299.369995117)],
    ),
    (
        "opengps/ISO5436-sample1.x3p",
        None,
        [(0, 0, 0.486219120804), (0, 3, -0.579793099037), (3, 0, 0.675397146761), (3, 3, -0.215696638465)],
    ),
    (
        "opengps/ISO5436-sample1_bin.x3p",
        None,
        [(0, 0, 0.486219120804), (0, 3, -0.579793099037), (3, 0, 0.675397146761), (3, 3, -0.215696638465)],
    ),
    ("opengps/ISO5436-sample4.x3p", None, [(0, 0, 0.486), (0, 3, -0.58), (3, 0, 0.675), (3, 3, -0.216)]),
    ("opengps/ISO5436-sample4_bin.x3p", None, [(0, 0, 0.486), (0, 3, -0.58), (3, 0, 0.675), (3, 3, -0.216)]),
    (
        "opengps/KautschukInfiniteFocus.x3p",
        None,
        [
            (3, 3, 6.81735127728e-06),
            (3, 856, 5.04471108798e-06),
            (630, 3, 3.6157221075e-06),
            (630, 856, -4.54317751064e-06),
        ],
    ),
    (
        "x3pio/iso25178-72-2017/surface_binary.x3p",
        None,
        [
            (0, 0, 9.99986586795e-07),
            (0, 199, -6.59805601019e-08),
            (149, 0, -3.82679549576e-07),
            (149, 199, 2.91869665515e-07),
        ],
    ),
    (
        "x3pio/iso25178-72-2017/surface_extensions_binary.x3p",
        None,
        [
            (0, 0, 9.99999997475e-07),
            (0, 99, 7.07106778464e-07),
            (79, 0, 9.23879554193e-07),
            (79, 99, 6.53281460927e-07),
        ],
    ),
    (
        "x3pio/iso25178-72-fdam1/surface_binary.x3p",
        None,
        [
            (0, 0, 9.99986586795e-07),
            (0, 199, -6.59805601019e-08),
            (149, 0, -3.82679549576e-07),
            (149, 199, 2.91869665515e-07),
        ],
    ),
    (
        "x3pio/iso25178-72-fdam1/surface_extensions_binary.x3p",
        None,
        [
            (0, 0, 9.99999997475e-07),
            (0, 99, 7.07106778464e-07),
            (79, 0, 9.23879554193e-07),
            (79, 99, 6.53281460927e-07),
        ],
    ),
    (
        "x3pio/iso25178-72-fdam1/surface_int32_binary.x3p",
        None,
        [
            (0, 0, 1.00000000011e-06),
            (0, 119, 1.26136815219e-06),
            (89, 0, -9.23879532318e-07),
            (89, 119, -5.96956774652e-07),
        ],
    ),
    (
        "x3pio/iso25178-72-fdam1/surface_int32_xml.x3p",
        None,
        [
            (0, 0, 1.00000000011e-06),
            (0, 119, 1.26136815219e-06),
            (89, 0, -9.23879532318e-07),
            (89, 119, -5.96956774652e-07),
        ],
    ),
    (
        "x3pio/iso25178-72-fdam1/surface_layers_binary.x3p",
        None,
        [(0, 0, 1e-06), (0, 159, -9.66914402322e-07), (119, 0, -9.23879532511e-07), (119, 159, 3.93473861303e-07)],
    ),
    (
        "x3pio/iso25178-72-fdam1/surface_layers_xml.x3p",
        None,
        [(0, 0, 1e-06), (0, 159, -9.66914402322e-07), (119, 0, -9.23879532511e-07), (119, 159, 3.93473861303e-07)],
    ),
    (
        "x3pio/iso25178-72-fdam1/surface_xml.x3p",
        None,
        [
            (0, 0, 9.99986586795e-07),
            (0, 199, -6.59805601019e-08),
            (149, 0, -3.82679549576e-07),
            (149, 199, 2.91869665515e-07),
        ],
    ),
    (
        "x3ptools/testing.x3p",
        None,
        [(0, 0, 0.00896233972162), (0, 29, 0.00231519341469), (19, 0, 0.00683678826317), (19, 29, -3.25008986692e-05)],
    ),
]
# (file, channel, [(x, y, heights()[x, y] in the topography's unit), ...])
SURFACETOPOGRAPHY = [
    (
        "SurfaceTopography/matrix-2.txt",
        None,
        [
            (0, 0, -2.24584980713e-07),
            (649, 0, -3.63868732263e-08),
            (0, 649, -6.09227732645e-07),
            (649, 649, 1.56584082685e-08),
        ],
    ),
    (
        "SurfaceTopography/matrix-3.txt",
        None,
        [(0, 0, 1.8823e-08), (255, 0, 1.7899e-07), (0, 255, 8.2126e-09), (255, 255, -7.5542e-08)],
    ),
    ("SurfaceTopography/matrix-6.txt", None, [(0, 0, 1.0), (3, 0, 4.0), (0, 2, 9.0), (3, 2, 12.0)]),
    (  # SurfaceTopography read the file unpacked
        "SurfaceTopography/matrix-4.txt.gz",
        None,
        [
            (0, 0, -1.298199355698e-07),
            (74, 0, -2.453013937096e-07),
            (0, 304, 2.13665054148e-07),
            (74, 304, 1.980200491684e-07),
        ],
    ),
    (
        "SurfaceTopography/mnt-1.mnt",
        None,
        [(0, 0, 50.6283722346), (959, 0, 50.6257972346), (0, 599, 50.6285057346), (959, 599, 50.5906906346)],
    ),
    (
        "SurfaceTopography/mnt-2.mnt",
        None,
        [(95, 95, 0.808742473278), (1184, 95, 0.905558806896), (95, 864, 0.865761708221), (1184, 864, 0.7722036166)],
    ),
    (
        "SurfaceTopography/nms-1.nms",
        None,
        [(0, 0, 2.6891245842), (511, 0, 4.8862038648), (0, 511, 3.81047504278), (511, 511, 6.00745305449)],
    ),
    (
        "SurfaceTopography/tmd-1.tmd",
        None,
        [(0, 0, 0.223517924547), (299, 0, 0.224121123552), (0, 299, 0.237542316318), (299, 299, 0.230540886521)],
    ),
    (
        "surfalize/test_1.zon",
        None,
        [(2, 2, 0.0002965), (1021, 2, 0.0008758), (2, 766, 0.0002902), (1021, 766, 0.0008314)],
    ),
]
# small files whose corners repeat: SurfaceTopography 1.27.1's whole heights()[x, y] (NaN: undefined)
WHOLE = [
    ("SurfaceTopography/txt_example.txt", [[1e-7, 5e-8, 0], [0, 5e-8, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0]]),
    ("SurfaceTopography/gwyddion-export-english.txt", [[1, -2, 0, 9], [1.5, -3, 0, 9], [3, -6, 0, 9]]),
    ("SurfaceTopography/xyz-2.txt", [[1, 1, 1, 1], [math.nan, 1, 1, 1], [1, math.nan, 2, 2], [2, 2, 2, 2]]),
    ("SurfaceTopography/nc-1.nc", [[9, 7, 5, 3, 1, -1, -3, -5, -7, -9]] * 5),
    ("SurfaceTopography/10x10-one_channel_without_name.ibw", [[1] * 10] * 5 + [[1.1421] * 10] + [[2] * 10] * 4),
]


def pattern(values):
    """``values`` shifted to their minimum and divided by their range: equal for two sets that differ by a
    positive scale and an offset, different for any other order of the same distinct values."""
    values = np.asarray(values, float)
    return (values - np.nanmin(values)) / (np.nanmax(values) - np.nanmin(values))


def read(name, channel):
    return rough.read(DATA / name, channel=channel).heights


@needs_data
@pytest.mark.parametrize("name, channel, points", GWYDDION, ids=[entry[0] for entry in GWYDDION])
def test_rows_and_columns_as_gwyddion_places_them(name, channel, points):
    z = read(name, channel)
    georeferenced = name.startswith("dem/")  # y north: Gwyddion's rows in reverse
    ours = [z[z.shape[0] - 1 - row if georeferenced else row, column] for row, column, _ in points]
    np.testing.assert_allclose(pattern(ours), pattern([value for *_, value in points]), atol=1e-6)


@needs_data
@pytest.mark.parametrize("name, channel, points", SURFACETOPOGRAPHY, ids=[entry[0] for entry in SURFACETOPOGRAPHY])
def test_rows_and_columns_as_surfacetopography_places_them(name, channel, points):
    z = read(name, channel)
    ours = [z[y, x] for x, y, _ in points]
    np.testing.assert_allclose(pattern(ours), pattern([value for *_, value in points]), atol=1e-6)


@needs_data
@pytest.mark.parametrize("name, heights", WHOLE, ids=[entry[0] for entry in WHOLE])
def test_small_maps_equal_surfacetopography_transposed(name, heights):
    z = read(name, None)
    np.testing.assert_allclose(pattern(z), pattern(np.array(heights).T), atol=1e-4)  # 1.1421: 5 digits
    np.testing.assert_array_equal(np.isnan(z), np.isnan(np.array(heights).T))


@needs_data
def test_di1_corners_as_surfacetopography_asserts_them():
    """SurfaceTopography's test_di_orientation: h[0, 0] 6.060, h[0, -1] 2.843, h[-1, 0] -9.740, h[-1, -1] -30.306 nm
    with h indexed [x, y], so z[0, 0], z[-1, 0], z[0, -1], z[-1, -1] here."""
    z = read("SurfaceTopography/di-1.di", "Height")
    corners = np.array([z[0, 0], z[-1, 0], z[0, -1], z[-1, -1]]) * 1e9
    np.testing.assert_allclose(corners, [6.060, 2.843, -9.740, -30.306], atol=1e-3)


@needs_data
@pytest.mark.parametrize("name, sq", [("frt-1.frt", 4.915785774480653e-06), ("frt-2.frt", 8.826763181113768e-06)])
def test_frt_heights_and_invalid_points_as_gwyddion_reads_them(name, sq):
    """Gwyddion 2.62's data field equals rough's heights exactly at every valid point and its mask marks the same
    points (76456 and 12314); the RMS height of the valid points is the Sq below. SurfaceTopography's test asserts
    2.047476e-05 and 1.853335e-05 m, which neither Gwyddion nor SurfaceTopography 1.27.1 (4.915786e-06 m for frt-1)
    reproduces."""
    z = read(f"SurfaceTopography/{name}", None)
    assert np.nanstd(z) == pytest.approx(sq, rel=1e-12)


# -- the drawing --------------------------------------------------------------------------------------


def north_up_geotiff(path, rows_from_north, spacing=1.0):
    """A north-up GeoTIFF (EPSG:32633) whose first stored row is the northern edge, written with rasterio."""
    rasterio = pytest.importorskip("rasterio")
    from rasterio.transform import Affine

    ny, nx = rows_from_north.shape
    transform = Affine(spacing, 0.0, 500000.0, 0.0, -spacing, 4000000.0 + ny * spacing)
    profile = {"driver": "GTiff", "width": nx, "height": ny, "count": 1, "dtype": "float64"}
    with rasterio.open(path, "w", crs="EPSG:32633", transform=transform, **profile) as dataset:
        dataset.write(rows_from_north, 1)
    return path


def drawn(surface):
    """The map of ``rough show`` as pixels (grey levels, row 0 at the top of the page) and its axes."""
    pytest.importorskip("matplotlib")
    from rough import plot

    figure = plot.surface_figure(surface, colormap="gray")
    figure.canvas.draw()
    axes = figure.axes[0]
    box = axes.get_window_extent()
    pixels = np.asarray(figure.canvas.buffer_rgba())[..., :3].mean(axis=2)
    height = pixels.shape[0]
    image = pixels[round(height - box.y1) + 2 : round(height - box.y0) - 2, round(box.x0) + 2 : round(box.x1) - 2]
    return image, axes


def test_a_dem_is_drawn_north_up(tmp_path):
    """A hill in the north-east corner of a north-up GeoTIFF is drawn at the upper right, with y (northing)
    increasing upwards."""
    ny, nx = 60, 80
    north, east = np.mgrid[ny:0:-1, 0:nx]  # rows from the north, as the file stores them
    hill = 100.0 + 5.0 * np.exp(-((east - 0.8 * nx) ** 2 + (north - 0.8 * ny) ** 2) / 20.0)
    scan = rough.read(north_up_geotiff(tmp_path / "hill.tif", hill))
    image, axes = drawn(scan)
    row, column = np.unravel_index(np.argmax(image), image.shape)
    assert row < 0.35 * image.shape[0] and column > 0.65 * image.shape[1], (row, column, image.shape)
    bottom, top = axes.get_ylim()
    assert axes.get_ylabel() == "y (m)" and (bottom, top) == pytest.approx((4000000, 4000060), rel=1e-12)  # the raster


def test_the_drawing_shows_the_lay_the_rose_finds_on_a_dem(tmp_path):
    """Ridges running south-west to north-east (lay 45°, counter-clockwise from east): the rose finds 45°, and on
    the drawn page the grey level changes less along 45° than across it."""
    from rough.fractal.sectors import rose

    spec = (2.3, 1e-6, 2.3, 8e-6, math.radians(45.0))  # 8 times rougher across the ridges than along
    ridges = synthesize_map((256, 256), (1e-6, 1e-6), None, seed=45, anisotropy=spec).heights * 1e6  # 1 m spacing
    scan = rough.read(north_up_geotiff(tmp_path / "ridges.tif", ridges[::-1]))
    lay = rose(scan, step=15.0).lay["resolution"]["direction"]
    assert min(abs(lay - 45.0), 180 - abs(lay - 45.0)) <= 15.0
    image, _ = drawn(scan)
    shift = 8  # pixels; page rows run downwards, so 45° on the page is (row - k, column + k)
    along = np.mean((image[shift:, :-shift] - image[:-shift, shift:]) ** 2)
    across = np.mean((image[:-shift, :-shift] - image[shift:, shift:]) ** 2)
    assert along < 0.7 * across, (along, across)


@needs_data
def test_the_real_dem_is_drawn_north_up():
    """TM1_564_146.tif's highest ground (325 m) is at its south-west corner (the file's last row, first column):
    it is drawn at the lower left."""
    scan = rough.read(DATA / "dem" / "TM1_564_146.tif")
    image, _ = drawn(scan)
    row, column = np.unravel_index(np.argmax(image), image.shape)
    assert row > 0.9 * image.shape[0] and column < 0.1 * image.shape[1], (row, column, image.shape)
