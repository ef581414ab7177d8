"""Keeping formation's behaviours (Parker §7.2), without physics: the line's geometry, each strategy's place, strategy
IV's lanes, the follower's drive laws, the teammate tracker and the leader's pacing."""
from __future__ import annotations

import math

import numpy as np
import pytest

from teamsim.controllers.base import Observation
from teamsim.controllers.behaviours.formation import (SIGNAL, Crossing, Goal, KeepFormation, KeepFormationParams,
                                                      Lanes, Line, RouteLeader, Track, place, swerve)
from teamsim.models import build_robot
from teamsim.positioning import PoseFix

LINE = Line(("A", "B", "C", "D"), "B", 1.2)  # Fig. 7-1
SQUARE = np.array([(0.0, 0.0), (10.0, 0.0), (10.0, 10.0)])  # a left turn of 90 degrees at (10, 0)


def test_offsets_and_assigned_neighbours_follow_fig_7_1():
    assert [LINE.offset(n) for n in LINE.names] == pytest.approx([1.2, 0.0, -1.2, -2.4])
    assert [LINE.reference(n) for n in ("A", "C", "D")] == ["B", "B", "C"]  # A left of B, C right of B, D of C
    assert LINE.sensed("D", "I") == ("C",)
    assert LINE.sensed("D", "II") == ("C", "B")  # from II on, the leader too
    assert LINE.sensed("B", "IV") == ("A", "C")


def test_strategy_i_places_a_robot_in_its_neighbours_frame_so_a_turned_round_neighbour_breaks_the_line():
    poses = {"B": np.array([0.0, 0.0, 0.0]), "C": np.array([0.0, -1.2, 0.0])}
    goal = place("I", LINE, "D", poses, None, None, 0)
    assert goal.point == pytest.approx([0.0, -2.4]) and goal.pace_of == "C" and not goal.lane
    poses["C"] = np.array([0.0, -1.2, math.pi])  # C turned round (Parker: "C turns around")
    assert place("I", LINE, "D", poses, None, None, 0).point == pytest.approx([0.0, 0.0], abs=1e-9)  # D's place
    # is now on C's other side, where the leader is: D ends up out of formation


def test_strategy_ii_places_across_the_leaders_heading_and_iii_across_the_announced_way():
    poses = {"B": np.array([1.0, 1.0, math.pi / 2])}
    assert place("II", LINE, "C", poses, None, None, 0).point == pytest.approx([2.2, 1.0])
    news = ((1.0, 1.0), (11.0, 1.0))  # announced at (1, 1): the next waypoint is due east
    goal = place("III", LINE, "C", poses, news, None, 0)
    assert goal.point == pytest.approx([1.0, -0.2]) and goal.heading == pytest.approx(0.0) and goal.lane
    assert place("II", LINE, "C", {"C": np.zeros(3)}, None, None, 0) is None  # the leader not sensed yet


def test_strategy_iv_lanes_stop_the_inside_robot_at_its_corner_before_the_leader_reaches_its_own():
    lanes = Lanes(SQUARE)
    assert lanes.corner_shift(1, 1.2) == pytest.approx(1.2)  # 1.2 tan(45 degrees)
    assert lanes.span(0, 1.2)[1] == pytest.approx(8.8)  # inside: the lane's leg ends 1.2 m early
    assert lanes.span(0, -1.2)[1] == pytest.approx(11.2)  # outside: 1.2 m late
    leader = np.array([9.5, 0.0])
    inside, heading, moving = lanes.place(0, 1.2, leader)
    assert inside == pytest.approx([8.8, 1.2]) and heading == pytest.approx(0.0) and not moving
    outside, _, moving = lanes.place(0, -1.2, leader)
    assert outside == pytest.approx([9.5, -1.2]) and moving
    # after the turn the inside robot's place is the same corner until the leader comes abreast of it
    assert lanes.place(1, 1.2, np.array([10.0, 0.5]))[0] == pytest.approx([8.8, 1.2])


def test_the_leaders_leg_advances_once_it_has_turned_at_the_corner_one_leg_at_a_time():
    lanes = Lanes(np.array([(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)]))
    assert lanes.leg_of(0, np.array([9.0, 0.0]), 0.0, 1.0) == 0
    assert lanes.leg_of(0, np.array([9.9, 0.1]), 0.3, 1.0) == 0  # at the corner, not yet turned
    assert lanes.leg_of(0, np.array([9.9, 0.1]), 1.2, 1.0) == 1
    assert lanes.leg_of(0, np.array([10.0, 9.9]), math.pi / 2, 1.0) == 1  # far along leg 1: one leg per call


def test_a_lane_goal_counts_a_robot_ahead_as_waiting_and_a_point_goal_counts_every_metre():
    lane = Goal(np.array([0.0, 0.0]), 0.0, "B", True)
    assert lane.lag(np.array([-2.0, 0.0])) == pytest.approx(2.0)
    assert lane.shortfall(np.array([2.0, 0.0])) == pytest.approx(0.0)  # ahead on its lane: waiting
    assert lane.shortfall(np.array([2.0, 0.5])) == pytest.approx(0.5)
    point = Goal(np.array([0.0, 0.0]), 0.0, "B", False)
    assert point.shortfall(np.array([2.0, 0.0])) == pytest.approx(2.0)


@pytest.fixture(scope="module")
def follower():
    return KeepFormation(build_robot("diffdrive", "C"), LINE, "IV", KeepFormationParams(), np.random.default_rng(0),
                         SQUARE)


def test_a_lane_keeper_ahead_of_its_place_waits_and_one_behind_drives_at_its_pace_plus_the_lag(follower):
    goal = Goal(np.array([5.0, 0.0]), 0.0, "B", True)
    v, _ = follower.keep_lane(np.array([6.0, 0.0, 0.0]), goal, pace=0.3)
    assert v == pytest.approx(0.0)
    v, omega = follower.keep_lane(np.array([4.8, 0.0, 0.0]), goal, pace=0.3)
    assert v == pytest.approx(0.3 + 0.8 * 0.2) and omega == pytest.approx(0.0)
    v, _ = follower.keep_lane(np.array([2.0, 0.0, 0.0]), goal, pace=0.3)
    assert v == pytest.approx(0.5)  # catch_up caps it


def test_a_point_follower_backs_into_a_place_just_behind_it_instead_of_turning_round(follower):
    goal = Goal(np.array([0.0, 0.0]), 0.0, "B", False)
    v, omega = follower.make_for(np.array([0.4, 0.0, 0.0]), goal, pace=0.0)
    assert v < 0 and omega == pytest.approx(0.0)
    v, omega = follower.make_for(np.array([3.0, 0.0, 0.0]), goal, pace=0.0)  # far behind: turn round
    assert v == 0.0 and abs(omega) > 0


def test_the_tracker_learns_a_teammates_velocity_from_noisy_positions():
    track, rng = Track(KeepFormationParams()), np.random.default_rng(1)
    for k in range(60):
        t = 0.6 * k
        track.update(np.array([0.3 * t, 1.0]) + rng.normal(0, 0.05, 2), 0.0, t)
    assert track.velocity == pytest.approx([0.3, 0.0], abs=0.05)
    assert track.pose(36.0)[:2] == pytest.approx([0.3 * 36.0, 1.0], abs=0.15)


BEARINGS = np.linspace(-math.pi, math.pi, 10, endpoint=False)


def observation(time: float, pose, sensed: dict, ranges=None) -> Observation:
    return Observation(time=time, robot="B", ir_raw=np.zeros(10),
                       ir_range=np.full(10, np.inf) if ranges is None else np.asarray(ranges, float),
                       ir_bearings=BEARINGS, pose=PoseFix(*pose, time), motor_speeds=np.zeros(2),
                       signals={SIGNAL: sensed})


def test_swerve_pushes_away_from_near_readings_only():
    params = KeepFormationParams()
    ranges = np.full(10, np.inf)
    assert swerve(observation(0.0, (0, 0, 0), {}, ranges), params) == pytest.approx([0.0, 0.0])
    ranges[5] = 0.3  # dead ahead (bearing 0), half the swerve range away
    assert swerve(observation(0.0, (0, 0, 0), {}, ranges), params) == pytest.approx([-0.75, 0.0])
    ranges[5] = 0.7  # a neighbour in the line, 0.7 m off: no push
    assert swerve(observation(0.0, (0, 0, 0), {}, ranges), params) == pytest.approx([0.0, 0.0])


def test_a_crossing_robot_waits_for_its_time_then_gives_way_to_what_is_ahead_for_a_while():
    robot = build_robot("diffdrive", "X1")
    driver = RouteLeader(robot, Line(("X1",), "X1", 1.2), "II", KeepFormationParams(), np.random.default_rng(0),
                         np.array([(0.0, 0.0), (10.0, 0.0)]), announce=False)
    crossing = Crossing(driver, robot, start_at=5.0)
    ahead = np.full(10, np.inf)
    ahead[robot.ir_bearings.tolist().index(min(robot.ir_bearings, key=abs))] = 0.3
    assert crossing(observation(0.0, (0.0, 0.0, 0.0), {})).behaviour == "wait"
    assert crossing(observation(6.0, (0.0, 0.0, 0.0), {})).behaviour == "follow-route"
    assert crossing(observation(7.0, (0.0, 0.0, 0.0), {}, ahead)).behaviour == "give-way"
    assert crossing(observation(7.0 + 16.0, (0.0, 0.0, 0.0), {}, ahead)).behaviour != "give-way"  # 15 s at most


@pytest.mark.parametrize("c_at, share", [((0.0, -1.2), 1.0), ((-2.0, -1.2), 0.0)])
def test_the_leader_drives_on_while_its_neighbours_keep_up_and_waits_for_one_that_lags(c_at, share):
    leader = RouteLeader(build_robot("diffdrive", "B"), LINE, "II", KeepFormationParams(), np.random.default_rng(0),
                         SQUARE)
    sensed = {"A": (0.0, 1.2, 0.0, 0.0), "C": (*c_at, 0.0, 0.0)}
    command = leader(observation(0.0, (0.0, 0.0, 0.0), sensed))
    assert leader.pace(leader.sense(observation(0.0, (0.0, 0.0, 0.0), sensed), np.zeros(3)), np.zeros(3)) \
        == pytest.approx(share)
    assert command.broadcast == {"waypoint": [10.0, 0.0]}  # strategy III's news rides on every broadcast


# -- a failed teammate (ALLIANCE's takeover, spec §1; docs/decisions.md, "Keeping formation") ---------------------

def test_with_robots_failed_each_robot_keeps_its_place_re_links_past_them_and_the_nearest_living_one_leads():
    no_b = Line(LINE.names, "B", 1.2, frozenset({"B"}))
    assert no_b.acting == "C"  # A and C are as near B's place: C is nearer the line's middle
    assert no_b.offset("A") == pytest.approx(1.2)  # places stay: B's is left empty
    assert no_b.reference("A") == "C" and no_b.reference("D") == "C"
    assert no_b.neighbours("A") == ("C",) and no_b.neighbours("C") == ("A", "D")
    assert no_b.sensed("D", "II") == ("C",)  # its neighbour is the acting leader
    no_c = Line(LINE.names, "B", 1.2, frozenset({"C"}))
    assert no_c.acting == "B" and no_c.reference("D") == "B" and no_c.neighbours("B") == ("A", "D")
    assert Line(LINE.names, "B", 1.2, frozenset(LINE.names)).acting is None
    # The leader's place is found from the acting leader's pose, so every robot's place is where it was.
    poses = {"C": np.array([2.0, 1.0 - 1.2, 0.0])}
    assert no_b.lead(poses) == pytest.approx([2.0, 1.0, 0.0])
    assert place("II", no_b, "D", poses, None, None, 0).point == pytest.approx([2.0, 1.0 - 2.4])
    assert place("I", no_b, "A", poses, None, None, 0).point == pytest.approx([2.0, 1.0 + 1.2])


def test_a_lane_as_waypoints_is_the_route_moved_aside_with_mitred_corners():
    lane = Lanes(SQUARE).lane(-1.2)  # on the outside of the left turn
    assert lane == pytest.approx(np.array([(0.0, -1.2), (11.2, -1.2), (11.2, 10.0)]))


def heard(time: float, pose, sensed: dict, present) -> Observation:
    return Observation(time=time, robot="C", ir_raw=np.zeros(10), ir_range=np.full(10, np.inf),
                       ir_bearings=BEARINGS, pose=PoseFix(*pose, time), motor_speeds=np.zeros(2),
                       robots_present=frozenset(present), signals={SIGNAL: sensed})


def test_a_teammate_silent_on_the_radio_and_standing_still_has_failed_one_that_moves_has_not():
    follower = KeepFormation(build_robot("diffdrive", "C"), LINE, "IV", KeepFormationParams(),
                             np.random.default_rng(0), SQUARE)
    for k in range(30):  # 18 s: B leads on, D stands (dead) and is silent
        t = 0.6 * k
        follower.sense(heard(t, (0.18 * k, 0.0, 0.0), {"B": (0.0, 1.2, 0.0, t), "D": (-0.18 * k, -1.2, 0.0, t)},
                             {"A", "B"}), np.array([0.18 * k, 0.0, 0.0]))
        if t < 10.0:
            assert follower.failed == frozenset()
    assert follower.failed == {"D"}  # dead_after (10 s) of standing silent
    assert follower.view.neighbours("C") == ("B",) and "D" in follower.sensing()  # still looked at
    follower.sense(heard(18.0, (5.4, 0.0, 0.0), {}, {"A", "B", "D"}), np.array([5.4, 0.0, 0.0]))
    assert follower.failed == frozenset()  # heard again (revived)


def test_a_robot_that_hears_nobody_doubts_its_radio_not_its_standing_teammates():
    follower = KeepFormation(build_robot("diffdrive", "C"), LINE, "IV", KeepFormationParams(),
                             np.random.default_rng(0), SQUARE)
    for k in range(30):
        t = 0.6 * k
        follower.sense(heard(t, (0.0, 0.0, 0.0), {"B": (0.0, 1.2, 0.0, t), "D": (0.0, -1.2, 0.0, t)}, ()),
                       np.zeros(3))
    assert follower.failed == frozenset()


def test_a_follower_takes_over_follow_route_along_its_own_lane_when_the_leader_is_gone():
    follower = KeepFormation(build_robot("diffdrive", "C"), LINE, "II", KeepFormationParams(),
                             np.random.default_rng(0), SQUARE)
    command = follower(heard(0.0, (0.0, -1.2, 0.0), {"B": (0.0, 1.2, 0.0, 0.0)}, {"A", "B", "D"}))
    assert command.behaviour == "keep-formation"
    for t in (1.0, 2.0, 3.0, 3.7):  # B taken out of the arena: neither heard nor seen any more
        command = follower(heard(t, (0.0, -1.2, 0.0), {}, {"A", "D"}))
    assert follower.failed == {"B"} and follower.view.acting == "C"
    assert command.behaviour == "follow-route" and command.broadcast == {"waypoint": [10.0, 0.0]}
    assert follower.route == pytest.approx(np.array([(0.0, -1.2), (11.2, -1.2), (11.2, 10.0)]))  # its lane
