"""``bench_alliance()``: how fast the ALLIANCE and L-ALLIANCE logic runs, and how long the optimal comparison of
Parker's §4.5.4 takes.

1. Motivation updates per second (one behaviour set's eq. (3.1) at one step) for a team of 20 robots with 10
   behaviour sets each, every robot stepped every control period with the activity messages its 19 teammates
   sent at the previous one; tasks finish and come back, so robots keep activating, hearing first messages and
   resetting. Measured for ALLIANCE and for L-ALLIANCE (strategy IV, learned times).
2. The wall time of strategy IV against the brute-force optimum over the 502 triples of
   :func:`~teamsim.tasks.lalliance_study.optimal_triples`, 200 runs each, without Progress When Working, on
   ``workers`` processes: the full comparison of §4.5.4, the default. On the two cores of the development
   machine it took 104 s of wall time (193 s of worker CPU) while other jobs shared the cores; the study also
   plays each problem with PWW, which doubles it. Pass ``triples`` and ``runs`` for a smaller comparison.
"""
from __future__ import annotations

import time

import numpy as np

from teamsim.controllers.alliance import AllianceParams, AllianceRobot, BehaviourSet, activity_message
from teamsim.controllers.lalliance import LAllianceParams, LAllianceRobot, TaskStatistics
from teamsim.radio import Message
from teamsim.tasks.lalliance_study import (HETEROGENEITY, RUNS_FULL, ScenarioJob, variants, optimal_triples,
                                           run_jobs)
from teamsim.tasks.abstract_allocation import TeamSettings

ROBOTS, SETS = 20, 10


def _team(kind: str, rng: np.random.Generator) -> list:
    names = [f"r{i}" for i in range(ROBOTS)]
    sets = [BehaviourSet(f"task{j}") for j in range(SETS)]
    if kind == "alliance":
        return [AllianceRobot(name, sets, AllianceParams()) for name in names]
    team = []
    for name in names:
        statistics = TaskStatistics(name)
        for s in sets:
            statistics.record_own(s.name, float(rng.uniform(20, 120)))
            for other in names:
                if other != name:
                    statistics.record_teammate(other, s.task, float(rng.uniform(20, 120)))
        team.append(LAllianceRobot(name, sets, LAllianceParams(), statistics))
    return team


def motivation_updates_per_second(kind: str, seconds: float = 2.0, control_dt: float = 0.1) -> float:
    """Set updates per wall-clock second for the 20 x 10 team (``kind``: "alliance" or "lalliance")."""
    rng = np.random.default_rng(0)
    team = _team(kind, rng)
    names = [robot.name for robot in team]
    present = {name: frozenset(names) - {name} for name in names}
    remaining = rng.uniform(5, 30, SETS)  # seconds of work left on each task; 0: done, back after a while
    activity: dict[str, str | None] = dict.fromkeys(names)
    steps, t = 0, 0.0
    start = time.perf_counter()
    while time.perf_counter() - start < seconds:
        sent = [Message(name, t, activity_message(task)) for name, task in activity.items()]
        feedback = {f"task{j}": remaining[j] > 0 for j in range(SETS)}
        for robot in team:
            activity[robot.name], _ = robot.step(t, feedback, [m for m in sent if m.sender != robot.name],
                                                 present[robot.name])
        for task in activity.values():
            if task is not None:
                remaining[int(task[4:])] -= control_dt
        done = remaining <= 0
        remaining[done & (rng.random(SETS) < 0.05)] = rng.uniform(5, 30)  # done tasks come back
        steps += 1
        t = round(t + control_dt, 9)
    return steps * ROBOTS * SETS / (time.perf_counter() - start)


def optimal_comparison_seconds(workers: int = 2, triples: list | None = None, runs: int = RUNS_FULL,
                               with_pww: bool = False) -> float:
    """Wall time of strategy IV against the brute-force optimum (§4.5.4) over ``triples`` (default: all), without
    Progress When Working (the setting comparable to an allocation optimum) or, ``with_pww``, also with it, as
    the study runs it."""
    settings = TeamSettings()
    played = variants("optimal", settings.boredom_delay)
    played = played if with_pww else tuple(v for v in played if not v[2])
    jobs = [ScenarioJob("optimal", n, m, c, HETEROGENEITY, runs, 0, settings, played)
            for n, m, c in (triples or optimal_triples())]
    start = time.perf_counter()
    run_jobs(jobs, workers)
    return time.perf_counter() - start


def bench_alliance(workers: int = 2, triples: list | None = None, runs: int = RUNS_FULL) -> dict:
    """Print and return the motivation update rates and the optimal comparison's wall time."""
    figures = {}
    print(f"bench alliance: {ROBOTS} robots x {SETS} behaviour sets, every robot hearing every teammate each step")
    for kind in ("alliance", "lalliance"):
        rate = motivation_updates_per_second(kind)
        figures[f"{kind}_updates_per_s"] = rate
        print(f"  {kind:>9}: {rate:12,.0f} motivation updates/s ({rate / (ROBOTS * SETS):8,.0f} team steps/s)",
              flush=True)
    count = len(triples or optimal_triples())
    print(f"  optimal comparison (§4.5.4, no PWW): {count} triples x {runs} runs on {workers} worker(s) ...",
          flush=True)
    seconds = optimal_comparison_seconds(workers, triples, runs)
    figures["optimal_comparison_s"] = seconds
    figures["optimal_runs"] = count * runs
    print(f"  optimal comparison: {seconds:.1f} s wall ({count * runs / seconds:,.0f} runs/s)")
    return figures
