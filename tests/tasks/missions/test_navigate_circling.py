"""Issue 22's regression: a pinned world (examples/navigate-circling.yaml) in which FRC as printed circles for good
beside two boxes, and teamsim's FRC, with its trap escape, arrives. Kinematic, as the study runs it."""
from __future__ import annotations

from pathlib import Path

import pytest

from teamsim.models import build_robot
from teamsim.runner import mission_of
from teamsim.scenario import load, read
from teamsim.tasks.missions.navigate import kinematic_metrics, nav_world_of

FILE = Path(__file__).resolve().parents[3] / "examples" / "navigate-circling.yaml"


@pytest.fixture(scope="module")
def world():
    return nav_world_of(load(read(FILE), mission_of("navigate"), FILE.parent))


def robot_b():
    return build_robot("diffdrive", "red", radius=0.35)


def test_frc_as_printed_circles_in_the_pinned_world(world):
    metrics = kinematic_metrics(world, robot_b(), "FRC-printed", 450.0)
    assert not metrics["success"]
    assert metrics["failure"] == "looping"
    assert 10.0 <= metrics["loop_period"] <= 25.0  # measured: 16 s
    assert metrics["loop_diameter"] <= 2.5  # measured: 1.75 m
    assert metrics["path_length"] > 100.0  # it keeps moving: a livelock, not a stall


def test_frc_with_the_trap_escape_arrives(world):
    metrics = kinematic_metrics(world, robot_b(), "FRC", 450.0)
    assert metrics["success"] and metrics["failure"] == ""
    assert metrics["nav_time"] < 200.0  # measured: 113 s
