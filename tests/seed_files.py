"""Small valid files of every format rough reads, as bytes: the seeds that the
mutation tests (tests/test_fuzz.py) and the coverage-guided fuzzer
(bench/fuzz_readers.py) start from. The vendor files are hand-made here from the
layouts the reader modules' docstrings state (rough/io/<format>.py), a few hundred
bytes each; tests/hostile/make_corpus.py damages the same files on purpose."""

import gzip
import importlib.util
import io
import struct
import zipfile
import zlib

import numpy as np

from rough import Surface

from format_files import al3d_file, sdf_binary

MAP = np.array([[1.0, 2.0, np.nan, 4.0], [5.0, 6.0, 7.0, 8.0], [9.0, 10.0, 11.0, 12.0]]) * 1e-6
PROFILE = np.array([0.0, 1.5, -2.0, 3.25, 0.5, 1.0]) * 1e-6
COUNTS = np.array([[1, -2, 3, 40], [5, 600, -7, 8], [9, 10, -11, 1200]])  # raw values of the vendor seeds


def _written(surface, fmt):
    buffer = io.BytesIO()
    surface.write(buffer, fmt)
    return buffer.getvalue()


def _installed(module):
    try:
        return importlib.util.find_spec(module) is not None
    except ImportError:
        return False


def seeds():
    """``{name: bytes}`` of valid inputs, one or more per reader."""
    surface = Surface(MAP, (1e-6, 2e-6), metadata={"title": "seed"})
    profile = Surface(PROFILE, (0.5e-6,))
    result = {f"map.{fmt}": _written(surface, fmt) for fmt in ("x3p", "exr", "gsf", "tsv", "npy")}
    result.update({f"profile.{fmt}": _written(profile, fmt) for fmt in ("x3p", "tsv")})
    result["columns.csv"] = b"x [um];z [um]\n0,0;1,5\n0,5;2,25\n1,0;BAD\n1,5;3,0\n"
    result["dektak.csv"] = (
        b"Scan Parameters\r\r\nLength,1.6 um\r\nResolution,0.156 um/sample\r\n\r\r\n"
        b"Scan Data\r\r\nLateral um,Raw Micrometer,\r\n0.0,-0.00933,,\r\n0.2,-0.00760,,\r\n"
        b"0.3,-0.00644,,\r\n0.5,-0.00498,,\r\n0.6,-0.00345,,\r\n0.8,-0.00200,,\r\n0.9,-0.00101,,\r\n"
        b"1.1,0.00012,,\r\n1.2,0.00140,,\r\n1.4,0.00261,,\r\n1.6,0.00398,,\r\n"
    )
    result["gwyddion.txt"] = (
        b"# Channel: Height\n# Width: 12.34 um\n# Height: 5.6789 um\n# Value units: m\n"
        b"1e-9 2e-9 3e-9\n4e-9 5e-9 6e-9\n7e-9 8e-9 9e-9\n1e-9 1e-9 1e-9\n"
    )
    result["grid.xyz"] = b"0 0 1\n1 0 2\n0 1 3\n1 1 4\n0 2 5\n1 2 6\n"
    result["ascii.sdf"] = (
        b"aISO-1.0\nManufacID = seed\nNumPoints = 3\nNumProfiles = 2\nXscale = 1e-6\nYscale = 1e-6\n"
        b"Zscale = 1e-6\nDataType = 7\n*\n1 2 BAD\n4 5 6\n*\n"
    )
    result["binary.sdf"] = sdf_binary(
        3, 2, 1e-6, 2e-6, datatype=5, body=np.arange(6, dtype="<i2").tobytes(), manufacturer=b"seed"
    )
    result["depth.al3d"] = al3d_file(
        np.arange(15, dtype="<f4").reshape(3, 5) * np.float32(1e-6), tags={"CreatingApplication": "seed"}
    )
    result["map.tsv.gz"] = gzip.compress(result["map.tsv"])
    if _installed("gwyfile"):
        result["map.gwy"] = _written(surface, "gwy")
        result["profile.gwy"] = _written(profile, "gwy")
    if _installed("rasterio"):
        result["map.tif"] = _written(Surface(MAP, (1.0, 2.0), metadata={"crs": "EPSG:32632"}), "geotiff")
    result.update(vendor_seeds())
    return result


def vendor_seeds():
    """``{name: bytes}`` of the hand-made vendor files, for the readers whose libraries are installed."""
    result = {
        "map.sur": sur_file(),
        "compressed.sur": sur_file(compressed=True),
        "map.tmd": tmd_file(),
        "map.frt": frt_file(),
        "map.dat": metropro_file(),
        "map.opd": opd_file(),
        "map.nms": nms_file(),
        "map.plu": plu_file(),
        "map.spm": di_file(),
        "map.bcr": bcr_file(),
        "map.mi": mi_file(),
        "map.nid": nid_file(),
        "map.top": wsxm_file(),
        "map.opdx": opdx_file(),
    }
    for name, module, build in (("map.ibw", "igor2", ibw_file), ("map.zon", "zstandard", zon_file)):
        if _installed(module):
            result[name] = build()
    if _installed("tifffile"):
        result["park.tiff"] = park_file()
    result["map.nc"] = netcdf_file()
    result["profile.zip"] = nmm_zip()
    return result


# -- hand-made vendor files (layouts from the docstrings of rough/io/<format>.py) -------------------


def sur_file(counts=COUNTS, bits=16, nx=None, ny=None, dx=1.0, dy=2.0, unit=b"um", compressed=False):
    """Digital Surf SUR: a 512-byte header, then int16 (int32) points row by row."""
    ny_, nx_ = np.shape(counts)
    points = np.asarray(counts, "<i2" if bits == 16 else "<i4").tobytes()
    header = bytearray(512)
    header[0:12] = b"DSCOMPRESSED" if compressed else b"DIGITAL SURF"
    struct.pack_into("<h", header, 14, 1)  # object count
    struct.pack_into("<h", header, 18, 2)  # a surface
    header[20:24] = b"seed"
    struct.pack_into("<h", header, 86, 1)  # non-measured points flagged
    struct.pack_into("<hii", header, 98, bits, -100, 2000)
    struct.pack_into("<ii", header, 108, nx if nx is not None else nx_, ny if ny is not None else ny_)
    struct.pack_into("<fff", header, 120, dx, dy, 0.01)
    for offset in (180, 196, 212):
        header[offset : offset + len(unit)] = unit
    struct.pack_into("<6h", header, 306, 5, 4, 3, 2, 1, 2020)
    if compressed:
        packed = [points[: len(points) // 2], points[len(points) // 2 :]]
        streams = [zlib.compress(part) for part in packed]
        sizes = b"".join(struct.pack("<II", len(a), len(b)) for a, b in zip(packed, streams))
        points = struct.pack("<I", len(streams)) + sizes + b"".join(streams)
        struct.pack_into("<I", header, 324, len(points))
    return bytes(header) + points


def tmd_file(heights=MAP * 1e6, nx=None, ny=None, lengths=(4.0, 6.0)):
    """TrueMap TMD v2: magic, comment, uint32 width and height, float32 lengths and offsets, float32 µm."""
    rows, cols = np.shape(heights)
    header = b"Binary TrueMap Data File v2.0\r\n\0" + b"seed".ljust(24, b"\0")
    header += struct.pack("<2I4f", nx or cols, ny or rows, *lengths, 0.5, -0.5)
    return header + np.asarray(heights, "<f4").tobytes()


def frt_file(counts=COUNTS + 100, nx=None, ny=None, bits=16, block_size=None):
    """FRT MicroProf 1.00: magic, version, block count, blocks of uint16 id and uint32 size."""
    rows, cols = np.shape(counts)
    points = np.asarray(counts, "<u2" if bits == 16 else "<i4").tobytes()
    blocks = [
        (0x0066, struct.pack("<3I", nx or cols, ny or rows, bits)),
        (0x0067, struct.pack("<4d", 4e-6, 6e-6, 0.0, 0.0)),
        (0x006C, struct.pack("<Id", 0, 1e-9)),
        (0x0072, struct.pack("<I", 1600000000)),
        (0x000B, points),
    ]
    body = b"".join(
        struct.pack("<HI", block, len(payload) if block_size is None or block != 0x0B else block_size) + payload
        for block, payload in blocks
    )
    return b"FRTM_GLIDERV1.00" + struct.pack("<H", len(blocks)) + body


def metropro_file(phase=COUNTS * 1000, cn=None, ac=(0, 0, 0), lateral=1e-6, buckets=None):
    """Zygo MetroPro, header format 1: 834 big-endian bytes, then the intensity buckets (``ac``: width,
    height, count of uint16; ``buckets`` overrides their bytes) and the int32 phase."""
    rows, cols = np.shape(phase)
    header = bytearray(834)
    struct.pack_into(">4sHI", header, 0, b"\x88\x1b\x03\x6f", 1, 834)
    header[12:16] = b"seed"
    struct.pack_into(">HHH", header, 52, *ac)
    struct.pack_into(">HH", header, 68, *(cn or (cols, rows)))
    struct.pack_into(">i", header, 76, 1600000000)
    struct.pack_into(">6f", header, 164, 0.5, 632.8e-9, 0.0, 1.0, 0.0, lateral)
    struct.pack_into(">h", header, 218, 1)
    buckets = bytes(2 * ac[0] * ac[1] * ac[2]) if buckets is None else buckets
    return bytes(header) + buckets + np.asarray(phase, ">i4").tobytes()


def opd_file(counts=COUNTS, sizes=None, directory_size=None):
    """Wyko OPD: ``01 00``, a directory of 24-byte entries (16-byte name, uint16 type, uint32 size, uint16
    flags), then the items' data in entry order; the Raw array holds int16 columns, each bottom row first.
    ``sizes`` overrides the sizes the directory declares."""
    rows, cols = np.shape(counts)
    array = struct.pack("<HHH", cols, rows, 2) + np.asarray(counts, "<i2")[::-1].T.tobytes()
    items = [
        ("Raw", 3, array),
        ("Wavelength", 7, struct.pack("<f", 632.8)),
        ("Pixel_size", 7, struct.pack("<f", 0.001)),
        ("Mult", 6, struct.pack("<h", 1)),
        ("Title", 5, b"seed\0"),
    ]
    sizes = {"Directory": directory_size or 24 * (len(items) + 1), **(sizes or {})}

    def entry(name, kind, payload):
        return name.encode().ljust(16, b"\0") + struct.pack("<HIH", kind, sizes.get(name, len(payload)), 0)

    directory = entry("Directory", 1, b"") + b"".join(entry(*item) for item in items)
    return b"\x01\x00" + directory + b"".join(item[2] for item in items)


def nms_file(counts=COUNTS + 100, nx=None, ny=None):
    """Nanofocus NMS: a 3468-byte header, then uint16 heights."""
    rows, cols = np.shape(counts)
    header = bytearray(3468)
    struct.pack_into("<I2d", header, 12, 65535, -1.0, 2.0)
    header[32:41] = b"OM_MS_2.0"
    header[52:73] = b"Confocal Height Image"
    header[1076:1092] = b"2020-01-02T03:04"
    struct.pack_into("<2I2d", header, 1368, nx or cols, ny or rows, 312.5, 312.5)
    return bytes(header) + np.asarray(counts, "<u2").tobytes() + bytes(rows * cols)


def plu_file(heights=MAP * 1e6, rows=None, cols=None, kind=3):
    """Sensofar PLU (by extension): a 500-byte header, then a layer of float32 µm."""
    shape = np.shape(heights)
    header = bytearray(500)
    header[0:10] = b"2020-01-02"
    struct.pack_into("<I", header, 128, 1600000000)
    header[132:136] = b"seed"
    struct.pack_into("<3If", header, 388, *shape, 0, 1.0)
    struct.pack_into("<2f", header, 404, 1.0, 2.0)
    struct.pack_into("<5I", header, 428, kind, 0, 0, 5, 0)
    header[428 + 61] = 1  # one layer
    values = np.where(np.isnan(heights), 1000001.0, heights)
    layer = struct.pack("<2I", rows or shape[0], cols or shape[1]) + np.asarray(values, "<f4").tobytes()
    return bytes(header) + layer + struct.pack("<2f", 0.0, 12.0)


def di_file(counts=COUNTS, fields=None, pad=640):
    """Bruker Nanoscope: a text header (File list, scanner list, one Ciao image list), then int16 points."""
    rows, cols = np.shape(counts)
    image = {
        "Data offset": pad,
        "Data length": 2 * rows * cols,
        "Bytes/pixel": 2,
        "Samps/line": cols,
        "Number of lines": rows,
        "Scan Size": "400 300 nm",
        "Line Direction": "Retrace",
        "@2:Image Data": 'S [Height] "Height"',
        "@2:Z scale": "V [Sens. Zsens] (0.006 V/LSB) 1.5 V",
    }
    image.update(fields or {})
    lines = ["\\*File list", "\\Version: 0x05120000", f"\\Data length: {pad}", "\\Date: 03:04:05 PM Thu Jan 02 2020"]
    lines += ["\\*Scanner list", "\\@Sens. Zsens: V 20.5 nm/V", "\\*Ciao image list"]
    lines += [f"\\{key}: {value}" for key, value in image.items()] + ["\\*File list end", ""]
    header = "\r\n".join(lines).encode("latin-1")
    return header.ljust(pad, b"\x1a") + np.asarray(counts, "<i2").tobytes()


def bcr_file(counts=COUNTS, fields=None, size=256):
    """BCR-STM: a ``key = value`` header of ``headersize`` characters, then int16 points."""
    rows, cols = np.shape(counts)
    header = {
        "fileformat": "bcrstm",
        "headersize": size,
        "xpixels": cols,
        "ypixels": rows,
        "xlength": 400,
        "ylength": 300,
        "xunit": "nm",
        "zunit": "nm",
        "bit2nm": 0.25,
        "intelmode": 1,
    }
    header.update(fields or {})
    text = "".join(f"{key} = {value}\n" for key, value in header.items()).encode("latin-1")
    return text.ljust(size, b"\0") + np.asarray(counts, "<i2").tobytes()


def mi_file(counts=COUNTS, fields=None):
    """Agilent MI image: 14-character keys, one channel, ``data BINARY``, then int16 points."""
    rows, cols = np.shape(counts)
    header = {"fileType": "Image", "xPixels": cols, "yPixels": rows, "xLength": 4e-6, "yLength": 3e-6}
    header.update(fields or {})
    channel = {"bufferLabel": "Topography", "bufferRange": "0.5", "bufferUnit": "um", "direction": "Trace"}
    lines = [f"{key:<14}{value}" for key, value in (*header.items(), *channel.items())]
    text = "\n".join(lines + ["data          BINARY", ""]).encode("latin-1")
    return text + np.asarray(counts, "<i2").tobytes()


def nid_file(counts=COUNTS, fields=None):
    """Nanosurf NID: an INI header, ``#!``, then int16 points."""
    rows, cols = np.shape(counts)
    data_set = {
        "Frame": "Scan forward",
        "Points": cols,
        "Lines": rows,
        "SaveBits": 16,
        "SaveSign": "Signed",
        "SaveOrder": "Intel",
        "Dim0Range": 4e-6,
        "Dim0Unit": "m",
        "Dim1Range": 3e-6,
        "Dim2Name": "Z-Axis",
        "Dim2Unit": "m",
        "Dim2Range": 1e-7,
        "Dim2Min": -5e-8,
    }
    data_set.update(fields or {})
    lines = ["[DataSet]", "Version=2", "GroupCount=1", "Gr0-Name=Scan forward", "Gr0-Count=1"]
    lines += ["Gr0-Ch0=DataSet-0:0", "", "[DataSet-Info]", "Date=02-01-2020", "Time=03:04:05", ""]
    lines += ["[DataSet-0:0]"] + [f"{key}={value}" for key, value in data_set.items()]
    return ("\r\n".join(lines) + "\r\n#!").encode("latin-1") + np.asarray(counts, "<i2").tobytes()


def wsxm_file(counts=COUNTS, fields=None):
    """WSxM image: the text header up to ``[Header end]``, then int16 points."""
    rows, cols = np.shape(counts)
    info = {"Image Data Type": "short", "Number of columns": cols, "Number of rows": rows, "Z Amplitude": "12 nm"}
    info.update(fields or {})
    lines = ["WSxM file copyright Nanotec Electronica", "SxM Image file", "Image header size: 0", ""]
    lines += ["[Control]", "", "    X Amplitude: 400 nm", "    Y Amplitude: 300 nm", "", "[General Info]", ""]
    lines += [f"    {key}: {value}" for key, value in info.items()]
    lines += ["", "[Miscellaneous]", "", "    Maximum: 1200", "    Minimum: -11", "", "[Header end]", ""]
    return "\r\n".join(lines).encode("latin-1") + np.asarray(counts, "<i2").tobytes()


def ibw_file(heights=MAP, dims=None, checksum=True, unit=b"m", sizes=None):
    """Igor binary wave, version 5: a 64-byte binary header and a 320-byte wave header whose 16-bit words
    add up to zero, then float32 values (x fastest: the image is stored transposed, column-major). ``sizes``
    sets int32 section sizes of the binary header by offset (12: noteSize, 36: dimLabelsSize[0], ...)."""
    rows, cols = np.shape(heights)
    values = np.asarray(heights, "<f4").T.tobytes(order="F")
    header = bytearray(64 + 320)
    struct.pack_into("<hhi", header, 0, 5, 0, 320 + len(values))  # version, checksum, wfmSize
    wave = 64
    struct.pack_into("<i h", header, wave + 12, rows * cols, 2)  # npnts, NT_FP32
    header[wave + 28 : wave + 32] = b"seed"  # bname
    struct.pack_into("<4i", header, wave + 68, *(dims or (cols, rows, 0, 0)))  # nDim: x points, y points
    struct.pack_into("<4d", header, wave + 84, 1e-6, 2e-6, 1.0, 1.0)  # sfA
    header[wave + 148 : wave + 148 + len(unit)] = unit  # dataUnits
    header[wave + 152 : wave + 152 + len(unit)] = unit  # dimUnits[0]
    header[wave + 156 : wave + 156 + len(unit)] = unit  # dimUnits[1]
    for offset, size in (sizes or {}).items():
        struct.pack_into("<i", header, offset, size)
    if checksum:
        total = int(np.frombuffer(bytes(header), "<u2").sum()) % 65536
        struct.pack_into("<H", header, 2, (65536 - total) % 65536)
    return bytes(header) + values


def opdx_file(heights=MAP * 1e6, rows=None, columns=None):
    """Bruker OPDx map: the VCA magic, then containers of typed items (see rough/io/opdx.py)."""
    shape = np.shape(heights)

    def item(name, kind, payload):
        raw = name.encode()
        return struct.pack("<I", len(raw)) + raw + bytes([kind]) + payload

    def sized(payload):
        return b"\x04" + struct.pack("<I", len(payload)) + payload

    def text(value):
        raw = value.encode()
        return struct.pack("<I", len(raw)) + raw

    def container(name, *children):
        return item(name, 0x7D, sized(b"".join(children) + item("", 0x7F, b"")))

    def quantity(value, symbol):
        return sized(struct.pack("<d", value) + text("unit") + text(symbol))

    matrix = text("float") + struct.pack("<I", 0) + text("m")
    matrix += sized(struct.pack("<2I", rows or shape[0], columns or shape[1]) + np.asarray(heights, "<f4").tobytes())
    return (
        b"VCA DATA\x01\x00\x00\x55"
        + container(
            "2D_Data",
            container(
                "Height",
                item("Dimension1Points", 0x07, struct.pack("<I", shape[0])),
                item("Dimension2Points", 0x07, struct.pack("<I", shape[1])),
                item("Dimension1Extent", 0x13, quantity(4.0, "µm")),
                item("Dimension2Extent", 0x13, quantity(3.0, "µm")),
                item("DataScale", 0x13, quantity(1.0, "µm")),
                item("Matrix", 0x00, matrix),
            ),
        )
        + container(
            "MetaData",
            item("DataKind", 0x12, sized(b"Surface Height")),
            item("PrimaryData2D", 0x12, sized(b"Height")),
        )
    )


def zon_file(counts=COUNTS, grid=None, calibration=(1e-6, 1e-9), zstd=False):
    """Keyence ZON (KPK0, or KPK1 with zstd-compressed members): uint32 BMP size, a BMP preview, then a zip
    of UUID-named members: the calibration XML and the int32 height grid (xres, yres, bytes per point, bytes
    per row, rows)."""
    rows, cols = np.shape(counts)
    xml = (
        f"<Calibration><XYCalibration><MeterPerPixel>{calibration[0]}</MeterPerPixel></XYCalibration>"
        f"<ZCalibration><MeterPerUnit>{calibration[1]}</MeterPerUnit></ZCalibration></Calibration>"
    ).encode()
    heights = struct.pack("<4I", *(grid or (cols, rows, 4, 4 * cols))) + np.asarray(counts, "<i4").tobytes()
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_STORED) as archive:
        for name, content in (
            ("686613b8-27b5-4a29-8ffc-438c2780873e", xml),
            ("4cdb0c75-5706-48cc-a9a1-adf395d609ae", heights),
        ):
            if zstd:
                import zstandard

                content = zstandard.ZstdCompressor().compress(content)
            archive.writestr(zipfile.ZipInfo(name, (2020, 1, 2, 3, 4, 6)), content)
    preview = b"BM" + bytes(14)
    return (b"KPK1" if zstd else b"KPK0") + struct.pack("<I", len(preview)) + preview + buffer.getvalue()


def park_header(nx=4, ny=3, size=(4.0, 3.0), data_type=0, image_type=0, version=2):
    """The binary header of a Park Systems TIFF (tag 50435), little-endian, text UTF-16."""
    header = bytearray(580 if version == 2 else 356)
    struct.pack_into("<I", header, 0, image_type)
    name = "Z Height".encode("utf-16-le")
    header[4 : 4 + len(name)] = name
    struct.pack_into("<II", header, 100, nx, ny)
    struct.pack_into("<dd", header, 140, *size)
    struct.pack_into("<ddd", header, 220, 1.0, 0.001, 0.0)  # data gain, z scale, z offset
    unit = "um".encode("utf-16-le")
    header[244 : 244 + len(unit)] = unit
    if version == 2:
        struct.pack_into("<I", header, 348, data_type)
    return bytes(header)


def park_file(counts=COUNTS, header=None, version=0x1000002, magic=0x0E031301):
    """Park Systems TIFF: an 8-bit preview whose first IFD holds Park's private tags 50432-50435."""
    import tifffile

    rows, cols = np.shape(counts)
    data = np.asarray(counts, "<i2").tobytes()
    header = park_header(cols, rows) if header is None else header
    tags = [(50432, 4, 1, magic, True), (50433, 4, 1, version, True)]
    tags += [(50434, 7, len(data), data, True), (50435, 7, len(header), header, True)]
    buffer = io.BytesIO()
    tifffile.imwrite(buffer, np.zeros((rows, cols), np.uint8), extratags=tags, software="seed", metadata=None)
    return buffer.getvalue()


def netcdf_file(heights=MAP.T * 1e6):
    """NetCDF classic in SurfaceTopography's layout: ``heights(x, y)`` in µm, x first, and coordinate
    variables whose ``length`` attribute is the size along that axis."""
    from scipy.io import netcdf_file as writer

    buffer = io.BytesIO()
    nc = writer(buffer, "w", version=1)
    for name, count in zip("xy", np.shape(heights)):
        nc.createDimension(name, count)
    variable = nc.createVariable("heights", "f8", ("x", "y"))
    variable[:] = np.nan_to_num(heights)
    variable.unit = "um"
    for name, count, length in (("x", np.shape(heights)[0], 4.0), ("y", np.shape(heights)[1], 6.0)):
        axis = nc.createVariable(name, "f8", (name,))
        axis[:] = np.arange(count)
        axis.length = length
        axis.unit = "um"
    nc.flush()
    data = buffer.getvalue()
    nc.close()
    return data


def nmm_zip(heights=PROFILE):
    """SIOS NMM line scan: a zip of a ``.dsc`` (one line per column) and a ``.dat`` (one row per point)."""
    count = len(heights)
    dsc = f"----\n0 : 11-Jan-2024 23:49:11 : XY vector : {count} : distance\n"
    dsc += f"1 : 11-Jan-2024 23:49:11 : -Lz+Az : {count} : Surface height (-LZ+AZ)\n----\n"
    dat = "".join(f"{k * 0.5e-6:.9e} {z:.9e}\n" for k, z in enumerate(heights))
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, text in (("scan.dsc", dsc), ("scan.dat", dat)):
            archive.writestr(zipfile.ZipInfo(name, (2024, 1, 11, 23, 49, 12)), text.encode())
    return buffer.getvalue()
