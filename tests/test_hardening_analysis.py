"""Issue 14's findings in the analysis step: absurd but legal geometry ends in a result
or a one-line refusal, and nothing undefined goes unannounced."""

import logging

import numpy as np
import pytest

from rough import Surface
from rough.fractal.result import FractalFit, announce
from rough.metrology import parameters

from conftest import assert_one_line_error


def test_a_map_with_an_extreme_spacing_ratio_gets_its_parameters(tmp_path, run):
    """48 points at 1 nm × 1 km: the autocorrelation's radial sampling stays bounded
    (it asked for 87 TiB before)."""
    np.save(tmp_path / "m.npy", np.random.default_rng(1).standard_normal((6, 8)) * 1e-6)
    result = run("features", "--json", "--spacing", "1e-9m,1e3m", tmp_path / "m.npy")
    assert result.returncode == 0, result.stderr.decode()


def test_extreme_ratio_sampling_leaves_ordinary_maps_unchanged():
    heights = np.random.default_rng(2).standard_normal((64, 64)) * 1e-6
    values = parameters(Surface(heights, (1e-6, 1e-6)))
    stretched = parameters(Surface(heights, (1e-6, 2e-6)))
    assert np.isfinite([values["Sal"], values["Str"], stretched["Sal"]]).all()


def test_every_undefined_parameter_is_named(caplog):
    """A NaN result without a listed reason still gets a warning."""
    from rough.metrology import announce_undefined as announce

    with caplog.at_level(logging.WARNING, logger="rough"):
        announce({"Ra": 1e-6, "peak_density": float("nan")})
    assert "peak_density" in caplog.text


def test_an_undefined_fit_result_is_named(caplog):
    fit = FractalFit(1.5, 0.01, float("nan"), float("nan"), 1e-6, float("inf"), 0.5, (0.0, 1.0), "whittle", "none",
                     "point", 10, float("nan"))  # fmt: skip
    with caplog.at_level(logging.WARNING, logger="rough"):
        announce(fit)
    assert "amplitude_coefficient" in caplog.text and "psd_prefactor" in caplog.text


@pytest.mark.parametrize("spacing", ["5e-324m", "1e-20m", "1e9m"])
def test_a_spacing_no_instrument_has_is_refused(tmp_path, run, spacing):
    np.save(tmp_path / "p.npy", np.random.default_rng(1).standard_normal(1000) * 1e-6)
    for command in ("features", "fit-fractal", "info"):
        assert_one_line_error(run(command, "--spacing", spacing, tmp_path / "p.npy"), "spacing")
