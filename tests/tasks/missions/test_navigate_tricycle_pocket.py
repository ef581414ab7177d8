"""Issue 22's tricycle regression: a pinned world (examples/navigate-tricycle-pocket.yaml) in which Robot A, trapped
with the way out behind it between two boxes, stood for good until FRC turned it round in legs
(``multi_point_turn``). Kinematic, as the study runs it."""
from __future__ import annotations

from pathlib import Path

import pytest

from teamsim.models import build_robot
from teamsim.runner import mission_of
from teamsim.scenario import load, read
from teamsim.tasks.missions.navigate import (kinematic_metrics, kinematic_robot, nav_metrics, nav_world_of,
                                             navigation_controller)
from teamsim.tasks.worlds.navigation import kinematic_run

FILE = Path(__file__).resolve().parents[3] / "examples" / "navigate-tricycle-pocket.yaml"


@pytest.fixture(scope="module")
def world():
    return nav_world_of(load(read(FILE), mission_of("navigate"), FILE.parent))


def test_without_the_multi_point_turn_the_tricycle_stands_in_the_pocket(world):
    robot = build_robot("tricycle", "red")
    controller = navigation_controller("FRC", robot, world)
    controller.turn = None  # FRC before the multi-point turn: the trapped tricycle never turns first
    controller.escape.turn_limit = 0.0
    run = kinematic_run(world, controller, kinematic_robot(robot), 450.0, on_contact="stop")
    metrics = nav_metrics(world, robot, run.reached, run.pose, run.travelled, run.time, controller.trail)
    assert not metrics["success"]
    assert metrics["failure"] == "stalled"
    assert metrics["path_length"] < 15.0  # measured: 9.4 m, then pressed against a box for good


def test_frc_turns_the_tricycle_round_and_arrives(world):
    metrics = kinematic_metrics(world, build_robot("tricycle", "red"), "FRC", 450.0)
    assert metrics["success"] and metrics["failure"] == ""
    assert metrics["nav_time"] < 250.0  # measured: 153 s
    assert metrics["touches"] <= 2  # measured: 1 (a refused motion, the robot halted)
