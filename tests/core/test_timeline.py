"""timeline.png and timeline.svg: behaviour rows, and for a motivation trace one row per behaviour set with its
active bars, m(t) against theta and the events, checked on the figure's artists and on the PNG's pixels."""
from __future__ import annotations

import cv2
import numpy as np
import pytest
from matplotlib.colors import to_rgb

from teamsim.plots import pyplot
from teamsim.recording import MotivationSeries
from teamsim.timeline import MARGIN, THETA_HEIGHT, behaviour_colours, draw_timeline, write_timeline

STEP = 0.1


def trace() -> MotivationSeries:
    """red: patrol's motivation climbs to theta = 1 at 2 s and patrol runs to 3 s; the controller is silent from
    3.0 to 5.0 s (removed), then rest runs."""
    series = MotivationSeries(("patrol", "rest"), 1.0)
    times = np.r_[np.arange(0.0, 3.0, STEP), np.arange(5.0, 6.0, STEP)]
    for t in times:
        series.times.append(t)
        series.levels.extend([min(t / 2.0, 1.0) if t < 3 else 0.0, 0.2])
        series.active.append(0 if 2.0 <= t < 3.0 else 1 if t >= 5.0 else -1)
    series.events += [(0.5, 0, "impatience_reset", ""), (1.0, 0, "impatience", "fast"),
                      (5.5, 1, "acquiescence", "psi")]
    return series


def figure_inputs():
    times = np.arange(0.0, 6.05, 0.5)
    behaviours = np.array([["patrol" if t < 3 else "absent" if t < 5 else "rest", "wander"] for t in times])
    return times, behaviours, ["red", "blue"], [{"robot": "red", "kind": "remove", "time": 3.0}]


def by_gid(axes, gid):
    return [a for a in axes.get_children() if a.get_gid() == gid]


def test_motivation_rows_show_m_of_t_theta_bars_and_events():
    times, behaviours, names, faults = figure_inputs()
    fig = draw_timeline(times, behaviours, names, faults, {"red": trace()})
    axes = fig.axes[0]
    colours = behaviour_colours(["patrol", "absent", "rest", "wander", "patrol", "rest"])
    [patrol] = by_gid(axes, "motivation/red/patrol")
    assert to_rgb(patrol.get_color()) == to_rgb(colours["patrol"])
    x, y = patrol.get_xdata(), patrol.get_ydata()
    span = 1 - 2 * MARGIN
    assert y[np.searchsorted(x, 2.0)] == pytest.approx(1 - MARGIN - THETA_HEIGHT * span)  # m = theta on theta
    assert np.isnan(y).sum() == 1 and np.isnan(x[30])  # the curve breaks where the trace pauses
    [bars] = by_gid(axes, "active/red/patrol")
    (x0, y0), (x1, _) = bars.get_paths()[0].vertices.min(0), bars.get_paths()[0].vertices.max(0)
    assert (x0, x1) == pytest.approx((2.0, 3.0)) and y0 == pytest.approx(MARGIN)  # ends a step after its last tick
    assert len(by_gid(axes, "impatience_reset/red")) == len(by_gid(axes, "acquiescence/red")) == 1
    assert len(by_gid(axes, "fault")) == 1 and by_gid(axes, "behaviour/blue")
    assert [t.get_text() for t in axes.get_yticklabels()] == ["patrol", "rest"]
    assert [t.get_text() for t in axes.child_axes[0].get_yticklabels()] == ["red", "blue"]
    pyplot().close(fig)


def test_written_as_png_and_svg_with_the_curves_drawn(tmp_path):
    times, behaviours, names, faults = figure_inputs()
    write_timeline(tmp_path / "timeline.png", times, behaviours, names, faults, {"red": trace()})
    assert 'id="motivation/red/patrol"' in (tmp_path / "timeline.svg").read_text()
    image = cv2.imread(str(tmp_path / "timeline.png"))[:, :, ::-1].astype(int)
    colours = behaviour_colours(["patrol", "absent", "rest"])
    for name in ("patrol", "rest"):
        target = np.array(to_rgb(colours[name])) * 255
        assert (np.abs(image - target).sum(axis=2) < 40).sum() > 20, name


def test_without_motivation_one_row_per_robot():
    times, behaviours, names, faults = figure_inputs()
    fig = draw_timeline(times, behaviours, names, faults)
    axes = fig.axes[0]
    assert not [a for a in axes.get_children() if str(a.get_gid()).startswith("motivation/")]
    assert axes.get_ylim() == (pytest.approx(2.3), 0.0)  # two rows and the gap between them
    pyplot().close(fig)
