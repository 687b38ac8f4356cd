"""A toy plugin package made on disk, as pip would install it: modules and a
``*.dist-info`` whose ``entry_points.txt`` declares rough's entry points."""

import os

from conftest import ROOT


def install_plugin(folder, modules, entry_points, package="toy_rough"):
    """Write ``package`` with ``modules`` (``{file name: source}``) and its dist-info
    declaring ``entry_points`` (``entry_points.txt`` text) in ``folder``; returns the
    environment that puts it, and this checkout, on PYTHONPATH."""
    (folder / package).mkdir()
    (folder / package / "__init__.py").write_text("")
    for name, source in modules.items():
        (folder / package / name).write_text(source)
    info = folder / f"{package}-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {package}\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(entry_points)
    return {"PYTHONPATH": os.pathsep.join([str(folder), str(ROOT), os.environ.get("PYTHONPATH", "")])}
