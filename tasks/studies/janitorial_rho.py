"""``teamsim study janitorial-rho``: Parker's communication-rate study on the janitorial service (§6.2.3, Fig. 6-13).

The ``janitorial`` mission at each broadcast rate rho (broadcasts per second per robot; 0: no messages at all), the
same ``missions`` seeds at every rho, so rates are compared mission by mission. The metric is mission completion
time. A run that did not complete has no mission time: its time is censored at the duration, and the report says
how many runs completed and when a mean over the completed ones is biased.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.stats import wilcoxon

from teamsim.config import TrialConfig
from teamsim.files import write_atomic, write_csv
from teamsim.plots import pyplot, save_figure
from teamsim.stats import ratio_ci
from teamsim.sweep import JOURNAL_NAME, run_trials
from teamsim.tasks.missions.janitorial import JanitorialMission, JanitorialParams
from teamsim.tasks.studies.findings import Finding, verdict

# where the team's robot-seconds went: column -> the behaviour-set names it sums over (all robots, every instance)
TIME_USES = {"empty_garbage": ("empty-garbage",), "dust_furniture": ("dust-furniture",),
             "clean_floor": ("clean-floor",), "verification": ("verify-",), "idle": ("idle",)}
COLUMNS = ("rho", "mission", "seed", "status", "completed", "mission_time_s", "cans_emptied", "cans",
           "objects_dusted", "objects", "floor_cleaned", *(f"{name}_s" for name in TIME_USES), "real_time_factor")
MIN_COMPLETED = 5  # completed runs each rho needs before its mean is compared
THESIS_RHO0_MEAN = 438  # time units of Parker's simulator, 10 runs (§6.2.3)
# (rho a, rho b) -> (the thesis's words, the range of b's change against a, in %, that reproduces them "as worded")
THESIS_STEPS = {(0.0, 0.1): ("about 22 % less time", (-33.0, -11.0)),
                (0.1, 0.5): ("a further 10 % less", (-15.0, -5.0)),
                (0.5, 2.0): ('"not getting closer to the optimal"', (-5.0, math.inf))}


@dataclass(frozen=True)
class JanitorialRhoStudy:
    rhos: tuple[float, ...] = (0.0, 0.1, 0.5, 2.0)
    missions: int = 10
    seed: int = 0
    workers: int | None = None
    out: Path = Path("renders/study-janitorial-rho")
    duration: float | None = None
    resume: bool = False  # continue the study in ``out`` from its journal (trials.jsonl), issue 29


def rhos_of(study: JanitorialRhoStudy) -> list[float]:
    """The study's rates, each once, in increasing order (the order consecutive rates are compared in)."""
    return sorted({float(rho) for rho in study.rhos})


def duration_of(study: JanitorialRhoStudy) -> float:
    """Simulated seconds per mission: where a run that did not complete is censored."""
    return study.duration or JanitorialMission.default_duration


def trial_configs(study: JanitorialRhoStudy) -> list[TrialConfig]:
    configs = []
    for rho in rhos_of(study):
        for k in range(study.missions):
            config = TrialConfig(mission="janitorial", params=JanitorialParams(rho=rho), seed=study.seed + k,
                                 duration=study.duration, out=str(study.out / "trials"), run_id=f"rho{rho:g}-{k}")
            config.video.fps = 2  # the trajectory of a study mission is for inspection, not for video
            configs.append(config)
    return configs


def result_row(config: TrialConfig, summary: dict) -> dict:
    """One run's row; ``mission_time_s`` only for a completed run (any other has no mission time)."""
    metrics = summary.get("metrics") or {}
    completed = bool(summary.get("completed", False))
    row = {"rho": config.params.rho, "mission": int(config.run_id.rsplit("-", 1)[1]), "seed": config.seed,
           "status": summary["status"], "completed": completed,
           "mission_time_s": metrics.get("mission_time_s") if completed else None,
           "real_time_factor": summary.get("real_time_factor")}
    for key in ("cans_emptied", "cans", "objects_dusted", "objects", "floor_cleaned"):
        row[key] = metrics.get(key)
    per_robot = (metrics.get("task_time_s") or {}).values()
    for name, prefixes in TIME_USES.items():
        row[f"{name}_s"] = round(sum(seconds for tasks in per_robot for task, seconds in tasks.items()
                                     if task.startswith(prefixes)), 1) if per_robot else None
    return row


def run_study(study: JanitorialRhoStudy) -> Path:
    configs = trial_configs(study)
    summaries = run_trials(configs, workers=study.workers, journal=study.out / JOURNAL_NAME, resume=study.resume)
    return write_results(study, configs, summaries)


def write_results(study: JanitorialRhoStudy, configs: list[TrialConfig], summaries: list[dict]) -> Path:
    """``results.csv``, ``times.png`` (and ``.svg``) and ``report.md`` in ``study.out`` from the trials' summaries."""
    rows = [result_row(c, s) for c, s in zip(configs, summaries)]
    study.out.mkdir(parents=True, exist_ok=True)
    write_csv(study.out / "results.csv", COLUMNS, rows)
    write_atomic(study.out / "report.md", report(study, rows).encode())
    plot_times(study.out / "times.png", rows, rhos_of(study), duration_of(study))
    return study.out


# -- statistics ---------------------------------------------------------------------------------------------------
def times(rows: list[dict], rho: float) -> dict[int, float]:
    """Mission time per seed of the runs at ``rho`` that completed."""
    return {r["seed"]: r["mission_time_s"] for r in rows if r["rho"] == rho and r["completed"]
            and r["mission_time_s"] is not None}


def at(rows: list[dict], rho: float) -> list[dict]:
    return [r for r in rows if r["rho"] == rho]


def mean_sd(values) -> tuple[float, float]:
    values = list(values)
    mean = float(np.mean(values)) if values else math.nan
    return mean, float(np.std(values, ddof=1)) if len(values) > 1 else math.nan


def wilcoxon_p(a: list[float], b: list[float]) -> float:
    """Two-sided p of the Wilcoxon signed-rank test on the pairs (a_i, b_i); nan with fewer than two pairs."""
    if len(a) < 2:
        return math.nan
    if all(x == y for x, y in zip(a, b)):
        return 1.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return float(wilcoxon(a, b).pvalue)


def step(rows: list[dict], a: float, b: float) -> dict:
    """Rho a against rho b: the ratio of their mean times (completed runs), the pairs both completed, the 95 %
    confidence interval of the ratio over those pairs (Fieller, ``teamsim.stats.ratio_ci``) and their p."""
    first, second = times(rows, a), times(rows, b)
    seeds = sorted(set(first) & set(second))
    ratio = mean_sd(second.values())[0] / mean_sd(first.values())[0] if first and second else math.nan
    few = min(len(first), len(second)) < MIN_COMPLETED
    _, low, high = ratio_ci([second[s] for s in seeds], [first[s] for s in seeds])
    return {"ratio": ratio, "pairs": len(seeds), "few": few, "ci": (low, high),
            "biased": any(not r["completed"] for r in at(rows, a) + at(rows, b)),
            "p": wilcoxon_p([first[s] for s in seeds], [second[s] for s in seeds])}


def claims(rows: list[dict], rhos: list[float]) -> list[tuple[Finding, int | None]]:
    """The thesis's statements about the rates this study ran, each with teamsim's figure, p, verdict and the
    number of missions the p is over (None: no comparison)."""
    found = []
    if 0.0 in rhos:
        done, runs = times(rows, 0.0), len(at(rows, 0.0))
        figure = f"{len(done)}/{runs} completed"
        if done:
            figure += f", mean {mean_sd(done.values())[0]:.0f} s" + (" (biased low)" if len(done) < runs else "")
        judged = ("too few completed runs to decide" if runs < MIN_COMPLETED else
                  verdict(int(len(done) == runs), 1) if len(done) in (0, runs) else "partly")
        found.append((Finding("rho = 0 (no messages): the mission still completes",
                              f"every run completed, mean {THESIS_RHO0_MEAN} time units", figure, judged), None))
    for a, b in zip(rhos, rhos[1:]):
        words, (lo, hi) = THESIS_STEPS.get((a, b), ("-", (math.nan, math.nan)))
        s = step(rows, a, b)
        change = 100 * (s["ratio"] - 1)
        figure = "no mean" if math.isnan(change) else f"x{s['ratio']:.2f} ({change:+.0f} %)"
        if not math.isnan(s["ci"][0]):
            figure += f" [95 % CI of the paired ratio: x{s['ci'][0]:.2f} to x{s['ci'][1]:.2f}]"
        if s["biased"] and not math.isnan(change):
            figure += ", biased: not every run completed"
        if s["few"]:
            judged = "too few completed runs to decide"
        elif words == "-":
            judged = "n/a"
        elif lo <= change <= hi:
            judged = "yes"
        else:
            judged = "partly" if hi < 0 and change < 0 else "**no**"
        found.append((Finding(f"rho {a:g} -> {b:g}: mean mission time", words, figure, judged, s["p"]), s["pairs"]))
    return found


# -- report -------------------------------------------------------------------------------------------------------
def report(study: JanitorialRhoStudy, rows: list[dict]) -> str:
    rhos, duration = rhos_of(study), duration_of(study)
    lines = ["# Communication-rate study (Parker §6.2.3, Fig. 6-13) re-run in teamsim", "",
             f"{study.missions} missions per rate (the thesis: 10), seeds {study.seed}.."
             f"{study.seed + study.missions - 1} at every rate. rho = broadcasts per second per robot; rho = 0: every "
             "robot's radio off from t = 0 (no messages at all). Mission time = simulated seconds until every can is "
             "emptied, every object dusted and the share `task.floor_share` of the floor cleaned. A run that did "
             f"not complete in its {duration:g} s has no mission time: it is censored at {duration:g} s. Per-mission "
             "rows: `results.csv`.", "",
             "## Mission time per rate", "",
             "Mean and s.d. over the runs that completed. Where some did not, that mean leaves the slowest missions "
             f"out and is **biased low**; \"lower bound\" counts each run that ran out of time at {duration:g} s "
             f"(those runs needed longer). Fewer than {MIN_COMPLETED} completed runs: too few to decide.", "",
             "| rho | n | completed | mean time (s) | s.d. (s) | not completed | lower bound (s) | note |",
             "|---|---|---|---|---|---|---|---|"]
    for rho in rhos:
        runs, done = at(rows, rho), times(rows, rho)
        mean, sd = mean_sd(done.values())
        timed_out = [r for r in runs if r["status"] == "failed"]
        other = [r for r in runs if not r["completed"] and r["status"] != "failed"]
        missing = [f"{len(timed_out)} ran out of time"] if timed_out else []
        missing += [f"{len(other)} ended in error ({', '.join(sorted({r['status'] for r in other}))})"] if other else []
        bound = mean_sd([*done.values(), *[duration] * len(timed_out)])[0] if timed_out and not other else math.nan
        notes = [] if len(done) >= MIN_COMPLETED else ["too few completed runs to decide"]
        notes += [f"mean biased low ({len(runs) - len(done)} of {len(runs)} runs left out)"] if 0 < len(done) < len(
            runs) else []
        lines.append(f"| {rho:g} | {len(runs)} | {len(done)} | {_number(mean)} | {_number(sd)} | "
                     f"{', '.join(missing) or '-'} | {_number(bound)} | {'; '.join(notes) or '-'} |")
    lines += ["", "## Against the thesis", "",
              "Change = the mean time at the second rate over the mean at the first (completed runs of each), as a "
              "ratio and in %. p: two-sided Wilcoxon signed-rank test (scipy.stats.wilcoxon, exact for small samples) "
              "on the missions both rates completed (pairs: how many; with fewer than 6 pairs p cannot fall below "
              "0.05). **yes** where the thesis's figure holds as worded (22 %: a reduction of 11-33 %; 10 %: 5-15 %; "
              "\"not getting closer\": less than 5 % faster), **partly** where the time falls but by another amount, "
              f"**no** otherwise; fewer than {MIN_COMPLETED} completed runs at either rate: too few completed runs to "
              "decide. A reduction with p >= 0.05 is not decided by this sample. The thesis's time units are its "
              "simulator's, not seconds: only its ratios compare.", "",
              "| claim | thesis | teamsim | pairs | p (Wilcoxon) | reproduced |", "|---|---|---|---|---|---|"]
    for found, pairs in claims(rows, rhos):
        undecided = pairs is not None and found.verdict in ("yes", "partly") and "not getting" not in found.thesis \
            and not found.p < 0.05
        lines.append(f"| {found.claim} | {found.thesis} | {found.teamsim} | {'-' if pairs is None else pairs} | "
                     f"{'-' if math.isnan(found.p) else f'{found.p:.2g}'} | "
                     f"{found.verdict}{', not decided by this sample' if undecided else ''} |")
    lines += ["", "![mission time per rate](times.png)", "", *time_uses(rows, rhos), "",
              "## Why teamsim may differ", "", DIFFERENCES]
    return "\n".join(lines) + "\n"


def time_uses(rows: list[dict], rhos: list[float]) -> list[str]:
    """The report's table of where the team's robot-seconds went at each rate, each against the lowest rate."""
    base = rhos[0]
    lines = ["## Where the team's time went", "",
             "Robot-seconds per mission summed over the robots, by what each was doing (`task_time_s` in the runs' "
             "summaries; columns `*_s` of `results.csv`): the three tasks, the low-priority verification sets and "
             f"idle. Median over every run at the rate; in brackets the paired Wilcoxon p against rho = {base:g} on "
             "the same seeds. Messages are there to cut the task columns (less duplicated work); the mission time "
             "falls only where the time saved shortens the last task to finish rather than turning into "
             "verification or idle time.", "",
             "| rho | " + " | ".join(name.replace("_", " ") for name in TIME_USES) + " |",
             "|---|" + "---|" * len(TIME_USES)]
    def per_seed(rho: float, name: str) -> dict[int, float]:
        return {r["seed"]: r[f"{name}_s"] for r in at(rows, rho) if r[f"{name}_s"] is not None}

    first = {name: per_seed(base, name) for name in TIME_USES}
    for rho in rhos:
        cells = []
        for name in TIME_USES:
            seconds = per_seed(rho, name)
            seeds = sorted(set(seconds) & set(first[name]))
            p = wilcoxon_p([first[name][s] for s in seeds], [seconds[s] for s in seeds]) if rho != base else math.nan
            median = float(np.median(list(seconds.values()))) if seconds else math.nan
            cells.append(_number(median) + ("" if math.isnan(p) else f" (p {p:.2g})"))
        lines.append(f"| {rho:g} | " + " | ".join(cells) + " |")
    return lines


def _number(value: float) -> str:
    return "-" if math.isnan(value) else f"{value:.0f}"


DIFFERENCES = """\
- Parker's times are in her simulator's time units; teamsim's are simulated seconds of MuJoCo physics. Only the
  ratios between rates compare.
- Her "optimal" reference came from hand-engineering every parameter and is given in Fig. 6-13 only; teamsim does
  not reproduce it, so "not getting closer to the optimal" is checked as: rho = 2 is less than 5 % faster than
  rho = 0.5.
- The room, its cans, objects and obstacles are drawn from the seed (the same rooms at every rate); Parker's
  variance came from sensor and effector noise in her simulator.
"""


# -- figure -------------------------------------------------------------------------------------------------------
def plot_times(path: Path, rows: list[dict], rhos: list[float], duration: float) -> None:
    """Fig. 6-13's form: each run's mission time at each rate, the mean of the completed runs marked; a run that
    did not complete is drawn hollow at the duration, where its time is censored (an errored run is not drawn).
    Written as ``path`` (PNG) and the same stem ``.svg``."""
    fig, axes = pyplot().subplots(figsize=(8.2, 3.8))
    finished = [r["mission_time_s"] for r in rows if r["completed"] and r["mission_time_s"] is not None]
    censored = any(r["status"] == "failed" for r in rows)
    if censored:
        axes.axhline(duration, color="0.47", lw=1)
        axes.annotate(f"duration {duration:g} s", (0, duration), xycoords=("axes fraction", "data"),
                      xytext=(4, 4), textcoords="offset points", color="0.47", fontsize=8)
    for c, rho in enumerate(rhos):
        runs = sorted(at(rows, rho), key=lambda r: r["seed"])
        spread = [c + 0.5 * ((k + 0.5) / len(runs) - 0.5) for k in range(len(runs))]  # the runs across the column
        done = [(x, r["mission_time_s"]) for x, r in zip(spread, runs) if r["completed"]
                and r["mission_time_s"] is not None]
        failed = [x for x, r in zip(spread, runs) if r["status"] == "failed"]
        axes.plot([x for x, _ in done], [t for _, t in done], "o", color="C0", ms=6,
                  label="completed run" if c == 0 else None)
        axes.plot(failed, [duration] * len(failed), "o", mfc="none", color="C3", ms=6,
                  label="not completed (censored at the duration)" if c == 0 else None)
        mean = mean_sd(times(rows, rho).values())[0]
        axes.hlines(mean, c - 0.35, c + 0.35, color="black", lw=2,
                    label="mean of the completed runs" if c == 0 else None)
    axes.set_xticks(range(len(rhos)), [f"rho = {rho:g}\n{len(times(rows, rho))}/{len(at(rows, rho))} completed"
                                       for rho in rhos])
    top = 1.08 * max([*finished, *([duration] if censored or not finished else [])])
    axes.set(xlim=(-0.5, len(rhos) - 0.5), ylim=(0, top), ylabel="time (s)")
    axes.set_title("Mission time per rate rho (Parker Fig. 6-13)", loc="left")
    axes.grid(axis="y", color="0.88")
    axes.set_axisbelow(True)
    axes.spines[["top", "right"]].set_visible(False)
    axes.legend(loc="upper left", bbox_to_anchor=(0, -0.2), ncol=3, frameon=False, fontsize=8)
    fig.tight_layout()
    save_figure(fig, path)
