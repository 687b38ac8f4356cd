"""Speed work must not change results: every parameter of every readable real file
in ../shared/data (and of seeded synthetic surfaces), saved by one version of rough
and checked by another to 1e-12 relative.

Run:  python bench/same_results.py --save before.json [DATA_FOLDER]
      python bench/same_results.py --check before.json [DATA_FOLDER]

Saved per file: ``parameters``, ``functional_parameters``, for maps
``feature_parameters``, for gap-free data ``fit_fractal`` and (maps) the rose; per
seeded synthesis, the heights' sum and sum of squares. A value differs when
``|a - b| > 1e-12 · max(|a|, |b|)`` (NaN equals NaN; an error message must match).
Exits 1 when anything differs.
"""

import argparse
import json
import logging
import math
import pathlib
import sys

import numpy as np

import rough
from rough.errors import InputError
from rough.fractal import synthesize_map, synthesize_profile
from rough.fractal.fit import fit_fractal
from rough.fractal.sectors import rose
from rough.metrology import feature_parameters, functional_parameters, parameters

SKIPPED = (".md", ".json", ".txt", ".py")
TOLERANCE = 1e-12


def evaluate(surface):
    values = {"parameters": _outcome(parameters, surface), "functional": _outcome(functional_parameters, surface)}
    if not np.isnan(surface.heights).any():
        values["fit"] = _outcome(lambda s: fit_fractal(s).as_dict(), surface)
    if not surface.is_profile:
        values["feature"] = _outcome(feature_parameters, surface)
        if not np.isnan(surface.heights).any():
            values["rose"] = _outcome(lambda s: rose(s, step=30).as_dict(), surface)
    return values


def _outcome(function, surface):
    try:
        return function(surface)
    except InputError as error:
        return {"error": str(error)}


def synthetic():
    yield "synth profile", synthesize_profile(4096, 1e-5, 1.3, rq=1e-5, seed=3)
    yield "synth map", synthesize_map((256, 384), (1e-5, 2e-5), 2.3, rq=1e-5, seed=3)


def collect(root):
    results = {}
    for name, surface in synthetic():
        results[name] = {"sums": [float(np.sum(surface.heights)), float(np.sum(surface.heights**2))]}
        results[name] |= evaluate(surface)
    for path in sorted(p for p in root.rglob("*") if p.is_file() and p.suffix.lower() not in SKIPPED):
        try:
            surface = rough.read(path)
        except Exception:
            continue
        results[str(path.relative_to(root))] = evaluate(surface)
        print(".", end="", flush=True, file=sys.stderr)
    print(file=sys.stderr)
    return results


def differences(before, after, where=""):
    if isinstance(before, dict) and isinstance(after, dict):
        for key in sorted(set(before) | set(after)):
            if key not in before or key not in after:
                yield f"{where}/{key}: only in {'after' if key in after else 'before'}"
            else:
                yield from differences(before[key], after[key], f"{where}/{key}")
    elif isinstance(before, list) and isinstance(after, list) and len(before) == len(after):
        for index, (a, b) in enumerate(zip(before, after)):
            yield from differences(a, b, f"{where}[{index}]")
    elif isinstance(before, float) or isinstance(after, float):
        a, b = float(before), float(after)
        if not (math.isnan(a) and math.isnan(b)) and not abs(a - b) <= TOLERANCE * max(abs(a), abs(b)):
            yield f"{where}: {a!r} → {b!r}"
    elif before != after:
        yield f"{where}: {before!r} → {after!r}"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    action = parser.add_mutually_exclusive_group(required=True)
    action.add_argument("--save", metavar="FILE")
    action.add_argument("--check", metavar="FILE")
    parser.add_argument("data", nargs="?", default=pathlib.Path(__file__).parents[2] / "shared" / "data")
    options = parser.parse_args()
    logging.getLogger("rough").setLevel(logging.CRITICAL)
    results = json.loads(json.dumps(collect(pathlib.Path(options.data))))  # as the file will hold them
    if options.save:
        pathlib.Path(options.save).write_text(json.dumps(results, indent=1))
        print(f"rough {rough.__version__}: {len(results)} surfaces saved to {options.save}")
        return 0
    found = list(differences(json.loads(pathlib.Path(options.check).read_text()), results))
    print("\n".join(found))
    print(
        f"rough {rough.__version__}: {len(results)} surfaces, {len(found)} values differ beyond {TOLERANCE:g} relative"
    )
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
