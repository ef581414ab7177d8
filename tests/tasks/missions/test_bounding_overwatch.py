"""End to end: Parker's bounding overwatch in physics (§6.3, Fig. 6-15), through the real World, with fixed seeds.

What the thesis describes and these tests check, on a three-waypoint route (the default has five): the eight
robots split into two groups with two of each kind, a leader emerges in each, and the groups alternate, one
bounding (its leader leading, the others following) while the other overwatches, until the last bound reaches the
route's end; with the leader of the bounding group killed mid-bound (by its role, ``kill:@leader@T``, resolved when
the fault is due), a new leader emerges in that group and the bounding goes on. Same seed, same trial. Bad input is
one line and exit status 2. The measurements over many seeds are in docs/bounding-overwatch.md.

Each trial runs once (functools.cache) and is read by several tests.
"""
from __future__ import annotations

import functools
import json
import math
from dataclasses import dataclass

import pytest

from teamsim.cli import main
from teamsim.config import TrialConfig
from teamsim.controllers.behaviours.bounding_overwatch import FOLLOW, GROUPS, LEAD, OVERWATCH
from teamsim.faults import parse_fault
from teamsim.runner import mission_of, state_digest
from teamsim.scenario import resolve
from teamsim.world import World

MISSION = mission_of("bounding-overwatch")
SEED = 1
WAYPOINTS = 3


@dataclass
class Trial:
    world: World
    completed: bool
    metrics: dict
    actives: list  # (time, {robot: behaviour, or "dead"}) every control period
    ends: dict  # bound -> {robot: true (x, y)} when the bound's completion was logged


@functools.cache
def trial(seed: int = SEED, *faults: str, duration: float = 400.0) -> Trial:
    config = resolve(TrialConfig(mission="bounding-overwatch", params=MISSION.Params(waypoints=WAYPOINTS), seed=seed,
                                 faults=[parse_fault(f) for f in faults]), MISSION)
    world = World(config, MISSION)
    actives, ends = [], {}
    while world.time < duration and not MISSION.done(world):
        world.tick()
        actives.append((world.time, {n: r.behaviour if r.active else "dead" for n, r in world.robots.items()}))
        for record in MISSION.bounds(world):
            if record.end is not None and record.bound not in ends:
                ends[record.bound] = {n: tuple(world.pose(r)[:2]) for n, r in world.robots.items()}
        world.advance(world.steps_per_tick)
    completed, metrics = MISSION.outcome(world)
    return Trial(world, completed, metrics, actives, ends)


def completed_bounds(metrics: dict) -> list:
    """[bound, group, leader, start, end] of the completed bounds, in order."""
    return [row for row in metrics["bounds"] if row[4] is not None]


def test_two_groups_of_two_of_each_kind():
    metrics = trial().metrics
    assert metrics["group_kinds"] == {g: {"diffdrive": 2, "tricycle": 2} for g in GROUPS}
    assert sorted(g for g, _ in metrics["groups"].values()) == ["A"] * 4 + ["B"] * 4


def test_a_leader_emerges_in_each_group_and_leads_its_bounds():
    metrics = trial().metrics
    leaders = {group: robot for group, robot, _, _ in metrics["leaders"]}
    assert set(leaders) == set(GROUPS) and len(metrics["leaders"]) == 2
    assert all(metrics["groups"][robot][0] == group for group, robot in leaders.items())
    assert all(leader == leaders[group] for _, group, leader, _, _ in completed_bounds(metrics))


def test_the_groups_alternate_along_the_route_to_its_end():
    t = trial()
    bounds = completed_bounds(t.metrics)
    assert t.completed and t.metrics["alternated"]
    assert [(b[0], b[1]) for b in bounds] == [(k, GROUPS[k % 2]) for k in range(WAYPOINTS)]
    assert all(a[4] <= b[3] for a, b in zip(bounds, bounds[1:]))  # one bound at a time
    route = t.world.scene.scenario.task.route
    for k, group, leader, _, _ in bounds:
        at = t.ends[k]
        assert math.dist(at[leader], route[k]) < 1.0  # the leader really reached its waypoint
        members = [n for n, (g, _) in t.metrics["groups"].items() if g == group]
        assert all(math.dist(at[n], route[k]) < 6.0 for n in members)  # its group came along


def test_while_one_group_bounds_the_other_overwatches():
    t = trial()
    groups = {n: g for n, (g, _) in t.metrics["groups"].items()}
    for k, group, leader, start, end in completed_bounds(t.metrics):
        during = [a for time, a in t.actives if start + 3.0 <= time <= end - 1.0]  # (news takes a radio period)
        other = [n for n, g in groups.items() if g != group]
        followers = [n for n, g in groups.items() if g == group and n != leader]
        assert all(a[leader] == LEAD for a in during)
        assert sum(a[n] == OVERWATCH for a in during for n in other) >= 0.95 * len(during) * len(other)
        assert sum(a[n] == FOLLOW for a in during for n in followers) >= 0.9 * len(during) * len(followers)


def leader_kill() -> tuple[str, str, float, Trial]:
    """The leader of the second bound killed 10 s into that bound, by its role (``kill:@leader@T``: whoever leads
    the bounding group then); the run without faults says who that is and when the bound starts."""
    _, group, leader, start, _ = completed_bounds(trial().metrics)[1]
    at = round(start + 10.0, 1)
    return group, leader, at, trial(SEED, f"kill:@leader@{at}")


def test_a_killed_leader_is_replaced_and_the_bounding_goes_on():
    group, dead, at, t = leader_kill()
    # The role was resolved when the fault was due: to the leader of the bound under way.
    assert t.world.fault_report() == [{"kind": "kill", "robot": "@leader", "time": at, "hit": dead, "hit_at": at}]
    assert t.metrics["gone"] == {dead: at}
    claims = [row for row in t.metrics["leaders"] if row[0] == group and row[1] != dead]
    # Survivors whose impatience crossed within one radio period of the first claim claim too (they had not heard
    # it yet); the earliest claim wins, and the others step down as soon as they hear it.
    holders = [row for row in claims if row[3] is None]
    assert len(holders) == 1 and all(row[3] - row[2] <= 1.5 for row in claims if row[3] is not None)
    _, successor, elected, _ = holders[0]
    assert elected == min(row[2] for row in claims)
    assert t.metrics["groups"][successor][0] == group
    assert at < elected < at + 10.0  # tau, then the most impatient survivor's delay
    assert t.completed and t.metrics["alternated"]
    bounds = completed_bounds(t.metrics)
    assert [b[1] for b in bounds] == [GROUPS[k % 2] for k in range(WAYPOINTS)]
    assert bounds[1][2] == successor  # the successor finished the dead leader's bound
    assert all(b[2] != dead for b in bounds[1:])
    assert t.metrics["final_behaviour"][dead] == "dead"


def test_same_seed_same_trial():
    def run():
        config = resolve(TrialConfig(mission="bounding-overwatch", params=MISSION.Params(), seed=3), MISSION)
        world = World(config, MISSION)
        while world.time < 15.0:
            world.tick()
            world.advance(world.steps_per_tick)
        return state_digest(world), [b.joins for b in world.scene.info["brains"].values()]
    assert run() == run()


@pytest.mark.parametrize("argv, fragment", [
    (["--set", "task.route=[[0, 0]]"], "task.route: needs at least two waypoints"),
    (["--set", "task.gather=[[0, 0]]"], "task.gather: needs exactly two gathering points"),
    (["--set", "task.route=[[0, 0], [90, 0]]"], "task.route[1]: (90, 0) is outside the field"),
    (["--set", "robots.red.kind=r2"], "robots.red.kind='r2': bounding overwatch is done by wheeled robots"),
    (["--set", "robots.red.controller.priority=1"], "robots.green.controller.priority=1: robots.red has it too"),
    (["--set", "per_kind=9"], "per_kind=9"),
    (["--fault", "add-robot:newbie@5,kind=diffdrive"], "--fault add-robot:newbie: the bounding overwatch team is"),
    (["--fault", "kill:@boss@5"], "faults[0] kill:@boss@5: bounding-overwatch has no role 'boss'; allowed roles: "
                                  "@leader, @leader:A, @leader:B"),
    (["--fault", "break-motor:@leader@5,motor=steer"], "(the role may fall to "),  # a diffdrive has no steer motor
    (["--fault", "revive:@leader@5"], "revive needs a robot's name, not a role"),
])
def test_bad_input_is_one_line_and_exit_2(capsys, tmp_path, argv, fragment):
    code = main(["run", "bounding-overwatch", *argv, "--duration", "1", "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1, err
    assert fragment in err


def test_a_fault_by_role_waits_for_the_role_and_the_run_records_whom_it_struck(tmp_path):
    """kill:@leader@0: no leader yet, so it waits; the first leader of the bounding group (A) is struck the moment
    it claims, and events.jsonl and summary.json name it."""
    code = main(["run", "bounding-overwatch", "--seed", str(SEED), "--duration", "40", "--fault", "kill:@leader@0",
                 "--out", str(tmp_path), "--run-id", "x"])
    run = tmp_path / "bounding-overwatch" / "x"
    summary = json.loads((run / "summary.json").read_text())
    events = [json.loads(line) for line in (run / "events.jsonl").read_text().splitlines()]
    assert code == 1 and summary["status"] == "failed"  # (40 s is too short to finish the route)
    waiting = [e for e in events if e["event"] == "fault-waiting"]
    struck = [e for e in events if e["event"] == "fault"]
    assert len(waiting) == 1 and waiting[0]["t"] == 0.0 and waiting[0]["robot"] == "@leader"
    assert len(struck) == 1 and struck[0]["target"] == "@leader" and struck[0]["time"] == 0.0
    dead, at = struck[0]["robot"], struck[0]["t"]
    assert summary["faults"] == [{"kind": "kill", "robot": "@leader", "time": 0.0, "hit": dead, "hit_at": at}]
    first = next(row for row in summary["metrics"]["leaders"] if row[0] == "A")
    assert first[1] == dead and at - first[2] <= 0.2  # (struck at the control tick its claim was made)
    assert summary["robots"][dead]["alive"] is False
