"""Writes the hostile corpus: crafted inputs for every reader that rough must refuse
with exit status 2 and one line naming the file and the problem, writing nothing, in
bounded memory and time. ``MANIFEST.tsv`` lists each file, a fragment its error must
contain, and what is wrong with it. Run: python tests/hostile/make_corpus.py
(the files are committed; this script documents and regenerates them)."""

import gzip
import io
import pathlib
import struct
import sys
import zipfile
import zlib

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from format_files import al3d_file, gsf, sdf_binary
from x3p_files import x3p_file

GRID = np.arange(12.0).reshape(3, 4) * 1e-6
CASES = []


def case(name, data, fragment, why):
    CASES.append((name, bytes(data), fragment, why))


# -- X3P (zip + XML) -------------------------------------------------------------------------


def zip_boundaries(blob):
    """Byte offsets where the archive's structures start: local headers, data, the
    central directory, its entries and the end record."""
    archive = zipfile.ZipFile(io.BytesIO(blob))
    marks = {}
    for info in archive.infolist():
        marks[f"local-header-{info.filename}"] = info.header_offset + 10
        name_end = info.header_offset + 30 + len(info.filename.encode())
        marks[f"data-of-{info.filename}"] = name_end + 2
    directory = blob.rfind(b"PK\x01\x02", 0, blob.rfind(b"PK\x05\x06"))
    marks["central-directory"] = blob.find(b"PK\x01\x02")
    marks["last-directory-entry"] = directory + 20
    marks["end-record"] = blob.rfind(b"PK\x05\x06") + 10
    return marks


def x3p_cases():
    good = x3p_file(GRID)
    for label, cut in sorted(zip_boundaries(good).items(), key=lambda item: item[1]):
        safe = label.replace("/", "-").replace(".", "-")
        case(f"x3p-truncated-at-{safe}.x3p", good[:cut], "", f"a valid X3P cut inside its {label}")
    case("x3p-wrong-magic.x3p", b"PK\x03\x04" + bytes(range(256)) * 4, "", "zip magic followed by noise")
    case(
        "x3p-no-main-xml.x3p",
        _zip({"bindata/data.bin": GRID.astype("<f8").tobytes()}),
        "main.xml",
        "a zip without main.xml",
    )
    case("x3p-main-not-xml.x3p", _zip({"main.xml": b"this is not XML <<<"}), "main.xml", "main.xml is not XML")
    laughs = (
        '<?xml version="1.0"?><!DOCTYPE lolz [<!ENTITY a "lol">'
        + "".join(f'<!ENTITY {chr(98 + k)} "{("&" + chr(97 + k) + ";") * 10}">' for k in range(9))
        + ']><p:ISO5436_2 xmlns:p="http://www.opengps.eu/2008/ISO5436_2">&j;</p:ISO5436_2>'
    ).encode()
    case("x3p-entity-bomb.x3p", _zip({"main.xml": laughs}), "DOCTYPE", "billion-laughs entity expansion in main.xml")
    utf16 = laughs.replace(b'version="1.0"', b'version="1.0" encoding="UTF-16"').decode().encode("utf-16")
    case(
        "x3p-entity-bomb-utf16.x3p", _zip({"main.xml": utf16}), "UTF-8", "the entity bomb in UTF-16, past a byte search"
    )
    case(
        "x3p-external-entity.x3p",
        x3p_file(GRID, doctype='<!DOCTYPE p [<!ENTITY e SYSTEM "file:///etc/passwd">]>'),
        "DOCTYPE",
        "main.xml declares an external entity",
    )
    case(
        "x3p-main-checksum-wrong.x3p",
        x3p_file(GRID, main_checksum="bad"),
        "checksum mismatch",
        "md5checksum.hex is wrong",
    )
    case(
        "x3p-main-checksum-missing.x3p",
        x3p_file(GRID, main_checksum="missing"),
        "md5checksum.hex",
        "no md5checksum.hex",
    )
    case("x3p-data-checksum-wrong.x3p", x3p_file(GRID, data_checksum="bad"), "checksum mismatch", "data MD5 is wrong")
    case(
        "x3p-data-checksum-missing.x3p", x3p_file(GRID, data_checksum="missing"), "no MD5 checksum", "data MD5 missing"
    )
    case(
        "x3p-zip-bomb.x3p",
        _swap_member(x3p_file(GRID), "bindata/data.bin", bytes(64 << 20)),
        "header implies",
        "data.bin inflates to 64 MB for a 4×3 header",
    )
    case(
        "x3p-member-size-lie.x3p",
        _lie_about_size(x3p_file(GRID, data_checksum="missing"), "bindata/data.bin", bytes(64 << 20), 96),
        "",
        "data.bin's zip entries claim 96 bytes; its deflate stream holds 64 MB",
    )
    case(
        "x3p-unknown-compression.x3p",
        _patch_headers(x3p_file(GRID), "main.xml", method=99),
        "cannot be unpacked",
        "main.xml compressed with method 99 (found by the fuzzer)",
    )
    case(
        "x3p-encrypted.x3p",
        _patch_headers(x3p_file(GRID), "main.xml", flags=0x1),
        "encrypted",
        "main.xml marked encrypted",
    )
    case(
        "x3p-absurd-size.x3p",
        x3p_file(GRID, size=(1000000, 1000000, 1)),
        "more than rough handles",
        "SizeX × SizeY = 10^12",
    )
    case(
        "x3p-size-mismatch.x3p", x3p_file(GRID, size=(4, 3, 1000000)), "header implies", "SizeZ 10^6 layers in 96 bytes"
    )
    case("x3p-zero-spacing.x3p", x3p_file(GRID, spacing=(0.0, 1e-6)), "spacing", "CX increment 0")
    case("x3p-negative-spacing.x3p", x3p_file(GRID, spacing=(1e-6, -1e-6)), "spacing", "CY increment negative")
    case("x3p-nan-only.x3p", x3p_file(np.full((3, 4), np.nan)), "no valid points", "every height is NaN")
    case("x3p-single-point.x3p", x3p_file(np.ones((1, 1)) * 1e-6), "two points", "a 1 × 1 surface")
    case("x3p-point-cloud.x3p", x3p_file(GRID, feature="PCL"), "point clouds", "a PCL (point list) file")
    case(
        "x3p-inline-short.x3p",
        x3p_file(GRID, inline=True, size=(5, 3, 1)),
        "DataList holds",
        "DataList shorter than declared",
    )


def _zip(members):
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, content in members.items():
            archive.writestr(name, content)
    return buffer.getvalue()


def _swap_member(blob, name, content):
    archive = zipfile.ZipFile(io.BytesIO(blob))
    members = {info.filename: archive.read(info) for info in archive.infolist()}
    members[name] = content
    return _zip(members)


def _lie_about_size(blob, name, content, claimed):
    """Replace ``name`` by ``content`` and patch both its zip headers to claim ``claimed`` bytes."""
    patched = bytearray(_swap_member(blob, name, content))
    encoded = name.encode()
    local = patched.find(b"PK\x03\x04" + bytes(0), 0)
    while local >= 0:
        length = struct.unpack_from("<H", patched, local + 26)[0]
        if bytes(patched[local + 30 : local + 30 + length]) == encoded:
            struct.pack_into("<I", patched, local + 22, claimed)
        local = patched.find(b"PK\x03\x04", local + 4)
    central = patched.find(b"PK\x01\x02")
    while central >= 0:
        length = struct.unpack_from("<H", patched, central + 28)[0]
        if bytes(patched[central + 46 : central + 46 + length]) == encoded:
            struct.pack_into("<I", patched, central + 24, claimed)
        central = patched.find(b"PK\x01\x02", central + 4)
    return bytes(patched)


def _patch_headers(blob, name, method=None, flags=None):
    """Set the compression method or flag bits of ``name`` in its local and central headers."""
    patched = bytearray(blob)
    encoded = name.encode()
    for signature, name_at, flags_at in ((b"PK\x03\x04", 26, 6), (b"PK\x01\x02", 28, 8)):
        at = patched.find(signature)
        while at >= 0:
            length = struct.unpack_from("<H", patched, at + name_at)[0]
            start = at + name_at + (4 if signature == b"PK\x03\x04" else 18)
            if bytes(patched[start : start + length]) == encoded:
                if flags is not None:
                    struct.pack_into("<H", patched, at + flags_at, flags)
                if method is not None:
                    struct.pack_into("<H", patched, at + flags_at + 2, method)
            at = patched.find(signature, at + 4)
    return bytes(patched)


# -- OpenEXR ---------------------------------------------------------------------------------


def exr_cases():
    from rough import Surface

    buffer = io.BytesIO()
    Surface(GRID, (1e-6, 1e-6)).write(buffer, "exr")
    good = buffer.getvalue()
    case("exr-truncated-header.exr", good[:40], "", "EXR cut inside its header")
    case("exr-truncated-pixels.exr", good[: len(good) - 20], "", "EXR cut inside its pixel data")
    case("exr-garbage-after-magic.exr", good[:4] + bytes(range(200)), "", "EXR magic followed by noise")
    window = good.find(b"dataWindow\0box2i\0")
    huge = bytearray(good)
    struct.pack_into("<iiii", huge, window + len(b"dataWindow\0box2i\0") + 4, 0, 0, 2**30, 2**30)
    case("exr-absurd-window.exr", huge, "OpenEXR", "dataWindow of 2^30 × 2^30 pixels")
    buffer = io.BytesIO()
    Surface(np.full((3, 4), np.nan), (1e-6, 1e-6)).write(buffer, "exr")
    case("exr-nan-only.exr", buffer.getvalue(), "no valid points", "every pixel NaN")
    chunk = next(x for x in range(8, len(good)) if int.from_bytes(good[x - 8 : x], "little") == x)
    leader = bytearray(good)
    leader[chunk] = 0xFF
    case(
        "exr-corrupt-chunk-leader.exr", leader, "", "the pixel chunk names scanline 255 (the bindings print to stdout)"
    )


# -- GSF ---------------------------------------------------------------------------------------


def gsf_cases():
    case("gsf-no-nul.gsf", b"Gwyddion Simple Field 1.0\nXRes = 2\nYRes = 2\n", "NUL", "header never ends")
    case(
        "gsf-wrong-version.gsf",
        gsf(["XRes = 2", "YRes = 2"], np.zeros(4)).replace(b"1.0", b"9.9", 1),
        "",
        "version 9.9",
    )
    case("gsf-zero-xres.gsf", gsf(["XRes = 0", "YRes = 2"], []), "XRes", "XRes 0")
    case(
        "gsf-absurd-size.gsf",
        gsf(["XRes = 1000000000", "YRes = 1000000000"], np.zeros(4)),
        "declares",
        "10^18 points in 16 bytes",
    )
    case("gsf-short-data.gsf", gsf(["XRes = 4", "YRes = 4"], np.zeros(5)), "declares", "16 points declared, 5 present")
    case(
        "gsf-zero-spacing.gsf",
        gsf(["XRes = 2", "YRes = 2", "XReal = 0", "YReal = 1e-6"], np.zeros(4)),
        "XReal",
        "XReal 0",
    )
    case(
        "gsf-negative-spacing.gsf",
        gsf(["XRes = 2", "YRes = 2", "XReal = -1e-6", "YReal = 1e-6"], np.zeros(4)),
        "XReal",
        "XReal negative",
    )
    case(
        "gsf-nan-only.gsf",
        gsf(["XRes = 2", "YRes = 2", "XReal = 1e-6", "YReal = 1e-6"], np.full(4, np.nan)),
        "no valid points",
        "every value NaN",
    )
    case(
        "gsf-single-point.gsf",
        gsf(["XRes = 1", "YRes = 1", "XReal = 1e-6", "YReal = 1e-6"], [1.0]),
        "two points",
        "one point",
    )
    case(
        "gsf-infinite-real.gsf",
        gsf(["XRes = 2", "YRes = 2", "XReal = inf", "YReal = 1e-6"], np.zeros(4)),
        "XReal",
        "XReal infinite",
    )


# -- text ----------------------------------------------------------------------------------------


def text_cases():
    case("text-nonuniform-x.txt", b"x z\n0 1\n1 2\n3 3\n3.5 4\n7 1\n", "not evenly spaced", "x steps 1, 2, 0.5, 3.5")
    case("text-duplicate-x.txt", b"x z\n1 1\n1 2\n1 3\n", "", "every x the same: zero spacing")
    case("text-single-point.txt", b"x z\n0 1e-6\n", "two points", "one row")
    case("text-nan-only.txt", b"x z\n0 nan\n1 nan\n2 nan\n", "no valid points", "every height NaN")
    case("text-overflow.txt", b"x z\n0 1e400\n1 1e400\n2 -1e400\n", "line 2", "heights overflow to infinity")
    case("text-bom-only.txt", b"\xef\xbb\xbf", "empty", "a UTF-8 byte-order mark and nothing else")
    case(
        "text-utf16-odd-length.txt",
        b"\xff\xfe" + "x z\n0 1\n".encode("utf-16-le") + b"\x00",
        "",
        "UTF-16 with a dangling byte",
    )
    case("text-bom-then-binary.txt", b"\xef\xbb\xbf" + bytes(range(256)), "", "a BOM then binary junk")
    case(
        "text-mixed-encodings.txt",
        "x z\n0 1\n1 2µ\n".encode() + b"2 3\xb5\n",
        "",
        "UTF-8 and Latin-1 mixed inside numbers",
    )
    case("text-unknown-unit.txt", b"# unit: furlong\nx z\n0 1\n1 2\n2 3\n", "furlong", "a unit that does not exist")
    case("text-words.txt", b"roughness measurements\nsample A was rough\nthe end\n", "", "prose, no numbers")
    case("text-ragged.txt", b"x z\n0 1\n1 2 3 4\n2\n", "", "rows of different lengths")
    case(
        "text-xyz-irregular.txt",
        b"x y z\n0 0 1\n0.3 0 1\n1.7 0 1\n0 1 1\n0.3 1 1\n1.7 1 1\n",
        "",
        "x y z on an uneven grid",
    )
    case(
        "text-dektak-truncated.csv",
        b"Meta Data\nVersion,1.0\nScan Rate,1\nResolution,0.156 um/sample\n",
        "",
        "Dektak header with no data",
    )
    case(
        "text-dektak-no-rows.csv",
        b"Scan Parameters\r\r\nLength,0.8 um\r\n\r\r\nScan Data\r\r\nLateral um,Raw Micrometer,\r\n",
        "no numeric data",
        "Dektak scan: header and column names, no data rows",
    )
    case(
        "text-gwyddion-zero-width.txt",
        b"Channel: Height\nWidth: 0 um\nHeight: 1 um\nValue units: m\nData values:\n1 2\n3 4\n",
        "",
        "Gwyddion text export with zero width",
    )
    case("text-long-line.txt", b"x z\n" + b"1" * (1 << 20) + b" 2\n0 1\n", "", "a 4 MB number")


# -- NPY ------------------------------------------------------------------------------------------


def npy(header, body=b"", version=(1, 0)):
    text = repr(header).encode() if not isinstance(header, bytes) else header
    text += b" " * (63 - (len(text) + 10) % 64) + b"\n"
    return b"\x93NUMPY" + bytes(version) + struct.pack("<H", len(text)) + text + body


def npy_cases():
    case(
        "npy-absurd-shape.npy",
        npy({"descr": "<f8", "fortran_order": False, "shape": (10**6, 10**6)}, bytes(64)),
        "declares",
        "10^12 points declared, 8 present",
    )
    case(
        "npy-object-pickle.npy",
        npy({"descr": "|O", "fortran_order": False, "shape": (2,)}, b"\x80\x04N."),
        "",
        "an object array: reading it would unpickle",
    )
    case(
        "npy-three-d.npy",
        npy({"descr": "<f8", "fortran_order": False, "shape": (2, 2, 2)}, bytes(64)),
        "",
        "a 3-D array",
    )
    case(
        "npy-complex.npy",
        npy({"descr": "<c16", "fortran_order": False, "shape": (4,)}, bytes(64)),
        "",
        "complex values",
    )
    case(
        "npy-strings.npy",
        npy({"descr": "<U3", "fortran_order": False, "shape": (3,)}, "abcdefghi".encode("utf-32-le")),
        "",
        "strings",
    )
    case("npy-bad-header.npy", npy(b"{'descr': '<f8', 'shape': (3,"), "", "a header that is not a dict")
    case(
        "npy-bad-version.npy",
        npy({"descr": "<f8", "fortran_order": False, "shape": (2,)}, bytes(16), version=(9, 9)),
        "",
        "NPY version 9.9",
    )


# -- SDF and AL3D -----------------------------------------------------------------------------------


def sdf_cases():
    ascii_header = (
        "aISO-1.0\nNumPoints = {n}\nNumProfiles = {m}\nXscale = {x}\nYscale = 1e-6\nZscale = 1e-6\nDataType = 7\n*\n"
    )
    case(
        "sdf-ascii-count.sdf",
        (ascii_header.format(n=3, m=2, x=1e-6) + "1 2 3\n*\n").encode(),
        "holds 3 values",
        "6 values declared, 3 present",
    )
    case(
        "sdf-ascii-huge.sdf",
        (ascii_header.format(n=10**9, m=10**9, x=1e-6) + "1 2\n*\n").encode(),
        "",
        "10^18 points declared",
    )
    case("sdf-ascii-zero-xscale.sdf", (ascii_header.format(n=2, m=2, x=0) + "1 2 3 4\n*\n").encode(), "", "Xscale 0")
    case("sdf-binary-truncated.sdf", sdf_binary(4, 4, body=bytes(40)), "too short", "16 doubles declared, 5 present")
    case("sdf-binary-bad-type.sdf", sdf_binary(2, 2, datatype=9, body=bytes(32)), "", "DataType 9 does not exist")
    case("sdf-binary-negative-yscale.sdf", sdf_binary(2, 2, yscale=-1e-6, body=bytes(32)), "", "Yscale negative")
    case("sdf-unclosed-header.sdf", b"aISO-1.0\nNumPoints = 2\nNumProfiles = 1\n", "not closed", "header never ends")


def al3d_cases():
    zeros = np.zeros((2, 2))
    case("al3d-truncated-header.al3d", al3d_file(zeros)[:120], "truncated", "cut inside the tags")
    case(
        "al3d-absurd-size.al3d",
        al3d_file(zeros, tags={"Cols": 10**9, "Rows": 10**9}),
        "runs past the end",
        "10^18 pixels",
    )
    case("al3d-zero-pixel.al3d", al3d_file(zeros, pixel=(0, 1e-6)), "pixel size", "pixel size 0")
    case(
        "al3d-tag-count.al3d",
        al3d_file(zeros)[: 17 + 52] + b"TagCount".ljust(20, b"\0") + b"99999999".ljust(30, b"\0") + b"\r\n",
        "tag count",
        "TagCount 99999999",
    )
    case(
        "al3d-all-invalid.al3d",
        al3d_file(np.full((2, 2), 1e30), invalid=1e30),
        "no valid points",
        "every pixel invalid",
    )


# -- compressed and anything else ---------------------------------------------------------------------


def other_cases():
    inner = _gzip_of_zeros(2 << 30)
    case("gzip-bomb.txt.gz", gzip.compress(inner, 9), "refusing", "gzip of a gzip that unpacks to 2 GiB")
    case("gzip-truncated.txt.gz", gzip.compress(b"x z\n0 1\n1 2\n" * 100)[:40], "truncated", "gzip stream cut short")
    case("gzip-of-noise.gz", gzip.compress(bytes(range(256)) * 4), "", "gzip of binary noise")
    case("empty.x3p", b"", "empty", "an empty file")
    case("noise.bin", np.random.default_rng(1).integers(0, 256, 4096, dtype=np.uint8).tobytes(), "", "random bytes")
    case("zeros.bin", bytes(1024), "", "NUL bytes only")


def _gzip_of_zeros(size):
    """gzip of ``size`` NUL bytes, streamed, so writing the bomb needs no memory."""
    packer = zlib.compressobj(9, zlib.DEFLATED, 31)
    chunk = bytes(1 << 20)
    parts = [packer.compress(chunk) for _ in range(size // len(chunk))]
    return b"".join(parts) + packer.flush()


# -- issue 14: silent changes, internal errors, bombs past the bounds ----------------------------------


def _rough_file(surface, format_name):
    buffer = io.BytesIO()
    surface.write(buffer, format_name)
    return buffer.getvalue()


def _lines_gzip(line, size):
    """gzip of ``line`` repeated to ``size`` bytes, streamed."""
    packer = zlib.compressobj(9, zlib.DEFLATED, 31)
    chunk = line * ((1 << 20) // len(line))
    return b"".join(packer.compress(chunk) for _ in range(size // len(chunk))) + packer.flush()


def hardening_cases():
    from rough import Surface

    profile = b"x z\n0 1\n1 2\n2 3\n"
    case("text-header-typo.txt", b"O.5 1.2\n1 2\n2 3\n", "neither column names", "first data row O.5 (a letter O)")
    case("text-number-typo.txt", b"0.O 1.2\n1 2\n2 3\n", "line 1", "first data row 0.O (a letter O)")
    case("text-rtl-override.txt", "\u202e0 1.2\n1 2\n2 3\n".encode(), "U+202E", "a leading right-to-left override")
    case(
        "text-huge-number.txt.gz",
        gzip.compress(b"x z\n0 1\n1 " + b"1" * 500001 + b"\n2 3\n", 9),
        "float64 range",
        "a 500,001-digit height",
    )
    case("text-bomb.txt.gz", _lines_gzip(b"0 0\n", 60 << 20), "compression bomb", "61 KB of gzip, 60 MiB of text")
    sdf_text = b"aISO-1.0\nNumPoints = 4000\nNumProfiles = 4000\nXscale = 1e-6\nYscale = 1e-6\nZscale = 1e-6\n*\n"
    case(
        "sdf-bomb.sdf.gz",
        gzip.compress(sdf_text + b"0 " * (32 << 20) + b"\n*\n", 9),
        "compression bomb",
        "a gzipped ASCII SDF of 64 MiB",
    )
    twelve = " ".join(str(v) for v in range(12))
    case(
        "sdf-zscale-overflow.sdf",
        f"aISO-1.0\nNumPoints = 4\nNumProfiles = 3\nXscale = 1\nYscale = 1\nZscale = 1e308\n*\n{twelve}\n*\n".encode(),
        "Zscale",
        "Zscale 1e308 overflows 10 of 12 heights",
    )
    case(
        "npy-negative-shape.npy",
        npy({"descr": "<f8", "fortran_order": False, "shape": (-1, 4)}, bytes(64)),
        "shape",
        "shape (-1, 4): numpy would infer 2 rows",
    )
    case("al3d-negative-pixel.al3d", al3d_file(np.zeros((2, 2)), pixel=(-1e-6, 1e-6)), "pixel size", "pixel size -1 µm")
    import OpenEXR

    parts = [
        OpenEXR.Part({"type": OpenEXR.scanlineimage}, {"Y": np.full((3, 4), k, np.float32)}, f"part{k}") for k in (1, 2)
    ]
    buffer = io.BytesIO()
    OpenEXR.File(parts).write(buffer)
    case("exr-two-parts.exr", buffer.getvalue(), "2 parts", "a second part would be ignored")
    damaged = Surface(GRID, (1e-6, 1e-6), history=[{"command": "synth", "parameters": [1, 2]}])
    for format_name, suffix in (("x3p", "x3p"), ("exr", "exr"), ("gsf", "gsf"), ("tsv", "txt")):
        case(
            f"{format_name}-history-not-object.{suffix}",
            _rough_file(damaged, format_name),
            "history",
            "a history entry whose parameters are a list",
        )
    deep = b'{"metadata": ' + b"[" * 100000 + b"]" * 100000 + b"}"
    case(
        "x3p-deep-json.x3p",
        _swap_member(_rough_file(Surface(GRID, (1e-6, 1e-6)), "x3p"), "vendor/rough.json", deep),
        "nested too deeply",
        "vendor JSON nested 100,000 deep",
    )
    layered = profile
    for _ in range(1100):
        layered = gzip.compress(layered, 9, mtime=0)
    case("gzip-nested.txt.gz", layered, "nested more than", "a profile gzipped 1,100 times")
    case("gzip-junk-after.txt.gz", gzip.compress(profile) + b"junk", "junk", "bytes after the gzip member")
    case(
        "x3p-deflate-ratio.x3p",
        x3p_file(np.zeros((1024, 1024))),
        "compression bomb",
        "data.bin deflates 1000:1 (8 MiB of zeros)",
    )
    xml = x3p_file(GRID, compression=zipfile.ZIP_STORED)
    main = zipfile.ZipFile(io.BytesIO(xml)).read("main.xml")
    for method, label in ((zipfile.ZIP_BZIP2, "bzip2"), (zipfile.ZIP_LZMA, "lzma")):
        case(
            f"x3p-{label}-main.x3p",
            _recompress(xml, "main.xml", main + b" " * (64 << 20), method),
            "compression bomb",
            f"main.xml is {label} of 64 MiB",
        )


def _recompress(blob, name, content, method):
    archive = zipfile.ZipFile(io.BytesIO(blob))
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as out:
        for info in archive.infolist():
            data = content if info.filename == name else archive.read(info)
            out.writestr(info.filename, data, compress_type=method if info.filename == name else zipfile.ZIP_STORED)
    return buffer.getvalue()


# -- vendor formats (read only): headers that lie about sizes, offsets and nesting ------------------


def _patched(blob, offset, fmt, *values):
    patched = bytearray(blob)
    struct.pack_into(fmt, patched, offset, *values)
    return bytes(patched)


def _gwy_object(kind, *components):
    """A serialised Gwyddion object: type name, uint32 size, components."""
    body = b"".join(components)
    return kind.encode() + b"\0" + struct.pack("<I", len(body)) + body


def _gwy_component(name, code, value):
    return name.encode() + b"\0" + code.encode() + value


def _gwy_field(xres, yres, values, count=None):
    data = np.asarray(values, "<f8").tobytes()
    return _gwy_object(
        "GwyDataField",
        _gwy_component("xres", "i", struct.pack("<i", xres)),
        _gwy_component("yres", "i", struct.pack("<i", yres)),
        _gwy_component("xreal", "d", struct.pack("<d", 4e-6)),
        _gwy_component("yreal", "d", struct.pack("<d", 3e-6)),
        _gwy_component("data", "D", struct.pack("<I", len(values) if count is None else count) + data),
    )


def _gwy_deep(depth):
    """``depth`` objects, each the only component of the one around it."""
    inner = _gwy_object("G")
    for _ in range(depth - 2):
        inner = _gwy_object("G", _gwy_component("", "o", inner))
    return b"GWYP" + _gwy_object("GwyContainer", _gwy_component("o", "o", inner))


def _opdx_deep(depth):
    """``depth`` OPDx containers, each holding the next."""
    inner = b""
    for _ in range(depth):
        inner = struct.pack("<I", 1) + b"c" + b"\x7d" + b"\x04" + struct.pack("<I", len(inner)) + inner
    return b"VCA DATA\x01\x00\x00\x55" + inner


def _zip_of(members, compression=zipfile.ZIP_DEFLATED):
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", compression) as archive:
        for name, content in members.items():
            archive.writestr(zipfile.ZipInfo(name, (2020, 1, 2, 3, 4, 6)), content, compress_type=compression)
    return buffer.getvalue()


def _hdf5(build):
    """An HDF5 file (h5py) in which ``build(create_dataset)`` made its datasets, without time stamps."""
    import h5py

    buffer = io.BytesIO()
    with h5py.File(buffer, "w", libver="earliest") as handle:
        build(lambda *args, **kwargs: handle.create_dataset(*args, track_times=False, **kwargs))
    return buffer.getvalue()


def _geotiff(crs, transform, width=4, height=3, tags=None, **extra):
    """A float32 GeoTIFF (rasterio) in ``crs`` with the geotransform ``transform`` (a, b, c, d, e, f)."""
    import rasterio
    from rasterio.transform import Affine

    profile = {"driver": "GTiff", "width": width, "height": height, "count": 1, "dtype": "float32"}
    profile.update(crs=crs, transform=Affine(*transform), **extra)
    with rasterio.MemoryFile() as memory:
        with memory.open(**profile) as dataset:
            if width * height <= 1 << 16:
                dataset.write(np.arange(width * height, dtype="float32").reshape(height, width), 1)
            if tags:
                dataset.update_tags(**tags)
        return memory.read()


def _netcdf_classic(dims, variable_dims):
    """A classic NetCDF header (CDF\\x01) with the dimensions ``dims`` and one float64 variable
    ``heights`` over ``variable_dims``, whose data (4 values) follow the header."""

    def name(text):
        raw = text.encode()
        return struct.pack(">I", len(raw)) + raw + bytes(-len(raw) % 4)

    header = b"CDF\x01" + struct.pack(">I", 0)
    header += struct.pack(">II", 0x0A, len(dims)) + b"".join(name(n) + struct.pack(">I", size) for n, size in dims)
    header += struct.pack(">II", 0, 0)  # no global attributes
    variable = name("heights") + struct.pack(">I", len(variable_dims))
    variable += b"".join(struct.pack(">I", index) for index in variable_dims)
    variable += struct.pack(">II", 0, 0) + struct.pack(">I", 6) + struct.pack(">I", 32)
    begin = len(header) + 8 + len(variable) + 4
    return header + struct.pack(">II", 0x0B, 1) + variable + struct.pack(">I", begin) + bytes(32)


def _zon_deflated(blob):
    """A ZON file with its zip members deflated."""
    start = blob.find(b"PK\x03\x04")
    archive = zipfile.ZipFile(io.BytesIO(blob[start:]))
    members = {info.filename: archive.read(info) for info in archive.infolist()}
    return blob[:start] + _zip_of(members)


def _opdx_map_points(blob, rows, columns):
    """An OPDx map whose Dimension1Points and Dimension2Points say ``rows`` and ``columns``."""
    patched = bytearray(blob)
    for name, value in ((b"Dimension1Points", rows), (b"Dimension2Points", columns)):
        at = patched.find(name) + len(name) + 1
        struct.pack_into("<I", patched, at, value)
    return bytes(patched)


def vendor_cases():
    from seed_files import (
        bcr_file,
        di_file,
        frt_file,
        ibw_file,
        metropro_file,
        mi_file,
        nid_file,
        nms_file,
        opd_file,
        opdx_file,
        park_file,
        park_header,
        plu_file,
        sur_file,
        tmd_file,
        wsxm_file,
        zon_file,
    )

    limit = "rough's limit"
    # Digital Surf SUR
    case("sur-absurd-size.sur", sur_file(nx=2**31 - 1, ny=2**31 - 1), limit, "points per line and lines 2^31 - 1")
    case("sur-negative-size.sur", sur_file(nx=-(2**31)), "empty or negative", "points per line -2^31")
    case("sur-truncated-points.sur", sur_file()[:530], "needs", "4 × 3 int16 points, 18 bytes present")
    case("sur-bits-8.sur", sur_file(bits=8), "8 bits", "8 bits per point")
    case(
        "sur-stream-count.sur",
        _patched(sur_file(compressed=True), 512, "<I", 0xFFFFFFFF),
        "streams",
        "DSCOMPRESSED data listing 2^32 - 1 zlib streams",
    )
    case(
        "sur-stream-sizes.sur",
        _patched(sur_file(compressed=True), 516, "<I", 0x7FFFFFFF),
        "not the 24 bytes",
        "a zlib stream claiming to unpack to 2 GiB",
    )
    case(
        "sur-zlib-bomb.sur",
        sur_file(np.zeros((2048, 2048), int), bits=32, compressed=True),
        "compression bomb",
        "DSCOMPRESSED: 16 MiB of int32 zeros in 16 KB of zlib (read as a flat surface before)",
    )
    case("sur-zero-spacing.sur", sur_file(dx=0.0), "spacing", "dx 0")
    case("sur-unit-volt.sur", sur_file(unit=b"V"), "not a length unit", "lateral and height unit V")
    # TrueMap TMD
    case("tmd-absurd-size.tmd", tmd_file(nx=2**31, ny=2**31), limit, "width and height 2^31")
    case("tmd-truncated-header.tmd", tmd_file()[:60], "truncated", "cut inside the width and height")
    case("tmd-short-data.tmd", tmd_file(ny=1000), "runs past the end", "4 × 1000 heights declared, 4 × 3 present")
    case("tmd-zero-length.tmd", tmd_file(lengths=(0.0, 6.0)), "x length", "x length 0")
    # FRT MicroProf
    frt = frt_file()
    case("frt-block-past-end.frt", frt_file(block_size=0xFFFFFFFF), "runs past the end", "image block of 4 GiB")
    case("frt-absurd-size.frt", frt_file(nx=2**31, ny=2**31), limit, "2^31 × 2^31 points")
    case("frt-wrong-version.frt", frt.replace(b"1.00", b"9.99", 1), "version", "version 9.99")
    case("frt-no-image.frt", frt[:18].replace(b"\x05\x00", b"\x00\x00", 1), "no image", "no blocks at all")
    # Zygo MetroPro
    case("metropro-absurd-size.dat", metropro_file(cn=(65535, 65535)), limit, "connected phase 65535 × 65535")
    case(
        "metropro-buckets-past-end.dat",
        metropro_file(ac=(65535, 65535, 65535), buckets=b""),
        "runs past the end",
        "intensity buckets of 65535 × 65535 × 65535 before the phase",
    )
    case(
        "metropro-header-size.dat",
        _patched(metropro_file(), 6, ">I", 0xFFFFFFFF),
        "does not match",
        "header_size 4 GiB",
    )
    case("metropro-zero-lateral.dat", metropro_file(lateral=0.0), "lateral_res", "lateral_res 0")
    # Wyko OPD
    case("opd-item-past-end.opd", opd_file(sizes={"Raw": 2**31}), "runs past the end", "a Raw item of 2 GiB")
    case(
        "opd-directory-past-end.opd",
        opd_file(directory_size=2**31),
        "runs past the end",
        "a Directory of 2 GiB",
    )
    case("opd-absurd-array.opd", _patched(opd_file(), 146, "<HH", 65535, 65535), limit, "Raw array 65535 × 65535")
    case(
        "opd-short-array.opd",
        _patched(opd_file(), 146, "<HH", 4, 300),
        "longer than its item",
        "a Raw array of 4 × 300 points in 30 bytes",
    )
    # Nanofocus NMS, Sensofar PLU (chosen by the extension)
    case("nms-truncated-header.nms", nms_file()[:30], "truncated", "30 bytes of a 3468-byte header")
    case("nms-absurd-size.nms", nms_file(nx=2**31, ny=2**31), limit, "2^31 × 2^31 points")
    case("nms-short-data.nms", nms_file(nx=1000, ny=1000), "runs past the end", "10^6 points declared, 12 present")
    case("plu-truncated-header.plu", plu_file()[:300], "truncated", "300 bytes of a 500-byte header")
    case("plu-absurd-layer.plu", plu_file(rows=2**31, cols=2**31), limit, "a layer of 2^31 × 2^31 points")
    case("plu-short-layer.plu", plu_file(rows=1000), "run past the end", "1000 × 4 points declared, 3 × 4 present")
    case("plu-wrong-type.plu", plu_file(kind=7), "measurement type", "measurement type 7")
    # Bruker Nanoscope
    case("di-offset-past-end.spm", di_file(fields={"Data offset": 10**9}), "truncated", "Data offset 10^9")
    case(
        "di-absurd-samples.spm",
        di_file(fields={"Samps/line": 10**9, "Number of lines": 10**9}),
        limit,
        "Samps/line and Number of lines 10^9",
    )
    case("di-huge-count.spm", di_file(fields={"Samps/line": "1e300"}), "not a count", "Samps/line 1e300")
    case("di-length-lie.spm", di_file(fields={"Data length": 4}), "exceed", "Data length 4 for 24 bytes of points")
    case("di-three-bytes.spm", di_file(fields={"Bytes/pixel": 3}), "bytes per pixel", "Bytes/pixel 3")
    # BCR-STM
    case("bcr-headersize-past-end.bcr", bcr_file(fields={"headersize": 10**9}), "does not fit", "headersize 10^9")
    case(
        "bcr-absurd-size.bcr",
        bcr_file(fields={"xpixels": 10**9, "ypixels": 10**9}),
        limit,
        "xpixels and ypixels 10^9",
    )
    case(
        "bcr-short-data.bcr", bcr_file(fields={"ypixels": 1000}), "runs past the end", "4 × 1000 points, 4 × 3 present"
    )
    case("bcr-fileformat.bcr", bcr_file(fields={"fileformat": "bcrxyz"}), "fileformat", "fileformat bcrxyz")
    # Agilent MI
    case("mi-absurd-pixels.mi", mi_file(fields={"xPixels": 10**12}), limit, "xPixels 10^12")
    case("mi-short-data.mi", mi_file(fields={"yPixels": 1000}), "runs past the end", "4 × 1000 points, 4 × 3 present")
    case("mi-negative-pixels.mi", mi_file(fields={"xPixels": -4}), "positive count", "xPixels -4")
    case("mi-ascii.mi", mi_file().replace(b"BINARY", b"ASCII "), "not read", "ASCII data")
    # Nanosurf NID
    case("nid-absurd-points.nid", nid_file(fields={"Points": 10**9, "Lines": 1}), limit, "Points 10^9")
    case("nid-block-past-end.nid", nid_file(fields={"Lines": 1000}), "ends at byte", "4 × 1000 points, 4 × 3 present")
    case(
        "nid-group-count.nid",
        nid_file()
        .replace(b"GroupCount=1", b"GroupCount=1e18")
        .replace(b"Gr0-Count=1", b"Gr0-Count=1e18")
        .replace(b"Gr0-Ch0=", b"Gr0-Xx0="),
        "no data set",
        "10^18 groups of 10^18 data sets listed, none present",
    )
    case("nid-no-end.nid", nid_file().replace(b"#!", b"!!"), "no end", "the header never ends (no #! line)")
    case("nid-bits.nid", nid_file(fields={"SaveBits": 12}), "12 bits", "SaveBits 12")
    # WSxM
    case("wsxm-absurd-rows.top", wsxm_file(fields={"Number of rows": 10**12}), limit, "Number of rows 10^12")
    case("wsxm-short-data.top", wsxm_file(fields={"Number of rows": 1000}), "runs past the end", "1000 rows, 3 present")
    case("wsxm-no-end.top", wsxm_file().replace(b"[Header end]", b"[Header fin]"), "Header end", "no [Header end]")
    case("wsxm-negative-rows.top", wsxm_file(fields={"Number of rows": -3}), "positive count", "Number of rows -3")
    # Igor binary wave (recognised by its checksum, or by the extension)
    ibw = ibw_file()
    case("ibw-bad-checksum.ibw", _patched(ibw, 2, "<H", 1), "checksum", "header checksum off by one")
    case("ibw-truncated.ibw", ibw[:400], "damaged or truncated", "12 float32 declared, 4 present")
    case(
        "ibw-absurd-dims.ibw",
        ibw_file(dims=(2**30, 2**30, 0, 0)),
        "damaged or truncated",
        "nDim 2^30 × 2^30 for 12 stored values",
    )
    case(
        "ibw-note-size.ibw",
        ibw_file(sizes={12: 2**26}),
        "declares",
        "noteSize 64 MiB in 432 bytes (igor2 took 2 GB and 5 s to refuse it)",
    )
    case("ibw-labels-size.ibw", ibw_file(sizes={44: 2**30}), "declares", "dimLabelsSize of the layers 1 GiB")
    case("ibw-negative-size.ibw", ibw_file(sizes={8: -1}), "section of -1", "formulaSize -1")
    case("ibw-volts.ibw", ibw_file(unit=b"V"), "not heights", "values in volts")
    # Park Systems TIFF
    case("ps-absurd-size.tiff", park_file(header=park_header(2**31, 2**31)), limit, "2^31 × 2^31 points")
    case("ps-short-data.tiff", park_file(header=park_header(1000, 1000)), "fewer than", "10^6 points, 12 stored")
    case("ps-version.tiff", park_file(version=3), "version", "version tag 3")
    case("ps-line-profile.tiff", park_file(header=park_header(image_type=1)), "not a 2-D map", "a line profile")
    case("ps-header-short.tiff", park_file(header=park_header()[:200]), "fewer than", "a 200-byte header")
    # Gwyddion GWY
    container = _gwy_object("GwyContainer", _gwy_component("/0/data", "o", _gwy_field(4, 3, np.zeros(4), 2**30)))
    case("gwy-array-past-end.gwy", b"GWYP" + container, "runs past the end", "data array of 2^30 doubles in 32 bytes")
    case("gwy-deep-nesting.gwy", _gwy_deep(10000), "nested more than", "objects nested 10,000 deep")
    huge = _gwy_object("GwyContainer", _gwy_component("/0/data", "o", _gwy_field(2**30, 2**30, np.zeros(4))))
    case("gwy-absurd-field.gwy", b"GWYP" + huge, limit, "xres and yres 2^30, 4 values")
    listing = _gwy_object("GwyContainer", _gwy_component("list", "O", struct.pack("<I", 0xFFFFFFFF)))
    case("gwy-list-count.gwy", b"GWYP" + listing, "longer than its object", "an object list of 2^32 - 1 items")
    case(
        "gwy-not-container.gwy",
        b"GWYP" + _gwy_field(2, 2, np.zeros(4)),
        "not a GwyContainer",
        "the top object is a data field",
    )
    case("gwy-unterminated.gwy", b"GWYP" + b"GwyContainer" * 40, "truncated", "a type name that never ends")
    # HDF5, NetCDF
    case(
        "hdf5-sparse-huge.h5",
        _hdf5(lambda create: create("height", (1 << 20, 1 << 20), "f8", chunks=(64, 64))),
        limit,
        "a chunked 2^20 × 2^20 dataset, nothing written",
    )
    case(
        "hdf5-sparse-bomb.h5",
        _hdf5(lambda create: create("height", (16384, 16384), "f8", chunks=(1024, 1024), fillvalue=1.0)),
        "compression bomb",
        "a chunked 16384 × 16384 dataset (2 GiB), nothing written: all fill value",
    )
    case(
        "hdf5-external.h5",
        _hdf5(lambda create: create("height", (4, 4), "f8", external=[("/etc/passwd", 0, 128)])),
        "outside the file",
        "a dataset stored in /etc/passwd",
    )
    case("hdf5-no-map.h5", _hdf5(lambda create: create("x", data=np.arange(4.0))), "2-D", "only a 1-D dataset")
    case(
        "netcdf-absurd-dims.nc",
        _netcdf_classic([("x", 2**30), ("y", 2**30)], [0, 1]),
        "malformed NetCDF",
        "heights(x, y) of 2^30 × 2^30 doubles, 4 present",
    )
    case(
        "netcdf-numrecs.nc",
        _patched(_netcdf_classic([("t", 0), ("x", 4)], [0, 1]), 4, ">I", 2**31 - 1),
        "malformed NetCDF",
        "heights(t, x) over a record dimension of 2^31 - 1 records, 4 values present",
    )
    case(
        "netcdf-no-heights.nc",
        _netcdf_classic([("x", 2), ("y", 2)], [0, 1]).replace(b"heights", b"hEights"),
        "heights",
        "no heights variable",
    )
    # GeoTIFF (rasterio)
    case(
        "geotiff-geographic.tif",
        _geotiff("EPSG:4326", (0.001, 0, 7.0, 0, -0.001, 46.0)),
        "reproject",
        "a DEM in degrees (EPSG:4326)",
    )
    case(
        "geotiff-rotated.tif",
        _geotiff("EPSG:32632", (1.0, 0.5, 500000.0, 0.3, -1.0, 5000000.0)),
        "rotated",
        "a rotated and sheared geotransform",
    )
    case(
        "geotiff-sparse-bomb.tif",
        _geotiff(
            "EPSG:32632",
            (1.0, 0, 500000.0, 0, -1.0, 5000000.0),
            width=16384,
            height=16384,
            tiled=True,
            blockxsize=1024,
            blockysize=1024,
            sparse_ok=True,
        ),
        "compression bomb",
        "16384 × 16384 float32 (1 GiB) in a sparse TIFF of a few KB",
    )
    case(
        "geotiff-undecodable-tag.tif",
        _geotiff("EPSG:4326", (0.001, 0, 7.0, 0, -0.001, 46.0), tags={"NOTE": "x"}).replace(
            b'<Item name="NOTE"', b'<Item \xf4a me="NOTE"'
        ),
        "geographic",
        "GDAL metadata holding a byte that is not UTF-8 (rasterio's logger printed a traceback; fuzzer)",
    )
    case("geotiff-no-georeference.tif", _geotiff(None, (1, 0, 0, 0, 1, 0)), "--spacing", "no CRS, no geotransform")
    # MountainsMap MNT, Keyence ZON, Bruker OPDx
    case(
        "mnt-not-ole.mnt",
        b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1" + bytes(range(256)) * 4,
        "OLE2",
        "OLE2 magic, then 1 KB of noise (olefile took short bytes for a file name)",
    )
    case(
        "zon-no-archive.zon",
        zon_file()[:4] + struct.pack("<I", 10**9) + zon_file()[8:],
        "no archive",
        "a BMP preview of 10^9 bytes",
    )
    case("zon-absurd-grid.zon", zon_file(grid=(65536, 65536, 4, 262144)), limit, "height grid 65536 × 65536")
    case("zon-short-grid.zon", zon_file(grid=(4, 1000, 4, 16)), "truncated", "height grid 4 × 1000, 4 × 3 present")
    zeros = np.zeros((2048, 2048), np.int32)
    case(
        "zon-grid-bomb.zon",
        _zon_deflated(zon_file(zeros)),
        "compression bomb",
        "a 16 MiB height grid deflated to 16 KB",
    )
    case(
        "zon-zstd-bomb.zon",
        zon_file(zeros, zstd=True),
        "compression bomb",
        "KPK1: a 16 MiB height grid in a zstd frame of a few hundred bytes",
    )
    case("opdx-deep-nesting.opdx", _opdx_deep(1000), "nested more than", "containers nested 1000 deep")
    case("opdx-absurd-map.opdx", _opdx_map_points(opdx_file(), 65536, 65536), limit, "Dimension points 65536 × 65536")
    case(
        "opdx-container-past-end.opdx",
        _patched(opdx_file(), 12 + 4 + len("2D_Data") + 1 + 1, "<I", 0x7FFFFFFF),  # magic, name, type, width
        "runs past the end",
        "a container of 2 GiB",
    )
    # Mitutoyo Excel, NMM zip
    case(
        "xlsx-doctype.xlsx",
        _zip_of({"[Content_Types].xml": b'<?xml version="1.0"?><!DOCTYPE t [<!ENTITY a "x">]><Types/>'}),
        "DOCTYPE",
        "[Content_Types].xml declares entities",
    )
    case(
        "xlsx-bomb.xlsx",
        _zip_of({"[Content_Types].xml": b"<Types/>", "xl/worksheets/sheet1.xml": b" " * (16 << 20)}),
        "compression bomb",
        "a sheet of 16 MiB deflated to 16 KB",
    )
    dsc = b"----\n10 : 11-Jan-2024 23:49:11 : -Lz+Az : 20001 : Surface height\n"
    dsc += b"11 : 11-Jan-2024 23:49:11 : XY vector : 20001 : xy\n----\n"
    case(
        "nmm-bomb.zip",
        _zip_of({"scan.dsc": dsc, "scan.dat": b"0 " * (8 << 20)}),
        "compression bomb",
        "a .dat of 16 MiB deflated to 16 KB",
    )
    case(
        "nmm-points.zip",
        _zip_of({"scan.dsc": dsc.replace(b"10 :", b"0 :").replace(b"11 :", b"1 :"), "scan.dat": b"0 1\n1 2\n2 3\n"}),
        "declares",
        "20001 points declared, 3 present",
    )


# -- issue 31: damaged files never pass as data ------------------------------------------------------


def damage_cases():
    from rough import Surface

    rng = np.random.default_rng(31)
    profile = _rough_file(Surface(rng.normal(size=200) * 1e-6, (1e-6,)), "tsv")
    case("text-tsv-cut-mid-number.txt", profile[: profile.rindex(b"e-")], "cut short", "rough's TSV cut in -4.67e-07")
    grid = _rough_file(Surface(rng.normal(size=(6, 8)) * 1e-6, (1e-6, 1e-6)), "tsv")
    rows = grid.split(b"\n\n")
    case("text-tsv-cut-at-a-row.txt", b"\n\n".join(rows[:3]) + b"\n\n", "cut short", "rough's TSV map, 3 rows of 6")
    heights = rng.normal(size=(8, 12)) * 1e-9
    export = "# Channel: Height\n# Width: 12.000 um\n# Height: 8.000 um\n# Value units: m\n" + "".join(
        "\t".join(f"{value:g}" for value in row) + "\n" for row in heights
    )
    case("text-gwyddion-cut-at-200.txt", export.encode()[:200], "cut short", "Gwyddion's text export cut at 200 bytes")
    case("text-short-last-row.txt", b"1 2 3 4\n5 6 7 8\n9 10\n", "line 3", "a matrix whose last row is short")
    case("text-short-last-row-no-end.txt", b"1 2 3 4\n5 6 7 8\n9 10", "cut short", "the same, no line end")
    huge = np.array([[1e-6, 2e-6, 1e308], [-1e308, 5e-6, 6e-6]])
    case("x3p-1e308.x3p", _rough_file(Surface(huge, (1e-6, 1e-6)), "x3p"), "beyond", "float64 heights of ±1e308")
    case("x3p-offset-1e308.x3p", x3p_file(np.array([[1, 2], [3, 4]]), code="I", offset=1e308), "beyond", "Offset 1e308")
    case("gwy-1e308.gwy", _rough_file(Surface(huge, (1e-6, 1e-6)), "gwy"), "beyond", "GWY heights of ±1e308")
    header = ["XRes = 16", "YRes = 16", "XReal = 1.6e-5", "YReal = 1.6e-5", "ZUnits = m"]
    case("gsf-3e38.gsf", gsf(header, np.resize([1e-6, 3e38, -3e38], 256)), "beyond", "float32 heights of ±3e38")
    measured = gsf(header, rng.normal(size=256) * 1e-6)
    start = len(measured) - 256 * 4
    noise = rng.integers(0, 256, 256 * 4, dtype=np.uint8).tobytes()
    case("gsf-random-data.gsf", measured[:start] + noise, "beyond", "random bytes in place of the heights")
    case("gsf-shifted-data.gsf", measured[:start] + b"\0\0\0" + measured[start:-3], "beyond", "heights 3 bytes late")
    big = _bigtiff()
    case("geotiff-bigtiff-cut.tif", big[: len(big) - 40], "GeoTIFF", "a BigTIFF cut short")
    case(
        "geotiff-bigtiff-ifd-far.tif",
        big[:8] + struct.pack("<Q", 1 << 44) + big[16:],
        "directory",
        "a BigTIFF whose first directory lies 16 TiB on (libtiff printed a line of its own)",
    )
    no_crs = _geotiff(None, (2.0, 0, 0, 0, -2.0, 0), width=64, height=64)
    case(
        "geotiff-no-crs-cut.tif",
        no_crs[:-1000],
        "IReadBlock",
        "a GeoTIFF with no CRS cut in its pixels (the warning about the CRS came before the refusal)",
    )


def _bigtiff():
    """A small georeferenced BigTIFF (rasterio), its tags after its pixels."""
    import rasterio
    from rasterio.transform import from_origin

    profile = {"driver": "GTiff", "width": 32, "height": 32, "count": 1, "dtype": "float32", "BIGTIFF": "YES"}
    with rasterio.MemoryFile() as memory:
        with memory.open(**profile, crs="EPSG:32632", transform=from_origin(500000, 5000000, 1, 1)) as dataset:
            dataset.write(np.arange(32 * 32, dtype="float32").reshape(32, 32), 1)
        return memory.read()


def main():
    x3p_cases()
    exr_cases()
    gsf_cases()
    text_cases()
    npy_cases()
    sdf_cases()
    al3d_cases()
    other_cases()
    hardening_cases()
    vendor_cases()
    damage_cases()
    for old in HERE.iterdir():
        if old.suffix not in (".py", ".tsv") and old.is_file():
            old.unlink()
    lines = ["file\tfragment\twhat is wrong"]
    for name, data, fragment, why in CASES:
        (HERE / name).write_bytes(data)
        lines.append(f"{name}\t{fragment}\t{why}")
    (HERE / "MANIFEST.tsv").write_text("\n".join(lines) + "\n")
    print(f"{len(CASES)} hostile files in {HERE}")


if __name__ == "__main__":
    main()
