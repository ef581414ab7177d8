"""``teamsim bench explore``: the explore mission's real-time factor for a [1 5] team (§8.2's largest) in the
38.4 m, 5 % world with bogs, measured in one run:
  physics    the MuJoCo mission, full control stack, no video, best of two runs of ``--seconds`` (default 120 s;
             issue 24's target: >= 10x real time);
  kinematic  the same world, team and controllers without physics over the whole MET of 5000 s (target: >= 200x,
             so that the run takes <= 60 s wall), and what share of the world it explored.
"""
from __future__ import annotations

import time

from teamsim.bench.physics import best_of, stack_steps_per_second
from teamsim.config import TrialConfig
from teamsim.scenario import resolve
from teamsim.tasks import MISSIONS
from teamsim.tasks.missions.explore import MET_LARGER, ExploreParams, kinematic_trial
from teamsim.world import World

TEAM = "1 5"


def bench_explore(seconds: float | None = None, seed: int = 1) -> dict:
    seconds = seconds or 120.0
    mission = MISSIONS["explore"]
    physics = TrialConfig(mission="explore", params=ExploreParams(team=TEAM), seed=seed)
    print(f"bench explore: team [{TEAM}], 38.4 m world, 5 % obstacles, 5 % bogs, seed {seed}, no video")
    worlds = []

    def stack() -> float:
        worlds.append(World(resolve(physics, mission), mission))
        return stack_steps_per_second(worlds[-1], seconds)

    physics_rtf = best_of(2, stack) * worlds[-1].physics_dt
    print(f"  physics, {seconds:g} s simulated   {physics_rtf:7.1f}x real time   (target >= 10x)")
    kinematic = TrialConfig(mission="explore", params=ExploreParams(team=TEAM, backend="kinematic"), seed=seed)
    began = time.perf_counter()
    run = kinematic_trial(kinematic)
    wall = time.perf_counter() - began
    kinematic_rtf = run["sim_time_s"] / wall
    print(f"  kinematic, {run['sim_time_s']:g} s simulated (MET {MET_LARGER:g} s) in {wall:.1f} s wall   "
          f"{kinematic_rtf:7.1f}x real time   (target >= 200x, <= 60 s wall); explored "
          f"{100 * run['metrics']['explored_share']:.1f} %, {run['status']}")
    return {"physics_rtf": physics_rtf, "kinematic_rtf": kinematic_rtf, "kinematic_wall_s": wall,
            "explored_share": run["metrics"]["explored_share"]}
