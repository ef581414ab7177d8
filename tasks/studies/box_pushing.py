"""``teamsim study box-pushing``: Parker's two box-pushing experiments (§6.1.2; spec §4.2, §7 claims 1-4), over
many seeds.

- **robot-failure** (Experiment 1): red and green push; green is taken away (``remove``, "seized and switched
  off") at a random time in ``remove_window`` and put back (``revive``) ``away`` s later; the trial ends
  ``after_return`` s after that. Measured: the takeover pause, from green's removal to red's activation of green's
  end, against the thesis's "about 5 to 8 seconds" (an observer's timing: "seized ... after a brief pause"); also
  from green's last push complete and from red's own last push; whether red then alternates both ends; whether,
  back, green pushes one end and the pair splits the ends again.
- **heterogeneity** (Experiment 2): green is replaced by Genghis-II (``remove`` green and ``add-robot`` genghis at
  the same random time); red is taken away ``with_genghis`` s later; the trial ends ``after_last`` s after that.
  Measured: red's pushes per minute before and with Genghis-II (paired over seeds), Genghis-II's push rate against
  an R-2's, and whether Genghis-II goes home once the last R-2 is gone.

Every trial also gives the box's advance and heading drift. Removal times come from a generator seeded by the study
seed and the trial number, the same for every experiment. Rows: ``results.csv``; verdicts: ``report.md``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from teamsim.config import TrialConfig
from teamsim.controllers.alliance.motivation import AllianceParams
from teamsim.controllers.behaviours.box_pushing import BoxPushParams
from teamsim.faults import Fault
from teamsim.files import write_atomic, write_csv
from teamsim.stats import paired_t_test, ratio_ci
from teamsim.sweep import JOURNAL_NAME, run_trials
from teamsim.tasks.missions.box_pushing import BoxPushingParams
from teamsim.tasks.studies.findings import interval_text

EXPERIMENTS = ("robot-failure", "heterogeneity")
THESIS_PAUSE = (5.0, 8.0)  # s, §6.1.2: "a brief pause of about 5 to 8 seconds"
RADIO_PERIOD = 3.0  # s: one broadcast per robot every 3 s (§2.2.3); the spread the pause may show beyond phi
COLUMNS = ("experiment", "trial", "seed", "status", "change_at", "second_change_at", "advance_m", "heading_drift_deg",
           "pause_own_s", "pause_dead_s", "takeover_at", "survivor_ends", "returned_pushes", "pair_split",
           "red_rate_before", "red_rate_after", "helper_rate", "genghis_rate", "final_genghis", "go_home_delay_s",
           "early_home_s", *(f"{end}_per_min_{k}" for k in (1, 2, 3) for end in ("left", "right")),
           "real_time_factor")
PHASES = {"robot-failure": ("before the removal", "while green is away", "after the return"),
          "heterogeneity": ("red and green", "red and Genghis-II", "Genghis-II alone")}


@dataclass(frozen=True)
class BoxPushingStudy:
    trials: int = 20
    seed: int = 0
    experiments: tuple[str, ...] = EXPERIMENTS
    remove_window: tuple[float, float] = (20.0, 60.0)  # s: when the first change happens
    away: float = 80.0  # s green is away in robot-failure: room for red to push both ends twice
    after_return: float = 60.0
    with_genghis: float = 100.0  # s Genghis-II and red push together in heterogeneity
    after_last: float = 40.0
    settle: float = 20.0  # s after a change that rates and the pair's split are not counted over
    workers: int | None = None
    out: Path = Path("renders/study-box-pushing")
    resume: bool = False  # continue the study in ``out`` from its journal (trials.jsonl), issue 29


def change_time(study: BoxPushingStudy, trial: int) -> float:
    return round(float(np.random.default_rng((study.seed, trial)).uniform(*study.remove_window)), 1)


def trial_config(study: BoxPushingStudy, experiment: str, trial: int) -> TrialConfig:
    at = change_time(study, trial)
    if experiment == "robot-failure":
        faults = [Fault("remove", "green", at), Fault("revive", "green", at + study.away)]
        duration = at + study.away + study.after_return
    else:
        faults = [Fault("remove", "green", at), Fault("add-robot", "genghis", at, {"kind": "genghis2"}),
                  Fault("remove", "red", at + study.with_genghis)]
        duration = at + study.with_genghis + study.after_last
    # The box must not finish the mission before the experiment is over: room to the east wall is the limit.
    config = TrialConfig(mission="box-pushing", params=BoxPushingParams(advance=6.0), seed=study.seed + trial,
                         duration=duration, out=str(study.out / "trials"), run_id=f"{experiment}-{trial}",
                         faults=faults)
    config.video.fps = 2
    return config


def rate(pushes: list, robot: str, start: float, stop: float, end: str | None = None) -> float:
    """Pushes per minute completed by ``robot`` (at ``end``, or either) in [start, stop)."""
    n = sum(1 for r, e, _, done in pushes if r == robot and start <= done < stop and end in (None, e))
    return 60.0 * n / (stop - start) if stop > start else math.nan


def takeover(pushes: list, removed_at: float) -> tuple[float, float, str]:
    """(pause from red's own last push, pause from green's last push complete, when): red's first activation at
    green's end (right) after the removal."""
    first = next((p for p in pushes if p[0] == "red" and p[1] == "right" and p[2] >= removed_at), None)
    if first is None:
        return math.nan, math.nan, math.nan
    own = max((p[3] for p in pushes if p[0] == "red" and p[3] <= first[2]), default=math.nan)
    dead = max((p[3] for p in pushes if p[0] == "green" and p[3] <= removed_at), default=math.nan)
    return first[2] - own, first[2] - dead, first[2]


def result_row(study: BoxPushingStudy, config: TrialConfig, summary: dict) -> dict:
    experiment, trial = config.run_id.rsplit("-", 1)
    metrics = summary.get("metrics") or {}
    pushes = metrics.get("push_log", [])
    at, end = change_time(study, int(trial)), config.duration
    row = {"experiment": experiment, "trial": int(trial), "seed": config.seed, "status": summary["status"],
           "change_at": at, "advance_m": metrics.get("advance_m"),
           "heading_drift_deg": metrics.get("heading_drift_deg"), "real_time_factor": summary.get("real_time_factor")}
    second = at + (study.away if experiment == "robot-failure" else study.with_genghis)
    for k, (start, stop) in enumerate(((0.0, at), (at + study.settle, second), (second + study.settle, end)), 1):
        for side in ("left", "right"):
            row[f"{side}_per_min_{k}"] = sum(rate(pushes, robot, start, stop, side)
                                             for robot in sorted({p[0] for p in pushes}))
    if experiment == "robot-failure":
        back = at + study.away
        own, dead, first = takeover(pushes, at)
        away = {e for r, e, _, done in pushes if r == "red" and at <= done < back}
        after = [(r, e) for r, e, _, done in pushes if done >= back + study.settle]
        ends = [{e for r, e in after if r == robot} for robot in ("red", "green")]
        split = all(len(e) == 1 for e in ends) and ends[0] != ends[1]
        row.update(second_change_at=back, pause_own_s=own, pause_dead_s=dead, takeover_at=first,
                   survivor_ends="+".join(sorted(away)),
                   returned_pushes=sum(r == "green" for r, _ in after),
                   pair_split=split,
                   red_rate_before=rate(pushes, "red", 0.0, at), red_rate_after=rate(pushes, "red", back + study.settle,
                                                                                       end))
    else:
        last = at + study.with_genghis
        final = (metrics.get("final_behaviour") or {}).get("genghis")
        home_at = (metrics.get("went_home_at") or {}).get("genghis")
        home_s = (summary.get("robots") or {}).get("genghis", {}).get("task_time_s", {}).get("go-home", 0.0)
        row.update(second_change_at=last, red_rate_before=rate(pushes, "red", 0.0, at, "left"),
                   red_rate_after=rate(pushes, "red", at + study.settle, last, "left"),
                   helper_rate=rate(pushes, "green", 0.0, at, "right"),
                   genghis_rate=rate(pushes, "genghis", at + study.settle, last),
                   final_genghis=final,
                   go_home_delay_s=round(home_at - last, 1) if final == "go-home" and home_at is not None else None,
                   # go-home time before the last R-2 went: Genghis-II heard nobody at the opposite end for tau
                   early_home_s=round(home_s - (end - home_at if final == "go-home" else 0.0), 1))
    return row


def run_study(study: BoxPushingStudy) -> Path:
    configs = [trial_config(study, e, k) for e in study.experiments for k in range(study.trials)]
    summaries = run_trials(configs, workers=study.workers, journal=study.out / JOURNAL_NAME,
                           resume=study.resume)
    rows = [result_row(study, c, s) for c, s in zip(configs, summaries)]
    study.out.mkdir(parents=True, exist_ok=True)
    write_csv(study.out / "results.csv", COLUMNS, rows, float_format=".4g")
    write_atomic(study.out / "report.md", report(study, rows).encode())
    return study.out


def _summary(values) -> str:
    v = np.array([x for x in values if x is not None and math.isfinite(x)])
    if v.size == 0:
        return "none measured"
    return f"median {np.median(v):.1f}, range {v.min():.1f}-{v.max():.1f}, mean {v.mean():.1f} (n = {v.size})"


def _robot_failure(study: BoxPushingStudy, rows: list[dict]) -> list[str]:
    n = len(rows)
    lo, hi = THESIS_PAUSE
    dead = [r["pause_dead_s"] for r in rows]
    removal = [r["takeover_at"] - r["change_at"] for r in rows]
    inside = sum(lo <= p <= hi for p in removal)
    spread = sum(lo - RADIO_PERIOD <= p <= hi + RADIO_PERIOD for p in removal)
    both = sum(r["survivor_ends"] == "left+right" for r in rows)
    split = sum(bool(r["pair_split"]) for r in rows)
    outside = [r for r in rows if not lo <= r["takeover_at"] - r["change_at"] <= hi]
    phi, tau = BoxPushParams().r2_patience, AllianceParams().tau
    lines = ["## Experiment 1: robot failure", "",
             f"green taken away at a random time in {study.remove_window[0]:g}-{study.remove_window[1]:g} s, put back "
             f"{study.away:g} s later; {n} trials. The takeover is red's activation of push-right (green's end). "
             "Parker times the pause from the seizure ('one R-2 is seized and switched off. After a brief pause of "
             "about 5 to 8 seconds ...'), the first row; the second times it from green's last push complete, "
             "which, when its news went out, red first answers with one more push at its own end.", "",
             "| what | thesis | teamsim | verdict |", "|---|---|---|---|",
             f"| takeover pause after green's removal (s) | about 5-8 | {_summary(removal)}; {inside}/{n} in 5-8 s, "
             f"{spread}/{n} within one radio period (3 s) of it | {'yes' if spread == n else 'partly'}: 'about', read "
             "as within a radio period |",
             f"| the same after green's last push complete (s) | - | {_summary(dead)}; "
             f"{sum(lo <= p <= hi for p in dead if math.isfinite(p))}/{n} in 5-8 s | |",
             f"| the same after red's own last push complete (s) | - | {_summary(r['pause_own_s'] for r in rows)} | "
             f"phi = {phi:g} s from green's first message after that push, or tau = {tau:g} s after green's last "
             "message, whichever comes first |",
             f"| red alternates both ends while green is away | yes | {both}/{n} | "
             f"{'yes' if both == n else 'partly'} |",
             f"| back, green pushes one end and the pair alternates (each robot one end from "
             f"{study.settle:g} s after the return) | yes | {split}/{n} | {'yes' if split == n else 'partly'} |",
             f"| red's pushes per minute: before / after the return | - | "
             f"{_mean(rows, 'red_rate_before'):.1f} / {_mean(rows, 'red_rate_after'):.1f} | |", ""]
    if outside:
        lines += [f"Pauses after the removal outside 5-8 s, with the times that make them. Red's impatience for "
                  f"green's end grows at delta_slow_R(R-2) = theta / phi (phi = {phi:g} s) from green's first message "
                  f"after red's own push, while green's claim on that end is within tau ({tau:g} s), and then at "
                  "delta_fast; red hears green only at green's 1/3 Hz radio slots, and news of a push green completed "
                  "just before it was taken away may never be sent:", ""]
        lines += [f"- trial {r['trial']} (seed {r['seed']}): {_pause_reason(r)}" for r in outside]
        lines.append("")
    return lines


def _pause_reason(row: dict) -> str:
    """The measured times around a takeover: when green went relative to its last push, and red's own last push."""
    if not math.isfinite(row["pause_dead_s"]):
        return f"red never took green's end over (status {row['status']})"
    first = row["takeover_at"]
    green_last, red_last = first - row["pause_dead_s"], first - row["pause_own_s"]
    return (f"pause {first - row['change_at']:.1f} s: green removed at {row['change_at']:.1f} s, "
            f"{row['change_at'] - green_last:.1f} s after its last push complete; red's own last push complete "
            f"{red_last - row['change_at']:+.1f} s from the removal; red activated push-right at {first:.1f} s")


def _mean(rows: list[dict], key: str) -> float:
    v = [r[key] for r in rows if r.get(key) is not None and math.isfinite(r[key])]
    return float(np.mean(v)) if v else math.nan


def _heterogeneity(study: BoxPushingStudy, rows: list[dict]) -> list[str]:
    n = len(rows)
    before, after = [r["red_rate_before"] for r in rows], [r["red_rate_after"] for r in rows]
    _, p = paired_t_test(after, before)
    fewer = sum(a < b for a, b in zip(after, before))
    home = sum(r["final_genghis"] == "go-home" for r in rows)
    early = [r for r in rows if (r.get("early_home_s") or 0.0) > 0.0]
    drop = _mean(rows, "red_rate_after") / _mean(rows, "red_rate_before")
    lines = ["## Experiment 2: heterogeneity", "",
             f"green replaced by Genghis-II at a random time in {study.remove_window[0]:g}-"
             f"{study.remove_window[1]:g} s; red taken away {study.with_genghis:g} s later; {n} trials.", "",
             "| what | thesis | teamsim | verdict |", "|---|---|---|---|",
             f"| red's left pushes per minute, with green / with Genghis-II | falls ('much less frequently') | "
             f"{_mean(rows, 'red_rate_before'):.1f} / {_mean(rows, 'red_rate_after'):.1f} (x{drop:.2f}, 95 % CI "
             f"{interval_text(*ratio_ci(after, before)[1:]) or '-'}); fewer in "
             f"{fewer}/{n}; paired t-test p = {p:.2g} | {'yes' if fewer == n and p < 0.05 else 'partly'} |",
             f"| pushes per minute at the right end, green (R-2) / Genghis-II | Genghis-II slower | "
             f"{_mean(rows, 'helper_rate'):.1f} / {_mean(rows, 'genghis_rate'):.1f} | "
             f"{'yes' if _mean(rows, 'genghis_rate') < _mean(rows, 'helper_rate') else 'no'} |",
             f"| Genghis-II goes home once the last R-2 is gone | yes | {home}/{n}; delay after red's removal: "
             f"{_summary(r['go_home_delay_s'] for r in rows)} s | {'yes' if home == n else 'partly'} |",
             f"| ... and not before | yes | went home while red was there in {len(early)}/{n}"
             + (": " + ", ".join(f"trial {r['trial']} ({r['early_home_s']:g} s)" for r in early) if early else "")
             + f" | {'yes' if not early else 'partly'} |", ""]
    if early:
        lines += ["Genghis-II joins as green leaves, and red takes green's end over after its pause unless it has "
                  "heard Genghis-II announce that end first (one radio slot, up to 3 s): then red pushes the right "
                  "end, nobody announces the left one, and Genghis-II, hearing nobody at the opposite end for tau, "
                  "goes home until red is back at the left end.", ""]
    return lines


def report(study: BoxPushingStudy, rows: list[dict]) -> str:
    lines = ["# Box pushing (Parker §6.1.2)", "",
             f"Seeds {study.seed}..{study.seed + study.trials - 1}; the thesis made more than 30 physical runs and "
             "reports no distribution. Per-trial rows: `results.csv`; each trial's outputs (timeline.png, "
             "events.jsonl): `trials/`.", ""]
    failed = [r for r in rows if r["status"] not in ("completed", "failed")]
    if failed:
        lines += ["Trials that did not run to their end: " + ", ".join(
            f"{r['experiment']} {r['trial']} ({r['status']})" for r in failed) + ".", ""]
    for experiment, section in (("robot-failure", _robot_failure), ("heterogeneity", _heterogeneity)):
        chosen = [r for r in rows if r["experiment"] == experiment]
        if chosen:
            lines += section(study, chosen)
    lines += ["## Pushes per minute at each end", "",
              f"All robots together, in each phase of a trial (the first {study.settle:g} s after a change left "
              "out). Means over trials.", "", "| experiment | phase | left | right |", "|---|---|---|---|"]
    for experiment in study.experiments:
        chosen = [r for r in rows if r["experiment"] == experiment]
        for k, phase in enumerate(PHASES[experiment], 1):
            lines.append(f"| {experiment} | {phase} | {_mean(chosen, f'left_per_min_{k}'):.1f} | "
                         f"{_mean(chosen, f'right_per_min_{k}'):.1f} |")
    lines += ["", "## The box", "", "| experiment | advance (m) | heading drift (deg) |", "|---|---|---|"]
    for experiment in study.experiments:
        chosen = [r for r in rows if r["experiment"] == experiment]
        lines.append(f"| {experiment} | {_summary(r['advance_m'] for r in chosen)} | "
                     f"{_summary(r['heading_drift_deg'] for r in chosen)} |")
    return "\n".join(lines) + "\n"
