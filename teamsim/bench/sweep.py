"""``teamsim bench sweep``: how much faster a sweep runs on several worker processes than on one, measured in one
run (target: 2 workers >= 1.8x one on a 2-core machine).

Two workloads, each run once with one worker and once with ``workers``, into a temporary folder:
- kinematic navigate trials as ``teamsim study navigation`` runs them (robots A and B, FRC, 10 % density);
- physics ``wander`` trials (three robots), as a sweep of MuJoCo missions runs them.
The pool starts its workers afresh each time (``spawn``), so the start-up of a worker (importing MuJoCo and
dm_control) is part of the figure, as it is for a user. Both runs must give the same summaries.
"""
from __future__ import annotations

import tempfile
import time
from pathlib import Path

from teamsim.config import TrialConfig
from teamsim.sweep import run_trials
from teamsim.tasks import MISSIONS
from teamsim.tasks.missions.navigate import kinematic_trial
from teamsim.tasks.studies.navigation import NavigationStudy, trial_configs

SPEEDUP_TARGET = 1.8


def navigation_trials(out: Path, trials: int) -> list[TrialConfig]:
    study = NavigationStudy(robots=("A", "B"), densities=(0.10,), controllers=("FRC",), trials=trials, out=out)
    return trial_configs(study)


def wander_trials(out: Path, trials: int, seconds: float) -> list[TrialConfig]:
    params = MISSIONS["wander"].Params(robots=3)
    return [TrialConfig(mission="wander", params=params, seed=seed, duration=seconds, out=str(out),
                        run_id=f"wander-{seed}") for seed in range(trials)]


def _comparable(summary: dict) -> tuple:
    return summary.get("status"), summary.get("metrics"), summary.get("final_state_sha256")


def time_sweep(configs: list[TrialConfig], workers: int, run=None) -> tuple[float, list[dict]]:
    began = time.perf_counter()
    summaries = run_trials(configs, workers=workers, run=run)
    return time.perf_counter() - began, summaries


def measure(name: str, make, workers: int, run=None) -> dict:
    with tempfile.TemporaryDirectory(prefix="teamsim-bench-sweep-") as folder:
        one_s, one = time_sweep(make(Path(folder) / "one"), 1, run)
        many_s, many = time_sweep(make(Path(folder) / "many"), workers, run)
    return {"workload": name, "trials": len(one), "one_s": one_s, "many_s": many_s, "speedup": one_s / many_s,
            "same": [_comparable(s) for s in one] == [_comparable(s) for s in many]}


def _nothing(config: TrialConfig) -> dict:
    return {}


def worker_start_seconds(workers: int) -> float:
    """The wall time of a sweep of ``workers`` empty trials: starting the pool's processes and importing the
    trial runner in each, the fixed cost every parallel sweep pays once."""
    began = time.perf_counter()
    run_trials(wander_trials(Path("unused"), workers, 1.0), workers=workers, run=_nothing)
    return time.perf_counter() - began


def bench_sweep(workers: int = 2, trials: int = 16, wander_seconds: float = 60.0) -> list[dict]:
    """Measure and print both workloads; returns the figures."""
    print(f"bench sweep: {trials} trials per workload, 1 worker against {workers}, target >= {SPEEDUP_TARGET:g}x",
          flush=True)
    rows = [measure("navigate, kinematic (study navigation)", lambda out: navigation_trials(out, trials // 2),
                    workers, kinematic_trial),
            measure(f"wander, physics, 3 robots, {wander_seconds:g} s",
                    lambda out: wander_trials(out, trials, wander_seconds), workers)]
    print(f"  starting {workers} workers (spawn, imports)  {worker_start_seconds(workers):6.1f} s, paid once per sweep")
    for row in rows:
        verdict = "ok" if row["speedup"] >= SPEEDUP_TARGET else "UNDER TARGET"
        print(f"  {row['workload']:<42} {row['trials']} trials: 1 worker {row['one_s']:6.1f} s, {workers} workers "
              f"{row['many_s']:6.1f} s, speed-up {row['speedup']:4.2f}x  {verdict}  same results: {row['same']}")
    return rows

