"""Physical checks before compiling: each bad scenario gets one line naming the field and what is allowed."""
from __future__ import annotations

import pytest
import yaml

from teamsim.cli import main
from teamsim.config import TrialConfig
from teamsim.runner import mission_of
from teamsim.scenario import check, config_of, generate

BASE = {"mission": "wander", "arena": {"size": [8, 8]}, "robots": {"red": {"pose": [0, 0, 0]}}}


def error_of(capsys, tmp_path, mission: str, changes: dict) -> str:
    data = yaml.safe_load(yaml.safe_dump(BASE))
    data["mission"] = mission
    for section, value in changes.items():
        data[section] = value
    file = tmp_path / "s.yaml"
    file.write_text(yaml.safe_dump(data, sort_keys=False))
    code = main(["scenario", "show", mission, "--scenario", str(file)])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("teamsim: error: ") and err.count("\n") == 1, err
    return err


RED = {"red": {"pose": [0, 0, 0]}}  # a diffdrive of radius 0.35 m at the centre


@pytest.mark.parametrize("changes, fragment", [
    ({"arena": {"size": [8, 8], "boxes": [{"x": 0.5, "y": 0, "half_x": 0.2, "half_y": 0.2}]}},
     "robots.red.pose: the robot (radius 0.35 m) overlaps arena.boxes[0]; its centre must be at least 0.35 m"),
    ({"arena": {"size": [8, 8], "boxes": [{"x": 0, "y": 0.7, "half_x": 0.5, "half_y": 0.05, "yaw": 1.5708}]}},
     "overlaps arena.boxes[0]"),  # only as rotated does it reach the robot
    ({"arena": {"size": [8, 8], "cylinders": [{"x": 0.6, "y": 0, "radius": 0.3}]}}, "overlaps arena.cylinders[0]"),
    ({"robots": {**RED, "green": {"pose": [0.6, 0, 0]}}},
     "robots.green.pose: overlaps robots.red (centres 0.6 m apart; must be at least 0.7 m)"),
    ({"robots": {"red": {"pose": [3.8, 0, 0]}}}, "robots.red.pose: x=3.8 must be in [-3.65, 3.65]"),
    ({"robots": {"red": {"kind": "tricycle", "pose": [3.3, 0, 0]}}},  # its pentagon is 0.25 m ahead of the pose
     "robots.red.pose: x=3.55 must be in [-3.5, 3.5]"),
    ({"objects": {"pucks": [{"x": 2, "y": 4.1}]}}, "objects.pucks[0]: y=4.1 must be in [-3.9746, 3.9746]"),
    ({"objects": {"boxes": [{"x": 3.8, "y": 0, "yaw": 1.5708}]}}, "objects.boxes[0]: x=3.8 must be in"),
    # the box's length lies along its own y: at yaw 0 it reaches 0.15 m along x, 0.75 m along y
    ({"objects": {"boxes": [{"x": 3.9, "y": 0, "yaw": 0}]}}, "objects.boxes[0]: x=3.9 must be in [-3.85, 3.85]"),
    ({"objects": {"boxes": [{"x": 0, "y": 3.5, "yaw": 0}]}}, "objects.boxes[0]: y=3.5 must be in [-3.25, 3.25]"),
    ({"objects": {"boxes": [{"x": 0, "y": 0}], "box": {"length": 9}}},
     "objects.boxes[0]: does not fit inside the 8 x 8 m arena: 9 m across along y"),
    ({"objects": {"pucks": [{"x": 0.2, "y": 0.1}]}}, "robots.red.pose: the robot (radius 0.35 m) overlaps "
                                                     "objects.pucks[0]"),
    ({"arena": {"size": [8, 8], "bogs": [{"x": 5, "y": 0}]}}, "arena.bogs[0]: x=5 must be in [-4, 4]"),
    ({"arena": {"size": [8, 8], "boxes": [{"x": 2, "y": 2, "half_x": 0}]}},
     "arena.boxes[0].half_x=0.0: must be in (0, 1000]"),
    ({"arena": {"size": [0, 8]}}, "arena.size[0]=0.0: must be in (0, 1000]"),
    ({"objects": {"puck": {"radius": -0.01}}}, "objects.puck.radius=-0.01: must be in (0, inf]"),
    ({"robots": {"red": {"options": {"radius": -0.3}}}}, "robots.red.options.radius=-0.3: must be in (0, 1e+06]"),
    ({"robots": {"red": {"options": {"ir_count": 60}}}},
     "robots.red.options.ir_count=60: must be in [1, 48] (the rim of a 0.35 m robot holds one 4.5 cm IR sensor"),
    ({"robots": {"red": {"options": {"ir_count": 60, "radius": 0.5}}}}, None),  # a larger rim holds 69
    ({"robots": {"red": {"options": {"ir_count": 0}}}}, "robots.red.options.ir_count=0: must be in (0, 1000]"),
    ({"robots": {"red": {"options": {"wheels": 3}}}}, "robots.red.options.wheels: unknown option for a diffdrive; "
                                                      "allowed: radius, ir_count"),
    ({"robots": {}}, "robots: a scenario needs at least one robot"),
    ({"faults": [{"kind": "kill", "robot": "mauve", "time": 1}]},
     "faults[0] kill:mauve@1: no robot 'mauve'; team: red"),
    ({"robots": {**RED, "blue": {"pose": [2, 2, 0]}}, "faults": [{"kind": "add-robot", "robot": "blue", "time": 1,
                                                                  "options": {"kind": "tracked"}}]},
     "faults[0] add-robot:blue@1: kind=tracked but robots.blue.kind is diffdrive; allowed: diffdrive"),
    ({"faults": [{"kind": "slow", "robot": "red", "time": 1, "options": {"factor": 3}}]},
     "factor must be in (0, 1]"),
])
def test_wander_checks(capsys, tmp_path, changes, fragment):
    if fragment is None:
        data = {**BASE, **changes}
        file = tmp_path / "ok.yaml"
        file.write_text(yaml.safe_dump(data, sort_keys=False))
        assert main(["scenario", "show", "wander", "--scenario", str(file)]) == 0
        return
    assert fragment in error_of(capsys, tmp_path, "wander", changes)


NAV_ROBOT = {"red": {"kind": "diffdrive", "pose": [-2, 2, 0]}}


@pytest.mark.parametrize("changes, fragment", [
    ({"robots": {**NAV_ROBOT, "blue": {"pose": [3, 3, 0]}}}, "robots: navigate drives exactly one robot; got 2"),
    ({"robots": {"red": {"kind": "r2", "pose": [0, 0, 0]}}}, "robots.red.kind='r2': navigate drives tricycle"),
    ({"robots": NAV_ROBOT, "arena": {"size": [8, 6]}}, "arena.size=[8, 6]: navigate's worlds are square"),
    ({"robots": NAV_ROBOT, "task": {"goal": [5, 0]}}, "task.goal=[5.0, 0.0]: must lie inside the arena"),
])
def test_navigate_checks(capsys, tmp_path, changes, fragment):
    assert fragment in error_of(capsys, tmp_path, "navigate", changes)


@pytest.mark.parametrize("mission, params", [
    *[("wander", {"kind": kind, "robots": 6, "obstacles": 6}) for kind in ("r2", "genghis2", "tricycle", "diffdrive",
                                                                             "tracked")],
    *[("navigate", {"robot": robot, "density": density}) for robot in ("A", "B", "C") for density in (0.05, 0.2)],
])
def test_generated_worlds_pass_the_checks(mission, params):
    m = mission_of(mission)
    for seed in range(3):
        config = TrialConfig(mission=mission, params=m.Params(**params), seed=seed)
        scenario = generate(config, m)
        check(scenario, [])
        assert config_of(scenario, m, config, []).scenario.robots == scenario.robots


def test_a_scene_that_does_not_compile_is_a_config_error(capsys, tmp_path):
    file = tmp_path / "s.yaml"
    # Each value is in range, but a shell lower than its ground clearance has a negative height.
    file.write_text(yaml.safe_dump({**BASE, "robots": {"red": {"options": {"height": 0.01}}}}))
    code = main(["run", "wander", "--scenario", str(file), "--out", str(tmp_path), "--duration", "1"])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1, err
    assert "teamsim: error: the scene does not compile: " in err
