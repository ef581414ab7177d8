"""The missions' figures through matplotlib, each as PNG and SVG: explore's map.png and coverage.png, janitorial's
floor.png."""
from __future__ import annotations

from types import SimpleNamespace

import cv2
import numpy as np
from matplotlib.colors import to_rgb

from teamsim.controllers.exploration.territory import Territory
from teamsim.plots import pyplot
from teamsim.runner import trial_config
from teamsim.scenario import resolve
from teamsim.tasks import MISSIONS
from teamsim.tasks.missions import explore_figures, janitorial_figures
from teamsim.tasks.missions.explore_figures import STATUS_RGB, write_coverage, write_map
from teamsim.tasks.missions.janitorial_figures import write_floor
from teamsim.world import World

TERRITORY = Territory(size=8.0, resolution=0.2, divisions=2)


def test_map_in_metres_with_statuses_trails_and_bogs(tmp_path, monkeypatch):
    probabilities = np.full((TERRITORY.cells, TERRITORY.cells), 0.5)
    probabilities[:20, :] = 0.0  # the south half explored and free
    probabilities[5:8, 30:33] = 1.0  # an obstacle at x 2.0-2.6, y -3.0 to -2.4
    args = (probabilities, TERRITORY, ["E", "PE", "UE", "assigned"], [False, True, False, False],
            {"Robot1": [(-3.0, -3.0), (-1.0, -2.0)], "Robot2": [(1.0, 1.0), (2.0, 3.0)]},
            [SimpleNamespace(x=-2.0, y=2.0, half_x=0.5, half_y=0.4)])
    write_map(tmp_path / "map.png", *args)
    assert (tmp_path / "map.svg").stat().st_size > 0
    drawn = []
    monkeypatch.setattr(explore_figures, "save_figure", lambda fig, path: drawn.append(fig))
    write_map(tmp_path / "again.png", *args)
    axes = drawn[0].axes[0]
    [image] = axes.get_images()
    assert image.get_extent() == [-4.0, 4.0, -4.0, 4.0] and image.origin == "lower"
    assert image.get_array()[6, 31] == 0.0 and image.get_array()[0, 0] == 1.0  # occupied black, free white
    edges = [to_rgb(p.get_edgecolor()) for p in axes.patches]
    assert edges[1:] == [to_rgb(STATUS_RGB[s]) for s in ("E", "PE", "UE", "assigned")]  # after the bog
    assert [t.get_text() for t in axes.texts] == ["0 E", "1 PE bog", "2 UE", "3 assigned"]
    assert [t.get_text() for t in axes.get_legend().get_texts()][:2] == ["Robot1", "Robot2"]
    pyplot().close(drawn[0])


def test_coverage_is_a_line_chart_with_the_events(tmp_path):
    write_coverage(tmp_path / "coverage.png", [(0.0, 0.0), (30.0, 0.2), (60.0, 0.5)],
                   [{"t": 40.0, "event": "bog", "robot": "Robot2"}])
    assert "bog Robot2" in (tmp_path / "coverage.svg").read_text()
    assert cv2.imread(str(tmp_path / "coverage.png")) is not None


def test_floor_in_metres_with_furniture_cans_and_robots(tmp_path, monkeypatch):
    config = trial_config("janitorial", seed=1, duration=5.0)
    world = World(resolve(config, MISSIONS["janitorial"]), MISSIONS["janitorial"])
    for _ in range(10):
        world.tick()
        world.advance(world.steps_per_tick)
    state = MISSIONS["janitorial"]._floor_state(world)
    write_floor(tmp_path / "floor.png", *state)
    assert (tmp_path / "floor.svg").stat().st_size > 0 and cv2.imread(str(tmp_path / "floor.png")) is not None
    drawn = []
    monkeypatch.setattr(janitorial_figures, "save_figure", lambda fig, path: drawn.append(fig))
    write_floor(tmp_path / "again.png", *state)
    axes = drawn[0].axes[0]
    [image] = axes.get_images()
    info = state[0]
    half_x, half_y = (v / 2 for v in info["floor"].size)
    assert image.get_extent() == [-half_x, half_x, -half_y, half_y]
    assert len(axes.patches) == len(info["furniture"].boxes) + len(info["cans"].cans)
    assert [t.get_text() for t in axes.texts] == list(state[2])  # the robots, labelled
    assert axes.get_title().startswith("t = 1 s   floor ")
    pyplot().close(drawn[0])
