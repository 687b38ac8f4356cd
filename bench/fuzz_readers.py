"""Coverage-guided fuzzing of every reader with atheris (libFuzzer for Python):
``rough.io.read_bytes`` must turn any input into a surface or an InputError, never
another exception, a crash or a hang. Seeds: the valid files of tests/seed_files.py, the
measured-float and ±1e308 files of tests/damaged_files.py, and the hostile corpus. Not
part of the test suite (tests/test_fuzz.py is its quick hypothesis-driven cousin).

    make fuzz     # or: pip install -e '.[fuzz]'; python bench/fuzz_readers.py -runs=1000000 -max_len=8192 -timeout=10

libFuzzer reports an uncaught exception with its input saved as ``crash-*``; replay one
with ``python bench/fuzz_readers.py crash-…``.
"""

import os
import pathlib
import shutil
import sys
import tempfile

import atheris

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))

with atheris.instrument_imports(include=["rough"]):
    from rough.errors import InputError
    from rough.io import ReadOptions, provenance, read_bytes, registry  # noqa: F401
    from rough.surface import Surface  # noqa: F401

    registry.formats()  # imports, and so instruments, every reader

OPTIONS = ReadOptions(spacing=(1e-6, 1e-6))
# formats without a magic number are reached through a file name with their extension
NAMES = [None] + [f"input{facts.extensions[0]}" for facts in registry.formats().values() if facts.by_extension]


def one_input(data):
    for name in NAMES:
        try:
            read_bytes(data, OPTIONS, name=name)
        except InputError:
            pass


def seed_folder():
    from damaged_files import measured_seeds, written_huge
    from seed_files import seeds

    folder = pathlib.Path(tempfile.mkdtemp(prefix="rough-fuzz-"))
    every = {**seeds(), **measured_seeds(), **written_huge()}
    for name, blob in every.items():  # the seeds' own names are lost: NAMES covers extension-only formats
        (folder / name).write_bytes(blob)
    for path in (HERE.parent / "tests" / "hostile").iterdir():
        if path.suffix not in (".py", ".tsv") and path.stat().st_size <= 1 << 16:
            shutil.copy(path, folder / f"hostile-{path.name}")
    return folder


def main():
    folder = seed_folder()
    arguments = [sys.argv[0], *sys.argv[1:], str(folder)]
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    atheris.Setup(arguments, one_input)
    atheris.Fuzz()


if __name__ == "__main__":
    main()
