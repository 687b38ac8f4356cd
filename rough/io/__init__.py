"""Reading and writing surfaces.

The input format is sniffed from the content (files and standard input alike); the
output format follows ``format=`` or the file extension, and a stream gets X3P.

>>> import pathlib, tempfile
>>> from rough import sample
>>> from rough.io import read, write
>>> scan = read(sample("rock-map.x3p"))
>>> scan.source_format, scan.heights.shape
('x3p', (96, 128))
>>> with tempfile.TemporaryDirectory() as folder:
...     write(scan, pathlib.Path(folder) / "scan.gsf")  # the format from the extension
...     again = read(pathlib.Path(folder) / "scan.gsf")
>>> again.source_format, again.heights.shape
('gsf', (96, 128))

Formats: one module each, declared in :mod:`rough.io.registry` (``rough formats``
lists them; packages add more through the ``rough.formats`` entry points). Gzip-compressed
input is unpacked first. The names in ``__init__.pyi`` load their modules on first use.
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
