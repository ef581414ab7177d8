"""``bench_alliance()``: how fast the ALLIANCE and L-ALLIANCE logic runs, and how long the optimal comparison of
Parker's §4.5.4 takes.

1. Motivation updates per second (one behaviour set's eq. (3.1) at one step) for a team of 20 robots with 10
   behaviour sets each, every robot stepped every control period with the activity messages its 19 teammates
   sent at the previous one; tasks finish and come back, so robots keep activating, hearing first messages and
   resetting. Measured for ALLIANCE and for L-ALLIANCE (strategy IV, learned times).
2. The wall time of the full optimal comparison of §4.5.4 as the study runs it: strategy IV against the
   brute-force optima over the thesis's 496 triples (:func:`~teamsim.tasks.studies.lalliance.optimal_triples`, whose
   comment gives the rule; the bounds the thesis states, n^m < or <= 2^17, would give 502 or 503), 200 runs
   each, every problem played both without and with Progress When Working (the thesis does not say which held;
   the study runs both, the optimum computed once per problem), on ``workers`` processes (2 by default). Pass
   ``triples``, ``runs`` or ``pww`` for a smaller comparison. On the shared two-core development machine (load
   about 6), the 496 triples with 50 runs each took 183 s of wall time and 130 s of worker CPU; the full 200 runs
   is four times the work, about 520 s of CPU, so about 4.5 minutes of wall time on two free cores.
"""
from __future__ import annotations

import time

import numpy as np

from teamsim.controllers.alliance.lalliance import LAllianceParams, LAllianceRobot, TaskStatistics
from teamsim.controllers.alliance.motivation import AllianceParams, AllianceRobot, BehaviourSet, activity_message
from teamsim.radio import Message
from teamsim.tasks.studies.lalliance import (HETEROGENEITY, RUNS_FULL, ScenarioJob, variants, optimal_triples,
                                             run_jobs)
from teamsim.tasks.worlds.abstract_allocation import TeamSettings

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
                               pww: tuple = (False, True)) -> float:
    """Wall time of strategy IV against the brute-force optimum (§4.5.4) over ``triples`` (default: the 496),
    each problem played with each Progress When Working setting in ``pww`` (default both, as the study)."""
    settings = TeamSettings()
    played = tuple(v for v in variants("optimal", settings.boredom_delay) if v[2] in pww)
    if not played:
        raise ValueError(f"pww {pww}: give False, True or both")
    jobs = [ScenarioJob("optimal", n, m, c, HETEROGENEITY, runs, 0, settings, played)
            for n, m, c in (optimal_triples() if triples is None else triples)]
    start = time.perf_counter()
    run_jobs(jobs, workers)
    return time.perf_counter() - start


def bench_alliance(workers: int = 2, triples: list | None = None, runs: int = RUNS_FULL,
                   pww: tuple = (False, True)) -> dict:
    """Print and return the motivation update rates and the optimal comparison's wall time."""
    figures = {}
    print(f"bench alliance: {ROBOTS} robots x {SETS} behaviour sets, every robot hearing every teammate each step")
    for kind in ("alliance", "lalliance"):
        rate = motivation_updates_per_second(kind)
        figures[f"{kind}_updates_per_s"] = rate
        print(f"  {kind:>9}: {rate:12,.0f} motivation updates/s ({rate / (ROBOTS * SETS):8,.0f} team steps/s)",
              flush=True)
    count = len(optimal_triples() if triples is None else triples)
    settings = " and ".join("with PWW" if p else "without PWW" for p in sorted(pww))
    full = "full, " if triples is None and runs == RUNS_FULL and set(pww) == {False, True} else ""
    print(f"  optimal comparison (§4.5.4, {full}{count} triples x {runs} runs, strategy IV {settings}) on "
          f"{workers} worker(s) ...", flush=True)
    seconds = optimal_comparison_seconds(workers, triples, runs, pww)
    missions = count * runs * len(set(pww))
    figures.update(optimal_comparison_s=seconds, optimal_triples=count, optimal_runs=count * runs,
                   optimal_missions=missions)
    print(f"  optimal comparison: {seconds:.1f} s wall on {workers} worker(s) ({count * runs} problems, "
          f"{missions} team missions, {missions / seconds:,.0f} missions/s)")
    return figures
