"""rough report as a reader sees it: the HTML rendered by headless Chromium (every
figure painted, the tables sort on a click) and the PDF read back with poppler
(pdftotext holds the parameters and values, pdftoppm pages are not blank, each
surface starts a page). Skips, saying why, where Chromium, poppler or WeasyPrint is
missing (``.ci/run`` installs Debian's ``chromium`` and ``poppler-utils``)."""

import importlib.util
import json
import re
import shutil
import subprocess

import numpy as np
import pytest
from skimage import io as images

from conftest import ROOT, rough

MAP = ROOT / "sample_profiles" / "rock-map.x3p"
PROFILE = ROOT / "sample_profiles" / "rock-profile.tsv"
EPOCH = {"SOURCE_DATE_EPOCH": "1700000000"}
WIDTH = 1280
TALLEST = 16000  # pixels: Chromium's screenshots stay well below its texture limit
# Appended to a copy of the report: once everything is loaded, write each image's
# natural width and page box, the top of each section and the page's height into the
# DOM for --dump-dom.
MEASURE = """<script>
window.addEventListener("load", function () {
  var boxes = Array.prototype.map.call(document.images, function (image) {
    var box = image.getBoundingClientRect();
    return [image.naturalWidth, box.left + window.scrollX, box.top + window.scrollY, box.width, box.height];
  });
  var sections = Array.prototype.map.call(document.querySelectorAll("section.surface"), function (section) {
    return section.getBoundingClientRect().top + window.scrollY;
  });
  var out = document.createElement("pre");
  out.id = "measured";
  out.textContent = JSON.stringify({boxes: boxes, sections: sections, height: document.documentElement.scrollHeight});
  document.body.appendChild(out);
});
</script>"""


def chromium():
    found = shutil.which("chromium") or shutil.which("chromium-browser")
    if found is None:
        pytest.skip("chromium is not installed (Debian's chromium package; .ci/run installs it)")
    return found


def browse(page, *flags, height=4000):
    """Run headless Chromium on ``page`` (a file); its standard output."""
    command = [chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars"]
    command += ["--force-device-scale-factor=1", f"--window-size={WIDTH},{height}", *flags, page.as_uri()]
    result = subprocess.run(command, capture_output=True, timeout=120, check=False)
    assert result.returncode == 0, result.stderr.decode(errors="replace")
    return result.stdout.decode()


@pytest.fixture(scope="module")
def synthetic(tmp_path_factory):
    """A second map, a thousandth of the sample map's height, so that the maps' summary has two rows."""
    target = tmp_path_factory.mktemp("synthetic") / "synthetic.x3p"
    rough(
        "synth",
        "--size",
        "64x64",
        "--step",
        "10um",
        "--dimension",
        "2.3",
        "--rq",
        "0.1um",
        "--seed",
        "1",
        "-o",
        target,
        check=True,
    )
    return target


@pytest.fixture(scope="module")
def html(tmp_path_factory, synthetic):
    target = tmp_path_factory.mktemp("rendered") / "report.html"
    result = rough("report", "--fill", MAP, synthetic, PROFILE, "-o", target, env=EPOCH)
    assert result.returncode == 0, result.stderr.decode()
    return target


def with_script(report, script, name):
    """A copy of ``report`` with ``script`` run at its end."""
    copy = report.with_name(name)
    copy.write_text(report.read_text(encoding="utf-8").replace("</body>", script + "\n</body>"), encoding="utf-8")
    return copy


def test_every_figure_is_painted(html, tmp_path):
    measured = with_script(html, MEASURE, "measured.html")
    dom = browse(measured, "--dump-dom")
    found = json.loads(re.search(r'<pre id="measured">(.*?)</pre>', dom, re.S)[1].replace("&quot;", '"'))
    height = min(int(found["height"]) + 50, TALLEST)
    assert found["height"] < TALLEST
    screenshot = tmp_path / "report.png"
    browse(measured, f"--screenshot={screenshot}", height=height)
    pixels = images.imread(screenshot)[..., :3].astype(float)
    assert len(found["boxes"]) == 4 + 4 + 3  # a map: surface, Abbott-Firestone, spectrum, rose; a profile: no rose
    for natural, left, top, width, height in found["boxes"]:
        assert natural > 0 and width > 100 and height > 100, found["boxes"]
        box = pixels[int(top) : int(top + height), int(left) : int(left + width)]
        painted = np.mean(box.min(axis=-1) < 200)  # neither white nor the light grey of a frame
        assert box.std() > 10 and painted > 0.01, (top, left, box.std(), painted)
    summary_end = int(found["boxes"][0][2]) - 120
    images.imsave(tmp_path / "report-summary.png", pixels[:summary_end].astype(np.uint8), check_contrast=False)
    images.imsave(
        tmp_path / "report-surface.png", pixels[summary_end - 60 :][:2600].astype(np.uint8), check_contrast=False
    )


def cells(dom, table_class, column):
    """The ``data-value`` of ``column`` (0 first) in each body row of the first table of ``table_class``."""
    table = re.search(rf'<table class="[^"]*{table_class}[^"]*">.*?<tbody>(.*?)</tbody>', dom, re.S)[1]
    rows = re.findall(r"<tr>(.*?)</tr>", table, re.S)
    return [re.findall(r'<td[^>]*data-value="([^"]*)"', row)[column] for row in rows]


def test_the_tables_sort_on_a_click(html, synthetic):
    click = (
        "<script>window.addEventListener('load', function () {"
        "document.querySelector('.summary-table th[data-key=\"Sa\"]').click();"
        "var value = document.querySelector('table.parameters th[data-key=\"value\"]');"
        "value.click(); value.click();});</script>"
    )
    dom = browse(with_script(html, click, "clicked.html"), "--dump-dom")
    assert cells(dom, "summary-table", 0) == [str(synthetic), str(MAP)]  # by Sa, ascending
    values = cells(dom, "parameters", 1)
    numbers = [float(value) for value in values if value]
    assert numbers == sorted(numbers, reverse=True)  # two clicks: descending
    assert values[: len(numbers)] == [value for value in values if value]  # undefined ones at the end


@pytest.fixture(scope="module")
def pdf(tmp_path_factory, synthetic):
    if importlib.util.find_spec("weasyprint") is None:
        pytest.skip("weasyprint is not installed (the report extra)")
    if shutil.which("pdftotext") is None or shutil.which("pdftoppm") is None:
        pytest.skip("poppler's pdftotext and pdftoppm are not installed (Debian's poppler-utils)")
    folder = tmp_path_factory.mktemp("pdf")
    target = folder / "report.pdf"
    result = rough("report", "--fill", MAP, synthetic, PROFILE, "-o", target, env=EPOCH)
    assert result.returncode == 0, result.stderr.decode()
    return target


def test_the_pdf_holds_the_parameters_and_values(pdf, html):
    text = subprocess.run(["pdftotext", pdf, "-"], capture_output=True, check=True).stdout.decode()
    listed = re.findall(
        r'<td data-value="([A-Za-z0-9_]+)">\1</td><td class="number" data-value="[^"]*">([^<]+)<', html.read_text()
    )
    assert len(listed) > 60
    captions = re.findall(r"<figcaption>([^<]+)</figcaption>", html.read_text(encoding="utf-8"))
    assert len(captions) == 11  # every figure, drawn: its caption is printed under it
    lines = [line.strip() for line in text.splitlines()]
    for caption in set(captions):
        assert lines.count(caption) == captions.count(caption), caption
    for key, value in listed:
        assert key in text
        if value != "undefined":
            assert value in text, (key, value)


def test_each_surface_starts_a_page_and_no_page_is_blank(pdf, synthetic, tmp_path):
    pages = subprocess.run(["pdftotext", "-layout", pdf, "-"], capture_output=True, check=True).stdout.decode()
    first_lines = [next((line.strip() for line in page.splitlines() if line.strip()), "") for page in pages.split("\f")]
    names = [str(MAP), str(synthetic), str(PROFILE)]
    assert [line for line in first_lines if line in names] == names
    subprocess.run(["pdftoppm", "-r", "50", "-png", pdf, tmp_path / "page"], check=True)
    drawn = sorted(tmp_path.glob("page-*.png"))
    assert len(drawn) == len([page for page in pages.split("\f") if page.strip()])
    for page in drawn:
        pixels = images.imread(page)[..., :3]
        assert np.count_nonzero(pixels.min(axis=-1) < 128) > 100, page.name  # a line of text has more
