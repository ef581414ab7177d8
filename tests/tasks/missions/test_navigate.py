"""The navigate mission's wiring (teamsim.tasks.missions.navigate): the IR sensors' distances from the centre that the
controllers get, the time limits, and a short physics run of each Table 3.1 robot."""
from __future__ import annotations

import math

import numpy as np
import pytest

from teamsim.config import TrialConfig
from teamsim.models import build_robot
from teamsim.runner import run_trial
from teamsim.tasks.missions.navigate import NavigateParams, ir_sensor_radii, robot_of, time_limit


def test_sensor_radii_follow_each_outline():
    tricycle = build_robot("tricycle", "red")
    radii = ir_sensor_radii(tricycle, tricycle.drive.wheelbase / 2)
    assert radii.shape == (11,)
    assert radii[0] == pytest.approx(0.5)  # the first sensor looks forward, out of the pentagon's front vertex
    assert radii.min() >= 0.5 * math.cos(math.pi / 5) - 1e-9  # no nearer than the pentagon's sides
    assert radii.min() < 0.45
    kind, options = robot_of("C")
    tracked = build_robot(kind, "red", **options)
    radii = ir_sensor_radii(tracked, 0.0)
    assert radii.max() <= 0.67 + 1e-9 and radii.min() < 0.45  # the rectangle's short sides are well inside
    kind, options = robot_of("B")
    np.testing.assert_allclose(ir_sensor_radii(build_robot(kind, "red", **options), 0.0), 0.355)  # on its rim


def test_time_limits_of_section_3_6_2():
    assert time_limit(0.05) == time_limit(0.10) == 300.0
    assert time_limit(0.15) == time_limit(0.20) == 450.0


@pytest.mark.parametrize("robot", ["A", "B", "C"])
def test_a_short_navigate_trial_drives_towards_the_goal(tmp_path, robot):
    config = TrialConfig(mission="navigate", params=NavigateParams(robot=robot, density=0.05), seed=2,
                         duration=8.0, out=str(tmp_path), run_id=robot)
    summary = run_trial(config, progress=False).summary
    assert summary["status"] == "failed" and not summary.get("error")  # ran, and could not arrive in 8 s
    metrics = summary["metrics"]
    start_distance = math.dist((-6.0, 6.0), (6.0, -6.0))
    assert metrics["final_distance_to_goal"] < start_distance - 0.3  # it set off towards the goal
    assert metrics["path_length"] > 0.3
