"""X3P: ISO 25178-72 (the ISO 5436-2 XML container), read and written.

A zip holding ``main.xml`` (namespace ``http://www.opengps.eu/2008/ISO5436_2``),
``md5checksum.hex`` (the MD5 of ``main.xml``) and, for binary data,
``bindata/data.bin`` (little-endian, x fastest) with an optional packed bit mask of
valid points (LSB first).

Reading: PRF, SUR and PCL features; int16/int32/float32/float64 data (``Increment``
scales integer data, ``Offset`` shifts every type); binary data or an inline
``DataList``; the valid-point mask and empty ``<Datum/>`` become NaN; ``main.xml`` may
sit under a folder and start with a BOM; Record2 is optional. Every MD5 the schema
defines is checked (``verify=False`` downgrades a mismatch to a warning). Files with a
DOCTYPE are refused. Rows are stored as the file stores them (row 0 = the first line,
smallest y), x fastest.

Layers: ``options.layer`` (from 0, default 0) picks one of SizeZ layers; the metadata
keys ``layer`` and ``layers`` record it for multi-layer files.

Placement (ISO 25178-72): a point is placed at ``R · (x, y, z) + offsets``, where R is
Record1's ``Rotation`` and the offsets are the axes' ``Offset`` values, which become the
origin. R is ignored when it is the identity, applied exactly when it turns a map about
z by a multiple of 90° (rows and columns transposed or reversed, the spacings swapped),
and a profile turned about z keeps its heights along its own axis; any other rotation
is refused unless ``options.regrid`` asks to resample the placed points.

Absolute X/Y axes whose coordinates form a regular grid are read as a grid; an
irregular grid and a point cloud (PCL, ``ListDimension``) are refused unless
``options.regrid`` = ``(spacing, method)`` asks to grid them: linear interpolation on
Delaunay triangles (``scipy.interpolate.griddata``) onto a square grid of that spacing,
NaN outside the points' convex hull, recorded as a ``regrid`` history entry. Maps are
always interpolated linearly (the band-limited method is for profiles). A profile with
unevenly spaced absolute x goes through :func:`rough.io.regrid.profile_from_points`.

Windows (:func:`open_tiles`): a map on an incremental grid whose data member is stored
(memory-mapped) or deflated (unpacked as far as each window) is read a window at a
time, with the scaling, layer and mask of :func:`read`; its MD5 is checked (or its
CRC-32, as above) in one pass when it is opened, before any window is read. Profiles,
point clouds, DataList, absolute or rotated axes are read whole.

Writing: PRF for profiles, SUR for maps, float64 data, stored (uncompressed) members
with the data aligned to 64 bytes, and rough's units, metadata and history in a
vendor-specific member named by the root's ``VendorSpecificID``, which other readers
ignore. Every local header carries its member's CRC-32 and sizes (no data
descriptors, even on a pipe), so that the next reader knows where each member ends
before it arrives; ZIP64 fields where a size or offset needs them
(:class:`rough.io.ziparchive.ZipWriter`).

Checksums, once per stage: the MD5 and the zip CRC-32 of ``bindata/data.bin`` are
computed in one pass over its bytes. A stream (standard input, a file) is hashed as it
arrives (:func:`rough.io.receiving.receive`), so hashing overlaps reading; a deflated
member is hashed as it is unpacked, in a worker thread beside zlib
(:func:`rough.io.x3pdata.inflated`). The MD5 is
checked against main.xml (a mismatch refuses the file unless ``verify=False``); the
CRC-32 is checked only where no MD5 is. Heights
written unchanged reuse both (they view the read-only bytes they were checked on);
other heights are hashed once when written, MD5 and CRC-32 at the same time.
"""

import hashlib
import json
import logging
import re
import weakref
import zipfile
from xml.etree import ElementTree

import numpy as np

from .. import __version__
from .. import io as rough_io  # lazy: rough.io.gridding (scipy) loads only when points are gridded
from ..errors import FormatError
from ..surface import Surface, Units, timestamp
from . import provenance, receiving, regrid, windowed, ziparchive
from .registry import Format
from .tiled import TiledSurface
from .x3pdata import DataSource, check, checked_member, open_data, scaled

FORMAT = Format(
    "x3p",
    "X3P (ISO 25178-72)",
    (".x3p",),
    magic=(b"PK\x03\x04", b"PK\x05\x06"),
    writes=True,
    carries=("spacing", "exact-grid", "units", "metadata", "time", "layers", "mask", "history", "tiles"),
)

NAMESPACE = "http://www.opengps.eu/2008/ISO5436_2"
VENDOR_ID = "urn:x-rough:x3p-vendor:1"
VENDOR_MEMBER = "vendor/rough.json"
DATA_TYPES = {"I": "<i2", "L": "<i4", "F": "<f4", "D": "<f8"}
MAX_POINTS = 1 << 31
MAX_XML_BYTES = 1 << 31
MAX_SIDE_BYTES = 1 << 26
ALIGNMENT = 64
ROTATION_TOLERANCE = 1e-6  # of a rotation matrix element

log = logging.getLogger("rough")


def read(data, options):
    data = data if isinstance(data, bytes) else memoryview(data).cast("B")
    header = _Header(data, options)
    archive, prefix, root = header.archive, header.prefix, header.root
    nx, ny, layers = header.nx, header.ny, header.layers
    digest = None
    if root.find("Record3/DataLink") is not None:
        count = nx * ny * layers
        records, valid, digest = _binary_records(archive, prefix, root, data, header.fields, count, options.verify)
        stored = (receiving.address(records), records.nbytes)  # where data.bin's bytes are
    elif root.find("Record3/DataList") is not None:
        records, valid = _list_records(root, header.fields, nx * ny * layers)
    else:
        raise FormatError("Record3 has neither a DataLink nor a DataList: no data")
    layer = _chosen_layer(options.layer, layers)
    chosen = slice(layer * nx * ny, (layer + 1) * nx * ny)
    records = records[chosen]
    valid = None if valid is None or valid[chosen].all() else valid[chosen]

    points = _Points(header.axes, records, valid, header.rotation, nx)
    if header.cloud:
        placed = rough_io.gridding.grid_points(*points.placed(), options, f"an X3P point cloud of {nx} points")
    elif ny == 1:
        placed = _profile(points, nx, options)
    else:
        placed = _surface(points, nx, ny, options)
    heights, spacing, origin, notes, steps = placed
    metadata, units, history = _provenance(header, data, layer)
    surface = Surface(heights, spacing, origin, units, {**metadata, **notes}, history + steps)
    if digest and _same_bytes(surface.heights, stored):
        _remember_digest(surface.heights, digest)
    return surface


def open_tiles(path, options):
    """A :class:`~rough.io.tiled.TiledSurface` of a binary X3P map read a window at a
    time from disk (a stored data member memory-mapped, a deflated one decompressed as
    far as each window), described from the header: the data's MD5 is checked by
    the source's ``check()`` (:func:`rough.io.open_tiles` calls it); None for what is
    read whole: profiles, point clouds, inline DataList, absolute or rotated axes, and
    data compressed otherwise than by deflate."""
    data = windowed.mapped(path)
    header = _Header(data, options)
    axes, root = header.axes, header.root
    if (
        header.feature != "SUR"
        or header.cloud
        or header.ny == 1
        or header.rotation is not None
        or "A" in (axes["CX"]["type"], axes["CY"]["type"])
        or root.find("Record3/DataLink") is None
    ):
        return None
    spacing = tuple(_increment(name, axes[name]) for name in ("CX", "CY"))
    link = _text(root, "Record3/DataLink/PointDataLink", required=True)
    count, dtype = header.nx * header.ny * header.layers, np.dtype(axes["CZ"]["dtype"])
    stated = _text(root, "Record3/DataLink/MD5ChecksumPointData")
    info = open_data(header.archive, header.prefix, link, data, count * dtype.itemsize)
    if info is None:
        return None
    mask = _mask(header.archive, header.prefix, root, data, count, options.verify)[0]
    layer = _chosen_layer(options.layer, header.layers)
    metadata, units, history = _provenance(header, data, layer)
    layout = (dtype.str, header.nx, layer * header.ny)
    source = DataSource(path, info.filename, mask, layout, axes["CZ"], stated, options.verify)
    origin = (0.0 + axes["CX"]["offset"], 0.0 + axes["CY"]["offset"])  # as _surface places them
    return TiledSurface(source, (header.ny, header.nx), spacing, origin, units, metadata, history)


def write(surface, stream):
    """Write ``surface`` to a binary stream as X3P: the heights go out as they are in
    memory (no copy), hashed only if they are not the unchanged heights of a file read."""
    heights = np.ascontiguousarray(surface.heights, dtype="<f8")
    payload = memoryview(heights).cast("B")
    with np.errstate(invalid="ignore"):
        holes = bool(np.isnan(heights.min()))  # NaN propagates: one pass, no temporary array
    mask = np.packbits(~np.isnan(heights).ravel(), bitorder="little").tobytes() if holes else None
    data_md5, data_crc = _digests(heights, payload)
    document = _main_xml(surface, data_md5, mask and hashlib.md5(mask).hexdigest())
    vendor = json.dumps(provenance.parts(surface), indent=1).encode("utf-8")
    archive = ziparchive.ZipWriter(stream)
    archive.add("main.xml", document)
    archive.add("md5checksum.hex", f"{hashlib.md5(document).hexdigest()} *main.xml\n".encode())
    archive.add("bindata/data.bin", payload, crc=data_crc, align=ALIGNMENT)
    if mask is not None:
        archive.add("bindata/valid.bin", mask)
    archive.add(VENDOR_MEMBER, vendor)
    archive.close()


# -- reading -------------------------------------------------------------------------


class _Header:
    """An X3P archive's main.xml, its checksum checked, and the grid it declares."""

    def __init__(self, data, options):
        try:
            self.archive = zipfile.ZipFile(ziparchive.ViewFile(data))
        except (*ziparchive.ZIP_ERRORS, ValueError) as error:
            raise FormatError(f"not a valid X3P zip archive ({error})") from None
        self.prefix, main_name = _find_main(self.archive)
        document = ziparchive.member(self.archive, main_name, data, limit=MAX_XML_BYTES)
        root = self.root = _parse_xml(bytes(document))
        check(options.verify, _main_checksum_problem(self.archive, self.prefix, root, document, data))
        self.feature = _text(root, "Record1/FeatureType", required=True).upper()
        if self.feature not in ("SUR", "PRF", "PCL"):
            raise FormatError(f"unknown X3P FeatureType {self.feature!r} (expected SUR, PRF or PCL)")
        axes = self.axes = {name: _axis(root, name) for name in ("CX", "CY", "CZ")}
        if axes["CZ"]["type"] != "A":
            raise FormatError("the X3P z axis (CZ) must be absolute (AxisType A)")
        self.rotation = _rotation(root)
        self.cloud = self.feature == "PCL" or root.find("Record3/ListDimension") is not None
        if self.cloud:
            if axes["CX"]["type"] != "A" or axes["CY"]["type"] != "A":
                raise FormatError("X3P point clouds need absolute CX and CY axes (AxisType A)")
            self.nx, self.ny, self.layers = _size(root, "Record3/ListDimension"), 1, 1
        else:
            self.nx, self.ny, self.layers = (_size(root, f"Record3/MatrixDimension/Size{c}") for c in "XYZ")
        if self.nx * self.ny * self.layers > MAX_POINTS:
            raise FormatError(f"Record3 declares {self.nx}×{self.ny}×{self.layers} points, more than rough handles")
        if self.feature == "PRF" and self.ny != 1:
            raise FormatError(f"an X3P profile (PRF) must have SizeY 1, not {self.ny}")
        absolute = [name for name in ("CX", "CY") if axes[name]["type"] == "A"]
        self.fields = [(name, axes[name]["dtype"]) for name in (*absolute, "CZ")]


def _provenance(header, data, layer):
    """``(metadata, units, history)``: rough's own record, else Record2's facts; the layer read."""
    archive, prefix = header.archive, header.prefix
    if _text(header.root, "VendorSpecificID") == VENDOR_ID and f"{prefix}{VENDOR_MEMBER}" in archive.namelist():
        metadata, units, history = _vendor(archive, prefix, data)
    else:
        metadata, units, history = _metadata(header.root), Units("m", "m"), []
    if header.layers > 1:
        metadata.update(layer=str(layer), layers=str(header.layers))
    return metadata, units, history


def _find_main(archive):
    candidates = [
        name
        for name in archive.namelist()
        if (name == "main.xml" or name.endswith("/main.xml")) and not name.startswith("__MACOSX/")
    ]
    if not candidates:
        raise FormatError("a zip archive without main.xml, so not an X3P file; unpack it and read the files inside")
    main = min(candidates, key=len)
    return main[: -len("main.xml")], main


def _parse_xml(document):
    if document.startswith((b"\xff\xfe", b"\xfe\xff")) or b"\x00" in document[:64]:
        raise FormatError("main.xml is not UTF-8, as X3P requires")
    if b"<!DOCTYPE" in document or b"<!ENTITY" in document:
        raise FormatError("main.xml declares a DOCTYPE or entities, which X3P does not use; refusing to parse it")
    document = document.removeprefix(b"\xef\xbb\xbf")
    try:
        root = ElementTree.fromstring(document)
    except ElementTree.ParseError as error:
        raise FormatError(f"main.xml is not well-formed XML ({error})") from None
    for element in root.iter():
        if isinstance(element.tag, str):
            element.tag = element.tag.rpartition("}")[2].rpartition(":")[2]
    if not root.tag.startswith("ISO5436"):
        raise FormatError(f"main.xml root is <{root.tag}>, not an ISO 5436-2 document")
    return root


def _main_checksum_problem(archive, prefix, root, document, data):
    name = _text(root, "Record4/ChecksumFile") or "md5checksum.hex"
    member = f"{prefix}{name}"
    if member not in archive.namelist():
        return f"the checksum file {name} named by Record4 is missing"
    stated = bytes(ziparchive.member(archive, member, data, limit=4096)).split()
    actual = hashlib.md5(document).hexdigest()
    if not stated or stated[0].decode("ascii", "replace").lower() != actual:
        shown = stated[0][:32].decode("ascii", "replace") if stated else "nothing"
        return f"main.xml checksum mismatch ({name} says {shown}, main.xml is {actual})"
    return None


def _text(root, path, required=False, default=None):
    element = root.find(path)
    if element is None or element.text is None or not element.text.strip():
        if required:
            raise FormatError(f"main.xml lacks {path.replace('/', ' > ')}")
        return default
    return element.text.strip()


def _number(root, path, default):
    text = _text(root, path)
    if text is None:
        return default
    try:
        value = float(text)
    except ValueError:
        raise FormatError(f"{path.replace('/', ' > ')} is not a number: {text!r}") from None
    if not np.isfinite(value):
        raise FormatError(f"{path.replace('/', ' > ')} is not finite: {text!r}")
    return value


def _axis(root, name):
    base = f"Record1/Axes/{name}"
    if root.find(base) is None:
        raise FormatError(f"main.xml lacks the axis description {name}")
    kind = _text(root, f"{base}/AxisType", required=True).upper()
    if kind not in ("I", "A"):
        raise FormatError(f"{name} AxisType must be I or A, not {kind!r}")
    code = (_text(root, f"{base}/DataType") or "D").upper()
    if code not in DATA_TYPES:
        raise FormatError(f"{name} DataType must be one of I, L, F, D, not {code!r}")
    return {
        "type": kind,
        "code": code,
        "dtype": DATA_TYPES[code],
        "increment": _number(root, f"{base}/Increment", 1.0),
        "offset": _number(root, f"{base}/Offset", 0.0),
    }


def _size(root, path):
    text = _text(root, path, required=True)
    if not text.isdigit() or int(text) < 1:
        raise FormatError(f"{path.replace('/', ' > ')} must be a positive whole number, not {text!r}")
    return int(text)


def _binary_records(archive, prefix, root, data, fields, count, verify):
    """``(records, valid mask or None, the data's (MD5, CRC-32) if the MD5 was verified)``."""
    link = _text(root, "Record3/DataLink/PointDataLink", required=True)
    record = np.dtype(fields)
    stated = _text(root, "Record3/DataLink/MD5ChecksumPointData")
    size = count * record.itemsize
    payload, actual, crc = checked_member(archive, prefix, link, data, stated, verify, expected=size)
    records = np.frombuffer(payload, dtype=record)
    verified = (actual, crc) if stated and stated.lower() == actual else None
    packed = _mask(archive, prefix, root, data, count, verify)[1]
    if packed is None:
        return records, None, verified
    valid = np.unpackbits(np.frombuffer(packed, np.uint8), count=count, bitorder="little").astype(bool)
    return records, valid, verified


def _mask(archive, prefix, root, data, count, verify):
    """``(zip name, packed bits)`` of the valid-point mask (its checksum and size
    checked), or ``(None, None)``."""
    valid_link = _text(root, "Record3/DataLink/ValidPointsLink")
    if valid_link is None:
        return None, None
    stated = _text(root, "Record3/DataLink/MD5ChecksumValidPoints")
    packed, _, _ = checked_member(archive, prefix, valid_link, data, stated, verify, limit=MAX_POINTS // 8 + 1)
    if len(packed) < (count + 7) // 8:
        raise FormatError(f"{valid_link} holds {len(packed)} bytes, too few for {count} points")
    return f"{prefix}{valid_link}", packed


def _list_records(root, fields, count):
    datums = root.findall("Record3/DataList/Datum")
    if len(datums) != count:
        raise FormatError(f"DataList holds {len(datums)} points, but MatrixDimension declares {count}")
    records = np.zeros(count, dtype=[(name, "<f8") for name, _ in fields])
    valid = np.ones(count, bool)
    width = len(fields)
    for index, datum in enumerate(datums):
        text = (datum.text or "").strip()
        if not text:
            valid[index] = False
            continue
        values = text.split(";")
        if len(values) < width:
            raise FormatError(f"Datum {index + 1} has {len(values)} values, needs {width}: {text!r}")
        records[index] = tuple(float(v) for v in values[-width:])
    return records, valid


def _chosen_layer(wanted, layers):
    """The layer to read: ``wanted`` (from 0), or 0 with a note when the file holds several."""
    if wanted is None:
        if layers > 1:
            log.info("the X3P file holds %d layers; reading layer 0 (--layer N picks another)", layers)
        return 0
    if not 0 <= int(wanted) < layers:
        held = "1 layer (0)" if layers == 1 else f"{layers} layers (0 to {layers - 1})"
        raise FormatError(f"no layer {wanted}; the file holds {held}")
    return int(wanted)


def _rotation(root):
    """Record1's rotation matrix, or None when there is none or it is the identity."""
    if root.find("Record1/Axes/Rotation") is None:
        return None
    matrix = np.array(
        [[_number(root, f"Record1/Axes/Rotation/r{i}{j}", float(i == j)) for j in (1, 2, 3)] for i in (1, 2, 3)]
    )
    if np.abs(matrix @ matrix.T - np.eye(3)).max() > ROTATION_TOLERANCE or np.linalg.det(matrix) < 0:
        raise FormatError("Record1 > Axes > Rotation is not a rotation matrix")
    return None if np.abs(matrix - np.eye(3)).max() <= ROTATION_TOLERANCE else matrix


def _quarter_turns(rotation):
    """How many quarter turns about z ``rotation`` makes (0 to 3), or None for any other rotation."""
    if rotation is None:
        return 0
    for turns, (cos, sin) in enumerate(((1, 0), (0, 1), (-1, 0), (0, -1))):
        exact = np.array([[cos, -sin, 0], [sin, cos, 0], [0, 0, 1]])
        if np.abs(rotation - exact).max() <= ROTATION_TOLERANCE:
            return turns
    return None


def _angle_about_z(rotation):
    """The angle in degrees of a rotation about z alone, else None."""
    if np.abs(rotation[2] - (0, 0, 1)).max() > ROTATION_TOLERANCE or np.abs(rotation[:2, 2]).max() > ROTATION_TOLERANCE:
        return None
    return float(np.degrees(np.arctan2(rotation[1, 0], rotation[0, 0])))


def _rotation_text(rotation):
    """``'10.0° about x'``: a rotation's angle and axis."""
    angle = float(np.degrees(np.arccos(np.clip((np.trace(rotation) - 1) / 2, -1, 1))))
    axis = np.array([rotation[2, 1] - rotation[1, 2], rotation[0, 2] - rotation[2, 0], rotation[1, 0] - rotation[0, 1]])
    if np.linalg.norm(axis) < ROTATION_TOLERANCE:  # a half turn
        axis = np.sqrt(np.clip((np.diag(rotation) + 1) / 2, 0, 1))
    axis = axis / np.linalg.norm(axis)
    for name, unit in zip("xyz", np.eye(3)):
        if abs(abs(axis @ unit) - 1) <= ROTATION_TOLERANCE:
            return f"{angle * np.sign(axis @ unit):.1f}° about {name}"
    return f"{angle:.1f}° about the axis ({axis[0]:.3g}, {axis[1]:.3g}, {axis[2]:.3g})"


class _Points:
    """The chosen layer's points: heights, and coordinates before and after the placement."""

    def __init__(self, axes, records, valid, rotation, nx):
        self.axes, self.records, self.valid, self.rotation, self.nx = axes, records, valid, rotation, nx

    def heights(self):
        z = scaled(self.records["CZ"], self.axes["CZ"])
        if self.valid is None or np.isnan(z[~self.valid]).all():  # as rough writes them: no copy
            return z
        return np.where(self.valid, z, np.nan)

    def local(self, name):
        """Coordinates along CX or CY without the axis offset; NaN at invalid points."""
        axis = self.axes[name]
        if axis["type"] == "I":
            index = np.arange(len(self.records))
            return (index % self.nx if name == "CX" else index // self.nx) * _increment(name, axis)
        values = scaled(self.records[name], axis, offset=False)
        return values if self.valid is None else np.where(self.valid, values, np.nan)

    def placed(self):
        """x, y and z of the valid points where the placement puts them: rotated, then
        shifted by the axis offsets."""
        z = scaled(self.records["CZ"], self.axes["CZ"], offset=False)
        coordinates = np.stack([self.local("CX"), self.local("CY"), z])
        if self.rotation is not None:
            coordinates = self.rotation @ coordinates
        coordinates += np.array([[self.axes[name]["offset"]] for name in ("CX", "CY", "CZ")])
        keep = np.isfinite(coordinates).all(axis=0)
        return tuple(coordinates[:, keep])


def _increment(name, axis):
    if not axis["increment"] > 0:
        raise FormatError(f"{name} Increment must be a positive length, not {axis['increment']}")
    return axis["increment"]


def _regular_axis(points, name, nx, ny):
    """``(step, start)`` of CX or CY, the start without the axis offset; None when absolute
    coordinates do not lie on a regular grid."""
    axis = points.axes[name]
    if axis["type"] == "I":
        return _increment(name, axis), 0.0
    n = nx if name == "CX" else ny
    coordinates = points.local(name).reshape(ny, nx)
    known = np.isfinite(coordinates)
    across = 0 if name == "CX" else 1
    counts = known.sum(axis=across)
    lines = np.flatnonzero(counts)  # an all-invalid line takes its place from the others
    if n < 2 or len(lines) < 2:
        return None
    along = np.where(known, coordinates, 0).sum(axis=across) / np.maximum(counts, 1)
    first, last = lines[0], lines[-1]
    step = (along[last] - along[first]) / (last - first)
    expected = along[first] + step * (np.arange(n) - first)
    full = expected[np.newaxis, :] if name == "CX" else expected[:, np.newaxis]
    if not step > 0 or np.nanmax(np.abs(coordinates - full)) > 1e-6 * step:
        return None
    return float(step), float(expected[0])


def _surface(points, nx, ny, options):
    """A map on its grid, turned by the placement's quarter turns about z; gridded on
    request when the grid is irregular or rotated otherwise."""
    turns = _quarter_turns(points.rotation)
    if turns is None:
        problem = f"rotated by {_rotation_text(points.rotation)} in its placement; rough keeps grids axis-aligned"
        if options.regrid is None:
            raise FormatError(f"{problem}: give --regrid SPACING to resample it in the placed frame")
        return rough_io.gridding.grid_points(*points.placed(), options, problem)
    axes = [_regular_axis(points, name, nx, ny) for name in ("CX", "CY")]
    if None in axes:
        return rough_io.gridding.grid_points(*points.placed(), options, f"an irregular grid of {nx}×{ny} points")
    (dx, x0), (dy, y0) = axes
    heights = points.heights().reshape(ny, nx)
    for _ in range(turns):  # (x, y) → (−y, x)
        heights, (dx, dy), (x0, y0) = heights.T[:, ::-1], (dy, dx), (-(y0 + (heights.shape[0] - 1) * dy), x0)
    notes = {"x3p_rotation": f"{90 * turns}° about z, applied"} if turns else {}
    origin = (x0 + points.axes["CX"]["offset"], y0 + points.axes["CY"]["offset"])
    return np.ascontiguousarray(heights), (dx, dy), origin, notes, []


def _profile(points, nx, options):
    """A profile along its own axis: incremental, absolute on a regular grid, or uneven
    absolute x (regridded on request). A turn about z leaves it unchanged."""
    notes = {}
    if points.rotation is not None:
        angle = _angle_about_z(points.rotation)
        if angle is None:
            raise FormatError(
                f"a profile rotated by {_rotation_text(points.rotation)} in its placement; "
                "rough reads profiles only in their own frame or turned about z"
            )
        notes["x3p_rotation"] = f"{angle:.6g}° about z, not applied (heights along the profile are unchanged)"
    heights, offset = points.heights(), points.axes["CX"]["offset"]
    regular = _regular_axis(points, "CX", nx, 1)
    if regular is not None:
        return heights, (regular[0],), (regular[1] + offset,), notes, []
    x = points.local("CX") + offset
    known = np.isfinite(x)
    profile = regrid.profile_from_points(x[known], heights[known], options)
    return profile.heights, profile.spacing, profile.origin, notes, profile.history


def _metadata(root):
    record = {
        "date": "Record2/Date",
        "creator": "Record2/Creator",
        "instrument_manufacturer": "Record2/Instrument/Manufacturer",
        "instrument_model": "Record2/Instrument/Model",
        "instrument_serial": "Record2/Instrument/Serial",
        "instrument_version": "Record2/Instrument/Version",
        "calibration_date": "Record2/CalibrationDate",
        "probing_type": "Record2/ProbingSystem/Type",
        "probing_identification": "Record2/ProbingSystem/Identification",
        "comment": "Record2/Comment",
    }
    metadata = {key: _text(root, path) for key, path in record.items()}
    return {key: value for key, value in metadata.items() if value is not None}


def _vendor(archive, prefix, data):
    """rough's own record, which holds the metadata that Record2 was written from."""
    stored = json.loads(bytes(ziparchive.member(archive, f"{prefix}{VENDOR_MEMBER}", data, limit=MAX_SIDE_BYTES)))
    return provenance.restore(stored, units=Units("m", "m"))


# -- writing -------------------------------------------------------------------------

_verified_digests = {}


def _same_bytes(heights, stored):
    """Whether ``heights`` are the float64 values of the bytes ``stored`` = ``(address,
    length)``, as they are: their digests are those bytes' digests."""
    return (
        heights.dtype == np.dtype("<f8")
        and heights.flags.c_contiguous
        and (receiving.address(heights), heights.nbytes) == stored
    )


def _remember_digest(heights, digests):
    """Remember the verified ``(MD5 hex, CRC-32)`` of a read-only height array that
    views the bytes they were computed on, so that writing the same array again need
    not hash it again. The array cannot change: its memory is a read-only view of bytes
    that nothing else holds (an immutable bytes object, or the buffer of
    :func:`rough.io.receiving.receive`)."""
    for key in [key for key, (ref, _) in _verified_digests.items() if ref() is None]:
        del _verified_digests[key]
    if not heights.flags.writeable:
        _verified_digests[id(heights)] = (weakref.ref(heights), digests)


def _digests(heights, payload):
    """``(MD5 hex, CRC-32)`` of the data: those verified when ``heights`` was read, or
    computed now."""
    ref, digests = _verified_digests.get(id(heights), (lambda: None, None))
    return digests if ref() is heights else receiving.hashes(payload)


def _main_xml(surface, data_md5, mask_md5):
    m = surface.metadata
    now = timestamp()
    axes = "".join(
        f"<{name}><AxisType>I</AxisType><DataType>D</DataType>"
        f"<Increment>{step!r}</Increment><Offset>{start!r}</Offset></{name}>"
        for name, step, start in zip(
            ("CX", "CY"),
            _pad(surface.spacing),
            _pad(surface.origin, 0.0),
        )
    )
    probing = (
        m.get("probing_type") if m.get("probing_type") in ("Contacting", "NonContacting", "Software") else "Software"
    )
    fields = {
        "manufacturer": m.get("instrument_manufacturer") or m.get("instrument") or "not available",
        "model": m.get("instrument_model") or "not available",
        "serial": m.get("instrument_serial") or "not available",
        "version": m.get("instrument_version") or "not available",
        "identification": m.get("probing_identification") or f"rough {__version__}",
    }
    fields = {key: escape(value) for key, value in fields.items()}
    comment = f"<Comment>{escape(m['comment'])}</Comment>" if m.get("comment") else ""
    creator = f"<Creator>{escape(m['creator'])}</Creator>" if m.get("creator") else ""
    valid = (
        f"<ValidPointsLink>bindata/valid.bin</ValidPointsLink><MD5ChecksumValidPoints>{mask_md5}</MD5ChecksumValidPoints>"
        if mask_md5
        else ""
    )
    nx, ny = (*surface.points, 1)[:2]
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        f'<p:ISO5436_2 xmlns:p="{NAMESPACE}">\n'
        f"<Record1><Revision>ISO5436 - "
        f"2000</Revision><FeatureType>{'PRF' if surface.is_profile else 'SUR'}</FeatureType>"
        f"<Axes>{axes}<CZ><AxisType>A</AxisType><DataType>D</DataType><Increment>1.0</Increment><Offset>0.0</Offset></CZ></Axes></Record1>\n"
        f"<Record2><Date>{escape(m.get('date') or now)}</Date>{creator}"
        f"<Instrument><Manufacturer>{fields['manufacturer']}</Manufacturer><Model>{fields['model']}</Model>"
        f"<Serial>{fields['serial']}</Serial><Version>{fields['version']}</Version></Instrument>"
        f"<CalibrationDate>{escape(m.get('calibration_date') or m.get('date') or now)}</CalibrationDate>"
        f"<ProbingSystem><Type>{probing}</Type><Identification>{fields['identification']}</Identification></ProbingSystem>"
        f"{comment}</Record2>\n"
        f"<Record3><MatrixDimension><SizeX>{nx}</SizeX><SizeY>{ny}</SizeY><SizeZ>1</SizeZ></MatrixDimension>"
        f"<DataLink><PointDataLink>bindata/data.bin</PointDataLink><MD5ChecksumPointData>{data_md5}</MD5ChecksumPointData>"
        f"{valid}</DataLink></Record3>\n"
        "<Record4><ChecksumFile>md5checksum.hex</ChecksumFile></Record4>\n"
        f"<VendorSpecificID>{VENDOR_ID}</VendorSpecificID>\n"
        "</p:ISO5436_2>\n"
    ).encode()


_NOT_XML = re.compile("[^\t\n\r\u0020-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def escape(text):
    """Text made safe for an XML 1.0 element: markup escaped, characters that XML
    cannot hold (control characters, lone surrogates) replaced by U+FFFD. The exact
    text travels in the vendor member."""
    return _NOT_XML.sub("\ufffd", str(text)).replace("&", "&amp;").replace(">", "&gt;").replace("<", "&lt;")


def _pad(values, fill=None):
    """Two values for CX and CY; a profile repeats its one spacing (or uses ``fill``)."""
    return (values[0], values[1]) if len(values) == 2 else (values[0], values[0] if fill is None else fill)
