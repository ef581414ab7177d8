"""Bounding overwatch over many seeds (Parker §6.3): do the groups split two and two by type, does a leader emerge in
each, do they alternate bounds to the route's end? Runs the default mission on each seed (2 workers), keeps a
journal so a killed run resumes, and writes ``results.csv`` and ``report.md`` with a row per seed and the counts.

    $ python examples/overwatch_seeds.py --seeds 1-20 --out docs/results/bounding-overwatch-seeds-1-20
"""
from __future__ import annotations

import argparse
from pathlib import Path

from teamsim.config import TrialConfig
from teamsim.files import write_atomic, write_csv
from teamsim.sweep import JOURNAL_NAME, run_trials
from teamsim.tasks.missions.bounding_overwatch import BoundingOverwatchParams


def row_of(summary: dict) -> dict:
    m = summary["metrics"]
    first_leader = {}
    for group, robot, start, _ in m["leaders"]:
        first_leader.setdefault(group, (robot, start))
    return {"seed": summary["seed"], "status": summary["status"], "completion_time_s": m["completion_time_s"],
            "kinds_A": "/".join(f"{k}:{n}" for k, n in m["group_kinds"]["A"].items()),
            "kinds_B": "/".join(f"{k}:{n}" for k, n in m["group_kinds"]["B"].items()),
            "balanced": m["balanced"], "rebalancing_moves": m["switches"],
            "leader_A": "{} at {:.1f} s".format(*first_leader["A"]) if "A" in first_leader else "",
            "leader_B": "{} at {:.1f} s".format(*first_leader["B"]) if "B" in first_leader else "",
            "bounds_completed": m["bounds_completed"], "route_bounds": m["route_length"],
            "alternated": m["alternated"]}


def report(rows: list[dict]) -> str:
    n = len(rows)
    count = {
        "completed": sum(r["status"] == "completed" for r in rows),
        "each group two of each kind": sum(r["kinds_A"] == r["kinds_B"] == "diffdrive:2/tricycle:2" for r in rows),
        "a leader emerged in each group": sum(bool(r["leader_A"] and r["leader_B"]) for r in rows),
        "every bound completed, alternating A-B-A-...": sum(
            r["alternated"] and r["bounds_completed"] == r["route_bounds"] for r in rows)}
    times = sorted(r["completion_time_s"] for r in rows if r["completion_time_s"] is not None)
    lines = [f"# Bounding overwatch over {n} seeds (Parker §6.3)", "",
             "Default mission (`teamsim run bounding-overwatch --seed S`), no faults. Per-seed rows: `results.csv`.",
             "", "| claim | seeds |", "|---|---|"]
    lines += [f"| {claim} | {k}/{n} |" for claim, k in count.items()]
    if times:
        lines += ["", f"Completion: {times[0]:.1f}-{times[-1]:.1f} s (median {times[len(times) // 2]:.1f} s)."]
    lines += ["", "| seed | status | group A | group B | moves | leader A | leader B | bounds | alternated |",
              "|---|---|---|---|---|---|---|---|---|"]
    lines += [f"| {r['seed']} | {r['status']} | {r['kinds_A']} | {r['kinds_B']} | {r['rebalancing_moves']} | "
              f"{r['leader_A']} | {r['leader_B']} | {r['bounds_completed']}/{r['route_bounds']} | {r['alternated']} |"
              for r in rows]
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="1-20", help="A-B")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", type=Path, default=Path("renders/overwatch-seeds"))
    args = parser.parse_args()
    first, _, last = args.seeds.partition("-")
    seeds = range(int(first), int(last or first) + 1)
    args.out.mkdir(parents=True, exist_ok=True)
    journal = args.out / JOURNAL_NAME
    configs = [TrialConfig(mission="bounding-overwatch", params=BoundingOverwatchParams(), seed=s,
                           out=str(args.out / "trials")) for s in seeds]
    summaries = run_trials(configs, workers=args.workers, journal=journal, resume=journal.exists())
    rows = [row_of(s) for s in summaries]
    write_csv(args.out / "results.csv", list(rows[0]), rows)
    write_atomic(args.out / "report.md", report(rows).encode())
    print(report(rows).split("\n\n")[2])


if __name__ == "__main__":
    main()
