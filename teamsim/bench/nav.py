"""``bench nav``: the navigation stack's speed, measured in one run and printed with ratios.

A*: one corner-to-corner search on a square grid of random single-cell obstacles, by Chand's modified A*
(``teamsim.controllers.navigation.astar``: numpy cost maps, and with this heuristic vectorised batch expansion over flat
cell indices) and by the plain dict-and-set ``reference_astar``, on the same cost maps (3.7) with the same admissible
octile heuristic, so both find paths of the same cost and the ratio is the implementation's alone. The modified A*
with the thesis's own Manhattan heuristic (3.4), which searches one cell at a time off a binary heap, is timed
too.

Dynamic window: the wall time of each controller call (direction sensor, dynamic window, obstacle memory: one
control tick of one robot) of FRC driving Chand's Robot A (tricycle) and Robot B (differential) across random
worlds without physics (``teamsim.tasks.worlds.navigation.kinematic_run``). Target (issue 21): a mean of 0.3 ms
and a p99 of 1 ms a call. The observations of every call of those runs are recorded and replayed, call by call
in turn, through two fresh FRC controllers: today's, and one whose dynamic-window decision is the plain
``reference_decide`` (``teamsim.controllers.navigation.reference_dwa``: Python loops over every candidate and
every obstacle point, the same window, candidates and objectives). Both must give the same command on every
call (v, omega, behaviour and the decision's branch, or the behaviour of a call that made no decision). Both
calls include the direction sensor and the obstacle memory, so the ratio of their mean times understates the
decision's own speed-up; their difference is the decision's alone.
"""
from __future__ import annotations

import math
import time

import numpy as np

from teamsim.controllers.navigation.astar import PlannerParams, astar, cost_maps, reference_astar
from teamsim.controllers.navigation.dynamic_window import FRC, INVALID, Decision
from teamsim.controllers.navigation.reference_dwa import reference_decide
from teamsim.models.robot import DriveLimits
from teamsim.tasks.worlds.navigation import KinematicRobot, kinematic_run, random_world

DECISION_TARGET_MEAN, DECISION_TARGET_P99 = 0.3e-3, 1e-3  # s per controller call
# Chand's Table 3.1 robots A and B with Scratchy's measured accelerations (Table 3.4).
LIMITS = DriveLimits(v_max=0.5, omega_max=math.pi / 7, accel_max=0.1, angular_accel_max=0.15)
ROBOTS = {
    "tricycle (A)": KinematicRobot("tricycle", LIMITS, radius=0.5, ir_count=11, centre_offset=0.25),
    "differential (B)": KinematicRobot("diffdrive", LIMITS, radius=0.35, ir_count=10),
}


def random_grid(size: int, density: float, seed: int) -> np.ndarray:
    """Occupancy probabilities with single-cell obstacles, the start and goal corners kept free."""
    grid = np.where(np.random.default_rng(seed).random((size, size)) < density, 0.95, 0.05)
    grid[:2, :2] = grid[-2:, -2:] = 0.05
    return grid


def time_astar(size: int, density: float, seed: int) -> dict:
    grid = random_grid(size, density, seed)
    start, goal = (0, 0), (size - 1, size - 1)
    octile = PlannerParams(heuristic="octile")
    began = time.perf_counter()
    maps = cost_maps(grid, octile)
    maps_time = time.perf_counter() - began
    result = astar(maps, start, goal, "octile")
    modified_time = time.perf_counter() - began
    began = time.perf_counter()
    reference = reference_astar(maps.blocked, maps.multiplier, start, goal)
    reference_time = time.perf_counter() - began
    began = time.perf_counter()
    thesis = astar(cost_maps(grid, PlannerParams()), start, goal, "manhattan")
    thesis_time = time.perf_counter() - began
    return {"size": size, "density": density, "modified_s": modified_time, "cost_maps_s": maps_time,
            "expanded": result.expanded, "reference_s": reference_time, "ratio": reference_time / modified_time,
            "same_cost": reference is not None and math.isclose(reference[1], result.cost, rel_tol=1e-9),
            "thesis_heuristic_s": thesis_time, "thesis_cost_excess": thesis.cost / result.cost - 1.0,
            "thesis_expanded": thesis.expanded}


class RecordingController:
    """A controller that keeps every observation it is given, in order."""

    def __init__(self, controller, observations: list):
        self.controller, self.observations = controller, observations

    def __call__(self, obs):
        self.observations.append(obs)
        return self.controller(obs)


def with_reference_decide(controller: FRC) -> FRC:
    """``controller``, its dynamic-window decision made by the plain ``reference_decide``."""
    window = controller.window

    def decide(state, points, heading, d_tgt, v_min_previous=0.0, v_cap=math.inf):
        v, omega, branch, v_min = reference_decide(window, state, points, heading, d_tgt, v_min_previous, v_cap)
        return Decision(v, omega, branch, INVALID, v_min)

    window.decide = decide
    return controller


def time_decisions(density: float, worlds: int, duration: float) -> dict:
    rows = {}
    for name, robot in ROBOTS.items():
        times, runs = [], []
        for seed in range(worlds):
            world = random_world(density, np.random.default_rng(seed))
            controller = FRC(robot.limits, robot.kind, robot.radius, world.goal, centre_offset=robot.centre_offset)
            observations = []
            times.append(kinematic_run(world, RecordingController(controller, observations), robot,
                                       duration).decision_times)
            runs.append((world.goal, observations))
        times = np.concatenate(times)
        rows[name] = {"calls": int(times.size), "mean_ms": 1e3 * float(times.mean()),
                      "median_ms": 1e3 * float(np.median(times)), "p99_ms": 1e3 * float(np.percentile(times, 99)),
                      "replay": replay_calls(robot, runs)}
    return rows


def branch_of(controller: FRC, before: Decision | None, command) -> str:
    """The branch of the decision ``controller`` just made, or the command's behaviour if the call made none
    (no fix yet, arrived): its ``last_decision`` is then still the one from ``before``."""
    decision = controller.last_decision
    return command.behaviour if decision is None or decision is before else decision.branch


def replay_calls(robot: KinematicRobot, runs: list) -> dict:
    """Each recorded run's observations through a fresh FRC and a fresh FRC deciding by ``reference_decide``,
    timed call by call in turn; whether they gave the same command (v and omega within 1e-9, behaviour) from the
    same branch."""
    frc_times, reference_times, same, branches = [], [], 0, {}
    for goal, observations in runs:
        frc, reference = (FRC(robot.limits, robot.kind, robot.radius, goal, centre_offset=robot.centre_offset)
                          for _ in range(2))
        with_reference_decide(reference)
        for obs in observations:
            decided = frc.last_decision, reference.last_decision
            began = time.perf_counter()
            command = frc(obs)
            middle = time.perf_counter()
            expected = reference(obs)
            reference_times.append(time.perf_counter() - middle)
            frc_times.append(middle - began)
            branch = branch_of(frc, decided[0], command)
            same += (abs(command.v - expected.v) <= 1e-9 and abs(command.omega - expected.omega) <= 1e-9
                     and command.behaviour == expected.behaviour
                     and branch == branch_of(reference, decided[1], expected))
            branches[branch] = branches.get(branch, 0) + 1
    frc_ms, reference_ms = 1e3 * float(np.mean(frc_times)), 1e3 * float(np.mean(reference_times))
    return {"calls": len(frc_times), "frc_mean_ms": frc_ms, "reference_mean_ms": reference_ms,
            "ratio": reference_ms / frc_ms, "same": same, "branches": branches}


def run(grid_size: int = 1000, grid_density: float = 0.2, seed: int = 0, world_density: float = 0.10,
        worlds: int = 3, duration: float = 60.0) -> dict:
    """Measure and print both benchmarks; returns the figures."""
    print(f"bench nav: A* corner to corner on a {grid_size}x{grid_size} grid, {grid_density:.0%} random obstacles, "
          "same cost maps (3.7) and octile heuristic", flush=True)
    a = time_astar(grid_size, grid_density, seed)
    print(f"  modified A* (cost maps + batches)      {a['modified_s']:8.2f} s  (cost maps {a['cost_maps_s']:.2f} s, "
          f"{a['expanded']} cells expanded)")
    print(f"  reference_astar (dicts and sets)       {a['reference_s']:8.2f} s")
    print(f"  ratio reference / modified             {a['ratio']:8.1f}x  (same path cost: {a['same_cost']})")
    print(f"  modified A*, thesis Manhattan (heap)   {a['thesis_heuristic_s']:8.2f} s  ({a['thesis_expanded']} "
          f"expanded, path cost +{a['thesis_cost_excess']:.1%})", flush=True)
    print(f"bench nav: FRC decision per control tick per robot, {worlds} worlds at {world_density:.0%}, "
          f"up to {duration:g} s each, target mean <= {DECISION_TARGET_MEAN * 1e3:g} ms, "
          f"p99 <= {DECISION_TARGET_P99 * 1e3:g} ms")
    decisions = time_decisions(world_density, worlds, duration)
    for name, row in decisions.items():
        on_target = row["mean_ms"] <= DECISION_TARGET_MEAN * 1e3 and row["p99_ms"] <= DECISION_TARGET_P99 * 1e3
        verdict = "ok" if on_target else "OVER TARGET"
        print(f"  {name:<17} mean {row['mean_ms']:5.2f} ms  median {row['median_ms']:5.2f} ms  "
              f"p99 {row['p99_ms']:5.2f} ms  over {row['calls']} calls  {verdict}")
    print("bench nav: the whole FRC call replayed on the recorded observations, today's against one deciding by the "
          "plain reference_decide")
    for name, row in decisions.items():
        r = row["replay"]
        branches = ", ".join(f"{branch} {count}" for branch, count in sorted(r["branches"].items()))
        print(f"  {name:<17} FRC mean {r['frc_mean_ms']:5.2f} ms  reference mean {r['reference_mean_ms']:5.2f} ms  "
              f"ratio reference / FRC {r['ratio']:4.1f}x  same command {r['same']}/{r['calls']}  "
              f"({branches})")
    return {"astar": a, "decisions": decisions}


def bench_nav() -> dict:
    """The default measurements, for ``teamsim bench nav``."""
    return run()
