"""``teamsim study cleanup-faults``: the hazardous-waste cleanup under the thesis's faults (§3.8.4, ch.5).

Each condition runs the 3-robot mission {red, blue, green} on the same seeds (0-9 by default), so conditions are
compared mission by mission:

- ``none``: the team as it is;
- ``kill-red``: red, the only robot with working side IR, is switched off at a random time during its methodical
  search (uniform in ``kill_window``, drawn per mission from a generator seeded by the study seed and the mission
  number); a teammate must take the search over with its wander version (§3.8.4);
- ``radio-off``: every robot's radio off from t = 0 (ch.5's "no awareness"); find-locations and report-progress
  are then replicated;
- ``break-gripper``: green's gripper breaks at ``gripper_break`` s (the grip and lift motors stop); the team must
  still finish, and the report shows what green did with move-spill afterwards.

The report gives the thesis's findings with teamsim's figures, p-values and verdicts (:func:`claims`), and per
condition how many missions completed, their mean time and energy, and the condition's own check: who took the
search over, how many robots searched and reported, how long green kept at move-spill. :func:`read_results`
reads a ``results.csv`` back, so a report can be re-made from the file.
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from teamsim.config import TrialConfig
from teamsim.faults import Fault
from teamsim.files import write_atomic, write_csv
from teamsim.sweep import JOURNAL_NAME, run_trials
from teamsim.tasks.missions.hazardous_waste import TEAMS, HazardousWasteParams
from teamsim.tasks.studies import findings
from teamsim.tasks.studies.findings import Finding, verdict

CONDITIONS = ("none", "kill-red", "radio-off", "break-gripper")
COLUMNS = ("condition", "mission", "seed", "fault_time", "status", "completed", "mission_time_s",
           "energy_parker_units", "pucks_at_goal", "transports", "reports", "reporters", "find_robots", "takeover",
           "green_transports", "green_move_spill_s", "real_time_factor")
TEAM = TEAMS[3]


@dataclass(frozen=True)
class CleanupFaultStudy:
    missions: int = 10
    seed: int = 0
    conditions: tuple[str, ...] = CONDITIONS
    kill_window: tuple[float, float] = (5.0, 85.0)  # s: red's wall-following search runs from about 2 s to 88 s
    gripper_break: float = 100.0  # s: after the search, while the team is moving the spill (README's example)
    workers: int | None = None
    out: Path = Path("renders/study-cleanup-faults")
    resume: bool = False  # continue the study in ``out`` from its journal (trials.jsonl), issue 29


def faults_of(study: CleanupFaultStudy, condition: str, mission: int) -> tuple[list[Fault], float | None]:
    """The condition's faults for one mission, and the time of the fault it injects (None: none)."""
    if condition == "kill-red":
        at = float(np.random.default_rng((study.seed, mission)).uniform(*study.kill_window))
        return [Fault("kill", "red", round(at, 1))], round(at, 1)
    if condition == "radio-off":
        return [Fault("radio-off", name, 0.0) for name in TEAM], 0.0
    if condition == "break-gripper":
        return [Fault("break-gripper", "green", study.gripper_break)], study.gripper_break
    return [], None


def trial_configs(study: CleanupFaultStudy) -> list[TrialConfig]:
    configs = []
    for condition in study.conditions:
        for k in range(study.missions):
            faults, _ = faults_of(study, condition, k)
            config = TrialConfig(mission="hazardous-waste", params=HazardousWasteParams(robots=3),
                                 seed=study.seed + k, out=str(study.out / "trials"), run_id=f"{condition}-{k}",
                                 faults=faults)
            config.video.fps = 2  # the trajectory of a study mission is for inspection, not for video
            configs.append(config)
    return configs


def result_row(study: CleanupFaultStudy, config: TrialConfig, summary: dict) -> dict:
    condition, mission = config.run_id.rsplit("-", 1)
    metrics = summary.get("metrics") or {}
    robots = summary.get("robots") or {}
    per_robot = metrics.get("per_robot", {})
    wanderers = [n for n in TEAM if robots.get(n, {}).get("task_time_s", {}).get("find-locations-wander")]
    return {
        "condition": condition, "mission": int(mission), "seed": config.seed,
        "fault_time": faults_of(study, condition, int(mission))[1], "status": summary["status"],
        "completed": summary.get("completed", False), "mission_time_s": metrics.get("mission_time_s"),
        "energy_parker_units": metrics.get("energy_parker_units"), "pucks_at_goal": metrics.get("pucks_at_goal"),
        "transports": metrics.get("transports"), "reports": metrics.get("reports"),
        "reporters": "+".join(n for n in TEAM if per_robot.get(n, {}).get("reports")),
        "find_robots": "+".join(metrics.get("find_locations_by", [])), "takeover": "+".join(wanderers),
        "green_transports": per_robot.get("green", {}).get("transports"),
        "green_move_spill_s": robots.get("green", {}).get("task_time_s", {}).get("move-spill"),
        "real_time_factor": summary.get("real_time_factor"),
    }


def run_study(study: CleanupFaultStudy) -> Path:
    configs = trial_configs(study)
    summaries = run_trials(configs, workers=study.workers, journal=study.out / JOURNAL_NAME,
                           resume=study.resume)
    rows = [result_row(study, c, s) for c, s in zip(configs, summaries)]
    study.out.mkdir(parents=True, exist_ok=True)
    write_csv(study.out / "results.csv", COLUMNS, rows)
    write_atomic(study.out / "report.md", report(study, rows).encode())
    return study.out


_NUMBERS = {"mission": int, "seed": int, "fault_time": float, "mission_time_s": float, "energy_parker_units": float,
            "pucks_at_goal": int, "transports": int, "reports": int, "green_transports": int,
            "green_move_spill_s": float, "real_time_factor": float}


def read_results(path: Path) -> list[dict]:
    """The rows of a ``results.csv`` as ``run_study`` made them."""
    with open(path, newline="") as file:
        rows = list(csv.DictReader(file))
    for row in rows:
        row["completed"] = row["completed"] == "True"
        for key, number in _NUMBERS.items():
            row[key] = number(row[key]) if row.get(key) else None
    return rows


def claims(rows: list[dict]) -> list[Finding]:
    """The findings of §3.8.4 and ch.5 this study can check, each counted over its missions; a comparison between
    conditions holds in the means and is paired by seed for its p."""
    rows = [{**r, "reports_per_move": r["reports"] / r["transports"] if r["transports"] else None} for r in rows]

    def of(condition: str) -> list[dict]:
        return [r for r in rows if r["condition"] == condition]

    def counted(condition: str, holds) -> tuple[int, int]:
        chosen = of(condition)
        return sum(bool(holds(r)) for r in chosen), len(chosen)

    def more(key: str, claim: str, thesis: str, digits: int) -> Finding:
        """radio-off's ``key`` above the radio's in the means, over the seeds where both completed."""
        off, on = findings.paired(rows, key, "condition", "radio-off", "none")
        if not off:
            return Finding(claim, thesis, "not measured", "n/a")
        higher = sum(a > b for a, b in zip(off, on))
        return Finding(claim, thesis, f"none {np.mean(on):.{digits}f}, radio-off {np.mean(off):.{digits}f}; higher "
                                      f"in {higher}/{len(off)} missions", verdict(int(np.mean(off) > np.mean(on)), 1),
                       *findings.compare(rows, key, "condition", "radio-off", "none"))

    present = [c for c in CONDITIONS if of(c)]
    complete = [c for c in present if all(r["completed"] for r in of(c))]
    alone, n_none = counted("none", lambda r: r["find_robots"] == "red")
    took, n_kill = counted("kill-red", lambda r: r["takeover"])
    replicated, n_off = counted("radio-off", lambda r: r["find_robots"].count("+") == len(TEAM) - 1)
    return [
        Finding("the cleanup completes under every fault (Theorem 2; ch.5: every run of III and IV completed)",
                "every mission", ", ".join(f"{c} {sum(r['completed'] for r in of(c))}/{len(of(c))}" for c in present),
                verdict(len(complete), len(present))),
        Finding("with its side IR working red alone runs the methodical find (§3.8.2)", "red only",
                f"red alone in {alone}/{n_none}", verdict(alone, n_none)),
        Finding("red killed during its search: a teammate takes find-locations over with its wander version "
                "(§3.8.4)", "a teammate takes over", f"in {took}/{n_kill}", verdict(took, n_kill)),
        Finding("without awareness every capable robot runs find-locations (ch.5)", "all three",
                f"all three in {replicated}/{n_off}", verdict(replicated, n_off)),
        more("reports_per_move", "without awareness report-progress is repeated: more reports per move (ch.5: "
                                 "0.86 against 0.58)", "radio-off > none", 2),
        more("energy_parker_units", "awareness saves energy (ch.5: 2-62 % on find-locations' cost)",
             "radio-off > none (Parker units)", 0),
    ]


def _mean(rows: list[dict], key: str) -> float:
    values = [r[key] for r in rows if r["completed"] and r[key] is not None]
    return float(np.mean(values)) if values else math.nan


def check(condition: str, rows: list[dict]) -> str:
    """The condition's own finding, counted over its missions."""
    n = len(rows)
    if condition == "kill-red":
        took_over = sum(bool(r["takeover"]) for r in rows)
        return f"a teammate took the search over (find-locations-wander) in {took_over}/{n}"
    if condition == "radio-off":
        replicated = sum(r["find_robots"].count("+") == len(TEAM) - 1 for r in rows)
        several = sum(r["reporters"].count("+") >= 1 for r in rows)
        return (f"every robot searched for itself in {replicated}/{n}; more than one robot reported in "
                f"{several}/{n}")
    if condition == "break-gripper":
        times = [r["green_move_spill_s"] or 0.0 for r in rows]
        return (f"green's move-spill time over the whole mission: mean {np.mean(times):.0f} s, max {max(times):.0f} s "
                f"(gripper broken at {rows[0]['fault_time']:g} s)")
    return f"red alone searched in {sum(r['find_robots'] == 'red' for r in rows)}/{n}"


def report(study: CleanupFaultStudy, rows: list[dict]) -> str:
    lines = ["# Hazardous-waste cleanup under the thesis's faults", "",
             f"3 robots (red, blue, green), {study.missions} missions per condition, seeds {study.seed}.."
             f"{study.seed + study.missions - 1} in every condition. Means over completed missions. Per-mission rows: "
             "`results.csv`; each mission's outputs: `trials/`.", "",
             "## Findings against the thesis", "", *findings.table(claims(rows), " (an ordering: in the means, "
                                                                                "counted over the missions)"), "",
             "## Conditions", "",
             "| condition | completed | time (s) | energy (Parker units) | transports | what the condition checks |",
             "|---|---|---|---|---|---|"]
    for condition in study.conditions:
        chosen = [r for r in rows if r["condition"] == condition]
        done = sum(r["completed"] for r in chosen)
        lines.append(f"| {condition} | {done}/{len(chosen)} | {_mean(chosen, 'mission_time_s'):.0f} | "
                     f"{_mean(chosen, 'energy_parker_units'):.0f} | {_mean(chosen, 'transports'):.1f} | "
                     f"{check(condition, chosen)} |")
    failed = [r for r in rows if not r["completed"]]
    if failed:
        lines += ["", "Missions that did not complete: " + ", ".join(
            f"{r['condition']} seed {r['seed']} ({r['status']}, {r['pucks_at_goal']} pucks)" for r in failed) + "."]
    return "\n".join(lines) + "\n"
