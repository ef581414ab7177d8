"""``teamsim study feedback``: Chand's feedback experiments (§8.2, Table 8.1 levels 1.2-3.4; §8.4-8.5, Figs
8.7-8.25), re-run on the ``explore`` mission's kinematic backend.

Every level compares runs with feedback against the same worlds and seeds without it (level 1: 1.1 no forced
failure, 1.2 a forced partial failure, 1.3 a forced complete failure), so its ratios (feedback / no feedback) and
paired two-sided t-tests are the thesis's. The levels, in the order of §8.2's tuning:

- ``task-score`` (level 2): task scores only, no reallocation; weight sets W1-W4 on [1 3] and [1 5];
- ``poor`` (3.1): the whole coordination; OTES_T P1-P4, TES_T 0.15 (F2), WS the best of level 2; all teams;
- ``partial`` (3.2): a forced partial failure (an explorer's motors break for good); TES_T F1-F4, OTES_T the best
  of 3.1; [1 3] and [1 5];
- ``complete`` (3.3): a forced complete failure (an explorer silenced for good), the best of 3.1 and 3.2;
- ``combined`` (3.4): every component at its best, no forced failure, all teams.

Tuning is at T_m = 60 s; the best variant of each level (per team, highest mean ER) is then re-run at 180 and 300
s. A level not run leaves the thesis's best (W3, P1, F2). The failing explorer and the failure time come from the
study seed, the world and the repeat, never a planner (docs/decisions.md, "Feedback study"): the same with and
without feedback.
"""
from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from teamsim.faults import parse_fault
from teamsim.files import write_atomic, write_csv
from teamsim.plots import pyplot, save_figure
from teamsim.stats import paired_t_test, ratio_ci
from teamsim.sweep import run_trials
from teamsim.tasks.missions.explore import TABLE_5_22, team_allocation
from teamsim.tasks.missions.explore import EXPLORER as EXPLORER_TASK
from teamsim.tasks.missions.explore import PLANNER as PLANNER_TASK
from teamsim.tasks.studies.exploration import (COLOURS, DENSITIES, MEASURED, NAME, TEAMS, explore_config,
                                               judged, paired_by, result_row, runs)
from teamsim.tasks.studies.findings import Finding, ratio_text, table


@dataclass(frozen=True)
class Level:
    name: str
    what: str
    teams: tuple[str, ...]
    failure: str  # forced failure: "none", "partial" or "complete"
    mode: str  # explore's feedback setting
    tuned: str | None  # the setting its variants try, or None (the best of the levels before)
    variants: tuple[str, ...]


LEVELS = {level.name: level for level in (
    Level("task-score", "task-score feedback (level 2)", ("1 3", "1 5"), "none", "scores", "weights",
          ("W1", "W2", "W3", "W4")),
    Level("poor", "poor-performance feedback (level 3.1)", TEAMS, "none", "on", "poor", ("P1", "P2", "P3", "P4")),
    Level("partial", "partial-failure feedback (level 3.2)", ("1 3", "1 5"), "partial", "on", "partial",
          ("F1", "F2", "F3", "F4")),
    Level("complete", "complete-failure feedback (level 3.3)", ("1 3", "1 5"), "complete", "on", None, ("best",)),
    Level("combined", "combined feedback (level 3.4)", TEAMS, "none", "on", None, ("best",)),
)}
THESIS_BEST = {"weights": "W3", "poor": "P1", "partial": "F2"}  # §8.4-8.5
T_M = (60.0, 180.0, 300.0)
FAILURE_WINDOW = (200.0, 600.0)  # s: a forced failure strikes at a time drawn uniformly from it
# (level, team, variant as the thesis names it, metric, the thesis's ratio feedback / no feedback), T_m 60 s
THESIS = (("task-score", "1 3", "W3", "explored_share", 1.026),
          ("poor", "1 1", "P1", "exploration_time", 0.733), ("poor", "1 3", "P1", "exploration_time", 0.89),
          ("poor", "1 5", "P1", "exploration_time", 0.895), ("poor", "1 1", "P1", "explored_share", 1.574),
          ("poor", "1 1", "P1", "exploration_rate", 2.13), ("poor", "1 3", "P1", "exploration_rate", 1.172),
          ("poor", "1 5", "P1", "exploration_rate", 1.078),
          ("partial", "1 3", "F2", "exploration_rate", 1.294), ("partial", "1 3", "F2", "explored_share", 1.108),
          ("partial", "1 3", "F2", "exploration_time", 0.881), ("partial", "1 5", "F1", "exploration_rate", 1.135),
          ("partial", "1 5", "F1", "exploration_time", 0.891),
          ("complete", "1 3", "best", "exploration_time", 0.899),
          ("complete", "1 3", "best", "exploration_rate", 1.281),
          ("complete", "1 5", "best", "exploration_time", 0.745),
          ("complete", "1 5", "best", "exploration_rate", 1.472),
          ("combined", "1 1", "best", "exploration_rate", 2.19),
          ("combined", "1 3", "best", "exploration_rate", 1.197),
          ("combined", "1 5", "best", "exploration_rate", 1.077))
COLUMNS = ("level", "team", "variant", "t_m", "failure", "fault", "weights", "poor", "partial", "density", "bogs",
           "world", "repeat", "seed", "world_seed", "status", "finished", "exploration_time", "explored_share",
           "exploration_rate", "map_accuracy", "partly_explored", "unexplored", "boggy_environments", "bogs_found",
           "reallocations", "flags", "detected_s", "real_time_factor")


@dataclass(frozen=True)
class FeedbackStudy:
    levels: tuple[str, ...] = tuple(LEVELS)
    worlds: int = 1  # per environment type (the thesis: 10)
    repeats: int = 1  # runs per world (the thesis: 10)
    seed: int = 0
    densities: tuple[float, ...] = DENSITIES
    bogs: tuple[bool, ...] = (False, True)
    retune_t_m: bool = True  # re-run each level's best at T_m 180 and 300 s
    workers: int | None = None
    ray: bool = False
    duration: float | None = None  # simulated seconds per run; None: MET
    out: Path = Path("renders/study-feedback")
    resume: bool = False


# -- the design -------------------------------------------------------------------------------------------------------
def forced_fault(study: FeedbackStudy, team: str, run: tuple, failure: str) -> str | None:
    """The fault spec of a forced failure in ``run``: an explorer that is not a planner, at a time in
    ``FAILURE_WINDOW``, both drawn from the study seed, the world and the repeat (so the same with and without
    feedback)."""
    if failure == "none":
        return None
    candidates = failable_explorers(team)
    _, _, _, repeat, layout = run
    rng = np.random.default_rng([study.seed, layout, repeat])
    robot = candidates[int(rng.integers(len(candidates)))]
    at = float(rng.uniform(*FAILURE_WINDOW))
    return f"{'break-motor' if failure == 'partial' else 'kill'}:{robot}@{at:.1f}"


@functools.cache
def failable_explorers(team: str) -> list[str]:
    """The team's explorers that are not also its planner (§8.2's team from Table 5.22)."""
    allocation = team_allocation(list(TABLE_5_22), *(int(n) for n in team.split()))
    candidates = [r for r in allocation.workers[EXPLORER_TASK] if r not in allocation.workers[PLANNER_TASK]]
    if not candidates:
        raise ValueError(f"team [{team}]: no explorer that is not also the planner, to fail")
    return candidates


def settings_of(level: Level, variant: str, best: dict) -> dict:
    """The explore settings of one variant of a level: the tuned setting at ``variant``, the others at the best
    found so far for the team (``best``: setting -> value)."""
    chosen = {"weights": best["weights"], "poor": best["poor"], "partial": best["partial"]}
    if level.name == "task-score":
        chosen.update(poor="off", partial="off")
    if level.tuned is not None:
        chosen[level.tuned] = variant
    if level.name == "poor":
        chosen["partial"] = "F2"  # Table 8.1: TES_T fixed at 0.15 while OTES_T is tuned
    return chosen


def baseline_configs(study: FeedbackStudy) -> list:
    """Level 1: each team of the levels asked for, with the forced failures they use, feedback off."""
    wanted = sorted({(team, LEVELS[name].failure) for name in study.levels for team in LEVELS[name].teams},
                    key=lambda pair: (TEAMS.index(pair[0]), pair[1]))
    configs = []
    for team, failure in wanted:
        for run in runs(study):
            fault = forced_fault(study, team, run, failure)
            configs.append(explore_config(study, team, run, f"baseline-{failure}_", feedback="off",
                                          faults=[parse_fault(fault)] if fault else []))
    return configs


def level_configs(study: FeedbackStudy, level: Level, best: dict, t_m: float, variants=None) -> list:
    """The runs of one level at ``t_m``: every variant (or ``variants``: team -> variant) of every team."""
    configs = []
    for team in level.teams:
        for variant in (variants[team],) if variants else level.variants:
            settings = settings_of(level, variant, best[team])
            for run in runs(study):
                fault = forced_fault(study, team, run, level.failure)
                configs.append(explore_config(
                    study, team, run, f"{level.name}-{variant}-{t_m:g}_", feedback=level.mode, t_m=t_m,
                    faults=[parse_fault(fault)] if fault else [], **settings))
    return configs


def fault_text(fault) -> str:
    return f"{fault.kind}:{fault.robot}@{fault.time:g}"


def row_of(config, summary: dict) -> dict:
    level_variant = config.run_id.split("_", 1)[0]
    params = config.params
    row = result_row(config, summary)
    level, variant, t_m = level_variant.rsplit("-", 2) if params.feedback != "off" else (
        "baseline", "-", "-")
    failure = "none" if not config.faults else "partial" if config.faults[0].kind == "break-motor" else "complete"
    metrics = summary.get("metrics") or {}
    flags = metrics.get("feedback_flags") or []
    return {**row, "level": level, "variant": variant, "t_m": t_m if t_m == "-" else float(t_m),
            "failure": failure, "fault": fault_text(config.faults[0]) if config.faults else "",
            "weights": params.weights, "poor": params.poor, "partial": params.partial,
            "reallocations": metrics.get("reallocations"),
            "flags": " ".join(f"{kind}:{sum(f['flag'] == kind for f in flags)}" for kind in ("PP", "PF", "CF")),
            "detected_s": detection_delay(config.faults, flags)}


def detection_delay(faults, flags: list[dict]) -> float | None:
    """Seconds from the forced failure to the feedback's first flag on the failed robot (None: never flagged)."""
    if not faults:
        return None
    times = [f["t"] for f in flags if f["robot"] == faults[0].robot and f["t"] >= faults[0].time]
    return round(min(times) - faults[0].time, 1) if times else None


# -- the study --------------------------------------------------------------------------------------------------------
def run_study(study: FeedbackStudy) -> Path:
    began = time.perf_counter()
    rows = run_stage(study, "baseline", baseline_configs(study))
    best = {team: dict(THESIS_BEST) for team in TEAMS}
    chosen = {}
    for name in LEVELS:
        if name not in study.levels:
            continue
        level = LEVELS[name]
        rows += run_stage(study, name, level_configs(study, level, best, T_M[0]))
        chosen[name] = {team: best_variant(rows, level, team) for team in level.teams}
        if level.tuned is not None:
            for team, variant in chosen[name].items():
                best[team][level.tuned] = variant
    if study.retune_t_m and chosen:
        configs = [c for name, variants in chosen.items() for t_m in T_M[1:]
                   for c in level_configs(study, LEVELS[name], best, t_m, variants)]
        rows += run_stage(study, "t_m", configs)
    return write_results(study, rows, chosen, time.perf_counter() - began)


def run_stage(study: FeedbackStudy, stage: str, configs: list) -> list[dict]:
    """One stage's runs, journalled in ``trials-<stage>.jsonl`` (``--resume`` skips those it holds; a stage the
    killed study never reached starts afresh)."""
    journal = study.out / f"trials-{stage}.jsonl"
    summaries = run_trials(configs, workers=study.workers, backend="ray" if study.ray else "process",
                           journal=journal, resume=study.resume and journal.exists())
    return [row_of(c, s) for c, s in zip(configs, summaries)]


def against_baseline(rows: list[dict], level: str, team: str, variant: str, t_m: float, key: str):
    """(ratio feedback / no feedback of the means, low, high, p, pairs) of ``key``."""
    failure = LEVELS[level].failure
    a, b = paired_by(rows, key, {"level": level, "team": team, "variant": variant, "t_m": t_m},
                     {"level": "baseline", "team": team, "failure": failure})
    ratio, low, high = ratio_ci(a, b)
    return ratio, low, high, paired_t_test(a, b)[1], len(a)


def best_variant(rows: list[dict], level: Level, team: str) -> str:
    """The variant with the highest mean ER at T_m 60 s (ties: the first)."""
    def rate(variant: str) -> float:
        ratio = against_baseline(rows, level.name, team, variant, T_M[0], "exploration_rate")[0]
        return -math.inf if math.isnan(ratio) else ratio
    return max(level.variants, key=rate)


# -- report ---------------------------------------------------------------------------------------------------------
def write_results(study: FeedbackStudy, rows: list[dict], chosen: dict, wall_s: float) -> Path:
    study.out.mkdir(parents=True, exist_ok=True)
    write_csv(study.out / "results.csv", COLUMNS, rows)
    plot_ratios(study.out / "feedback.png", rows, study, chosen)
    write_atomic(study.out / "report.md", report(study, rows, chosen, wall_s).encode())
    return study.out


def ratio_cell(rows, level, team, variant, t_m, key) -> str:
    ratio, _, _, p, pairs = against_baseline(rows, level, team, variant, t_m, key)
    return "-" if math.isnan(ratio) else f"{ratio:.3f} (p {p:.2g})"


def report(study: FeedbackStudy, rows: list[dict], chosen: dict, wall_s: float) -> str:
    pairs = len(runs(study))
    lines = ["# Feedback coordination (Chand §8.4-8.5, Table 8.1 levels 1.2-3.4) re-run in teamsim", "",
             f"{study.worlds} worlds x {study.repeats} repeats per environment type (the thesis: 10 x 10), densities "
             f"{', '.join(f'{100 * d:.0f} %' for d in study.densities)}, "
             f"{'with and without bogs' if len(study.bogs) == 2 else 'bogs' if study.bogs[0] else 'no bogs'}: "
             f"{pairs} runs per condition, each paired with the same world and seed without feedback. Kinematic "
             f"backend, study seed {study.seed}. " + ("" if study.duration is None else
                                                      f"Runs cut at {study.duration:g} s (not the thesis's MET). ") +
             "Forced failures: an explorer that is not the planner, at a time in "
             f"{FAILURE_WINDOW[0]:g}-{FAILURE_WINDOW[1]:g} s, drawn per world and repeat (`fault` in `results.csv`).",
             "", f"Wall time: {wall_s / 60:.1f} min for this invocation ({len(rows)} runs).", "",
             "Cells: the ratio feedback / no feedback of the means over the paired runs, with the paired two-sided "
             "t-test's p.", ""]
    for name, variants in chosen.items():
        level = LEVELS[name]
        lines += [f"## {level.what[0].upper()}{level.what[1:]}", "",
                  "| team | variant | T_m (s) | ET | area (PAE) | ER | best |", "|---|---|---|---|---|---|---|"]
        for team in level.teams:
            for variant in level.variants:
                for t_m in T_M if variant == variants[team] else T_M[:1]:
                    if not any(r["level"] == name and r["team"] == team and r["variant"] == variant
                               and r["t_m"] == t_m for r in rows):
                        continue
                    cells = [ratio_cell(rows, name, team, variant, t_m, key) for key in MEASURED]
                    lines.append(f"| [{team}] | {variant} | {t_m:g} | " + " | ".join(cells) +
                                 f" | {'yes' if variant == variants[team] else ''} |")
        lines.append("")
    lines += ["## What the feedback did", ""] + actions(rows, chosen) + [""]
    lines += ["## Against the thesis (T_m 60 s)", ""]
    lines += table(claims(rows, chosen), " (the change has the thesis's sign and half to twice its size)")
    lines += ["", "![ER with feedback over ER without, per level and variant](feedback.png)", "",
              "## Why teamsim may differ", "", DIFFERENCES]
    return "\n".join(lines) + "\n"


def actions(rows: list[dict], chosen: dict) -> list[str]:
    """Per level, team and variant at T_m 60 s: the runs in which the feedback reallocated, the flags it raised,
    and (with a forced failure) in how many runs and how soon it flagged the failed explorer."""
    lines = ["| level | team | variant | runs | reallocated in | flags (PP / PF / CF) | failed explorer flagged | "
             "after (median s) |", "|---|---|---|---|---|---|---|---|"]
    for name in chosen:
        for team, variant in ((t, v) for t in LEVELS[name].teams for v in LEVELS[name].variants):
            ran = [r for r in rows if r["level"] == name and r["team"] == team and r["variant"] == variant
                   and r["t_m"] == T_M[0] and r["status"] in ("completed", "failed")]
            if not ran:
                continue
            counts = [sum(int(part.split(":")[1]) for r in ran for part in r["flags"].split() if part.startswith(k))
                      for k in ("PP", "PF", "CF")]
            delays = [r["detected_s"] for r in ran if r["detected_s"] is not None]
            forced = LEVELS[name].failure != "none"
            reallocated = sum(bool(r["reallocations"]) for r in ran)
            lines.append(f"| {name} | [{team}] | {variant} | {len(ran)} | {reallocated} | "
                         f"{' / '.join(map(str, counts))} | {f'{len(delays)} of {len(ran)}' if forced else '-'} | "
                         f"{f'{np.median(delays):.0f}' if delays else '-'} |")
    return lines


def claims(rows: list[dict], chosen: dict) -> list[Finding]:
    found = []
    for level, team, variant, key, thesis in THESIS:
        if level not in chosen or team not in chosen[level]:
            continue
        ratio, low, high, p, pairs = against_baseline(rows, level, team, variant, T_M[0], key)
        found.append(Finding(f"{LEVELS[level].what}, [{team}] {variant}: {NAME[key]}", f"x {thesis:.3g}",
                             f"x {ratio:.3g} ({pairs} pairs)", judged(ratio, thesis), p,
                             ratio_text("with/without", ratio, low, high)))
    return found


DIFFERENCES = """\
- Table 8.1 is badly garbled in the thesis; its levels are read from the fragments and §8.2's text (spec §5.2). The
  failure times and robots are not given; teamsim draws them (above). Combined feedback (3.4) is run without forced
  failures, as the level 1.1 worlds: the thesis does not say which it used.
- The runs themselves differ from the thesis's as the exploration study's do (its report, "Why teamsim may
  differ"); in particular RA' is calibrated for Robot4 and Robot2 only and scaled for the others
  (docs/decisions.md, "Exploration"), and what counts as poor performance depends on it.
"""


def plot_ratios(path: Path, rows: list[dict], study: FeedbackStudy, chosen: dict) -> None:
    """One panel per level: ER with / without feedback per variant at T_m 60 s, a bar per team."""
    names = list(chosen) or ["none"]
    fig, axes = pyplot().subplots(1, len(names), figsize=(4.2 * len(names), 4), squeeze=False)
    for ax, name in zip(axes[0], names):
        if name not in LEVELS:
            continue
        level = LEVELS[name]
        width = 0.8 / len(level.teams)
        for k, team in enumerate(level.teams):
            ratios = [against_baseline(rows, name, team, v, T_M[0], "exploration_rate")[0] for v in level.variants]
            ax.bar(np.arange(len(level.variants)) + k * width, np.asarray(ratios) - 1.0, width, bottom=1.0,
                   color=COLOURS.get(team), label=f"[{team}]")  # from 1: a change of a few % stays visible
        ax.axhline(1.0, color="black", linewidth=0.8)
        ax.set(xticks=np.arange(len(level.variants)) + 0.4 - width / 2, xticklabels=level.variants,
               title=level.what, ylabel="ER with / without feedback")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    save_figure(fig, path)
