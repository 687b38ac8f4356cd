"""rough report: the HTML holds a section per input, the summary holds the numbers of
``rough features --json`` for each file (read from the cells' SI ``data-value``), every
figure is embedded, nothing is fetched, a lab's template is used, bad input ends in one
line, and the bytes are the same on every run."""

import html.parser
import json
import math
import os
import re
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import rough
from rough.extras import DISTRIBUTION
from rough.reports.sections import Parameter, Section, _facts, actionable, form_text

from conftest import ROOT, assert_one_line_error
from conftest import rough as run_rough

MAP = ROOT / "sample_profiles" / "rock-map.x3p"
PROFILE = ROOT / "sample_profiles" / "rock-profile.tsv"
EPOCH = {"SOURCE_DATE_EPOCH": "1700000000"}


class Page(html.parser.HTMLParser):
    """What a test needs of a report: sections, summary tables, images and links."""

    def __init__(self, text):
        super().__init__()
        self.sections, self.images, self.links, self.tables = [], [], [], []
        self._in_summary = False
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "section" and "surface" in attrs.get("class", ""):
            self.sections.append(attrs["id"])
        if tag == "img":
            self.images.append(attrs["src"])
        if tag == "a" and "href" in attrs:
            self.links.append(attrs["href"])
            if self._in_summary and self.tables[-1]["rows"]:
                self.tables[-1]["rows"][-1]["href"] = attrs["href"]
        if tag == "table":
            self._in_summary = "summary-table" in attrs.get("class", "")
            if self._in_summary:
                self.tables.append({"headers": [], "rows": []})
        if not self._in_summary:
            return
        table = self.tables[-1]
        if tag == "th":
            table["headers"].append(attrs["data-key"])
        if tag == "tr" and table["headers"]:
            table["rows"].append({"cells": []})
        if tag == "td":
            table["rows"][-1]["cells"].append(attrs.get("data-value"))

    def handle_endtag(self, tag):
        if tag == "table":
            self._in_summary = False

    @property
    def rows(self):
        return [row for table in self.tables for row in table["rows"]]

    def summary(self):
        """{file name: {key: data-value}} of the summary tables."""
        return {
            row["cells"][0]: dict(zip(table["headers"][1:], row["cells"][1:]))
            for table in self.tables
            for row in table["rows"]
        }


def report(*args, env=EPOCH):
    return run_rough("report", *args, env=env)


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    target = tmp_path_factory.mktemp("report") / "report.html"
    result = report("--fill", MAP, PROFILE, "-o", target)
    assert result.returncode == 0, result.stderr.decode()
    return target.read_text(encoding="utf-8")


def features_json(*args):
    result = run_rough("features", "--json", *args, check=True)
    return json.loads(result.stdout)


def parameters_of(document):
    """The parameters of a ``features --json`` document: its numeric top-level keys
    (with a profile's ``feature_count``)."""
    return {key: value for key, value in document.items() if value is None or isinstance(value, (int, float))}


def assert_same_numbers(cells, document):
    expected = parameters_of(document)
    assert set(expected) <= set(cells), sorted(set(expected) - set(cells))
    for key, value in expected.items():
        if value is None or math.isnan(value):
            assert cells[key] == "", key
        else:
            assert float(cells[key]) == pytest.approx(value, rel=1e-12, abs=0), key


def test_one_section_per_input_and_a_link_to_each(written):
    page = Page(written)
    assert len(page.sections) == 2
    assert [row["href"] for row in page.rows] == [f"#{anchor}" for anchor in page.sections]
    assert set(page.summary()) == {str(MAP), str(PROFILE)}


def test_the_summary_holds_the_numbers_of_features(written):
    summary = Page(written).summary()
    assert_same_numbers(summary[str(MAP)], features_json(MAP))
    assert_same_numbers(summary[str(PROFILE)], features_json(PROFILE))
    assert "Sa" not in summary[str(PROFILE)]  # a profile has no areal parameters: a table of its own


def test_every_figure_is_embedded_and_nothing_is_fetched(written):
    page = Page(written)
    # the map: surface, Abbott-Firestone curve, spectrum, rose; the profile: no rose
    assert len(page.images) == 4 + 3
    assert all(re.match(r"data:image/(png|svg\+xml);base64,", src) for src in page.images)
    assert all(link.startswith("#") for link in page.links)
    outside_images = re.sub(r"data:[^\"']+", "", written)
    assert "http" not in outside_images and "file:" not in outside_images


def test_the_parameters_name_their_standard_and_unit(written):
    assert re.search(r"<td[^>]*>Sa</td><td[^>]*>[0-9.]+ µm</td><td>arithmetic mean height</td>", written)
    assert "ISO 25178-2" in written and "ISO 21920-2" in written
    assert "spectrum: power law" in written


def test_the_report_is_the_same_to_the_byte(tmp_path):
    first, second = tmp_path / "first.html", tmp_path / "second.html"
    for target in (first, second):
        assert report(PROFILE, "-o", target).returncode == 0
    assert first.read_bytes() == second.read_bytes()
    assert "2023-11-14T22:13:20Z" in first.read_text(encoding="utf-8")  # the date is SOURCE_DATE_EPOCH


def test_the_filter_and_form_are_those_of_features_and_detrend(tmp_path):
    target = tmp_path / "filtered.html"
    assert report("--cutoff", "0.8mm", "--order", "1", PROFILE, "-o", target).returncode == 0
    levelled = run_rough("detrend", "--order", "1", PROFILE, check=True).stdout
    document = json.loads(run_rough("features", "--cutoff", "0.8mm", "--json", input=levelled, check=True).stdout)
    summary = Page(target.read_text(encoding="utf-8")).summary()
    assert_same_numbers(summary[str(PROFILE)], document)


def test_a_map_with_gaps_says_why_it_has_no_spectrum(tmp_path):
    target = tmp_path / "gaps.html"
    result = report(MAP, "-o", target)
    assert result.returncode == 0, result.stderr.decode()
    text = target.read_text(encoding="utf-8")
    assert "spectrum: not fitted (" in text and "rose: not computed (" in text
    assert len(Page(text).images) == 2  # the surface and the Abbott-Firestone curve are still drawn


def test_a_lab_template_is_used(tmp_path):
    template = tmp_path / "lab.html.j2"
    template.write_text(
        "{{ title }}|{% for s in sections %}{{ s.name }}={{ s.values['Rq'].value }} {{ s.values['Rq'].unit }}"
        "{% endfor %}|{{ summaries[0].columns[0].key }}"
    )
    target = tmp_path / "lab.html"
    assert report("--template", template, "--title", "Lab 7", PROFILE, "-o", target).returncode == 0
    rq = features_json(PROFILE)["Rq"]
    assert target.read_text() == f"Lab 7|{PROFILE}={rq!r} m|Ra"


@pytest.mark.parametrize(
    "text, fragment",
    [("{% for s in sections %}", "line 1"), ("{{ no_such_variable }}", "no_such_variable")],
)
def test_a_bad_template_is_one_line(tmp_path, text, fragment):
    template = tmp_path / "bad.j2"
    template.write_text(text)
    target = tmp_path / "bad.html"
    result = report("--template", template, PROFILE, "-o", target)
    assert_one_line_error(result, fragment)
    assert not target.exists()


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("a\n{{ sectoins }}", "bad.j2: line 2: not a valid report template: 'sectoins' is undefined"),
        ('a\n\n{% include "mystyle.css" %}', "bad.j2: line 3: not a valid report template: mystyle.css is found"),
        ('{% include "part.j2" %}', "part.j2: line 1: not a valid report template: 'nothing' is undefined"),
    ],
)
def test_a_template_is_refused_before_any_input_is_read(tmp_path, text, fragment):
    (tmp_path / "bad.j2").write_text(text)
    (tmp_path / "part.j2").write_text("{{ nothing }}")
    result = report("--template", tmp_path / "bad.j2", tmp_path / "no-such-input.tsv", "-o", tmp_path / "r.html")
    assert_one_line_error(result, fragment)


def test_a_template_includes_a_file_beside_it(tmp_path):
    (tmp_path / "lab.j2").write_text('{% include "lab.css" %}|{% include "sortable.js" %}')
    (tmp_path / "lab.css").write_text("h1 { color: teal }")
    target = tmp_path / "lab.html"
    assert report("--template", tmp_path / "lab.j2", PROFILE, "-o", target).returncode == 0
    assert target.read_text().startswith("h1 { color: teal }|")


def test_a_template_failing_as_it_renders_is_one_line_naming_its_line(tmp_path):
    template = tmp_path / "lab.j2"
    template.write_text("{{ title }}\n{{ sections[0].name }}{{ 1 / 0 }}")
    target = tmp_path / "lab.html"
    result = report("--template", template, PROFILE, "-o", target)
    assert_one_line_error(result, f"{template}: line 2: the report template failed: division by zero")
    assert not target.exists()


def test_an_unreadable_input_is_one_line(tmp_path):
    broken = tmp_path / "broken.x3p"
    broken.write_bytes(b"PK\x03\x04 not a zip")
    target = tmp_path / "report.html"
    assert_one_line_error(report(broken, "-o", target), "broken.x3p")
    assert not target.exists()


def test_with_several_inputs_a_bad_one_is_left_out(tmp_path):
    broken = tmp_path / "broken.tsv"
    broken.write_text("not a number\n")
    target = tmp_path / "report.html"
    result = report(PROFILE, broken, "-o", target)
    assert_one_line_error(result, "broken.tsv")
    assert len(Page(target.read_text(encoding="utf-8")).sections) == 1


def test_the_output_is_checked_before_any_work(tmp_path):
    assert_one_line_error(report(PROFILE, "-o", tmp_path / "report.txt"), ".txt")
    assert_one_line_error(report(PROFILE, "-o", tmp_path / "no-folder" / "report.html"), "does not exist")
    assert_one_line_error(report(PROFILE, "--parameters", "height,colour", "-o", tmp_path / "r.html"), "colour")
    assert_one_line_error(report(PROFILE, "-o", tmp_path), "is a folder, not a file to write")
    assert_one_line_error(report(PROFILE, "-o", tmp_path / "r{stem}.html"), "without {…} placeholders")
    assert os.listdir(tmp_path) == []


def test_standard_output_is_html_and_the_sets_choose_the_columns():
    result = report("--parameters", "hybrid", PROFILE, "-o", "-")
    assert result.returncode == 0, result.stderr.decode()
    page = Page(result.stdout.decode())
    assert [table["headers"] for table in page.tables] == [["file", "Rdq"]]


def test_the_library_call_takes_surfaces(tmp_path):
    profile = rough.read(PROFILE)
    sections = rough.reports.write_report([profile], tmp_path / "library.html", parameters=["height"])
    assert [p.key for p in sections[0].parameters] == ["Ra", "Rq", "Rsk", "Rku", "Rp", "Rv", "Rz", "Rt"]
    assert sections[0].values["Rq"].value == pytest.approx(rough.parameters(profile)["Rq"], rel=1e-15)
    assert [figure.caption for figure in sections[0].figures][:2] == ["surface", "Abbott–Firestone curve"]


def test_a_real_instrument_file(shared_data, tmp_path):
    scan = shared_data / "x3ptools" / "sample-land.x3p"
    target = tmp_path / "land.html"
    result = report(scan, "-o", target)
    assert result.returncode == 0, result.stderr.decode()
    page = Page(target.read_text(encoding="utf-8"))
    assert_same_numbers(page.summary()[str(scan)], features_json(scan))
    assert len(page.images) == 2  # it has gaps: no spectrum or rose without --fill


def test_help_loads_no_numpy():
    code = "import sys; from rough.cli.main import run; run(['report', '--help']); print('numpy' in sys.modules)"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, check=True)
    assert result.stdout.decode().split()[-1] == "False"


@given(
    st.lists(st.floats(1e-11, 1e4).map(lambda v: float(f"{v:.6g}")), min_size=1, max_size=5),
    st.sampled_from(["m", "1/m", "m2", "m3/m2", "%", "1"]),
)
def test_a_summary_cell_reads_back_as_its_si_value(values, unit):
    """The summary shows each value as a number in its column's unit, whose scale is a
    power of ten: that number is the SI value times the scale to half the last digit."""
    (column,) = summary_of(values, unit).columns
    assert column.symbol in rough.units.format_quantity(max(values), unit)
    assert column.scale == 10.0 ** round(math.log10(column.scale))  # a prefix, exactly
    for value, (_, text) in zip(values, (row["cells"][0] for row in summary_of(values, unit).rows)):
        assert text == f"{value * column.scale:.4g}"
        half_digit = 0.5 * 10.0 ** (math.floor(math.log10(value * column.scale)) - 3)
        assert abs(float(text) - value * column.scale) <= half_digit * (1 + 1e-9)


def summary_of(values, unit, key="X"):
    """The summary of one parameter ``key`` in ``unit`` over surfaces of ``values``."""
    sections = [
        Section(f"s{i}", f"s{i}", "profile", [], "", "", [Parameter(key, v, unit, "", "", "other", "")], *[[]] * 6)
        for i, v in enumerate(values)
    ]
    (summary,) = rough.reports.summaries(sections)
    return summary


def test_the_same_number_is_rounded_the_same_in_every_column():
    """Two checkerboards (±1e-4 m and ±1.2345001e-5 m): Sa, Sq, Sp and Sv are the same
    number on each and read the same, as features prints it (12.345 µm → 12.35)."""
    values = [9.99995e-5, 1.2345001e-05]
    sections = [
        Section(
            f"s{i}",
            f"s{i}",
            "map",
            [],
            "",
            "",
            [Parameter(k, v, "m", "", "", "height", "") for k in "Sa Sq Sp Sv".split()],
            *[[]] * 6,
        )
        for i, v in enumerate(values)
    ]
    (summary,) = rough.reports.summaries(sections)
    assert [text for _, text in summary.rows[1]["cells"]] == ["12.35"] * 4
    assert [column.symbol for column in summary.columns] == ["µm"] * 4


@pytest.mark.parametrize(("unit", "symbol"), [("m", "m"), ("m2", "m²"), ("1/m2", "/m²"), ("m3", "m³"), ("1", "")])
def test_a_column_with_no_usable_value_shows_the_si_unit(unit, symbol):
    for values in ([math.nan], [0.0, math.nan]):
        (column,) = summary_of(values, unit).columns
        assert (column.symbol, column.scale) == (symbol, 1.0)


@pytest.mark.parametrize(("hidden", "extra"), [("jinja2", "report"), ("matplotlib", "plot"), ("weasyprint", "report")])
def test_a_missing_extra_is_named_before_any_work(tmp_path, hidden, extra):
    args = ["report", str(PROFILE), "-o", "report.pdf"]
    code = f"import sys; sys.modules[{hidden!r}] = None; import rough.cli.main as m; m.main({args!r})"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, cwd=tmp_path, check=False)
    assert_one_line_error(result, f"pip install '{DISTRIBUTION}[{extra}]'", status=1)
    assert os.listdir(tmp_path) == []


def test_the_units_say_which_were_assumed():
    heights = np.zeros((4, 4))
    stated = dict(_facts(rough.Surface(heights, (1e-6, 1e-6))))["units in the file"]
    assumed = dict(_facts(rough.Surface(heights, (1e-6, 1e-6), units=rough.Units(assumed=("xy", "z")))))
    assert stated == "xy m, z m (as the file states)"
    assert assumed["units in the file"].startswith("xy m, z m (assumed: the source file stated no unit for xy or z;")


def test_the_first_order_form_of_a_profile_is_a_line(tmp_path):
    target = tmp_path / "line.html"
    assert report("--order", "1", "--parameters", "height", PROFILE, "-o", target).returncode == 0
    text = target.read_text(encoding="utf-8")
    assert "the least-squares line" in text and "least-squares plane<" not in text
    assert form_text(1, "map") == "the least-squares plane"


def test_the_band_is_that_of_fit_fractal(tmp_path):
    target = tmp_path / "band.html"
    assert report("--band", "0.5/mm:20/mm", "--parameters", "height", PROFILE, "-o", target).returncode == 0
    fitted = run_rough("fit-fractal", "--band", "0.5/mm:20/mm", "--json", PROFILE, check=True)
    low, high = json.loads(fitted.stdout)["fit_band"]
    text = target.read_text(encoding="utf-8")
    assert f"fit band</dt><dd>{rough.units.format_range(low, high, '1/m')}</dd>" in text
    assert "fit band</dt><dd>0.5 to 20 /mm</dd>" in text  # the settings


@pytest.mark.parametrize(
    ("message", "command", "said"),
    [
        ("use wider sectors (--width) or a wider band", "rose", "(--width of rough rose) or a wider band"),
        ("do not determine it (use a lower --order)", "fit-fractal", "(use a lower --order of rough fit-fractal)"),
        ("in the fit band; widen --band or use more points", "fit-fractal", "widen --band or use more points"),
    ],
)
def test_a_hint_names_the_command_of_an_option_report_lacks(message, command, said):
    assert actionable(message, command).endswith(said)


def test_a_set_with_no_parameter_for_the_surface_says_so():
    section = rough.reports.surface_section(rough.read(MAP), parameters=["other"])
    assert section.parameters == []
    assert "no parameter of the chosen sets applies to maps" in section.warnings
    section = rough.reports.surface_section(rough.read(PROFILE), parameters=["feature"])
    assert [(p.key, p.text) for p in section.parameters] == [
        ("feature_count", str(features_json(PROFILE)["feature_count"]))
    ]
