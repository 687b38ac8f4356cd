"""rough show and the figures of rough.plot: the map at its true aspect, invalid
points marked, the file name in the title, the output contract; the percentage
figure's n and Wilson error bars."""

import os
import pathlib
import pty
import struct
import subprocess
import sys

import numpy as np
import pytest

import rough
from rough import metrology
from rough.fractal.synth_map import synthesize_map

from conftest import assert_one_line_error
from conftest import rough as run_rough

pytest.importorskip("matplotlib")

from rough import plot  # noqa: E402 -- after the skip: plot needs matplotlib

PNG = b"\x89PNG\r\n\x1a\n"
MAP = rough.sample("rock-map.x3p")
PROFILE = rough.sample("rock-profile.tsv")


def png_size(data):
    """(width, height) in pixels, from the PNG's IHDR chunk."""
    assert data[:8] == PNG, data[:16]
    return struct.unpack(">II", data[16:24])


def image_ratio(figure):
    """Width / height of the map's axes as drawn (the first axes)."""
    figure.draw_without_rendering()
    box = figure.axes[0].get_window_extent()
    return box.width / box.height


def texts(figure):
    """Every text in the figure: titles, labels, legends, annotations."""
    return [t.get_text() for t in figure.findobj(lambda artist: hasattr(artist, "get_text"))]


@pytest.fixture(scope="module")
def strip(tmp_path_factory):
    """A 10 mm × 0.5 mm map (20:1), as a file."""
    path = tmp_path_factory.mktemp("maps") / "strip.x3p"
    synthesize_map((1000, 50), (10e-6, 10e-6), 2.3, rq=2e-6, seed=1).write(path)
    return path


# -- the command ---------------------------------------------------------------------------------


def test_a_map_as_png(tmp_path):
    out = tmp_path / "map.png"
    result = run_rough("show", MAP, "--plot", out)
    assert result.returncode == 0, result.stderr.decode()
    assert result.stdout == b"" and result.stderr == b""
    width, height = png_size(out.read_bytes())
    assert 1.1 < width / height < 1.9  # 6.4 mm × 4.8 mm, plus the colour bar at the right


def test_a_profile_as_png(tmp_path):
    out = tmp_path / "profile.png"
    run_rough("show", PROFILE, "--plot", out, check=True)
    width, height = png_size(out.read_bytes())
    assert width / height > 2


def test_a_wide_map_is_a_wide_strip_not_a_column(strip, tmp_path):
    out = tmp_path / "strip.png"
    run_rough("show", strip, "--plot", out, check=True)
    width, height = png_size(out.read_bytes())
    assert width / height > 3, (width, height)


def test_a_tall_map_is_tall(tmp_path):
    path = tmp_path / "tall.x3p"
    synthesize_map((40, 400), (10e-6, 10e-6), 2.3, rq=2e-6, seed=2).write(path)
    out = tmp_path / "tall.png"
    run_rough("show", path, "--plot", out, check=True)
    width, height = png_size(out.read_bytes())
    assert height / width > 1.1, (width, height)  # the long title (the path) widens it a little


def test_the_title_is_the_file_name_and_svg_is_written(tmp_path):
    out = tmp_path / "map.svg"
    run_rough("show", MAP, "--plot", out, check=True)
    text = out.read_text()
    assert text.startswith("<?xml") and "<svg" in text
    assert f"<!-- {MAP} -->" in text  # matplotlib names each text drawn as paths in a comment


def test_title_option_and_format_option(tmp_path):
    out = tmp_path / "figure"  # no extension: --format says
    run_rough("show", MAP, "--plot", out, "--format", "svg", "--title", "Sample 7, fault face", check=True)
    assert "<!-- Sample 7, fault face -->" in out.read_text()


def test_standard_output_carries_png_and_standard_input_is_named(tmp_path):
    result = run_rough("show", "-", input=pathlib.Path(MAP).read_bytes(), check=True)
    assert result.stdout.startswith(PNG)
    svg = run_rough("show", "--format", "svg", input=pathlib.Path(MAP).read_bytes(), check=True).stdout.decode()
    assert "<!-- standard input -->" in svg


def test_pdf(tmp_path):
    out = tmp_path / "map.pdf"
    run_rough("show", MAP, "--plot", out, check=True)
    assert out.read_bytes().startswith(b"%PDF")


def test_hillshade_and_levelling(tmp_path):
    out = tmp_path / "shaded.png"
    run_rough("show", MAP, "--hillshade", "--order", "1", "--dpi", "72", "--plot", out, check=True)
    width, _ = png_size(out.read_bytes())
    assert width < 900  # 72 dpi, not 150


def test_a_bad_input_is_one_line_status_2_and_no_file(tmp_path):
    out = tmp_path / "map.png"
    assert_one_line_error(run_rough("show", tmp_path / "missing.x3p", "--plot", out), "missing.x3p")
    bad = tmp_path / "bad.x3p"
    bad.write_bytes(b"not a zip archive")
    assert_one_line_error(run_rough("show", bad, "--plot", out), "bad.x3p")
    assert not out.exists()
    assert not list(tmp_path.glob(".rough-*"))


def test_an_unknown_extension_is_refused_before_any_work(tmp_path):
    out = tmp_path / "map.txt"
    assert_one_line_error(run_rough("show", MAP, "--plot", out), ".txt", "--format")
    assert not out.exists()


def test_binary_output_to_a_terminal_is_refused():
    controller, terminal = pty.openpty()
    try:
        result = subprocess.run(
            [sys.executable, "-m", "rough", "show", str(MAP)],
            stdout=terminal,
            stderr=subprocess.PIPE,
            stdin=subprocess.DEVNULL,
            timeout=120,
            check=False,
        )
    finally:
        os.close(terminal)
        os.close(controller)
    result.stdout = b""
    assert_one_line_error(result, "terminal")


def test_without_matplotlib_one_line_before_reading(tmp_path):
    fake = tmp_path / "fake" / "matplotlib"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("raise ImportError('no matplotlib here')\n")
    path = os.pathsep.join(filter(None, [str(fake.parent), os.environ.get("PYTHONPATH")]))
    result = run_rough("show", tmp_path / "missing.x3p", "--plot", tmp_path / "x.png", env={"PYTHONPATH": path})
    assert_one_line_error(result, "matplotlib", "pip install", status=1)  # not "missing.x3p: no such file"


# -- the figure ------------------------------------------------------------------------------------


def test_surface_figure_follows_the_extent():
    strip = synthesize_map((1000, 100), (10e-6, 10e-6), 2.3, rq=2e-6, seed=4)  # 10 mm × 1 mm
    assert image_ratio(plot.surface_figure(strip)) == pytest.approx(10, rel=0.02)
    # unequal spacing: 100 × 100 points, 10 µm × 40 µm apart, is four times taller than wide
    tall = rough.Surface(np.random.default_rng(5).normal(size=(100, 100)) * 1e-7, spacing=(10e-6, 40e-6))
    assert image_ratio(plot.surface_figure(tall)) == pytest.approx(0.25, rel=0.02)


def test_features_figure_draws_maps_at_their_aspect_too(strip):
    surface = rough.read(strip)
    figure = plot.features_figure(surface, (), metrology.amplitude_density(surface), title="strip.x3p")
    assert image_ratio(figure) == pytest.approx(20, rel=0.02)
    assert "strip.x3p" in texts(figure)


def test_invalid_points_are_counted_and_grey():
    from matplotlib.colors import to_rgba

    scan = rough.read(MAP)
    figure = plot.surface_figure(scan, title="rock-map.x3p")
    assert figure.get_suptitle() == "rock-map.x3p"
    assert "invalid (NaN): 6 points" in texts(figure)
    image = figure.axes[0].get_images()[0]
    assert tuple(image.get_cmap().get_bad()) == pytest.approx(to_rgba(plot.INVALID_COLOUR))
    assert figure.axes[0].get_xlabel() == "x (mm)" and figure.axes[1].get_ylabel() == "height (µm)"
    assert "1 mm" in texts(figure)  # the scale bar, a fifth of 6.4 mm or less


def page(figure):
    """The first axes' pixels as drawn (grey levels, row 0 at the top of the page)."""
    figure.canvas.draw()
    box = figure.axes[0].get_window_extent()
    pixels = np.asarray(figure.canvas.buffer_rgba())[..., :3].mean(axis=2)
    top, bottom = round(pixels.shape[0] - box.y1) + 2, round(pixels.shape[0] - box.y0) - 2
    return pixels[top:bottom, round(box.x0) + 2 : round(box.x1) - 2]


@pytest.mark.parametrize("hillshade", [False, True])
def test_maps_are_drawn_with_y_upwards(hillshade):
    """Row 0 at the bottom: a bump at large x and large y (the last rows) is drawn at the upper right, the y axis
    increases upwards from the first sample's pixel edge, and a hill-shaded bump is lit from the upper left."""
    y, x = np.mgrid[0:60, 0:80]
    bump = 1e-6 * np.exp(-((x - 60) ** 2 + (y - 45) ** 2) / 30.0)
    scan = rough.Surface(bump, spacing=10e-6, origin=(0.0, 1e-3))
    figure = plot.surface_figure(scan, colormap="gray", hillshade=hillshade)
    assert figure.axes[0].get_ylabel() == "y (µm)"
    assert figure.axes[0].get_ylim() == pytest.approx((995, 1595))  # y0 − dy/2 to y0 + 60 dy − dy/2
    image = page(figure)
    rows, columns = image.shape
    if not hillshade:
        row, column = np.unravel_index(np.argmax(image), image.shape)
        assert row < 0.35 * rows and column > 0.65 * columns, (row, column, image.shape)
    else:  # the bump's centre on the page, then its north-west and south-east flanks
        row, column = round(rows * (1 - 45.5 / 60)), round(columns * 60.5 / 80)
        step = round(columns * 3 / 80)
        assert image[row - step, column - step] > image[row + step, column + step] + 20


def test_units_follow_the_sizes():
    small = rough.Surface(np.random.default_rng(6).normal(size=(64, 64)) * 5e-9, spacing=1e-6)  # 64 µm, nm heights
    figure = plot.surface_figure(small)
    assert figure.axes[0].get_xlabel() == "x (µm)" and figure.axes[1].get_ylabel() == "height (nm)"
    assert "10 µm" in texts(figure)
    assert figure.get_suptitle() == "surface"


def test_a_profile_with_gaps():
    heights = np.sin(np.linspace(0, 20, 2000)) * 1e-6
    heights[500:600] = np.nan
    figure = plot.surface_figure(rough.Surface(heights, spacing=1e-6), title="gaps")
    assert "invalid (NaN): 100 points" in texts(figure)
    line = figure.axes[0].get_lines()[0]
    assert np.isnan(line.get_ydata()[500:600]).all()  # a gap, not a line drawn across
    assert figure.axes[0].get_xlabel() == "x (mm)" and figure.axes[0].get_ylabel() == "height (µm)"


def test_a_spike_does_not_wash_out_the_colours():
    heights = np.random.default_rng(7).normal(size=(100, 100)) * 1e-6
    heights[3, 3] = 1e-3
    figure = plot.surface_figure(rough.Surface(heights, spacing=1e-6))
    bar = figure.axes[1]
    assert bar.get_ylim()[1] < 10  # µm, not 1000
    assert "1 points beyond the arrows" in bar.get_ylabel()


def test_every_figure_shares_the_style():
    scan = rough.read(MAP)
    figure = plot.surface_figure(rough.read(PROFILE))
    assert figure.axes[0].xaxis.get_gridlines()[0].get_visible()  # the style's grid
    assert figure.get_layout_engine() is not None
    assert plot.surface_figure(scan).axes[0].get_images()  # maps: no grid over the image
    assert not plot.surface_figure(scan).axes[0].xaxis.get_gridlines()[0].get_visible()


# -- the shared data: real instruments ----------------------------------------------------------------


def test_a_real_scan_with_invalid_points(shared_data, tmp_path):
    path = shared_data / "x3ptools" / "sample-land.x3p"  # 918 × 256, 25292 NaN
    figure = plot.surface_figure(rough.read(path), title=path.name)
    assert "invalid (NaN): 25,292 points" in texts(figure)
    assert image_ratio(figure) == pytest.approx(918 / 256, rel=0.02)
    out = tmp_path / "land.png"
    run_rough("show", path, "--plot", out, check=True)
    width, height = png_size(out.read_bytes())
    assert width > height


def test_a_real_scan_with_unequal_spacing(shared_data, tmp_path):
    path = shared_data / "SurfaceTopography" / "x3p-2.x3p"  # 650 × 650 points, 83 µm × 204 µm
    figure = plot.surface_figure(rough.read(path), title=path.name)
    assert image_ratio(figure) == pytest.approx(8.29767313942749e-5 / 2.044783737930349e-4, rel=0.02)
    assert figure.axes[0].get_xlabel() == "x (µm)"
    out = tmp_path / "x3p-2.png"
    run_rough("show", path, "--plot", out, check=True)
    width, height = png_size(out.read_bytes())
    assert height > 1.15 * width  # the title and the facts above it are wider than the map


# -- the percentage figure (experiment analyze --plot) ------------------------------------------------


@pytest.fixture(scope="module")
def answered(tmp_path_factory):
    from rough.experiment.design import grid_design, load_study, write_study
    from rough.experiment.session import run_session

    surfaces, sets = grid_design([(1.275, 0.2781e-3)], 0.075, 1.2593)
    folder = tmp_path_factory.mktemp("study") / "study"
    study = write_study(folder, surfaces, sets, ["S01", "S02", "S03"], 5, 4e-3, 30.9e-6, 0.1545e-3)
    choices = iter(["first", "second", "first"] * 100)
    for subject in study.subjects:
        run_session(study, subject, lambda trial: (next(choices), 1.0, 1), "script")
    return load_study(folder)


def test_percentage_figure_has_n_and_wilson_error_bars(answered):
    from matplotlib.container import BarContainer, ErrorbarContainer

    from rough.experiment.analysis import percentages

    cells = percentages(answered, 1)
    figure = plot.percentage_figure(answered, [1], title="study")
    axes = figure.axes[0]
    bars = [c for c in axes.containers if isinstance(c, BarContainer)]
    errors = [c for c in axes.containers if isinstance(c, ErrorbarContainer)]
    labels = [t.get_text() for t in axes.texts]
    assert len(bars) == len(errors) == len(cells) == 8
    assert sorted(label.split("n = ")[1] for label in labels) == sorted(str(c[4]) for c in cells)
    for (_, _, _, percent, answers), error in zip(cells, errors):
        low, high = plot.proportion_interval(round(percent * answers / 100), answers)
        segment = error.lines[2][0].get_segments()[0]  # the vertical bar: (x, low), (x, high)
        assert segment[0][1] == pytest.approx(100 * low) and segment[1][1] == pytest.approx(100 * high)
    assert figure.get_suptitle() == "study"


def test_the_wilson_interval_without_statsmodels(monkeypatch):
    pytest.importorskip("statsmodels")
    cases = [(0, 3), (1, 3), (6, 8), (8, 8), (17, 40)]
    expected = [plot.proportion_interval(k, n) for k, n in cases]
    monkeypatch.setitem(sys.modules, "statsmodels.stats.proportion", None)  # import fails
    for (k, n), interval in zip(cases, expected):
        assert plot.proportion_interval(k, n) == pytest.approx(interval, abs=1e-12)
    # Wilson (1927) for 6 of 8 at 95 %: 0.4093 to 0.9285
    assert plot.proportion_interval(6, 8) == pytest.approx((0.40927, 0.92849), abs=1e-4)


def test_the_plots_stub_loads_matplotlib_only_to_draw():
    code = (
        "import sys; from rough import plot; "
        "print('matplotlib' in sys.modules, plot.length_unit(6.4e-3), plot.proportion_interval(6, 8)[0] > 0.4); "
        "plot.surface_figure; print('matplotlib' in sys.modules)"
    )
    env = {**os.environ, "PYTHONPATH": str(pathlib.Path(rough.__file__).parent.parent)}
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, env=env, check=True)
    assert result.stdout.decode().split("\n")[:2] == ["False (1000.0, 'mm') True", "False"]


def test_no_plots_module_shadows_a_public_name():
    modules = {path.stem for path in pathlib.Path(plot.__file__).parent.glob("*.py")}
    assert not modules & set(plot.__all__)
    assert all(getattr(plot, name) is not None for name in plot.__all__)
