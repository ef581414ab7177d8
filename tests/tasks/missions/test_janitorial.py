"""End to end: Parker's janitorial service in physics (§6.2), through the real World, with fixed seeds.

These check what the thesis reports of the mission's control, on a small room (two cans, one dustable object):
cans are emptied by the garbage robots, each can once, and two robots that set out for the same frequency do not
both stay on it; dynamic events (a can added mid-mission, a can emptied by someone else, a robot whose tools fail,
a robot added) are absorbed; with no messages at all the cans are still emptied; bad input is one line and exit 2.
Whether whole default missions complete is measured outside the tests (docs/janitorial.md).
"""
from __future__ import annotations

import dataclasses
import functools

import pytest

from teamsim.cli import main
from teamsim.config import TrialConfig
from teamsim.faults import parse_fault
from teamsim.runner import mission_of, state_digest
from teamsim.scenario import config_of, generate
from teamsim.tasks.missions.janitorial import JanitorialParams
from teamsim.world import World

MISSION = mission_of("janitorial")
SMALL = dict(size_x=(4.5, 4.5), size_y=(4.0, 4.0), cans=2, objects=1, obstacles=0, frequencies=2)
SEED = 3


def run(duration: float, faults=(), seed: int = SEED, edit=None, **params) -> World:
    """A world of the small room run for ``duration`` s (or until the mission is done); ``world.scene.info
    ["actives"]`` keeps (time, {robot: active set}) at every control period."""
    base = TrialConfig(mission="janitorial", params=JanitorialParams(**{**SMALL, **params}), seed=seed)
    faults = [parse_fault(f) for f in faults]
    scenario = generate(dataclasses.replace(base, faults=faults), MISSION)
    if edit is not None:
        scenario = edit(scenario)
    world = World(config_of(scenario, MISSION, base, faults), MISSION)
    actives = world.scene.info["actives"] = []
    while world.time < duration and not MISSION.done(world):
        world.tick()
        actives.append((world.time, {n: b.active for n, b in world.scene.info["brains"].items()}))
        world.advance(world.steps_per_tick)
    return world


@functools.cache
def default_small() -> World:
    return run(150.0)


def cans(world) -> list:
    return world.scene.info["cans"].cans


def test_every_can_is_emptied_once_by_a_garbage_robot():
    world = default_small()
    assert all(c.emptied_at is not None and c.emptied_by in ("r1", "r2") for c in cans(world))


def test_robots_that_set_out_for_the_same_frequency_do_not_both_stay_on_it():
    """r1 and r2 both hear every frequency from the start and begin on the same one; the later (or, at a tie, the
    one later in name order) yields it after psi, plus at most a broadcast period to hear the other."""
    world = default_small()
    psi = world.scene.info["brains"]["r1"].params.garbage_rates.psi
    period = 1 / world.config.radio.rate_hz
    longest, since = 0.0, None
    for time, active in world.scene.info["actives"]:
        shared = active["r1"] is not None and active["r1"].startswith("empty-garbage") and active["r1"] == active["r2"]
        since = (since if since is not None else time) if shared else None
        longest = max(longest, time - since) if shared else longest
    assert 0.0 < longest <= psi + period + 0.3


def test_a_can_added_mid_mission_is_emptied_and_a_can_emptied_by_someone_else_is_dropped():
    def edit(scenario):
        task = scenario.task
        task.cans[0].appears = 40.0
        task.cans[1].emptied_at = 5.0
        return scenario
    world = run(200.0, edit=edit)
    added, dropped = cans(world)
    assert added.emptied_at is not None and added.emptied_at > 40.0 and added.emptied_by in ("r1", "r2")
    assert dropped.emptied_by == "event" and dropped.emptied_at == pytest.approx(5.0, abs=0.2)


def test_a_robot_whose_tools_fail_has_its_can_taken_over():
    """break-gripper disables every tool: the robot holds at the can in vain, its teammate grows impatient (phi)
    and empties it."""
    world = run(400.0, faults=["break-gripper:r2@1"], cans=1, frequencies=1)
    (can,) = cans(world)
    assert can.emptied_by == "r1"


def test_a_robot_added_mid_mission_joins_the_team():
    world = run(120.0, faults=["add-robot:r4@20,kind=janitor"])
    r4 = world.scene.info["brains"]["r4"]
    assert world.robots["r4"].behaviour_time.get("idle", 0.0) < world.time - 20.0  # it took up a task
    assert any(t > 0 for n, t in world.robots["r4"].behaviour_time.items() if n != "idle")
    assert r4.alliance.log.robots_present(world.time)  # and it hears the others


def test_with_no_messages_the_cans_are_still_emptied():
    world = run(300.0, rho=0.0)
    assert all(not r.health.radio_on for r in world.robots.values())
    assert all(c.emptied_at is not None for c in cans(world))


def test_same_seed_same_trial():
    assert state_digest(run(20.0)) == state_digest(run(20.0))


@pytest.mark.parametrize("argv, fragment", [
    (["--set", "robots.r1.controller.tools=[mop]"], "robots.r1.controller.tools: unknown task 'mop'"),
    (["--set", "task.cans[0].x=40"], "task.cans[0]: (40,"),
    (["--set", "rho=-1"], "rho=-1"),
    (["--set", "task.cans[0].frequency=f9"], "task.cans[0].frequency='f9'"),
])
def test_bad_input_is_one_line_and_exit_2(capsys, tmp_path, argv, fragment):
    code = main(["run", "janitorial", *argv, "--duration", "1", "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1, err
    assert fragment in err


@pytest.mark.parametrize("seed", [0, 6, 11, 61, 83])
def test_the_default_room_always_gets_a_layout(seed):
    """About 7 % of layout draws fit the default's eight things 0.7 m apart; with 50 draws these layout streams
    (and the mission's seed 204) found none and the default mission stopped with a configuration error."""
    import numpy as np

    from teamsim.tasks.missions.janitorial import JanitorialMission

    scenario = JanitorialMission().scenario(JanitorialParams(), np.random.default_rng(seed), [])
    assert len(scenario.task.cans) == 3 and len(scenario.task.furniture) == 3 and len(scenario.arena.boxes) == 2
