"""FRC's trap escape (teamsim.controllers.navigation.trap_escape): the hit map, the trap test and the escape plan."""
from __future__ import annotations

import math

import numpy as np
import pytest

from teamsim.controllers.navigation.trap_escape import EscapeParams, HitMap, TrapEscape


def wall(x: float, y0: float, y1: float) -> np.ndarray:
    """Hits along a wall x = const, one every 5 cm."""
    y = np.arange(y0, y1, 0.05)
    return np.column_stack([np.full_like(y, x), y])


def test_hit_map_rasterises_hits_into_a_known_map_spanning_them_and_the_kept_points():
    hits = HitMap(0.1)
    hits.add(np.array([[1.04, 2.01], [1.06, 2.09], [-0.55, 0.35]]))
    assert hits.cells == {(10, 20), (-6, 3)}
    grid = hits.grid((3.0, -1.0), margin=0.5)
    occupied = grid.probabilities > 0.5
    assert occupied.sum() == 2
    for x, y in ((1.05, 2.05), (-0.55, 0.35)):
        row, col = grid.world_to_cell(x, y)
        assert occupied[row, col]
    x, y = grid.cell_to_world(0, 0)
    assert x <= -0.55 - 0.5 + 0.1 and y <= -1.0 - 0.5 + 0.1  # the margin round the lowest point


def test_no_escape_while_the_robot_gets_closer_to_the_goal():
    escape = TrapEscape(goal=(10.0, 0.0), radius=0.35)
    for k in range(600):  # 60 s at 0.1 s, closing in at 0.1 m/s
        assert escape.waypoint(k * 0.1, (k * 0.01, 0.0)) == (10.0, 0.0)
    assert not escape.escaping and escape.escapes == 0


def test_no_progress_for_a_period_makes_a_trap_and_the_plan_leads_round_the_wall():
    # The goal lies behind a wall 4 m long; the robot circles in front of it.
    escape = TrapEscape(goal=(4.0, 0.0), radius=0.35, params=EscapeParams(period=30.0))
    escape.hits.add(wall(2.0, -2.0, 2.0))
    time, waypoint = 0.0, None
    while not escape.escaping:
        centre = (0.5 * math.cos(time), 0.5 * math.sin(time))
        waypoint = escape.waypoint(time, centre)
        time += 0.1
    assert time == pytest.approx(30.0 + 0.1, abs=0.2)  # the first period without progress
    path = escape.follower.path
    assert path[-1] == pytest.approx((4.0, 0.0), abs=0.1)  # reaches the goal
    assert np.abs(path[:, 1]).max() > 2.0 + 0.35  # round an end of the wall, clear of it
    crossing = path[np.abs(path[:, 0] - 2.0) < 0.05]
    assert (np.abs(crossing[:, 1]) > 2.0 + 0.35).all()
    assert np.hypot(*(path - waypoint).T).min() < 1e-9  # it aims along the plan, not at the goal


def test_progress_past_the_best_ends_the_escape():
    escape = TrapEscape(goal=(4.0, 0.0), radius=0.35, params=EscapeParams(period=1.0))
    escape.hits.add(wall(2.0, -2.0, 2.0))
    escape.waypoint(0.0, (0.0, 0.0))
    escape.waypoint(1.5, (0.0, 0.1))
    assert escape.escaping
    escape.waypoint(2.0, (1.0, 2.6))  # round the wall's end: 3.9 m from the goal, not 0.5 m better than 4 m
    assert escape.escaping
    escape.waypoint(2.5, (2.5, 2.6))  # 3.0 m: progress
    assert not escape.escaping


def test_a_robot_beside_a_wall_plans_from_the_nearest_free_cell_and_turns_to_face_the_plan_first():
    escape = TrapEscape(goal=(4.0, 0.0), radius=0.35, params=EscapeParams(period=1.0))
    escape.hits.add(wall(2.0, -2.0, 2.0))
    escape.waypoint(0.0, (1.5, 0.0))  # 0.5 m from the wall: inside HRD's 0.55 m inflation
    escape.waypoint(1.5, (1.5, 0.0))
    path = escape.follower.path
    assert tuple(path[0]) == (1.5, 0.0) and path[1][0] < 1.5  # first away from the wall
    assert escape.turn_first(math.radians(90), 1.6) and escape.turn_first(math.radians(45), 1.7)
    assert not escape.turn_first(math.radians(20), 1.8)  # facing it: drive
    assert not escape.turn_first(math.radians(90), 1.9)  # and only once per plan


def test_turning_to_face_a_plan_gives_up_after_its_time():
    escape = TrapEscape(goal=(4.0, 0.0), radius=0.35, params=EscapeParams(period=1.0, turning=15.0))
    escape.hits.add(wall(2.0, -2.0, 2.0))
    escape.waypoint(0.0, (1.0, 0.0))
    escape.waypoint(1.5, (1.0, 0.0))  # planned at 1.5 s
    assert escape.turn_first(math.radians(120), 16.0)
    assert not escape.turn_first(math.radians(120), 16.6)  # 15 s on, still not facing it: drive anyway


def test_standing_still_makes_a_trap_before_the_period_is_up():
    escape = TrapEscape(goal=(4.0, 0.0), radius=0.5, params=EscapeParams(period=30.0, standstill=10.0))
    escape.hits.add(wall(2.0, -2.0, 2.0))
    for k in range(95):  # 9.5 s rocking a millimetre to and fro
        escape.waypoint(k * 0.1, (0.001 * (k % 2), 0.0))
    assert not escape.escaping
    escape.waypoint(10.0, (0.0, 0.0))
    assert escape.escaping and escape.escapes == 1


def test_a_re_plan_during_a_multi_point_turn_does_not_restart_its_clock():
    escape = TrapEscape(goal=(4.0, 0.0), radius=0.5, params=EscapeParams(period=1.0, replan=20.0),
                        multi_point=True)
    escape.hits.add(wall(2.0, -2.0, 2.0))
    escape.waypoint(0.0, (1.0, 0.0))
    escape.waypoint(1.5, (1.0, 0.0))  # planned at 1.5 s: the turn begins
    for time in (21.5, 41.5):  # re-planned twice while still turning
        escape.waypoint(time, (1.0, 0.0))
        assert escape.turn_first(math.radians(120), time)
    assert escape.escapes == 3
    assert not escape.turn_first(math.radians(120), 61.6)  # 60 s from the turn's start, not from the last plan


def test_moving_or_turning_on_the_spot_is_not_standing():
    escape = TrapEscape(goal=(4.0, 0.0), radius=0.35, params=EscapeParams(period=100.0, standstill=10.0))
    escape.hits.add(wall(2.0, -2.0, 2.0))
    for k in range(200):  # 20 s creeping 1 cm a second along the wall: no progress to speak of, but moving
        escape.waypoint(k * 0.1, (1.0, 0.001 * k))
    assert not escape.escaping
    for k in range(200, 400):  # 20 s turning on the spot at 0.3 rad/s
        escape.waypoint(k * 0.1, (1.0, 0.2), heading=0.03 * (k - 200))
    assert not escape.escaping
