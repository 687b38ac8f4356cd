"""Damaged copies of the seed files (tests/seed_files.py), each with what a reader must
do with it (tests/test_damaged_files.py):

truncated
    the file cut short, at every byte of its last 96 and every 7th byte before;
shifted
    the data block moved by 1 to 16 bytes (:data:`SHIFTS`: bytes put in before it,
    or taken from before it), the header left as it was;
random
    random bytes in place of the data block;
huge
    the heights of the data block, or of a whole surface written by rough, near the
    top of the float range (±1e308, or ±3e38 in a float32 block).

A read may refuse (InputError) or read values the undamaged file holds at the same
points (a truncated file may lose its last points: they are then missing, or NaN),
with the same spacing. Anything else is a read of changed data. The data block is
found by looking for the seed's heights (tests/seed_files.py) in every integer and
float encoding rough's readers take.

    PYTHONPATH=. python tests/damaged_files.py    # the counts of each outcome, per seed and kind
"""

import collections
import io
import logging
import random

import numpy as np

from rough import Surface
from rough.errors import InputError
from rough.io import ReadOptions, read_bytes

from format_files import al3d_file
from seed_files import COUNTS, MAP, PROFILE, ibw_file, opdx_file, plu_file, seeds, tmd_file

OPTIONS = ReadOptions(spacing=None)
SPACED = ReadOptions(spacing=(1e-6, 1e-6))
SHIFTS = (-16, -8, -7, -4, -3, -1, 1, 2, 3, 4, 5, 7, 8, 16)
HEIGHTS = np.random.default_rng(31).normal(size=(12, 16)) * 1e-6  # a measurement's full mantissas, in metres
_DTYPES = ("<i2", ">i2", "<u2", ">u2", "<i4", ">i4", "<f4", ">f4", "<f8", ">f8")
_ARRAYS = (
    COUNTS,
    COUNTS + 100,
    COUNTS * 1000,
    MAP,
    MAP * 1e6,
    MAP.T * 1e6,
    PROFILE,
    np.arange(6),
    np.arange(15) * 1e-6,
    HEIGHTS,
    HEIGHTS * 1e6,
)
_WRITTEN = ("x3p", "npy", "tsv", "gwy")  # formats rough writes in float64, for surfaces of ±1e308


def options_for(name):
    return SPACED if name.endswith((".npy", ".h5")) else OPTIONS


def data_block(blob):
    """``(start, end, dtype)`` of the seed's heights in ``blob``, or None (text, or
    compressed data). A block with NaN points is found from its rows after the first."""
    best = None
    for values in _ARRAYS:
        for dtype in _DTYPES:
            if np.dtype(dtype).kind in "iu" and not np.all(np.isfinite(values)):
                continue
            encoded = np.asarray(values).astype(dtype)
            if np.dtype(dtype).kind in "iu" and not np.array_equal(encoded, np.asarray(values)):
                continue
            for tail in (encoded, encoded[1:] if encoded.ndim == 2 else encoded[2:]):
                at = blob.find(tail.tobytes())
                if at >= 0 and len(tail.tobytes()) >= 12:
                    start = at - (encoded.nbytes - tail.nbytes)
                    if start >= 0 and (best is None or encoded.nbytes > best[1] - best[0]):
                        best = (start, start + encoded.nbytes, dtype)
                    break
    return best


def is_text(name):
    return name.endswith((".tsv", ".csv", ".txt", ".xyz")) or name == "ascii.sdf"


def variants(name, blob, rng):
    """``(kind, detail, bytes)`` of every damaged copy of one seed."""
    cuts = sorted(set(range(max(1, len(blob) - 96), len(blob))) | set(range(1, len(blob), 7)))
    for cut in cuts:
        yield "truncated", f"cut at {cut}", blob[:cut]
    block = None if is_text(name) else data_block(blob)
    if block is None:
        return
    start, end, dtype = block
    for shift in SHIFTS:
        if shift > 0:
            yield (
                "shifted",
                f"+{shift} at {start}",
                blob[:start] + bytes(rng.randrange(256) for _ in range(shift)) + blob[start:],
            )
        elif start + shift >= 0:
            yield "shifted", f"{shift} at {start}", blob[: start + shift] + blob[start:]
    for attempt in range(4):
        noise = bytes(rng.randrange(256) for _ in range(end - start))
        yield "random", f"attempt {attempt}", blob[:start] + noise + blob[end:]
    if np.dtype(dtype).kind == "f":
        top = 1e308 if np.dtype(dtype).itemsize == 8 else 3e38
        count = (end - start) // np.dtype(dtype).itemsize
        huge = (np.resize([top, -top, 1.0], count)).astype(dtype).tobytes()
        yield "huge", dtype, blob[:start] + huge + blob[end:]


def measured_seeds():
    """``{name: bytes}`` of the float formats holding :data:`HEIGHTS`, whose values use
    every bit of the mantissa as a measurement's do (the seeds' round numbers do not)."""
    surface = Surface(HEIGHTS, (1e-6, 1e-6))
    result = {
        "measured.tmd": tmd_file(HEIGHTS * 1e6),
        "measured.plu": plu_file(HEIGHTS * 1e6),
        "measured.ibw": ibw_file(HEIGHTS),
        "measured.al3d": al3d_file(HEIGHTS.astype("<f4")),
        "measured.opdx": opdx_file(HEIGHTS * 1e6),
    }
    for fmt in ("npy", "gsf", "gwy", "exr"):
        buffer = io.BytesIO()
        try:
            surface.write(buffer, fmt)
        except ImportError:
            continue
        result[f"measured.{fmt}"] = buffer.getvalue()
    return result


def written_huge():
    """``{name: bytes}`` of surfaces holding ±1e308 written by rough (and an X3P whose
    Offset is 1e308)."""
    heights = MAP.copy()
    heights[1, 1], heights[2, 3] = 1e308, -1e308
    result = {}
    for fmt in _WRITTEN:
        try:
            surface = Surface(heights, (1e-6, 1e-6))
            buffer = io.BytesIO()
            surface.write(buffer, fmt)
        except (ImportError, InputError):
            continue
        result[f"huge.{fmt}"] = buffer.getvalue()
    from x3p_files import x3p_file

    result["offset.x3p"] = x3p_file(COUNTS, code="I", offset=1e308)
    try:
        import h5py

        buffer = io.BytesIO()
        with h5py.File(buffer, "w") as file:
            file.create_dataset("heights", data=heights)
        result["huge.h5"] = buffer.getvalue()
    except ImportError:
        pass
    return result


def outcome(name, original, blob):
    """What reading one damaged file gave: ``"refused"``; ``"same"`` (the values of the
    undamaged file at the points read, its spacing); ``"shorter"`` (those values, but
    fewer points and another spacing: a file cut at a line end, which only a count in
    the file can tell); ``"warned"`` (other values, with a warning that the file may be
    cut); ``"changed"`` (other values, silently); or ``"internal: ..."``."""
    records = []
    handler = logging.Handler(logging.WARNING)
    handler.emit = records.append
    logger = logging.getLogger("rough")
    logger.addHandler(handler)
    try:
        surface = read_bytes(blob, options_for(name), name=name)
    except InputError:
        return "refused"
    except Exception as error:  # noqa: BLE001 - what the test counts
        return f"internal: {type(error).__name__}: {error}"
    finally:
        logger.removeHandler(handler)
    if original is not None and _same_values(surface, original):
        if np.allclose(surface.spacing, _spacing(surface, original), rtol=1e-12, atol=0):
            return "same"
        return "shorter" if surface.heights.size < original.heights.size else "changed"
    return "warned" if any("cut short" in record.getMessage() for record in records) else "changed"


def _spacing(surface, original):
    return original.spacing[: surface.heights.ndim]


def _same_values(surface, original):
    """Whether ``surface`` holds the values of ``original`` at its points (a map read as
    its first row, or with fewer rows or columns, included)."""
    heights, reference = surface.heights, original.heights
    if heights.ndim < reference.ndim:
        reference = reference[0]
    if heights.ndim != reference.ndim or any(a > b for a, b in zip(heights.shape, reference.shape)):
        return False
    part = reference[tuple(slice(0, n) for n in heights.shape)]
    read = ~np.isnan(heights)
    return bool(np.array_equal(heights[read], part[read]))


def tally(kinds=("truncated", "shifted", "random", "huge")):
    """``{(seed, kind): Counter of outcomes}`` and a list of the internal errors and
    changed reads (seed, kind, detail, outcome)."""
    rng = random.Random(31)
    counts, bad = collections.defaultdict(collections.Counter), []
    for name, blob in sorted({**seeds(), **measured_seeds()}.items()):
        original = read_bytes(blob, options_for(name), name=name)
        for kind, detail, damaged in variants(name, blob, rng):
            if kind not in kinds:
                continue
            result = outcome(name, original, damaged)
            counts[name, kind][result.split(":")[0]] += 1
            if result not in ("refused", "same"):
                bad.append((name, kind, detail, result))
    for name, blob in sorted(written_huge().items()):
        try:
            read_bytes(blob, options_for(name), name=name)
            result = "changed"
        except InputError as error:  # refused for its heights, not for a missing spacing
            result = "refused" if "beyond ±100 km" in str(error) else f"refused for another reason: {error}"
        except Exception as error:  # noqa: BLE001 - what the test counts
            result = f"internal: {type(error).__name__}: {error}"
        counts[name, "huge"][result.split(":")[0]] += 1
        if result != "refused":
            bad.append((name, "huge", "written", result))
    return counts, bad


if __name__ == "__main__":
    logging.getLogger("rough").propagate = False
    counts, bad = tally()
    totals = collections.defaultdict(collections.Counter)
    for (name, kind), counter in sorted(counts.items()):
        totals[kind].update(counter)
        print(f"{name:16} {kind:10} " + " ".join(f"{key} {value}" for key, value in sorted(counter.items())))
    for kind, counter in totals.items():
        print(f"{'ALL':16} {kind:10} " + " ".join(f"{key} {value}" for key, value in sorted(counter.items())))
    for row in bad:
        if row[3].startswith("internal"):
            print("INTERNAL", *row)
