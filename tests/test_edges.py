"""Numerical edge cases through every analysing command: constant surfaces, a single
spectral line, nanometre and kilometre scales, float32 data. Each command either
succeeds with every result defined or announced as undefined on stderr (a JSON null
or NaN with no warning naming it is a leak), or refuses in one line with status 2."""

import json
import math

import numpy as np
import pytest

from rough import Surface
from rough.fractal import synth, synth_map
from rough.io import read

from conftest import assert_one_line_error, rough
from x3p_files import x3p_file

PARAMETERS = {"cutoff"}  # keys whose null means "not asked for", not an undefined result


def fractal_profile(points, spacing, rq):
    return synth.synthesize_profile(points, spacing, 1.4, rq=rq, seed=5).heights


def fractal_map(size, spacing, rq):
    return synth_map.synthesize_map((size, size), (spacing, spacing), 2.4, rq=rq, seed=5).heights


def sine(points, cycles, amplitude, offset=0.0):
    return offset + amplitude * np.sin(2 * np.pi * cycles * np.arange(points) / points)


SURFACES = {
    "constant-profile": lambda: Surface(np.full(2048, 3e-3), (1e-6,)),
    "constant-map": lambda: Surface(np.full((96, 128), -7e-4), (1e-6, 1e-6)),
    "plane-map": lambda: Surface(1e-3 + 2e-3 * np.add.outer(np.arange(96), np.arange(128)) * 1e-2, (1e-6, 1e-6)),
    "sine-profile": lambda: Surface(sine(2048, 32, 1e-6, offset=5e-3), (1e-6,)),
    "sine-map": lambda: Surface(np.tile(sine(128, 8, 1e-6), (96, 1)), (1e-6, 1e-6)),
    "nanometre-profile": lambda: Surface(fractal_profile(4096, 1e-9, 1e-10), (1e-9,)),
    "nanometre-map": lambda: Surface(fractal_map(128, 1e-9, 1e-10), (1e-9, 1e-9)),
    "kilometre-profile": lambda: Surface(fractal_profile(4096, 10.0, 50.0) + 3e3, (10.0,)),
    "kilometre-map": lambda: Surface(fractal_map(128, 100.0, 50.0), (100.0, 100.0)),
}
COMMANDS = {
    "info": ["info", "--json"],
    "features": ["features", "--json"],
    "fit-fractal": ["fit-fractal", "--json"],
    "rose": ["rose", "--json"],
    "render": ["render", "--json", "--duration", "50ms"],
}
MAP_ONLY, PROFILE_ONLY = {"rose"}, set()
# null by design: no noise floor found, no roll-off asked for, no hint needed
NOT_APPLICABLE = {"noise_rms", "noise_crossover", "rolloff_wavelength", "hint"}
# a bound is a result: its standard errors are null (the warning says "bound")
BOUND_ERRORS = {"fractal_dimension_stderr", "amplitude_coefficient_stderr", "dimension_error", "amplitude_error"}


def undefined_keys(value, key=None):
    """Every key (at any depth) whose value is null or NaN."""
    if isinstance(value, dict):
        return set().union(*(undefined_keys(v, k) for k, v in value.items()))
    if isinstance(value, list):
        return set().union(*(undefined_keys(v, key) for v in value))
    return {key} if value is None or (isinstance(value, float) and math.isnan(value)) else set()


def assert_defined_or_announced(result):
    """Status 0 with no silent NaN, or a one-line refusal."""
    if result.returncode == 2:
        assert_one_line_error(result)
        return
    stderr = result.stderr.decode()
    assert result.returncode == 0, stderr
    assert "Traceback" not in stderr and "RuntimeWarning" not in stderr, stderr
    document = json.loads(result.stdout)
    allowed = PARAMETERS | NOT_APPLICABLE
    if "bound" in stderr:
        allowed |= BOUND_ERRORS
    if "no power-law range" in stderr:
        allowed |= set(document)
    silent = {key for key in undefined_keys(document) - allowed if key not in stderr}
    assert not silent, f"undefined without a warning: {sorted(silent)}; stderr: {stderr}"


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("edges")
    paths = {}
    for name, make in SURFACES.items():
        paths[name] = folder / f"{name}.x3p"
        make().write(paths[name])
    values = fractal_map(128, 1e-6, 1e-6).astype(np.float32)
    paths["float32-x3p-map"] = folder / "float32-map.x3p"
    paths["float32-x3p-map"].write_bytes(x3p_file(values, code="F", spacing=(1e-6, 1e-6)))
    paths["float32-npy-profile"] = folder / "float32-profile.npy"
    np.save(paths["float32-npy-profile"], fractal_profile(2048, 1e-6, 1e-6).astype(np.float32))
    return paths


def cases():
    names = [*SURFACES, "float32-x3p-map", "float32-npy-profile"]
    for name in names:
        for command in COMMANDS:
            is_map = "map" in name
            if (command in MAP_ONLY and not is_map) or (command in PROFILE_ONLY and is_map):
                continue
            yield name, command


@pytest.mark.parametrize("name, command", list(cases()))
def test_results_are_defined_or_announced(files, name, command):
    extra = ["--spacing", "1um"] if name.endswith("npy-profile") else []
    assert_defined_or_announced(rough(*COMMANDS[command], *extra, files[name]))


@pytest.mark.parametrize("name", ["constant-profile", "constant-map", "plane-map"])
def test_flat_surfaces_are_refused_by_the_fits_and_say_why(files, name):
    for command in ("fit-fractal", "rose") if "map" in name else ("fit-fractal",):
        assert_one_line_error(rough(command, files[name]), "flat once its form is removed")


def test_a_constant_surface_has_zero_height_parameters_and_undefined_shape_ones(files):
    result = rough("features", "--json", files["constant-map"], check=True)
    values = json.loads(result.stdout)
    assert [values[k] for k in ("Sa", "Sq", "Sp", "Sv", "Sz", "Sdq", "Sdr")] == [0.0] * 7
    assert all(values[k] is None for k in ("Ssk", "Sku", "Sal", "Str", "Std"))
    warnings = result.stderr.decode().splitlines()  # the ISO 4287/25178 values, then the features'
    assert len(warnings) == 2 and "no height variation" in warnings[0] and "no significant hill" in warnings[1]


@pytest.mark.parametrize("name", [*SURFACES, "float32-x3p-map"])
def test_derived_surfaces_stay_finite(files, tmp_path, name):
    """detrend, resample and the tip keep every point of a gap-free surface defined."""
    spacing = read(files[name]).spacing[0]
    for command in (["detrend"], ["resample", "--step", f"{2 * spacing}m"], ["detrend", "--tip", f"{3 * spacing}m"]):
        target = tmp_path / "out.x3p"
        result = rough(*command, files[name], "-o", target)
        assert result.returncode == 0, result.stderr.decode()
        assert np.isfinite(read(target).heights).all(), command


def test_sine_fits_say_the_data_are_not_fractal(files):
    """A sine is no fractal: the fit says so (no power-law range, a bound), or at least
    gives no confident D (the profile's leakage below the line passes as a power law
    over 1.4 decades, with a standard error of 0.12)."""
    for name in ("sine-profile", "sine-map"):
        result = rough("fit-fractal", "--json", files[name])
        values = json.loads(result.stdout)
        assert result.returncode == 0
        assert values["verdict"] != "power law" or values["fractal_dimension_stderr"] > 0.05


@pytest.mark.parametrize("scale", [1e-9, 1e3])
def test_parameters_scale_with_the_units(scale):
    """The same surface in nanometres and kilometres: lengths scale, ratios do not."""
    from rough.metrology import parameters

    base = Surface(fractal_map(128, 1e-6, 1e-6), (1e-6, 1e-6))
    scaled = Surface(base.heights * scale / 1e-6, (scale, scale))
    one, other = parameters(base), parameters(scaled)
    for key in ("Sa", "Sq", "Sz", "Sal"):
        assert other[key] == pytest.approx(one[key] * scale / 1e-6, rel=1e-9)
    for key in ("Ssk", "Sku", "Sdq", "Str", "Std"):
        assert other[key] == pytest.approx(one[key], rel=1e-9, abs=1e-9)


def test_only_the_rounding_of_the_mean_counts_as_flat():
    """A kilometre offset with sub-nanometre roughness is rough; a constant is flat."""
    from rough.metrology import parameters

    noise = np.random.default_rng(1).normal(size=4096) * 1e-10
    assert parameters(Surface(1e3 + noise, (1e-6,)))["Rq"] == pytest.approx(1e-10, rel=0.05)
    flat = parameters(Surface(np.full(4096, 1e3 + 1e-10), (1e-6,)))
    assert flat["Rq"] == 0.0 and math.isnan(flat["Rsk"])
