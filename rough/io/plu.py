"""Sensofar PLU (PLu, SensoSCAN confocal and interferometric profilers), read only.

Layout (little-endian), as SurfaceTopography's ``PLU.py`` and surfalize's ``plu.py``
read it: a 128-byte date string, a uint32 Unix time, a 256-byte comment; calibration
at byte 388 (uint32 rows and columns, uint32 N_tall, float32 dy_multip, µm per pixel in
x and y, x and y offsets, µm per pixel in z, z offset); measure configuration at 428
(uint32 type, algorithm, method, objective, area type; 40 bytes of scan settings; bytes
restore, layer count, version, hardware, image count, 3 reserved, uint32 factor). The
layers follow at 500: uint32 rows and columns, rows × columns float32 heights in µm
(x fastest, first stored row kept as row 0 here), float32 min and max. The value
1000001 marks non-measured points (NaN here). There is no magic number: the format is
chosen by its extension (.plu, .apx). Several layers are offered as channels
``layer 0``, ``layer 1``, ...; the colour image after the layers (rows × columns RGB bytes) is not read.
After the last layer's min and max the file ends, or holds at least that colour image (plu-1.plu
holds 133,133 bytes more, of unknown layout); a file that ends inside a layer's min and max, or
holds fewer bytes than the colour image after it, is refused. The min and max cannot check the
heights: plu-1.plu states -1000001 and 1000001.
"""

import datetime
import struct

import numpy as np

from ..errors import FormatError
from ..surface import Surface, Units, check_size
from . import registry
from .registry import Format

FORMAT = Format(
    "plu",
    "Sensofar PLU",
    (".plu", ".apx"),
    by_extension=True,
    carries=("spacing", "units", "metadata", "time", "channels", "mask"),
)

CALIBRATION, CONFIGURATION, LAYERS = 388, 428, 500
NON_MEASURED = 1000001.0
MICROMETRE = 1e-6
TYPES = {1: "profile", 3: "topography"}


def read(data, options):
    data = bytes(data)
    if len(data) < LAYERS:
        raise FormatError(f"PLU header is truncated ({len(data)} bytes of {LAYERS} bytes)")
    measurement_type = struct.unpack_from("<I", data, CONFIGURATION)[0]
    if measurement_type not in TYPES:
        raise FormatError(f"PLU measurement type {measurement_type} is not a profile or topography")
    layer_count = data[CONFIGURATION + 61]
    layers = _layers(data, max(layer_count, 1))
    names = [f"layer {index}" for index in range(len(layers))]
    index = registry.choose_channel(names, options.channel)
    heights = layers[index].astype(np.float64)
    heights[heights == NON_MEASURED] = np.nan
    dx, dy = struct.unpack_from("<2f", data, CALIBRATION + 16)
    for name, step in (("x", dx), ("y", dy)):
        if not 0 < step < np.inf:
            raise FormatError(f"PLU {name} spacing is {step!r} µm, not a positive length")
    metadata = _metadata(data, measurement_type)
    if len(layers) > 1:
        metadata |= registry.channel_metadata(names, index)
    units = Units(xy="um", z="um")
    if heights.shape[0] == 1:
        return Surface(heights[0] * MICROMETRE, (dx * MICROMETRE,), units=units, metadata=metadata)
    return Surface(heights * MICROMETRE, (dx * MICROMETRE, dy * MICROMETRE), units=units, metadata=metadata)


def _layers(data, count):
    layers, position = [], LAYERS
    for _ in range(count):
        if position + 8 > len(data):
            raise FormatError("PLU layer header runs past the end of the file")
        rows, columns = struct.unpack_from("<2I", data, position)
        if rows < 1 or columns < 1:
            raise FormatError(f"PLU layer of {columns} × {rows} points is empty")
        check_size((rows, columns), "the PLU layer")
        position += 8
        if position + rows * columns * 4 + 8 > len(data):
            raise FormatError(
                f"PLU heights of {columns} × {rows} points and their min and max run past the end of the file"
            )
        layers.append(np.frombuffer(data, "<f4", rows * columns, position).reshape(rows, columns))
        position += rows * columns * 4 + 8
    if 0 < len(data) - position < 3 * rows * columns:
        raise FormatError(
            f"PLU file holds {len(data) - position:,} bytes after its layers, where only nothing or their "
            f"{columns} × {rows} colour image ({3 * rows * columns:,} bytes) and more may follow"
        )
    return layers


def _metadata(data, measurement_type):
    metadata = {"vendor": "Sensofar", "plu_type": TYPES[measurement_type]}
    seconds = struct.unpack_from("<I", data, 128)[0]
    if seconds:
        metadata["date"] = datetime.datetime.fromtimestamp(seconds, datetime.timezone.utc).isoformat()
    comment = data[132:388].split(b"\0", 1)[0].decode("latin-1").strip()
    if comment and comment != "(None)":
        metadata["comment"] = comment
    metadata["plu_objective"] = str(struct.unpack_from("<I", data, CONFIGURATION + 12)[0])
    return metadata
