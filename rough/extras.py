"""Optional dependencies: the packages a few commands need beyond the metrology core,
and the one-line message that says how to install them.

>>> from rough.extras import require
>>> require("json").__name__              # present: the module itself
'json'
"""

import importlib

from .errors import RoughError

DISTRIBUTION = "rough-metrology"
# module -> (what needs it, the package on PyPI, the extra that installs it)
EXTRAS = {
    "matplotlib": ("figures (--plot, show, report)", "matplotlib", "plot"),
    "hidraw": ("the HID joystick", "hidapi", "haptics"),
    "hidtools": ("the HID joystick", "hid-tools", "haptics"),
    "evdev": ("an evdev force-feedback device", "evdev", "haptics"),
    "statsmodels": ("the experiment's analysis", "statsmodels", "experiment"),
    "OpenEXR": ("reading and writing OpenEXR", "OpenEXR", "formats"),
    "h5py": ("reading HDF5", "h5py", "formats"),
    "igor2": ("reading Igor IBW", "igor2", "formats"),
    "openpyxl": ("reading Mitutoyo Excel files", "openpyxl", "formats"),
    "olefile": ("reading MountainsMap MNT", "olefile", "formats"),
    "zstandard": ("reading Keyence ZON", "zstandard", "formats"),
    "gwyfile": ("writing Gwyddion GWY", "gwyfile", "formats"),
    "rasterio": ("reading and writing GeoTIFF", "rasterio", "formats"),
    "tifffile": ("reading TIFF", "tifffile", "formats"),
    "distributed": ("--scheduler (a Dask cluster)", "distributed", "cluster"),
    "jinja2": ("rough report", "Jinja2", "report"),
    "weasyprint": ("a PDF report", "weasyprint", "report"),
}


class MissingExtra(RoughError):
    """An optional package is not installed; exit status 1."""


def require(module):
    """Import ``module``, or raise :class:`MissingExtra` naming the extra to install."""
    try:
        return importlib.import_module(module)
    except ImportError:
        top = module.split(".")[0]
        purpose, package, extra = EXTRAS.get(top, (top, top, "all"))
        raise MissingExtra(
            f"{purpose} needs {package}, which is not installed: pip install '{DISTRIBUTION}[{extra}]' "
            f"(pipx: pipx inject {DISTRIBUTION} {package})"
        ) from None
