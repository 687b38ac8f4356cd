"""The X3P pass-through: a stream hashed as it arrives (``receiving.receive``), digests
reused when heights pass unchanged, and the zip writer whose local headers hold every
size, on pipes too. Corrupted data must still be refused on the fast path."""

import hashlib
import io
import shutil
import struct
import subprocess
import sys
import threading
import warnings
import zipfile
import zlib

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rough import Surface
from rough.errors import FormatError, InputError
from rough.io import read_bytes, receiving, x3p, ziparchive

from conftest import assert_one_line_error, rough
from x3p_files import GRID, written, x3p_file


def data_bin(blob):
    with zipfile.ZipFile(io.BytesIO(blob)) as archive:
        return archive.read("bindata/data.bin")


class Trickle(io.RawIOBase):
    """A pipe's worth of bytes, given out in pieces of the sizes asked for (cycled),
    the first at least ``first`` bytes: no file number, no size, as standard input
    from a pipe looks to rough."""

    def __init__(self, blob, pieces=(1, 7, 4096, 65536, 3), first=4):
        self.blob, self.pieces, self.position, self.turn, self.first = blob, pieces, 0, 0, first

    def readable(self):
        return True

    def readinto(self, target):
        size = min(len(target), max(self.pieces[self.turn % len(self.pieces)], self.first if not self.turn else 0))
        self.turn += 1
        part = self.blob[self.position : self.position + size]
        target[: len(part)] = part
        self.position += len(part)
        return len(part)


def received(blob, pieces=(1, 7, 4096, 65536, 3)):
    return receiving.read_capped(io.BufferedReader(Trickle(blob, pieces), buffer_size=16), "<stdin>")


@pytest.fixture(autouse=True)
def small_members_hashed(monkeypatch):
    """The test maps are small: hash their members on the way in as a large map's are."""
    monkeypatch.setattr(receiving, "HASHED_FROM", 1)


@pytest.fixture
def small_steps(monkeypatch):
    """Steps small enough that a test map crosses many: reads, hashing jobs and the
    buffer's growth."""
    monkeypatch.setattr(receiving, "RECEIVE_STEP", 97)
    monkeypatch.setattr(receiving, "HASH_STEP", 64)
    monkeypatch.setattr(receiving, "FIRST_CAPACITY", 16)


def map_with_holes(shape=(40, 30), seed=5):
    heights = np.random.default_rng(seed).normal(size=shape) * 1e-6
    heights[3, 4:9] = np.nan
    return Surface(heights, (1e-6, 2e-6), metadata={"title": "holes"})


# -- receiving ---------------------------------------------------------------------


@pytest.mark.parametrize("pieces", [(1,), (5, 3000), (1 << 20,)])
def test_a_stream_in_pieces_arrives_whole_and_hashed(small_steps, pieces):
    blob = written(map_with_holes())
    view = received(blob, pieces)
    assert isinstance(view, memoryview) and view.readonly and bytes(view) == blob
    payload = data_bin(blob)
    regions = {size: digests for size, digests in view.obj.regions.values()}
    assert regions[len(payload)] == (hashlib.md5(payload).hexdigest(), zlib.crc32(payload))


def test_a_stream_whose_first_read_is_shorter_than_a_zip_signature_is_read_as_before():
    blob = written(map_with_holes())
    data = receiving.read_capped(io.BufferedReader(Trickle(blob, (1, 5000), first=1)), "<stdin>")
    assert data == blob and isinstance(data, bytes)
    assert np.array_equal(read_bytes(data).heights, map_with_holes().heights, equal_nan=True)


def test_only_zip_archives_are_received_into_a_view():
    text = b"x[mm]\tz[um]\n0\t1\n1\t2\n"
    assert receiving.read_capped(io.BufferedReader(Trickle(text)), "<stdin>") == text
    assert receiving.receive(io.BytesIO(b"PK\x03\x04"), "<stdin>", 100) is None  # no peek: read as before


def test_a_regular_file_is_received_at_its_size(tmp_path):
    path = tmp_path / "map.x3p"
    map_with_holes().write(path)
    with open(path, "rb") as stream:
        view = receiving.read_capped(stream, str(path))
    assert bytes(view) == path.read_bytes() and len(view.obj) == len(view)


def test_a_regular_file_is_looked_at_without_filling_its_buffer(tmp_path):
    """Other formats' files are read with one read() as before: a peek would leave
    bytes in the buffer that read() then joins to the rest, a copy of the whole file."""

    class NoPeek(io.BufferedReader):
        def peek(self, size=0):
            raise AssertionError("peeked")

    for name in ("map.gsf", "map.x3p"):
        map_with_holes().write(tmp_path / name)
        with NoPeek(io.FileIO(tmp_path / name)) as stream:
            assert bytes(receiving.read_capped(stream, name)) == (tmp_path / name).read_bytes()


@pytest.mark.parametrize("regular", [False, True])
def test_a_stream_past_the_cap_is_refused(tmp_path, monkeypatch, regular):
    blob = written(map_with_holes())
    monkeypatch.setenv("ROUGH_MAX_INPUT_BYTES", str(len(blob) - 1))
    if regular:
        (tmp_path / "big.x3p").write_bytes(blob)
        stream = open(tmp_path / "big.x3p", "rb")
    else:
        stream = io.BufferedReader(Trickle(blob))
    with stream, pytest.raises(InputError, match="larger than"):
        receiving.read_capped(stream, "<stdin>")
    monkeypatch.setenv("ROUGH_MAX_INPUT_BYTES", str(len(blob)))
    assert bytes(received(blob)) == blob


def test_only_the_first_few_large_members_are_hashed_on_the_way_in(monkeypatch):
    monkeypatch.setattr(receiving, "HASHED_FROM", 1000)
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        for index in range(3000):
            archive.writestr(f"m{index}", bytes(1000 if index % 2 else 10))
    view = received(buffer.getvalue())
    assert sorted(size for size, _ in view.obj.regions.values()) == [1000] * receiving.HASHED_AT_MOST


def test_a_failing_stream_leaves_no_hashing_thread(small_steps):
    class Broken(Trickle):
        def readinto(self, target):
            if self.position > 600:
                raise OSError("the pipe broke")
            return super().readinto(target)

    before = threading.active_count()
    with pytest.raises(OSError, match="the pipe broke"):
        receiving.read_capped(io.BufferedReader(Broken(written(map_with_holes()))), "<stdin>")
    assert threading.active_count() == before


def test_a_hash_failing_in_the_worker_leaves_the_check_to_the_reader(monkeypatch):
    class Failing:
        def update(self, data):
            raise MemoryError

    blob = written(map_with_holes())
    with monkeypatch.context() as patch:
        patch.setattr(receiving.hashlib, "md5", Failing)
        view = received(blob)
    assert bytes(view) == blob and view.obj.regions == {}
    assert np.array_equal(read_bytes(view).heights, map_with_holes().heights, equal_nan=True)
    with pytest.raises(FormatError, match="checksum mismatch"):
        read_bytes(received(corrupted(blob)))


def test_members_with_data_descriptors_are_read_and_hashed_later(small_steps):
    """A zip written to a pipe by zipfile gives its sizes after the data: nothing is
    hashed on the way in, and the reader hashes (and checks) the data itself."""
    blob = written(map_with_holes())
    streamed = io.BytesIO()
    with zipfile.ZipFile(io.BytesIO(blob)) as source, zipfile.ZipFile(_Unseekable(streamed), "w") as target:
        for info in source.infolist():
            target.writestr(info.filename, source.read(info))
    piped = streamed.getvalue()
    assert struct.unpack_from("<H", piped, 6)[0] & 0x8
    view = received(piped)
    assert view.obj.regions == {}
    np.testing.assert_array_equal(read_bytes(view).heights, map_with_holes().heights)


class _Unseekable(io.RawIOBase):
    def __init__(self, target):
        self.target = target

    def writable(self):
        return True

    def write(self, data):
        return self.target.write(data)


# -- checksums on the fast path ------------------------------------------------------


def corrupted(blob, at=5):
    payload = data_bin(blob)
    damaged = bytearray(blob)
    damaged[blob.find(payload) + at] ^= 0x01
    return bytes(damaged)


@pytest.mark.parametrize("pieces", [(1,), (4096,)])
def test_corrupted_data_are_refused_on_the_fast_path(small_steps, pieces):
    view = received(corrupted(written(Surface(GRID, (1e-6, 1e-6)))), pieces)
    assert view.obj.regions  # hashed on the way in
    with pytest.raises(FormatError, match="bindata/data.bin checksum mismatch"):
        read_bytes(view)


def test_a_wrong_stated_checksum_is_refused_on_the_fast_path():
    view = received(x3p_file(GRID, data_checksum="bad", compression=zipfile.ZIP_STORED))
    assert view.obj.regions
    with pytest.raises(FormatError, match="bindata/data.bin checksum mismatch"):
        read_bytes(view)


def test_digests_of_other_bytes_are_not_taken():
    """Two members named data.bin: the first, intact, is hashed on the way in, but the
    central directory names the second, damaged one, which must be hashed and refused."""
    blob = written(Surface(GRID, (1e-6, 1e-6)))
    good = data_bin(blob)
    bad = bytearray(good)
    bad[3] ^= 0x10
    buffer = io.BytesIO()
    with zipfile.ZipFile(io.BytesIO(blob)) as source, zipfile.ZipFile(buffer, "w") as target, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # duplicate name
        for info in source.infolist():
            target.writestr(info.filename, source.read(info))
            if info.filename == "bindata/data.bin":
                target.writestr(info.filename, bytes(bad))
    view = received(buffer.getvalue())
    assert [size for size, _ in view.obj.regions.values()].count(len(good)) == 2  # both hashed on the way in
    with pytest.raises(FormatError, match="bindata/data.bin checksum mismatch"):
        read_bytes(view)


def test_a_local_header_that_disagrees_on_the_size_does_not_lend_its_digest():
    blob = bytearray(written(Surface(GRID, (1e-6, 1e-6))))
    with zipfile.ZipFile(io.BytesIO(bytes(blob))) as archive:
        offset = archive.getinfo("bindata/data.bin").header_offset
    struct.pack_into("<2L", blob, offset + 18, GRID.nbytes + 8, GRID.nbytes + 8)  # local sizes 8 bytes long
    view = received(bytes(blob))
    assert GRID.nbytes + 8 in {size for size, _ in view.obj.regions.values()}
    np.testing.assert_array_equal(read_bytes(view).heights, GRID)  # hashed again over the right bytes


def test_ignoring_checksums_reads_a_wrong_md5_but_not_damaged_bytes(caplog):
    """--ignore-checksums downgrades an MD5 mismatch to a warning; the zip CRC-32 then
    stands in for it, so damaged bytes are still refused."""
    blob = x3p_file(GRID, data_checksum="bad", compression=zipfile.ZIP_STORED)
    surface = read_bytes(received(blob), x3p_options(verify=False))
    np.testing.assert_array_equal(surface.heights, GRID)
    assert "checksum mismatch" in caplog.text
    with pytest.raises(FormatError, match="fails its zip CRC check"):
        read_bytes(received(corrupted(written(Surface(GRID, (1e-6, 1e-6))))), x3p_options(verify=False))


def x3p_options(**changes):
    from rough.io import ReadOptions

    return ReadOptions(**changes)


# -- digests reused, each byte hashed once per stage ---------------------------------


def test_heights_read_and_written_unchanged_are_not_hashed_again(monkeypatch):
    for surface in (Surface(GRID, (1e-6, 1e-6)), map_with_holes()):
        blob = written(surface)
        view = received(blob)
        hashed = []
        original = receiving.hashes
        with monkeypatch.context() as patch:
            patch.setattr(receiving, "hashes", lambda content: hashed.append(len(content)) or original(content))
            again = read_bytes(view)
            assert not again.heights.flags.writeable
            out = written(again.derive("convert", {}))
        assert hashed == []
        assert data_bin(out) == data_bin(blob)
        assert zipfile.ZipFile(io.BytesIO(out)).testzip() is None  # every CRC-32 right
        read_bytes(out)  # every MD5 right


@pytest.mark.parametrize("layer", [0, 1])
def test_one_layer_of_several_is_hashed_when_written(layer):
    """A layer views part of data.bin: the verified digest is that of every layer."""
    layers = np.concatenate([GRID, GRID * 3])
    blob = x3p_file(layers, size=(4, 3, 2), compression=zipfile.ZIP_STORED)
    surface = read_bytes(received(blob), x3p_options(layer=layer))
    assert not surface.heights.flags.writeable  # a view of the bytes read
    out = written(surface.derive("convert", {}))
    np.testing.assert_array_equal(read_bytes(out).heights, GRID * (1 + 2 * layer))


def test_changed_heights_are_hashed_when_written():
    surface = read_bytes(received(written(Surface(GRID, (1e-6, 1e-6)))))
    changed = surface.derive("scale", {}, heights=surface.heights * 2)
    out = written(changed)
    np.testing.assert_array_equal(read_bytes(out).heights, GRID * 2)
    assert zipfile.ZipFile(io.BytesIO(out)).testzip() is None


def test_invalid_points_that_hold_numbers_become_nan_and_are_hashed_again():
    valid = np.ones(GRID.shape, bool)
    valid[1, 2] = False
    surface = read_bytes(received(x3p_file(GRID, valid=valid, compression=zipfile.ZIP_STORED)))
    assert np.isnan(surface.heights[1, 2]) and surface.heights.flags.writeable
    out = written(surface)
    assert np.array_equal(read_bytes(out).heights, surface.heights, equal_nan=True)
    assert zipfile.ZipFile(io.BytesIO(out)).testzip() is None


def test_a_wrong_crc_with_a_right_md5_is_not_passed_on():
    """The MD5 is what X3P checks; the CRC-32 the next file carries is computed from
    the bytes, never copied."""
    blob = bytearray(written(Surface(GRID, (1e-6, 1e-6))))
    with zipfile.ZipFile(io.BytesIO(bytes(blob))) as archive:
        info = archive.getinfo("bindata/data.bin")
    struct.pack_into("<L", blob, info.header_offset + 14, info.CRC ^ 1)
    for at in _central_entries(bytes(blob)):
        if bytes(blob[at + 46 : at + 46 + 16]) == b"bindata/data.bin":
            struct.pack_into("<L", blob, at + 16, info.CRC ^ 1)
    assert zipfile.ZipFile(io.BytesIO(bytes(blob))).testzip() == "bindata/data.bin"
    surface = read_bytes(received(bytes(blob)))
    out = written(surface.derive("convert", {}))
    assert zipfile.ZipFile(io.BytesIO(out)).getinfo("bindata/data.bin").CRC == info.CRC
    assert zipfile.ZipFile(io.BytesIO(out)).testzip() is None


def _central_entries(blob):
    at = blob.find(b"PK\x01\x02")
    while at >= 0:
        yield at
        at = blob.find(b"PK\x01\x02", at + 4)


@pytest.mark.parametrize("size", [10, 1 << 21])
def test_hashes_in_one_pass_match_hashlib_and_zlib(monkeypatch, size):
    monkeypatch.setattr(receiving, "HASH_STEP", 1024)
    content = np.random.default_rng(size).bytes(size)
    assert receiving.hashes(memoryview(content)) == (hashlib.md5(content).hexdigest(), zlib.crc32(content))


# -- the writer ------------------------------------------------------------------------


def test_local_headers_hold_sizes_even_on_a_pipe():
    target = io.BytesIO()
    x3p.write(map_with_holes(), _Unseekable(target))
    blob = target.getvalue()
    with zipfile.ZipFile(io.BytesIO(blob)) as archive:
        assert archive.testzip() is None
        for info in archive.infolist():
            _, flags, _, _, _, crc, packed, size = struct.unpack_from("<5H3L", blob, info.header_offset + 4)
            assert not flags & 0x8 and (crc, packed, size) == (info.CRC, info.file_size, info.file_size)
    assert set(x3p_regions(blob)) >= {len(data_bin(blob))}


def x3p_regions(blob):
    return {size for size, _ in received(blob).obj.regions.values()}


def test_zip64_fields_where_sizes_need_them(monkeypatch, tmp_path):
    monkeypatch.setattr(ziparchive, "ZIP64_LIMIT", 100)  # every member past the first and every offset
    surface = map_with_holes()
    blob = written(surface)
    with zipfile.ZipFile(io.BytesIO(blob)) as archive:
        assert archive.testzip() is None
        assert archive.getinfo("bindata/data.bin").file_size == surface.heights.nbytes
    assert np.array_equal(read_bytes(blob).heights, surface.heights, equal_nan=True)
    assert b"PK\x06\x06" in blob and b"PK\x06\x07" in blob
    if shutil.which("unzip"):
        (tmp_path / "zip64.x3p").write_bytes(blob)
        result = subprocess.run(["unzip", "-t", tmp_path / "zip64.x3p"], capture_output=True)
        assert result.returncode == 0, result.stdout.decode()


def test_written_file_passes_unzip(tmp_path):
    if not shutil.which("unzip"):
        pytest.skip("no unzip")
    map_with_holes().write(tmp_path / "map.x3p")
    result = subprocess.run(["unzip", "-t", tmp_path / "map.x3p"], capture_output=True)
    assert result.returncode == 0 and b"No errors" in result.stdout, result.stdout.decode()


def test_a_failed_write_leaves_no_file(tmp_path, monkeypatch):
    def fail(self, name, content, crc=None, align=None):
        if name == "bindata/data.bin":
            raise OSError(28, "No space left on device")
        return original(self, name, content, crc, align)

    original = ziparchive.ZipWriter.add
    monkeypatch.setattr(ziparchive.ZipWriter, "add", fail)
    with pytest.raises(OSError, match="No space left"):
        map_with_holes().write(tmp_path / "map.x3p")
    assert list(tmp_path.iterdir()) == []


# -- round trips -----------------------------------------------------------------------


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    shape=st.one_of(
        st.tuples(st.integers(2, 40)),
        st.tuples(st.integers(2, 12), st.integers(2, 12)),
    ),
    values=st.lists(st.one_of(st.floats(-1e5, 1e5), st.just(float("nan"))), min_size=1, max_size=64),
    pieces=st.lists(st.integers(1, 300), min_size=1, max_size=5),
)
def test_round_trip_through_a_trickling_stream_is_exact(small_steps, shape, values, pieces):
    count = int(np.prod(shape))
    heights = np.resize(np.array(values, dtype=np.float64), count)
    heights[0] = 0.0 if np.isnan(heights[0]) else heights[0]  # at least one valid point
    surface = Surface(heights.reshape(shape), tuple(1e-6 for _ in shape))
    blob = written(surface)
    view = received(blob, tuple(pieces))
    assert bytes(view) == blob
    again = read_bytes(view)
    assert again.heights.tobytes() == surface.heights.tobytes()  # bit for bit, NaN and -0.0 included
    out = written(again.derive("convert", {}))
    assert data_bin(out) == data_bin(blob)
    assert zipfile.ZipFile(io.BytesIO(out)).testzip() is None
    assert read_bytes(out).heights.tobytes() == surface.heights.tobytes()


def test_pipeline_of_stages_is_exact_and_refuses_damage(tmp_path):
    surface = map_with_holes((300, 200))
    heights = surface.heights.copy()
    heights[7, 7], heights[8, 8], heights[9, 9] = -0.0, 5e-324, 1e5  # 1e5 m: the largest height rough reads
    surface = Surface(heights, surface.spacing, metadata=surface.metadata)
    surface.write(tmp_path / "in.x3p")
    command = [sys.executable, "-m", "rough", "convert"]
    with open(tmp_path / "in.x3p", "rb") as source:
        first = subprocess.Popen(command, stdin=source, stdout=subprocess.PIPE)
        second = subprocess.Popen(command, stdin=first.stdout, stdout=subprocess.PIPE)
        first.stdout.close()
        out, _ = second.communicate(timeout=120)
    assert first.wait(timeout=60) == 0 and second.returncode == 0
    assert data_bin(out) == data_bin((tmp_path / "in.x3p").read_bytes())
    assert zipfile.ZipFile(io.BytesIO(out)).testzip() is None
    again = read_bytes(out)
    assert again.heights.tobytes() == heights.tobytes()
    assert [entry["command"] for entry in again.history] == ["convert", "convert"]

    result = rough("convert", input=corrupted((tmp_path / "in.x3p").read_bytes(), at=100))
    assert_one_line_error(result, "<stdin>: ", "bindata/data.bin checksum mismatch")
    assert result.stdout == b""


def test_the_shared_checks_take_one_pass_and_still_catch_everything(caplog):
    """rough.io's checks after every reader: a sum of squares says whether any height is
    NaN, infinite or beyond ±100 km; only then are the heights looked at in full."""
    edge = np.full((3, 4), 1e5)  # at the limit: their squares pass the quick bound, the full look reads them
    np.testing.assert_array_equal(read_bytes(received(written(Surface(edge, (1e-6, 1e-6))))).heights, edge)
    assert "infinite" not in caplog.text
    with pytest.raises(FormatError, match="a height of 1.5e\\+308 m .* is beyond ±100 km"):
        read_bytes(received(written(Surface(np.full((3, 4), 1.5e308), (1e-6, 1e-6)))))
    spiky = GRID.copy()
    spiky[1, 1] = np.inf
    again = read_bytes(received(written(Surface(spiky, (1e-6, 1e-6)))))
    assert np.isnan(again.heights[1, 1]) and np.isfinite(np.delete(again.heights.ravel(), 5)).all()
    assert "1 infinite heights marked invalid" in caplog.text
    with pytest.raises(FormatError, match="holds no valid points"):
        read_bytes(received(written(Surface(np.full((2, 3), np.nan), (1e-6, 1e-6)))))
