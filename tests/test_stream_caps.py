"""The text cap applies while standard input arrives (issue 31: ``yes '1 2' | rough info``
read 3 GiB before the 256 MiB text cap refused it)."""

import os
import subprocess
import sys

import pytest


def _fed(command, chunk, total, env, tmp_path):
    """Run ``command`` with ``total`` bytes of ``chunk`` written to its standard input;
    ``(exit status, its standard error, bytes it took before closing the pipe)``."""
    with open(tmp_path / "stderr", "w+b") as stderr:
        process = subprocess.Popen(
            command, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=stderr, env={**os.environ, **env}
        )
        written = 0
        try:
            while written < total:
                process.stdin.write(chunk)
                written += len(chunk)
            process.stdin.close()
        except BrokenPipeError:
            pass
        status = process.wait(timeout=300)
        stderr.seek(0)
        return status, stderr.read().decode(), written


def test_text_on_standard_input_is_refused_at_the_cap_not_after_reading_it_all(tmp_path):
    status, stderr, taken = _fed(
        [sys.executable, "-m", "rough", "info"],
        b"1 2\n" * (1 << 14),
        64 << 20,
        {"ROUGH_MAX_TEXT_BYTES": "1M"},
        tmp_path,
    )
    assert status == 2 and len(stderr.strip().splitlines()) == 1, stderr
    assert "<stdin>: more than 1 MiB of text, more than rough parses" in stderr
    assert taken < 8 << 20, f"read {taken >> 20} MiB of a 64 MiB stream"  # the cap, the pipe's buffer and a chunk


@pytest.mark.parametrize("size", [300, 5000])
def test_short_text_below_the_head_is_capped_too(size):
    text = b"x z\n" + b"".join(b"%d %d\n" % (i, i % 7) for i in range(size))
    result = subprocess.run(
        [sys.executable, "-m", "rough", "info"],
        input=text,
        capture_output=True,
        env={**os.environ, "ROUGH_MAX_TEXT_BYTES": "1K"},
        check=False,
    )
    assert result.returncode == 2
    assert "of text is more than rough parses (1 KiB)" in result.stderr.decode()


def test_binary_input_is_not_held_to_the_text_cap(tmp_path):
    import numpy as np

    np.save(tmp_path / "m.npy", np.random.default_rng(1).normal(size=(300, 300)) * 1e-6)
    data = (tmp_path / "m.npy").read_bytes()
    result = subprocess.run(
        [sys.executable, "-m", "rough", "info", "--spacing", "1um"],
        input=data,
        capture_output=True,
        env={**os.environ, "ROUGH_MAX_TEXT_BYTES": "64K"},
        check=False,
    )
    assert result.returncode == 0, result.stderr.decode()


def test_gzip_text_is_capped_as_it_unpacks(tmp_path):
    import gzip

    path = tmp_path / "long.txt.gz"
    path.write_bytes(gzip.compress(b"x z\n" + b"".join(b"%d 1e-6\n" % i for i in range(400000))))
    result = subprocess.run(
        [sys.executable, "-m", "rough", "info", str(path)],
        capture_output=True,
        env={**os.environ, "ROUGH_MAX_TEXT_BYTES": "1M"},
        check=False,
    )
    assert result.returncode == 2
    assert f"{path}: more than 1 MiB of text, more than rough parses" in result.stderr.decode()
