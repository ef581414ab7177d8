"""Bounding overwatch behaviour sets (Parker §6.3, Fig. 6-14) on hand-made observations and messages, no physics:
the join-group rule and the rebalancing of simultaneous joins, leader emergence (first to arrive, ties, a silent
leader replaced), and the alternation of bounds between the two groups' leaders."""
from __future__ import annotations

import math

import numpy as np
import pytest

from teamsim.controllers.base import Observation
from teamsim.controllers.behaviours.bounding_overwatch import (EMERGE, FOLLOW, JOIN, LEAD, OVERWATCH, DeadReckoning,
                                                               Driver, Knowledge, OverwatchParams, OverwatchRobot,
                                                               wedge)
from teamsim.positioning import PoseFix, wrap_angle
from teamsim.radio import Message

ROUTE = [(5.0, 2.0), (9.0, -2.0), (13.0, 2.0)]
GATHER = [(0.0, 2.0), (0.0, -2.0)]
TAU = 3.0
BEARINGS = np.linspace(-math.pi, math.pi, 10, endpoint=False)


def payload(group, kind="diffdrive", prio=5, joined=0.0, visited=True, leader=None, leading=None, at=(0.0, 0.0, 0.0),
            bounds=0, task=None) -> dict:
    return {"task": task, "group": group, "kind": kind, "prio": prio, "joined": joined, "visited": visited,
            "leader": leader, "leading": leading, "at": list(at), "v": 0.0, "bounds": bounds}


def heard(knowledge: Knowledge, **team) -> Knowledge:
    for name, data in team.items():
        knowledge.hear(name, data, 0.0, 0.0)
    knowledge.refresh()
    return knowledge


def obs(t: float, pose, inbox=(), ranges=None) -> Observation:
    ranges = np.full(10, math.inf) if ranges is None else ranges
    return Observation(time=t, robot="red", ir_raw=np.zeros(10), ir_range=ranges, ir_bearings=BEARINGS,
                       pose=PoseFix(pose[0], pose[1], pose[2], t), inbox=tuple(inbox), velocity=(0.0, 0.0))


def robot(name="red", kind="diffdrive", priority=0, leader_delay=1.0, seed=0, **params) -> OverwatchRobot:
    p = OverwatchParams(**{"max_wait": 0.0, **params})
    return OverwatchRobot(name, kind, ROUTE, GATHER, priority, leader_delay, np.random.default_rng(seed), p, tau=TAU)


def run(brain: OverwatchRobot, start: float, end: float, pose, messages=lambda t: ()) -> list:
    """Step ``brain`` every 0.1 s over [start, end) at ``pose`` (a function of time or fixed); the commands."""
    commands = []
    for k in range(round((end - start) / 0.1)):
        t = round(start + 0.1 * k, 3)
        commands.append(brain(obs(t, pose(t) if callable(pose) else pose, messages(t))))
    return commands


# -- join-group ------------------------------------------------------------------------------------------------------
def test_join_picks_the_group_with_fewest_of_my_kind():
    k = heard(Knowledge("red", "tricycle", 0, TAU, 3), a=payload("A", "tricycle"), b=payload("B", "diffdrive"),
              c=payload("B", "diffdrive"))
    assert k.choose(0.0) == "B" and k.choose(0.99) == "B"  # B is bigger but has no tricycle


def test_join_breaks_an_equal_kind_count_by_fewest_members():
    k = heard(Knowledge("red", "tricycle", 0, TAU, 3), a=payload("A", "tricycle"), b=payload("B", "tricycle"),
              c=payload("B", "diffdrive"))
    assert k.choose(0.0) == "A" and k.choose(0.99) == "A"


def test_join_breaks_a_full_tie_by_the_draw():
    k = heard(Knowledge("red", "tricycle", 0, TAU, 3), a=payload("A", "diffdrive"), b=payload("B", "diffdrive"))
    assert {k.choose(0.2), k.choose(0.8)} == {"A", "B"}


def test_the_wait_is_drawn_from_the_seeded_stream_within_max_wait():
    waits = [robot(seed=s, max_wait=10.0).wait for s in range(50)]
    assert all(0.0 <= w <= 10.0 for w in waits) and len(set(waits)) == 50
    assert robot(seed=3, max_wait=10.0).wait == robot(seed=3, max_wait=10.0).wait


def test_a_robot_waits_listening_then_joins_and_announces():
    brain = robot(max_wait=5.0, seed=1)
    wait = brain.wait
    early = run(brain, 0.0, wait - 0.05, (-3.0, 0.0, 0.0),
                lambda t: [Message("blue", t, payload("A", "diffdrive", visited=False))] if t == 0.5 else [])
    assert brain.group is None and all(c.v == 0.0 and c.broadcast["group"] is None for c in early)
    later = run(brain, round(math.ceil(wait * 10) / 10, 3), 8.0, (-3.0, 0.0, 0.0))
    assert brain.group == "B"  # blue, a diffdrive as red, went to A
    assert later[-1].broadcast["group"] == "B" and later[-1].broadcast["kind"] == "diffdrive"
    assert later[-1].behaviour == JOIN and later[-1].v > 0.0  # heading for B's gathering point


def test_only_the_latest_of_a_surplus_kind_moves_over():
    team = dict(a=payload("A", "tricycle", joined=1.0, prio=1), b=payload("A", "tricycle", joined=2.0, prio=2),
                c=payload("B", "diffdrive", joined=2.5, prio=3))
    latest = heard(Knowledge("red", "tricycle", 0, TAU, 3), **team)
    latest.me.group, latest.me.joined = "A", 3.0
    assert latest.should_switch()
    earlier = heard(Knowledge("red", "tricycle", 0, TAU, 3), **team)
    earlier.me.group, earlier.me.joined = "A", 1.5
    assert not earlier.should_switch()  # b joined A last: b moves, not red
    balanced = heard(Knowledge("red", "tricycle", 0, TAU, 3), a=payload("A", "tricycle"), b=payload("B", "tricycle"))
    balanced.me.group, balanced.me.joined = "A", 3.0
    assert not balanced.should_switch()


# -- emerge-leader ---------------------------------------------------------------------------------------------------
def joined_red(delay: float = 1.0, **params) -> OverwatchRobot:
    """red, told by blue's message that A lacks a diffdrive, joins A at its gathering point."""
    brain = robot(leader_delay=delay, **params)
    run(brain, 0.0, 0.3, GATHER[0] + (0.0,), lambda t: [Message("blue", 0.0, payload("B", visited=False))]
        if t == 0.0 else [])
    assert brain.group == "A" and brain.k.me.visited
    return brain


def test_the_first_to_arrive_emerges_as_leader_after_its_delay():
    brain = joined_red(delay=1.0)
    commands = run(brain, 0.3, 2.0, GATHER[0] + (0.0,))
    became = next(k for k, c in enumerate(commands) if c.broadcast["leader"] is not None)
    assert EMERGE in [c.behaviour for c in commands] and 0.9 <= became * 0.1 <= 1.4
    assert brain.is_leader and brain.leaderships[0].start == pytest.approx(0.3 + became * 0.1, abs=0.01)


def test_a_group_with_a_leader_heard_does_not_elect_another():
    brain = joined_red()
    green = lambda t: [Message("green", t, payload("A", prio=1, leader=0.1))] if round(t * 10) % 10 == 0 else []
    commands = run(brain, 0.3, 5.0, GATHER[0] + (0.0,), green)
    assert not brain.is_leader and EMERGE not in [c.behaviour for c in commands]


def test_an_earlier_claim_wins_and_equal_claims_go_to_priority():
    brain = joined_red()
    run(brain, 0.3, 2.0, GATHER[0] + (0.0,))
    since = brain.k.me.leader_since
    run(brain, 2.0, 2.2, GATHER[0] + (0.0,), lambda t: [Message("green", t, payload("A", prio=1, leader=since))])
    assert brain.is_leader  # same claim time: red's priority 0 beats green's 1
    run(brain, 2.2, 2.4, GATHER[0] + (0.0,), lambda t: [Message("green", t, payload("A", prio=1, leader=0.2))])
    assert not brain.is_leader and brain.leaderships[0].end == pytest.approx(2.2)


def test_a_silent_leader_is_replaced_after_tau():
    brain = joined_red(delay=1.0)
    green = lambda t: [Message("green", t, payload("A", prio=1, leader=0.1))] if t <= 2.0 and round(t * 10) % 10 == 0 \
        else []
    commands = run(brain, 0.3, 8.0, GATHER[0] + (0.0,), green)
    elected = brain.leaderships[0].start
    assert brain.is_leader and TAU + 2.0 <= elected <= TAU + 2.0 + 1.5  # green last heard at 2.0
    assert [c.behaviour for c in commands].count(EMERGE) >= 1


# -- bounding --------------------------------------------------------------------------------------------------------
def b_team(t: float, bounds: int = 0) -> list:
    """B's leader (magenta) and a member, gathered, at their point."""
    return [Message("magenta", t, payload("B", prio=5, leader=1.0, bounds=bounds, at=GATHER[1] + (0.0,))),
            Message("cyan", t, payload("B", prio=4, at=GATHER[1] + (0.0,)))]


def test_the_first_groups_leader_bounds_at_once_and_the_completion_is_broadcast():
    brain = joined_red()
    run(brain, 0.3, 2.0, GATHER[0] + (0.0,), b_team)
    assert brain.is_leader
    start = run(brain, 2.0, 3.5, GATHER[0] + (0.0,), b_team)
    assert start[-1].behaviour == LEAD and start[-1].broadcast["leading"] == 0 and start[-1].v >= 0.0
    end = run(brain, 3.5, 5.0, ROUTE[0] + (0.0,), b_team)  # arrived at waypoint 0
    assert end[-1].broadcast["bounds"] == 1 and end[-1].broadcast["leading"] is None
    assert end[-1].behaviour in (OVERWATCH, "idle")
    assert brain.bound_log[0].bound == 0 and brain.bound_log[0].end is not None
    later = run(brain, 5.0, 7.0, ROUTE[0] + (0.0,), b_team)
    assert later[-1].behaviour == OVERWATCH  # B's turn: red overwatches


def test_the_other_leader_bounds_when_it_hears_the_bound_complete():
    brain = robot("magenta", priority=5)
    red = lambda t, bounds=0, leading=0: [Message("red", t, payload("A", prio=0, leader=0.5, leading=leading,
                                                                    bounds=bounds, at=GATHER[0] + (0.0,)))]
    run(brain, 0.0, 2.5, GATHER[1] + (0.0,), lambda t: red(t))  # red leads A's bound 0: magenta joins B
    assert brain.group == "B" and brain.is_leader
    waiting = run(brain, 2.5, 4.0, GATHER[1] + (0.0,), lambda t: red(t))
    assert all(c.behaviour != LEAD for c in waiting) and waiting[-1].behaviour == OVERWATCH
    going = run(brain, 4.0, 6.0, GATHER[1] + (0.0,), lambda t: red(t, bounds=1, leading=None))
    assert going[-1].behaviour == LEAD and going[-1].broadcast["leading"] == 1
    assert brain.bound_log[-1].bound == 1 and brain.bound_log[-1].group == "B"


def test_a_member_follows_its_leader_while_it_leads_then_overwatches():
    brain = robot("green", priority=1)
    red = lambda t, bounds=0, leading=0: [Message("red", t, payload("A", prio=0, leader=0.2, leading=leading,
                                                                    bounds=bounds, at=(3.0, 2.0, 0.0)))] + b_team(t)
    blue = [Message("blue", 0.0, payload("B", visited=False))]  # so green (diffdrive) joins A
    run(brain, 0.0, 0.1, GATHER[0] + (0.0,), lambda t: blue)
    commands = run(brain, 0.1, 3.0, GATHER[0] + (0.0,), red)
    assert brain.group == "A" and commands[-1].behaviour == FOLLOW and commands[-1].v > 0.0
    done = run(brain, 3.0, 5.0, GATHER[0] + (0.0,), lambda t: red(t, bounds=1, leading=None))
    assert done[-1].behaviour == OVERWATCH and done[-1].v == 0.0


def test_the_leader_waits_for_a_lagging_follower_only_while_it_gains_ground():
    """A follower alive and talking but 10 m behind its wedge slot (a broken steering motor: robustness study, seed
    0) stops its leader; after ``patience`` without gaining 0.5 m the leader goes on, and waits again once it
    gains ground."""
    brain = joined_red(patience=5.0)
    run(brain, 0.3, 2.0, GATHER[0] + (0.0,), b_team)
    green = lambda t, x=-12.0: [Message("green", t, payload("A", prio=1, at=(x, 2.0, 0.0)))] + b_team(t)
    waiting = run(brain, 2.0, 6.0, GATHER[0] + (0.0,), green)
    leading = [c for c in waiting if c.behaviour == LEAD]
    assert leading and all(c.v == 0.0 for c in leading)
    going = run(brain, 6.0, 9.0, GATHER[0] + (0.0,), green)
    assert going[-1].behaviour == LEAD and going[-1].v > 0.0
    closer = run(brain, 9.0, 10.0, GATHER[0] + (0.0,), lambda t: green(t, x=-11.0))
    assert closer[-1].v == 0.0


def test_the_route_ends_after_its_last_bound():
    k = Knowledge("red", "diffdrive", 0, TAU, 3)
    assert [k.turn() for k.bounds in range(4)] == ["A", "B", "A", None]


# -- geometry and estimation ---------------------------------------------------------------------------------------
def test_the_wedge_fills_its_rows_nearest_the_track_first():
    p = OverwatchParams(wedge_back=2.0, wedge_side=1.0)
    assert [wedge(r, p) for r in range(5)] == [(-2.0, 1.0), (-2.0, -1.0), (-4.0, 0.0), (-4.0, 2.0), (-4.0, -2.0)]


def test_dead_reckoning_follows_odometry_and_pulls_towards_fixes():
    estimate = DeadReckoning(gain=0.5)
    first = Observation(0.0, "red", np.zeros(0), np.zeros(0), np.zeros(0), pose=PoseFix(0.0, 0.0, 0.0, 0.0),
                        velocity=(0.0, 0.0))
    estimate.update(first)
    moved = Observation(1.0, "red", np.zeros(0), np.zeros(0), np.zeros(0), pose=PoseFix(0.0, 0.0, 0.0, 0.0),
                        velocity=(0.5, 0.0))
    assert estimate.update(moved)[0] == pytest.approx(0.5)  # no new fix: odometry only
    fixed = Observation(1.1, "red", np.zeros(0), np.zeros(0), np.zeros(0), pose=PoseFix(1.0, 0.0, 0.0, 1.1),
                        velocity=(0.0, 0.0))
    assert estimate.update(fixed)[0] == pytest.approx(0.75)


def test_a_robot_that_goes_nowhere_backs_off_turning_towards_its_goal():
    p = OverwatchParams(stuck_time=4.0, escape_time=2.0)
    drive = Driver(p, omega_max=0.45, point_turns=False)
    wall = np.full(10, math.inf)
    wall[5] = 0.4  # something ahead (bearing 0), nearer than avoid_range: it slows, never stops
    pose = np.array([0.0, 0.0, 0.0])
    goal = np.array([0.0, 1.0])  # to its left
    commands = [drive(obs(0.1 * k, pose, ranges=wall), pose, goal, 0.3) for k in range(60)]
    assert commands[0][0] > 0.0 and commands[-1][0] == -0.12 and commands[-1][1] > 0.0
    assert drive.escapes == 1
    free = np.full(10, math.inf)
    assert drive(obs(8.5, pose, ranges=free), pose, goal, 0.3)[0] > 0.0  # the escape is over


def test_a_leader_held_off_its_waypoint_by_something_there_has_arrived_after_patience():
    """Within blocked_radius (2 m) of its waypoint and gaining less than 0.5 m for patience (30 s), the leader is as
    near as it gets (a dead leader lay beside the waypoint: seed 41). Held back for its followers it is not
    blocked; farther off, or gaining ground, it drives on."""
    p = OverwatchParams()
    leader = robot("red")
    near = p.blocked_radius - 0.05
    assert not leader._blocked(0.0, near, 1.0)
    assert not leader._blocked(p.patience - 1.0, near - 0.3, 1.0)  # (gained less than PROGRESS: still the clock)
    assert not leader._blocked(p.patience + 1.0, near - 0.3, 0.5)  # held back for a follower
    assert leader._blocked(p.patience + 1.0, near - 0.3, 1.0)
    far = robot("blue")
    assert not any(far._blocked(t, p.blocked_radius + 0.1, 1.0) for t in (0.0, 3 * p.patience))
    gaining = robot("cyan")
    assert not any(gaining._blocked(t, near - 0.6 * k, 1.0) for k, t in enumerate((0.0, p.patience / 2 + 1)))
    assert not gaining._blocked(p.patience + 2.0, near - 0.6, 1.0)  # the clock restarted when it gained 0.6 m


# Real readings (bounding-overwatch, leader killed): the next leader in the crowd at the gathering point.
SEED167_RANGES = np.array([0.21, 0.976, 0.838, math.inf, math.inf, math.inf, math.inf, 0.079, math.inf, math.inf])
SEED167_BEARINGS = np.arange(10) * 0.6283  # a differential drive's ten IR sensors
SEED126_RANGES = np.array([0.147, math.inf, math.inf, math.inf, math.inf, math.inf, 0.422, math.inf, math.inf, 1.142,
                           0.331])
SEED126_BEARINGS = np.arange(11) * 0.5712  # a tricycle's eleven


def reading(t: float, pose, ranges, bearings) -> Observation:
    return Observation(time=t, robot="cyan", ir_raw=np.zeros(len(ranges)), ir_range=ranges, ir_bearings=bearings,
                       pose=PoseFix(pose[0], pose[1], pose[2], t), velocity=(0.0, 0.0))


def test_a_trapped_leader_heads_through_the_clear_gap_nearest_its_waypoint():
    """kill:@leader@48.9, seed 167, t = 116 s: a differential drive among three robots (one its dead predecessor),
    its waypoint at bearing 0.18 rad. Pushed by the IR it turns left, away from the waypoint (it spun in place for
    850 s); through the gap it turns right, towards the clear ray at 0.21 rad."""
    pose = np.array([-8.014, 1.639, 1.463])
    goal = np.array([-3.25, 2.5]) - pose[:2]
    drive = Driver(OverwatchParams(), omega_max=0.45, point_turns=True)
    seen = reading(116.0, pose, SEED167_RANGES, SEED167_BEARINGS)
    assert drive(seen, pose, goal, 0.25)[1] > 0.0
    gap = drive._gap(seen, pose, goal)
    assert math.atan2(gap[1], gap[0]) == pytest.approx(wrap_angle(pose[2] + SEED167_BEARINGS[8]))
    v, omega = drive(seen, pose, goal, 0.25, through_gap=True)
    assert v == 0.0 and omega == pytest.approx(-0.45)  # a point turn first: the gap is 1.26 rad to its right
    blind = reading(116.0, pose, np.full(10, 0.1), SEED167_BEARINGS)
    assert np.allclose(drive._gap(blind, pose, goal), goal)  # no clear ray: the goal's direction


def test_a_leader_that_gains_no_ground_far_from_its_waypoint_is_trapped_after_patience():
    """Beyond blocked_radius, not held back, no nearer by 0.5 m for patience: trapped, until it gains ground."""
    p = OverwatchParams()
    far = p.blocked_radius + 3.0
    leader = robot("red")
    assert not leader._trapped(0.0, far, 1.0)
    assert not leader._trapped(p.patience - 1.0, far - 0.3, 1.0)
    assert leader._trapped(p.patience + 1.0, far - 0.3, 1.0)
    assert not leader._trapped(p.patience + 2.0, far - 0.9, 1.0)  # gained 0.9 m: the clock restarts
    held = robot("blue")
    assert not any(held._trapped(t, far, 0.5) for t in (0.0, 3 * p.patience))  # waiting for its followers
    near = robot("cyan")
    assert not any(near._trapped(t, p.blocked_radius - 0.1, 1.0) for t in (0.0, 3 * p.patience))


def test_a_tricycle_backs_off_what_is_ahead_for_escape_time_turning_to_its_goal_side():
    """kill:@leader@14, seed 126, t = 92.2 s: a tricycle 0.15 m from its dead predecessor, its want (goal and IR
    push) to its left. It backs off for escape_time with its nose swinging left, also once the reading clears.
    (Backing one step at a time with the turn reversed, each creep's turn was undone: 820 s at 0.2 m.)"""
    p = OverwatchParams()
    pose = np.array([-9.23, 1.725, 0.859])
    goal = np.array([-3.25, 2.5]) - pose[:2]
    drive = Driver(p, omega_max=0.45, point_turns=False)
    assert drive(reading(92.2, pose, SEED126_RANGES, SEED126_BEARINGS), pose, goal, 0.25) == (-0.12, 0.4)
    clear = np.full(11, math.inf)
    during = [drive(reading(92.3 + 0.1 * k, pose, clear, SEED126_BEARINGS), pose, goal, 0.25)
              for k in range(round(p.escape_time / 0.1) - 2)]
    assert all(command == (-0.12, 0.4) for command in during)
    assert drive(reading(92.2 + p.escape_time + 0.1, pose, clear, SEED126_BEARINGS), pose, goal, 0.25)[0] > 0.0
