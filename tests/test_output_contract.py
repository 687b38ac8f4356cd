"""The output contract (docs/output.rst) over every command that reports: --json is one
object naming its input with a list of warnings, --tsv rows are file, key, value, unit
with a number or nothing as value (text in the last column), every TSV key is a path
into the JSON with the same value, and the text table uses the same keys (apart from
the labelled rows of per-angle and per-run tables). Several inputs give JSON Lines or
one TSV table, going on past a bad file."""

import io
import json
import math
import re
import subprocess
import sys

import pytest

from rough import sample

PROFILE = str(sample("rock-profile.tsv"))
MAP = str(sample("rock-map.x3p"))
# text rows labelled for people (tables), each documented in docs/output.rst
LABELLED = re.compile(
    r"^(θ =.*|\S+mm_s\.\S+|variable|answers|likelihood ratio|log-likelihood|fractal dimension D|Rq \(per mm\)"
    r"|constant|subject \S+|.*\(L=.*\)|scaling|estimator \S+|λ = .*)$"
)


def rough(*args, stdin=None):
    return subprocess.run(
        [sys.executable, "-m", "rough", *args], input=stdin, capture_output=True, timeout=600, check=False
    )


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    folder = tmp_path_factory.mktemp("contract") / "study"
    assert (
        rough("experiment", "design", "--preset", "costa2000", "--subjects", "3", "--seed", "1", str(folder)).returncode
        == 0
    )
    for subject in ("S01", "S02", "S03"):
        assert (
            rough("experiment", "run", str(folder), "--subject", subject, "--observer", "rq=12,dimension=-4").returncode
            == 0
        )
    return str(folder)


COMMANDS = {
    "info profile": ("info", PROFILE),
    "info map": ("info", MAP),
    "features profile": ("features", "--vs-length", PROFILE),
    "features map": ("features", MAP),
    "fit-fractal profile": ("fit-fractal", PROFILE),
    "fit-fractal dfa": ("fit-fractal", "--estimator", "dfa", "--replicates", "4", PROFILE),
    "fit-fractal map": ("fit-fractal", "--fill", MAP),
    "fit-fractal profiles": ("fit-fractal", "--profiles", "30", MAP),
    "rose": ("rose", "--fill", "--angle-step", "30", MAP),
    "rose profiles": ("rose", "--fill", "--angle-step", "30", "--profiles", MAP),
    "render": ("render", "--speed", "20mm/s", PROFILE),
    "render two speeds": ("render", "--speed", "20mm/s", "--speed", "60mm/s", PROFILE),
    "formats": ("formats",),
}


def resolve(document, key):
    for part in key.split("."):
        document = document[int(part)] if isinstance(document, list) else document[part]
    return document


def same(cell, last, value):
    """Whether the TSV cells ``cell`` (value) and ``last`` (unit or text) hold ``value``:
    a number in the value column (``nan`` for null), anything else as text in the last
    with no value."""
    if value is None:
        return cell == "nan"
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return cell != "" and math.isclose(float(cell), value, rel_tol=0, abs_tol=0)
    return cell == "" and last == (str(value).lower() if isinstance(value, bool) else str(value))


def check(args, file):
    document = json.loads(rough(*args, "--json").stdout)
    assert document["file"] == file
    assert isinstance(document["warnings"], list)
    assert list(document)[0] == "file" and list(document)[-1] == "warnings"
    table = rough(*args, "--tsv").stdout.decode().splitlines()
    assert table
    keys = set()
    for line in table:
        cells = line.split("\t")
        assert len(cells) == 4, line
        name, key, value, unit = cells
        assert name == file
        assert not value.startswith("np."), line
        if value:
            float(value)  # numbers only
        assert same(value, unit, resolve(document, key)), (line, resolve(document, key))
        keys.add(key)
    text = rough(*args).stdout.decode().splitlines()
    assert text[0].split()[0] == "file"
    for line in text[1:]:
        label = re.split(r"\s{2,}", line)[0]
        if LABELLED.match(label):
            continue
        label = f"runs.0.{label}" if f"runs.0.{label}" in keys else label  # one render run
        assert label in keys or any(key.startswith(label + ".") for key in keys), label
    return document


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_every_report_keeps_the_contract(name):
    if name == "formats":
        check_formats()
    else:
        check(COMMANDS[name], COMMANDS[name][-1])


def check_formats():
    document = json.loads(rough("formats", "--json").stdout)
    assert document["file"] is None and document["warnings"] == []
    for line in rough("formats", "--tsv").stdout.decode().splitlines():
        name, key, value, last = line.split("\t")
        assert name == "" and same(value, last, resolve(document, key))


def test_experiment_reports_keep_the_contract(study):
    document = check(("experiment", "analyze", study), study)
    assert {"fractal_dimension", "rq", "constant"} <= set(document["coefficients"])
    assert json.loads(rough("experiment", "analyze", "--json", study).stdout)["n"] == 3 * 16


def test_render_json_is_one_object_with_runs_for_any_number_of_speeds():
    one = json.loads(rough("render", "--json", PROFILE).stdout)
    two = json.loads(rough("render", "--json", "--speed", "20mm/s", "--speed", "60mm/s", PROFILE).stdout)
    assert len(one["runs"]) == 1 and len(two["runs"]) == 2
    assert [run["speed"] for run in two["runs"]] == [0.02, 0.06]


def test_fit_fractal_tsv_has_plain_numbers_and_standard_errors():
    rows = {
        line.split("\t")[1]: line.split("\t")[2:]
        for line in rough("fit-fractal", "--tsv", PROFILE).stdout.decode().splitlines()
    }
    assert float(rows["amplitude_coefficient"][0]) > 0 and rows["amplitude_coefficient"][1] == "m"
    assert float(rows["fractal_dimension_stderr"][0]) > 0
    assert float(rows["amplitude_coefficient_stderr"][0]) > 0


def test_flagged_and_undefined_values_are_listed_in_warnings(tmp_path):
    spiky = tmp_path / "spiky.tsv"
    spiky.write_text("".join(f"{i * 1e-3} {(0.05 if i % 2 else -0.05)}\n" for i in range(400)))
    document = json.loads(rough("features", "--json", str(spiky)).stdout)
    assert not 0 <= document["JRC"] <= 20
    assert any("JRC" in warning for warning in document["warnings"])
    flat = tmp_path / "flat.tsv"
    flat.write_text("".join(f"{i * 1e-3} 0\n" for i in range(100)))
    document = json.loads(rough("features", "--json", str(flat)).stdout)
    assert document["Rsk"] is None
    assert "Rsk is undefined (NaN)" in document["warnings"]


def test_several_inputs_give_json_lines_and_one_table_past_a_bad_file(tmp_path):
    bad = tmp_path / "bad.x3p"
    bad.write_bytes(b"not a surface")
    result = rough("info", "--json", PROFILE, str(bad), MAP)
    assert result.returncode == 2
    lines = result.stdout.decode().splitlines()
    assert [json.loads(line)["file"] for line in lines] == [PROFILE, MAP]
    errors = result.stderr.decode().splitlines()
    assert len(errors) == 1 and errors[0].startswith(f"rough info: {bad}: ")
    table = rough("features", "--tsv", PROFILE, str(bad), MAP)
    assert table.returncode == 2
    files = {line.split("\t")[0] for line in table.stdout.decode().splitlines()}
    assert files == {PROFILE, MAP}
    text = rough("fit-fractal", PROFILE, PROFILE).stdout.decode()
    assert len(re.findall(rf"^file\s+{re.escape(PROFILE)}$", text, re.M)) == 2 and "\n\nfile" in text


def test_several_inputs_need_named_side_files_and_an_output_directory(tmp_path):
    plot = rough("features", "--plot", str(tmp_path / "p.png"), PROFILE, PROFILE)
    assert plot.returncode == 2 and b"{stem}" in plot.stderr
    dash = rough("features", "--list", "-", PROFILE, MAP)
    assert dash.returncode == 2 and not dash.stdout
    listed = rough("features", "--list", str(tmp_path / "{stem}-features.tsv"), PROFILE, MAP)
    assert listed.returncode == 0
    assert (tmp_path / "rock-profile-features.tsv").exists() and (tmp_path / "rock-map-features.tsv").exists()
    file_output = rough("detrend", PROFILE, MAP, "-o", str(tmp_path / "one.x3p"))
    assert file_output.returncode == 2 and b"directory" in file_output.stderr
    out = tmp_path / "levelled"
    assert rough("detrend", "--order", "1", PROFILE, MAP, "-o", f"{out}/").returncode == 0
    assert sorted(p.name for p in out.iterdir()) == ["rock-map.x3p", "rock-profile.x3p"]
    converted = rough("convert", PROFILE, MAP, "-f", "gsf", "-o", f"{out}/")
    assert converted.returncode == 0 and (out / "rock-map.gsf").exists()


def test_warnings_name_the_file_when_there_are_several(tmp_path):
    result = rough("info", "--spacing", "1um", MAP, PROFILE)
    lines = result.stderr.decode().splitlines()
    assert (
        f"rough info: {MAP}: warning: the spacing given, 1 µm × 1 µm, overrides the file's own, 50 µm × 50 µm" in lines
    )
    assert any(line.startswith(f"rough info: {PROFILE}: warning: the spacing given") for line in lines)


def test_side_file_names_take_the_inputs_stem():
    from rough.cli.batch import stem_name

    assert stem_name("plots/{stem}.png", "scans/a.b.x3p") == "plots/a.b.png"
    assert stem_name("{stem}.png", "scans/.hidden.x3p") == ".hidden.png"
    assert stem_name("{name}.json", "-") == "stdin.json"


def test_an_undefined_number_is_nan_and_only_a_text_row_has_no_value(tmp_path):
    flat = tmp_path / "flat.tsv"
    flat.write_text("".join(f"{i * 1e-3} 0\n" for i in range(100)))
    rows = {
        line.split("\t")[1]: line.split("\t")[2:]
        for line in rough("features", "--tsv", str(flat)).stdout.decode().splitlines()
    }
    assert rows["Rsk"] == ["nan", "1"]
    units = {
        line.split("\t")[1]: line.split("\t")[2:]
        for line in rough("info", "--tsv", str(flat)).stdout.decode().splitlines()
    }
    assert units["units.xy"] == ["", "m"] and units["format"] == ["", "tsv"]
    pandas = pytest.importorskip("pandas")
    table = pandas.read_csv(
        io.BytesIO(rough("features", "--tsv", str(flat)).stdout),
        sep="\t",
        names=["file", "key", "value", "unit"],
        keep_default_na=False,
    )
    numbers = table[table["value"] != ""].astype({"value": float})  # docs/output.rst's recipe
    wide = numbers.pivot(index="file", columns="key", values="value")
    assert math.isnan(wide["Rsk"].iloc[0]) and wide["Rq"].iloc[0] == 0
    assert "evaluation.basis" not in wide
