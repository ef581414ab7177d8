"""End to end: Parker's keeping formation (§7.2) in physics, through the real World, with fixed seeds.

The routes the mission draws; the local sensing; strategy IV keeping a 4-robot line through sharp corners to the
end of its route, and strategy I's line breaking there (§7.2: "it fails on sharp turns"); the metric sampled
once a second; determinism; bad input as one line and exit 2. The strategies' comparison at the thesis's sample
size is the study's (`teamsim study formation`, docs/formation.md).
"""
from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from teamsim.cli import main
from teamsim.config import TrialConfig
from teamsim.controllers.behaviours.formation import SIGNAL
from teamsim.faults import parse_fault
from teamsim.positioning import wrap_angle
from teamsim.runner import mission_of, state_digest
from teamsim.scenario import resolve
from teamsim.tasks.missions.formation import FormationParams, draw_route
from teamsim.world import World

MISSION = mission_of("formation")
SEED = 1  # a sharp route with a left and a right corner of 80-110 degrees


def world_of(seed: int = SEED, **params) -> World:
    config = resolve(TrialConfig(mission="formation", params=FormationParams(**params), seed=seed), MISSION)
    return World(config, MISSION)


def run(world: World, duration: float) -> World:
    while world.time < duration and not MISSION.done(world):
        world.tick()
        world.advance(world.steps_per_tick)
    return world


@functools.lru_cache(maxsize=None)
def finished(strategy: str):
    world = run(world_of(strategy=strategy), 400.0)
    return MISSION.outcome(world)


def turns(route: np.ndarray) -> np.ndarray:
    legs = np.diff(route, axis=0)
    headings = np.arctan2(legs[:, 1], legs[:, 0])
    return np.array([wrap_angle(b - a) for a, b in zip(headings, headings[1:])])


@pytest.mark.parametrize("seed", range(5))
def test_a_sharp_route_turns_80_to_110_degrees_alternately_and_a_smooth_one_by_arcs(seed):
    sharp = draw_route(np.random.default_rng(seed), FormationParams(turns=3))
    angles = turns(sharp)
    assert len(sharp) == 5 and np.all(np.abs(angles) >= math.radians(80) - 1e-9)
    assert np.all(np.abs(angles) <= math.radians(110) + 1e-9) and np.all(angles[1:] * angles[:-1] < 0)
    smooth = draw_route(np.random.default_rng(seed), FormationParams(turns=3, route="smooth"))
    assert np.all(np.abs(turns(smooth)) <= math.radians(30) + 1e-9)
    assert np.allclose(smooth[[0, -1]], sharp[[0, -1]])  # the same legs, corners rounded


def test_robots_sense_their_neighbours_and_from_strategy_ii_the_leader_relative_to_themselves():
    for strategy, sensed in (("I", {"C"}), ("II", {"C", "B"})):
        world = world_of(strategy=strategy)
        readings = MISSION.sense(world, "D")[SIGNAL]
        assert set(readings) == sensed
        dx, dy, dheading, _ = readings["C"]  # C starts 1.2 m to D's left, heading the same way
        assert (dx, dy, dheading) == pytest.approx((0.0, 1.2, 0.0), abs=0.1)
        assert MISSION.sense(world, "D")[SIGNAL] is readings  # held until the next positioning period


def test_strategy_iv_keeps_the_line_through_sharp_corners_to_the_end_of_the_route():
    completed, metrics = finished("IV")
    assert completed
    assert metrics["turned_round_s"] <= 5 and metrics["order_broken_s"] <= 5  # 4 s and 0 s measured
    assert metrics["normalised_error"] < 2.0  # m summed over three followers (1.39 m measured at this seed)
    assert len(metrics["fe"]) == math.floor(metrics["mission_time_s"]) + 1  # fe_t at every integer second


def test_strategy_i_breaks_the_line_on_sharp_corners_where_iv_does_not():
    _, local = finished("I")
    _, route = finished("IV")
    assert local["order_broken_s"] >= 10 and local["turned_round_s"] >= 10  # 53 s and 29 s measured
    assert local["normalised_error"] > route["normalised_error"]


def test_a_crossing_team_drives_across_the_middle_leg_once_its_time_comes():
    world = world_of(crossing=2, strategy="II")
    crossers = {n: r for n, r in world.scene.scenario.robots.items() if n.startswith("X")}
    assert set(crossers) == {"X1", "X2"}
    start_at = crossers["X1"].controller.start_at
    assert start_at > 0
    before = world.pose(world.robots["X1"])[:2].copy()
    run(world, start_at + 15.0)
    assert np.linalg.norm(world.pose(world.robots["X1"])[:2] - before) > 2.0


def test_when_the_leader_is_taken_out_the_nearest_living_robot_leads_on_and_the_rest_keep_their_places():
    """Seed 0, ``remove:B@74.6`` (docs/results/robustness/report.md): B, the leader, carried out of the arena; it
    failed at 600 s with the followers sensing B parked outside and nobody leading. Now C, as near B's place as A
    and nearer the line's middle, takes over follow-route along its own lane within tau plus lost_after, and the
    living line completes with B's place left empty (130.9 s measured)."""
    config = resolve(TrialConfig(mission="formation", params=FormationParams(), seed=0), MISSION)
    config.faults = [parse_fault("remove:B@74.6")]
    world = run(World(config, MISSION), 250.0)
    completed, metrics = MISSION.outcome(world)
    brains = world.scene.info["brains"]
    assert completed and metrics["mission_time_s"] < 200.0
    assert brains["C"].route is not None and brains["C"].finished_at is not None  # C led to the route's end
    assert all(brains[n].failed == {"B"} for n in "ACD")
    assert metrics["order_broken_s"] <= 5  # 0 s measured


def test_same_seed_same_trial():
    assert state_digest(run(world_of(strategy="III"), 15.0)) == state_digest(run(world_of(strategy="III"), 15.0))


@pytest.mark.parametrize("argv, fragment", [
    (["--set", "robots=15"], "robots=15"),
    (["--set", "strategy=V"], "strategy='V'"),
    (["--set", "task.route=[{x: 0, y: 0}]"], "task.route: a route needs at least two waypoints; got 1"),
    (["--set", "task.leader=Z"], "task.leader='Z'"),
])
def test_bad_input_is_one_line_and_exit_2(capsys, tmp_path, argv, fragment):
    code = main(["run", "formation", *argv, "--duration", "1", "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1, err
    assert fragment in err
