"""rough synth, fit-fractal and resample as a user runs them."""

import json

import pytest

from conftest import assert_one_line_error, rough

FIT_KEYS = {
    "fractal_dimension",
    "fractal_dimension_stderr",
    "amplitude_coefficient",
    "resolution",
    "psd_prefactor",
    "hurst",
    "band",
    "method",
    "window",
    "sampling",
}


def fit_json(*args, input=None):
    return json.loads(rough("fit-fractal", "--json", *args, input=input, check=True).stdout)


def test_synth_profile_then_fit():
    profile = rough(
        "synth", "--length", "40mm", "--dimension", "1.35", "--rq", "0.3mm", "--seed", "4", check=True
    ).stdout
    values = fit_json(input=profile)
    assert FIT_KEYS <= set(values)
    assert values["fractal_dimension"] == pytest.approx(1.35, abs=4 * values["fractal_dimension_stderr"])
    assert values["resolution"] == pytest.approx(0.0309e-3)
    assert values["parseval"] == pytest.approx(1.0, abs=1e-12)
    assert values["band"][0] < values["band"][1]
    facts = json.loads(rough("info", "--json", input=profile, check=True).stdout)
    assert facts["Rq"] == pytest.approx(0.3e-3, rel=1e-9)
    assert facts["shape"] == [round(40 / 0.0309)]


def test_synth_map_then_fit_reports_the_surface_dimension():
    surface = rough(
        "synth",
        "--size",
        "256x256",
        "--step",
        "10um",
        "--dimension",
        "2.3",
        "--amplitude",
        "1um",
        "--seed",
        "2",
        check=True,
    ).stdout
    values = fit_json(input=surface)
    assert values["fractal_dimension"] == pytest.approx(2.3, abs=0.03)
    assert values["profile_dimension"] == pytest.approx(values["fractal_dimension"] - 1)
    assert values["amplitude_coefficient"] == pytest.approx(1e-6, rel=0.1)


def test_seed_gives_identical_files(tmp_path):
    env = {"SOURCE_DATE_EPOCH": "1767225600"}
    for name in ("a", "b"):
        rough(
            "synth",
            "--length",
            "5mm",
            "--dimension",
            "1.4",
            "--amplitude",
            "2um",
            "--seed",
            "9",
            "-o",
            tmp_path / f"{name}.x3p",
            env=env,
            check=True,
        )
    assert (tmp_path / "a.x3p").read_bytes() == (tmp_path / "b.x3p").read_bytes()


def test_anisotropic_map_from_the_command_line():
    surface = rough(
        "synth",
        "--size",
        "256x256",
        "--step",
        "10um",
        "--anisotropy",
        "2.2,1um,2.5,3um,30",
        "--seed",
        "1",
        check=True,
    ).stdout
    facts = json.loads(rough("info", "--json", input=surface, check=True).stdout)
    assert facts["history"][-1]["parameters"]["anisotropy"] == [2.2, 1e-6, 2.5, 3e-6, pytest.approx(30.0)]


def test_fragments_warn(tmp_path):
    result = rough(
        "synth",
        "--length",
        "10mm",
        "--dimension",
        "1.275",
        "--amplitude",
        "1um",
        "--fragments",
        "--seed",
        "1",
        "-o",
        tmp_path / "f.x3p",
    )
    assert result.returncode == 0
    assert b"drop every wavelength longer than a fragment" in result.stderr


def test_fit_outputs_spectrum_and_plot(tmp_path):
    surface = rough(
        "synth", "--length", "20mm", "--dimension", "1.3", "--rq", "0.2mm", "--seed", "3", check=True
    ).stdout
    fit_json("--psd", tmp_path / "psd.tsv", "--plot", tmp_path / "psd.png", input=surface)
    lines = (tmp_path / "psd.tsv").read_text().splitlines()
    assert lines[1] == "frequency_per_m\tdensity_m3\tcount" and len(lines) > 10
    assert (tmp_path / "psd.png").read_bytes()[:4] == b"\x89PNG"


def test_band_estimator_and_sampling():
    surface = rough(
        "synth", "--length", "40mm", "--dimension", "1.3", "--rq", "0.2mm", "--seed", "5", check=True
    ).stdout
    banded = fit_json("--band", "0.1/mm:5/mm", input=surface)
    assert banded["band"][0] >= 100 and banded["band"][1] <= 5000
    assert fit_json("--estimator", "variogram", "--replicates", "4", input=surface)["estimator"] == "variogram"
    assert fit_json("--sampling", "point", input=surface)["sampling"] == "point"


def test_resample_command():
    surface = rough(
        "synth",
        "--length",
        "10mm",
        "--step",
        "0.0309mm",
        "--dimension",
        "1.3",
        "--rq",
        "0.1mm",
        "--seed",
        "1",
        check=True,
    ).stdout
    coarse = rough("resample", "--step", "0.1545mm", input=surface, check=True).stdout
    facts = json.loads(rough("info", "--json", input=coarse, check=True).stdout)
    assert facts["spacing"] == [pytest.approx(0.1545e-3)]
    assert [entry["command"] for entry in facts["history"]] == ["synth", "resample"]


@pytest.mark.parametrize(
    "args,message",
    [
        (["synth", "--length", "10mm", "--dimension", "2.3", "--rq", "1um"], "Ds = D + 1"),
        (["synth", "--size", "64x64", "--dimension", "1.3", "--rq", "1um"], "D = Ds - 1"),
        (["synth", "--length", "10mm", "--dimension", "1.3"], "--amplitude"),
        (["synth", "--dimension", "1.3", "--rq", "1um"], "--length"),
        (["synth", "--size", "64", "--dimension", "2.3", "--rq", "1um"], "NXxNY"),
    ],
)
def test_synth_refusals(args, message):
    assert_one_line_error(rough(*args), message)


def test_fit_refusals(tmp_path):
    import numpy as np

    from rough import Surface

    heights = 1e-6 * np.sin(np.arange(500) / 7.0)
    heights[40] = np.nan
    Surface(heights, (1e-6,)).write(tmp_path / "gap.x3p")
    assert_one_line_error(rough("fit-fractal", tmp_path / "gap.x3p"), "--fill")
    assert rough("fit-fractal", "--fill", tmp_path / "gap.x3p").returncode == 0
    assert_one_line_error(
        rough("fit-fractal", "--band", "1/mm:1.001/mm", tmp_path / "gap.x3p", "--fill"), "frequencies in the fit band"
    )
    assert_one_line_error(rough("fit-fractal", "--band", "fast", tmp_path / "gap.x3p"), "FMIN:FMAX")
