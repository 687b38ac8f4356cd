"""The tribology parameters on every readable file in ../shared/data: a robustness
sweep over real instrument files (no failures allowed), with each file's time.

Run:  .venv/bin/python bench/sweep_tribology.py [DATA_FOLDER]

Prints one line per file: kind, points, seconds, Rk or Sk, for maps Spd and S10z,
and the parameters that came out undefined (NaN). Files rough cannot read are
skipped silently (the readers' own tests cover them).
"""

import logging
import math
import pathlib
import sys
import time

import rough
from rough.metrology import feature_parameters, functional_parameters

SKIPPED = (".md", ".json", ".txt", ".py")


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).parents[2] / "shared" / "data")
    logging.getLogger("rough").setLevel(logging.ERROR)
    counts = {"ok": 0, "failed": 0}
    for path in sorted(p for p in root.rglob("*") if p.is_file() and p.suffix.lower() not in SKIPPED):
        try:
            surface = rough.read(path)
        except Exception:
            continue
        started = time.perf_counter()
        try:
            values = functional_parameters(surface)
            features = {} if surface.is_profile else feature_parameters(surface)
        except Exception as error:
            print(f"{path.relative_to(root)} FAILED {type(error).__name__}: {error}")
            counts["failed"] += 1
            continue
        took = time.perf_counter() - started
        undefined = [key for key, value in {**values, **features}.items() if math.isnan(value)]
        core = f"Rk={values['Rk']:.4g} m" if surface.is_profile else f"Sk={values['Sk']:.4g} m"
        extra = "" if surface.is_profile else f" Spd={features['Spd']:.3g}/m² S10z={features['S10z']:.3g} m"
        name = str(path.relative_to(root))[:60]
        size = f"{surface.kind:7} {surface.heights.size:9} pts {took:6.2f} s"
        print(f"{name:60} {size} {core}{extra} NaN: {','.join(undefined)}")
        counts["ok"] += 1
    print(f"{counts['ok']} files evaluated, {counts['failed']} failed")
    return 1 if counts["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
