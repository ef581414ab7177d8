"""teamsim.plots: every figure as PNG and SVG side by side, the same bytes for the same figure, and matplotlib
imported only when a figure is drawn."""
from __future__ import annotations

import subprocess
import sys
import xml.etree.ElementTree as ElementTree

import cv2
import numpy as np

from teamsim import plots
from teamsim.plots import grouped_bars, line_chart, pyplot, save_figure


def test_save_figure_writes_png_and_svg_and_the_same_bytes_again(tmp_path):
    for run in ("a", "b"):
        fig, axes = pyplot().subplots(figsize=(4, 3))
        axes.plot([0, 1, 2], [1, 0, 1])
        (tmp_path / run).mkdir()
        save_figure(fig, tmp_path / run / "chart.png")
    png, svg = tmp_path / "a" / "chart.png", tmp_path / "a" / "chart.svg"
    assert cv2.imread(str(png)).shape == (330, 440, 3)  # 4 x 3 in at 110 dpi
    assert ElementTree.parse(svg).getroot().tag.endswith("svg")
    assert png.read_bytes() == (tmp_path / "b" / "chart.png").read_bytes()
    assert svg.read_bytes() == (tmp_path / "b" / "chart.svg").read_bytes()  # no date, fixed ids
    assert not pyplot().get_fignums()  # closed


def test_grouped_bars_leave_nan_bars_out(tmp_path, monkeypatch):
    drawn = []
    monkeypatch.setattr(plots, "save_figure", lambda fig, path: drawn.append(fig))
    grouped_bars(tmp_path / "bars.png", "title", ["A", "B", "C"], {"one": [1.0, np.nan, 3.0], "two": [2.0, 2.0, 2.0]},
                 "s", y_max=4.0)
    [fig] = drawn
    axes = fig.axes[0]
    assert [bar.get_height() for bar in axes.patches] == [1.0, 3.0, 2.0, 2.0, 2.0]
    assert [t.get_text() for t in axes.get_xticklabels()] == ["A", "B", "C"] and axes.get_ylim() == (0.0, 4.0)
    assert [t.get_text() for t in axes.get_legend().get_texts()] == ["one", "two"]
    pyplot().close(fig)


def test_line_chart_marks_events(tmp_path):
    line_chart(tmp_path / "line.png", "explored", [0, 10, 20], {"explored %": [0, 40, 80]}, "time, s", "%",
               y_max=100.0, marks=[(12.0, "bog Robot2")])
    assert "bog Robot2" in (tmp_path / "line.svg").read_text()
    assert cv2.imread(str(tmp_path / "line.png")) is not None


def test_matplotlib_is_not_imported_with_the_cli_or_the_tasks():
    code = ("import sys, teamsim.cli.main, teamsim.tasks, teamsim.runner, teamsim.tasks.studies.formation, "
            "teamsim.tasks.studies.navigation; print('matplotlib' in sys.modules)")
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True).stdout.strip() == "False"
