"""rough's tribology parameters beside surfalize's, on the same surfaces.

Run:  .venv/bin/python bench/compare_surfalize.py --surfalize /path/to/venv/bin/python

``--surfalize`` is a Python that has surfalize installed (GPL-3.0; e.g.
``python -m venv /tmp/sfz && /tmp/sfz/bin/pip install surfalize``); it runs in its
own process. The surfaces: surfalize's own test surface (tests/conftest.py), a
smoothed Gaussian noise map and an egg-box. surfalize's material-ratio curve is
taken both with its default 10 000 classes and at every point (``nbins`` = the
number of points; slow: minutes per surface). Each row prints rough's value,
surfalize's, and their relative difference. The explanations of the differences
are in docs/conventions.rst ("Tribology conventions") and tests/test_material_ratio.py.
"""

import argparse
import json
import pathlib
import subprocess
import tempfile

import numpy as np
from scipy import ndimage

from rough import Surface
from rough.metrology import feature_parameters, functional_parameters

SURFALIZE_SIDE = """
import json, sys
import numpy as np
from surfalize import Surface
from surfalize.abbottfirestone import AbbottFirestoneCurve

heights = np.load(sys.argv[1])
step = float(sys.argv[2])
surface = Surface(heights, step, step)
every = AbbottFirestoneCurve(surface, nbins=heights.size) if sys.argv[3] == "every" else None
values = {
    "Sk": surface.Sk(), "Spk": surface.Spk(), "Svk": surface.Svk(), "Smr1": surface.Smr1(),
    "Smr2": surface.Smr2(), "Sxp": surface.Sxp(), "Vmp": surface.Vmp(), "Vmc": surface.Vmc(),
    "Vvc": surface.Vvc(), "Vvv": surface.Vvv(),
    "Spd": surface.Spd(),
    "Spc": surface.Spc(), "S5p": surface.S5p(), "S5v": surface.S5v(), "S10z": surface.S10z(),
    "area_um2": surface.width_um * surface.height_um,
}
if every is not None:
    values.update({
        "every Sk": every.k(), "every Spk": every.pk(), "every Svk": every.vk(), "every Smr1": every.mr1(),
        "every Smr2": every.mr2(), "every Vmp": every.vmp(), "every Vvv": every.vvv(),
    })
print(json.dumps({k: float(v) for k, v in values.items()}))
"""


def surfaces():
    np.random.seed(0)
    x, y = np.meshgrid(np.arange(1000), np.arange(700))
    z = np.sin(x / 200 * 2 * np.pi)
    z += 0.5 * (np.sin((x - 200 / 2) / 200 * 2 * np.pi) + 1) * 0.3 * np.sin((np.sin(y / 10) + x) / 10 * 2 * np.pi)
    z += np.random.normal(size=z.shape) / 5
    yield "surfalize test surface 700×1000", z, 0.1
    noise = ndimage.gaussian_filter(np.random.default_rng(1).standard_normal((256, 256)), 3.0)
    yield "smoothed noise 256²", noise / noise.std(), 0.5
    u = (np.arange(310) + 0.5) / 31 * 2 * np.pi
    yield "egg-box 10×10 periods", np.cos(u)[None, :] + np.cos(u)[:, None], 1.0


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--surfalize", required=True, help="a Python with surfalize installed")
    parser.add_argument("--every", action="store_true", help="also surfalize's curve at every point (slow)")
    options = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        side = pathlib.Path(folder) / "side.py"
        side.write_text(SURFALIZE_SIDE)
        for name, heights, step in surfaces():
            path = pathlib.Path(folder) / "heights.npy"
            np.save(path, heights)
            command = [options.surfalize, str(side), str(path), str(step), "every" if options.every else "classes"]
            theirs = json.loads(subprocess.run(command, capture_output=True, text=True, check=True).stdout)
            surface = Surface(heights, (step, step))
            ours = {**functional_parameters(surface), **feature_parameters(surface)}
            # surfalize's Spd is per its area (nx-1)·(ny-1)·step², rough's per nx·ny·step²
            theirs["Spd"] *= theirs["area_um2"] / (heights.size * step * step)
            print(f"\n{name}\n{'':8}{'rough':>16}{'surfalize':>16}{'relative':>12}")
            for key, value in theirs.items():
                mine = ours.get(key.removeprefix("every "))
                if mine is None:
                    continue
                relative = (mine - value) / abs(value) if value else float("nan")
                print(f"{key:<12}{mine:16.9g}{value:16.9g}{relative:12.2e}")


if __name__ == "__main__":
    main()
