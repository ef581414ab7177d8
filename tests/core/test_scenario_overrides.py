"""Override precedence on scenarios, lowest first: the file (or the world the mission generates from its
parameters), then --seed and --duration, then --set by dotted path in command-line order, then --fault appended
after the scenario's faults (teamsim/cli/scenario.py)."""
from __future__ import annotations

import pytest
import yaml

from teamsim.cli import main
from teamsim.config import ConfigError
from teamsim.scenario import set_path

FILE = """\
mission: wander
seed: 5
duration: 20
arena: {size: [8, 8], boxes: [{x: 2, y: 2}, {x: -2, y: 2}]}
robots:
  red: {pose: [0, 0, 0]}
  green: {kind: tracked, pose: [-2, -2, 0]}
radio: {loss: 0.1}
faults: [{kind: kill, robot: green, time: 4}]
"""


@pytest.fixture
def scenario_file(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text(FILE)
    return path


def show(capsys, *argv) -> dict:
    code = main(["scenario", "show", *map(str, argv)])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    return yaml.safe_load(captured.out)


def error(capsys, *argv) -> str:
    code = main(["scenario", "show", *map(str, argv)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1, err
    return err


def test_the_file_alone(capsys, scenario_file):
    s = show(capsys, "wander", "--scenario", scenario_file)
    assert (s["seed"], s["duration"], s["radio"]["loss"]) == (5, 20.0, 0.1)
    assert s["faults"] == [{"kind": "kill", "robot": "green", "time": 4.0, "options": {}}]


def test_flags_override_the_file_and_set_overrides_flags(capsys, scenario_file):
    s = show(capsys, "wander", "--scenario", scenario_file, "--seed", 7, "--duration", 9)
    assert (s["seed"], s["duration"]) == (7, 9.0)
    s = show(capsys, "wander", "--scenario", scenario_file, "--seed", 7, "--set", "seed=9")
    assert s["seed"] == 9


def test_later_set_wins(capsys, scenario_file):
    s = show(capsys, "wander", "--scenario", scenario_file, "--set", "radio.loss=0.2", "--set", "radio.loss=0.3")
    assert s["radio"]["loss"] == 0.3


def test_set_reaches_any_field_by_path(capsys, scenario_file):
    s = show(capsys, "wander", "--scenario", scenario_file, "--set", "robots.red.pose=[1,-2,0.5]",
             "--set", "arena.boxes[1].half_z=0.4", "--set", "robots.red.options.radius=0.4",
             "--set", "robots.green.controller.cruise_speed=0.2", "--set", "arena.image=null")
    assert s["robots"]["red"]["pose"] == [1.0, -2.0, 0.5]
    assert s["arena"]["boxes"][1]["half_z"] == 0.4
    assert s["robots"]["red"]["options"] == {"radius": 0.4}
    assert s["robots"]["green"]["controller"]["cruise_speed"] == 0.2


def test_set_can_add_a_robot_that_a_fault_then_brings_in(capsys, scenario_file):
    s = show(capsys, "wander", "--scenario", scenario_file, "--set", "robots.blue.pose=[2,-2,0]",
             "--fault", "add-robot:blue@3,kind=diffdrive")
    assert list(s["robots"]) == ["red", "green", "blue"]
    assert s["faults"][-1] == {"kind": "add-robot", "robot": "blue", "time": 3.0, "options": {"kind": "diffdrive"}}


def test_faults_are_appended_after_set(capsys, scenario_file):
    s = show(capsys, "wander", "--scenario", scenario_file, "--fault", "slow:red@1,factor=0.5")
    assert [f["kind"] for f in s["faults"]] == ["kill", "slow"]
    # --set replaces the file's faults; --fault still comes after, whatever the order on the command line.
    s = show(capsys, "wander", "--scenario", scenario_file, "--fault", "slow:red@1", "--set", "faults=[]")
    assert [f["kind"] for f in s["faults"]] == ["slow"]


def test_without_a_file_parameters_generate_and_paths_edit(capsys):
    s = show(capsys, "wander", "--seed", 3, "--set", "robots=2", "--set", "obstacles=0",
             "--set", "robots.green.pose=[0,0,0]", "--set", "radio.loss=0.4")
    assert list(s["robots"]) == ["red", "green"] and s["arena"]["boxes"] == []
    assert s["robots"]["green"]["pose"] == [0.0, 0.0, 0.0]
    assert s["radio"]["loss"] == 0.4
    same_world = show(capsys, "wander", "--seed", 3, "--set", "robots=2", "--set", "obstacles=0")
    assert same_world["robots"]["red"] == s["robots"]["red"]


def test_set_errors_name_the_path(capsys, scenario_file):
    assert "--set arena.boxes[5].x: no item 5 in arena.boxes (a list of 2)" in error(
        capsys, "wander", "--scenario", scenario_file, "--set", "arena.boxes[5].x=1")
    assert "--set radio.loss.x: radio.loss is not a mapping" in error(
        capsys, "wander", "--scenario", scenario_file, "--set", "radio.loss.x=1")
    assert "radio.lost: unknown key; allowed: rate_hz" in error(
        capsys, "wander", "--scenario", scenario_file, "--set", "radio.lost=1")
    assert "--set robots.red.pose: not valid YAML at line 1, column 5" in error(
        capsys, "wander", "--scenario", scenario_file, "--set", "robots.red.pose=[1,2")
    assert "robots.red.pose: expected a list of 3 numbers, got [1, 2]" in error(
        capsys, "wander", "--scenario", scenario_file, "--set", "robots.red.pose=[1,2]")
    # Without a file, a bare unknown key still lists what --set accepts.
    assert "--set speed: unknown key for mission 'wander'; allowed: robots" in error(capsys, "wander", "--set",
                                                                                      "speed=3")


def test_set_path_on_plain_data():
    data = {"arena": {"boxes": [{"x": 1}]}}
    assert set_path(data, "arena.boxes[0].y=2.5") == {"arena": {"boxes": [{"x": 1, "y": 2.5}]}}
    with pytest.raises(ConfigError, match="expected a dotted path"):
        set_path(data, "arena..x=1")
    with pytest.raises(ConfigError, match="expected key=value"):
        set_path(data, "arena.size")
