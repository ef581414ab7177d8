"""The hazardous-waste behaviours' logic, without physics: locations from extents (§3.8.1), beliefs merged
from broadcasts, the report trigger (ch.5), the pose estimate and the go-to and avoid layers."""
from __future__ import annotations

import math

import numpy as np
import pytest

from teamsim.controllers.base import Observation
from teamsim.controllers.cleanup import CleanupKnowledge, locations_from_extents
from teamsim.controllers.goto import AvoidObstacles, DriveParams, steer_to
from teamsim.controllers.pose_estimate import PoseEstimate
from teamsim.models.robot import DifferentialSpec
from teamsim.positioning import PoseFix

EXTENTS = np.array([-3.7, 3.7, -1.6, 1.6])  # (xmin, xmax, ymin, ymax) of a robot's track


@pytest.mark.parametrize("home, spill, goal, entrance", [
    ((-3.2, 0.3), (-3.7 + 7.4 / 6, 0.0), (3.7 - 0.4, 0.0), (-3.7, 0.0)),  # entrance west
    ((3.3, -0.2), (3.7 - 7.4 / 6, 0.0), (-3.7 + 0.4, 0.0), (3.7, 0.0)),  # entrance east
    ((0.5, 1.4), (0.0, 1.6 - 3.2 / 6), (0.0, -1.6 + 0.4), (0.0, 1.6)),  # entrance north
])
def test_spill_is_the_centre_of_the_front_third_and_goal_the_back_centre(home, spill, goal, entrance):
    found = locations_from_extents(EXTENTS, np.array(home), clearance=0.4)
    assert found["spill"] == pytest.approx(spill)
    assert found["goal"] == pytest.approx(goal)
    assert found["entrance"] == pytest.approx(entrance)


def test_a_robot_learns_locations_and_reports_from_teammates_broadcasts():
    k = CleanupKnowledge(report_interval=240.0)
    k.hear({"task": "idle", "report": 0.0, "spill_empty": False})
    assert not k.located
    k.hear({"task": "find-locations", "spill": (1, 2), "goal": (3, 4), "entrance": (0, 0), "report": 0.0})
    assert k.located and k.spill == (1, 2) and k.goal == (3, 4)
    k.hear({"spill": (9, 9), "goal": (9, 9), "entrance": (9, 9)})  # first locations stick
    assert k.goal == (3, 4)
    k.delivered()
    assert k.report_due(250.0)
    k.hear({"report": 245.0})  # a teammate reported: this robot's delivery is covered
    assert not k.report_due(500.0) and k.last_report == 245.0
    k.hear({"spill_empty": True})
    assert k.spill_empty


def test_report_is_due_only_after_a_delivery_and_the_interval():
    k = CleanupKnowledge(report_interval=240.0)
    assert not k.report_due(1000.0)  # nothing delivered yet
    k.delivered()
    assert not k.report_due(239.0) and k.report_due(240.0)
    k.reported(240.0)
    assert k.reports == 1 and not k.report_due(1000.0)
    assert k.message()["report"] == 240.0


def _observation(t, fix, wheel_speed, touch=None, ir=None):
    ir = np.full(4, np.inf) if ir is None else np.asarray(ir, float)
    return Observation(time=t, robot="red", ir_raw=np.zeros(len(ir)), ir_range=ir,
                       ir_bearings=np.array([0.0, math.pi / 2, math.pi, -math.pi / 2]), pose=fix,
                       motor_speeds=np.array([wheel_speed, wheel_speed]), touch=touch or {})


def test_pose_estimate_is_steadier_than_the_raw_fixes():
    """Straight at 0.3 m/s with 0.15 m fix noise every 0.6 s: the blended estimate's error is well below it."""
    rng = np.random.default_rng(0)
    drive = DifferentialSpec(wheel_radius=0.05, track_width=0.3, left=("l",), right=("r",))
    estimate, dt, speed = PoseEstimate(drive), 0.1, 0.3
    errors, fix = [], None
    for k in range(600):
        t = k * dt
        if k % 6 == 0:
            fix = PoseFix(speed * t + 0.15 * rng.standard_normal(), 0.15 * rng.standard_normal(), 0.0, t)
        pose = estimate.update(_observation(t, fix, speed / drive.wheel_radius))
        errors.append(math.hypot(pose[0] - speed * t, pose[1]))
    assert np.sqrt(np.mean(np.square(errors[60:]))) < 0.5 * 0.15 * math.sqrt(2)


def test_steer_to_turns_on_the_spot_when_far_off_heading_and_stops_on_arrival():
    params = DriveParams()
    v, omega = steer_to(np.array([0.0, 0.0, 0.0]), (0.0, 2.0), params, arrive=0.2)
    assert v == 0.0 and omega > 0
    v, omega = steer_to(np.array([0.0, 0.0, 0.0]), (2.0, 0.1), params, arrive=0.2)
    assert v == pytest.approx(params.cruise, rel=0.01) and omega > 0
    assert steer_to(np.array([1.95, 0.0, 0.0]), (2.0, 0.0), params, arrive=0.2) is None


def test_avoid_backs_off_from_a_front_bump_then_turns_right_and_releases():
    avoid = AvoidObstacles(("a", "b", "c", "d"), np.array([0.0, math.pi / 2, math.pi, -math.pi / 2]),
                           ("bump_front", "bump_back"), np.random.default_rng(0))
    p = avoid.params
    assert avoid(_observation(0.0, None, 0.0)) is None
    v, omega = avoid(_observation(0.1, None, 0.0, touch={"bump_front": 5.0}))
    assert v < 0 and omega == 0.0
    v, omega = avoid(_observation(0.1 + p.back_time + 0.05, None, 0.0))
    assert v == 0.0 and omega < 0  # dead ahead: turn right, so two robots meeting pass left to left
    assert avoid(_observation(0.2 + p.back_time + p.turn_time, None, 0.0)) is None
    v, omega = avoid(_observation(10.0, None, 0.0, ir=[np.inf, 0.1, np.inf, np.inf]))  # close on the left
    assert v > 0 and omega == 0.0  # not ahead: it moves on, then turns away to the right
    assert avoid(_observation(10.0 + p.back_time + 0.05, None, 0.0))[1] < 0
