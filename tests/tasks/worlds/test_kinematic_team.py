"""The kinematic team's shortcuts read exactly what the plain computation reads: a box's clearance from the compiled
offsets and the nearest boxes' ``math.hypot``, and IR ranges that skip robots beyond every ray's reach; the
robots' circles by hand."""
from __future__ import annotations

import math

import numpy as np
import pytest

from teamsim.models.robot import DriveLimits
from teamsim.tasks.worlds.exploration import ExploreWorldParams, explore_world
from teamsim.tasks.worlds.kinematic_team import KinematicTeam, Member, circle_ranges
from teamsim.tasks.worlds.navigation import KinematicBody, KinematicRobot, clearance

LIMITS = DriveLimits(v_max=0.5, omega_max=math.pi / 7, accel_max=0.1, angular_accel_max=0.15)
WORLD = explore_world(ExploreWorldParams(size=19.2, divisions=2, density=0.15), np.random.default_rng(4)).nav


def box_by_box(world, x: float, y: float) -> float:
    """Clearance as first written: every box in turn."""
    boxes = [math.hypot(max(abs(x - b.x) - b.half_x, 0.0), max(abs(y - b.y) - b.half_y, 0.0)) for b in world.boxes]
    return min([world.size / 2 - max(abs(x), abs(y))] + boxes)


def test_clearance_is_the_box_by_box_value_to_the_bit():
    rng = np.random.default_rng(0)
    points = rng.uniform(-WORLD.size / 2, WORLD.size / 2, (5000, 2))
    corners = [(b.x + sx * b.half_x, b.y + sy * b.half_y) for b in WORLD.boxes for sx in (-1, 1) for sy in (-1, 1)]
    assert all(clearance(WORLD, x, y) == box_by_box(WORLD, x, y) for x, y in [*points, *corners])


def test_ranges_skipping_robots_out_of_reach_are_the_ranges_over_every_robot():
    robot = KinematicRobot("diffdrive", LIMITS, radius=0.4, ir_count=10)
    rng = np.random.default_rng(1)
    for _ in range(300):
        me = KinematicBody(robot, (0.0, 0.0, rng.uniform(-math.pi, math.pi)))
        # others around the edge of the IR's reach (1.5 m + the sensor radius + their radius), some inside it
        others = {f"r{k}": KinematicBody(robot, (*(rng.uniform(1.7, 2.5) * np.array([math.cos(a), math.sin(a)])), 0.0))
                  for k, a in enumerate(rng.uniform(-math.pi, math.pi, 4))}
        team = KinematicTeam(WORLD, [], {"me": Member(me, None, 1.0)} | {n: Member(b, None, 1.0)
                                                                         for n, b in others.items()}, network=None)
        origins, directions = me.rays()
        every = circle_ranges(origins, directions, np.array([b.centre(b.x, b.y, b.heading) for b in others.values()]),
                              np.full(len(others), robot.radius), robot.ir_range)
        assert np.array_equal(team._ranges("me", me), np.minimum(me.ranges(WORLD), every))


def test_circle_ranges_by_hand():
    origins = np.array([[0.0, 0.0], [0.0, 0.0], [2.0, 0.1], [0.0, 0.4]])
    directions = np.array([[1.0, 0.0], [-1.0, 0.0], [1.0, 0.0], [1.0, 0.0]])
    centres, radii = np.array([[2.0, 0.0], [6.0, 0.0]]), np.array([0.5, 0.5])
    ranges = circle_ranges(origins, directions, centres, radii, 1.5)
    # ahead at 1.5 m; behind: none; starting inside the first circle and the second beyond reach: none;
    # off the axis by 0.4: enters at 2 - sqrt(0.25 - 0.16) = 1.7 m, beyond the 1.5 m reach
    assert ranges.tolist() == [1.5, math.inf, math.inf, math.inf]
    assert circle_ranges(origins[3:], directions[3:], centres, radii, 2.0)[0] == pytest.approx(1.7)
