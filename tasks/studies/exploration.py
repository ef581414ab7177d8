"""``teamsim study exploration``: Chand's exploration experiment without feedback (§8.2-8.3, Table 8.1 level 1.1,
Figs 8.2-8.6), re-run on the ``explore`` mission's kinematic backend (``backend="physics"`` for a spot check).

Environment types: obstacle densities 5, 10 and 15 %, each without bogs and with about 5 % boggy terrain (§8.2).
Each type has ``worlds`` worlds drawn from the study seed, and each world runs ``repeats`` times with trial seeds
``seed .. seed + repeats - 1`` (the sensing and positioning noise). Every team [1 1], [1 3], [1 5] runs the same
worlds and seeds, so team comparisons are paired run by run, as the thesis's t-tests were. The thesis's design is
10 worlds x 10 repeats (``--full``); the default is 3 x 1.

Metrics (§8.1, (8.1)): ET, the exploration time (MET when the team did not finish: 15000 s for [1 1], 5000 s for
the larger teams, §8.2), PAE, the share of the world explored, and ER = PAE / ET. Every run that ended by
finishing or at MET counts; a run that ended otherwise (``unstable``, ``error``) is reported and left out of the
comparisons with its pairs.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from teamsim.config import TrialConfig
from teamsim.files import write_atomic, write_csv
from teamsim.plots import pyplot, save_figure
from teamsim.stats import paired_t_test, ratio_ci
from teamsim.sweep import JOURNAL_NAME, default_workers, run_trials
from teamsim.tasks.missions.explore import ExploreParams, team_duration
from teamsim.tasks.studies.findings import Finding, ratio_text, table

TEAMS = ("1 1", "1 3", "1 5")  # [planners explorers], §8.2
DENSITIES = (0.05, 0.10, 0.15)
BOG_SHARE = 0.05  # "about 5 % boggy terrain" (§8.2)
COLUMNS = ("team", "density", "bogs", "world", "repeat", "seed", "world_seed", "status", "finished",
           "exploration_time", "explored_share", "exploration_rate", "map_accuracy", "partly_explored",
           "unexplored", "boggy_environments", "bogs_found", "real_time_factor")
MEASURED = ("exploration_time", "explored_share", "exploration_rate")
LABEL = {"exploration_time": "ET (s)", "explored_share": "PAE (share explored)", "exploration_rate": "ER (1/s)"}
VALID = ("completed", "failed")  # finished, or ran to MET: both are results (§8.2 counts a run at MET with ET = MET)
# §8.3, [1 1] as the baseline unless said: (team, baseline, metric, the thesis's ratio team/baseline)
THESIS = (("1 3", "1 1", "exploration_time", 0.321), ("1 3", "1 1", "explored_share", 1.589),
          ("1 3", "1 1", "exploration_rate", 4.80), ("1 5", "1 1", "exploration_time", 0.245),
          ("1 5", "1 1", "explored_share", 1.648), ("1 5", "1 1", "exploration_rate", 7.28),
          ("1 5", "1 3", "exploration_time", 0.763), ("1 5", "1 3", "explored_share", 1.036),
          ("1 5", "1 3", "exploration_rate", 1.52))
NAME = {"exploration_time": "ET", "explored_share": "area (PAE)", "exploration_rate": "ER"}


@dataclass(frozen=True)
class ExplorationStudy:
    worlds: int = 3  # per environment type (the thesis: 10)
    repeats: int = 1  # runs per world (the thesis: 10)
    seed: int = 0
    teams: tuple[str, ...] = TEAMS
    densities: tuple[float, ...] = DENSITIES
    bogs: tuple[bool, ...] = (False, True)
    workers: int | None = None
    ray: bool = False  # run the trials on a local Ray instance instead of worker processes
    duration: float | None = None  # simulated seconds per run; None: MET
    backend: str = "kinematic"  # or "physics": every run a MuJoCo explore mission (the spot check)
    out: Path = Path("renders/study-exploration")
    resume: bool = False


def world_seed(study_seed: int, density: float, bogs: bool, world: int) -> int:
    """The layout seed of world ``world`` of an environment type: distinct per type, from the study seed."""
    key = [study_seed, round(density * 1000), int(bogs), world]
    return int(np.random.SeedSequence(key).generate_state(1)[0] % 2**31)


def runs(study) -> list[tuple[float, bool, int, int, int]]:
    """(density, bogs, world, repeat, world seed) of every run a team makes in ``study``."""
    return [(density, bogs, world, repeat, world_seed(study.seed, density, bogs, world))
            for density in study.densities for bogs in study.bogs for world in range(study.worlds)
            for repeat in range(study.repeats)]


def explore_config(study, team: str, run: tuple, label: str, faults=(), backend: str = "kinematic",
                   **settings) -> TrialConfig:
    """Run ``run`` (of :func:`runs`) of ``team`` on the study's backend, in a folder named by ``label``, the team
    and the run; ``settings``: further ``ExploreParams``."""
    density, bogs, world, repeat, layout = run
    params = ExploreParams(team=team, density=density, bog_share=BOG_SHARE if bogs else 0.0, world_seed=layout,
                           backend=backend, **settings)
    run_id = f"{label}{team.replace(' ', '-')}_d{round(density * 100)}_{'bog' if bogs else 'dry'}_w{world}_r{repeat}"
    return TrialConfig(mission="explore", seed=study.seed + repeat, params=params, duration=study.duration,
                       faults=list(faults), out=str(study.out / "trials"), run_id=run_id)


def trial_configs(study: ExplorationStudy) -> list[TrialConfig]:
    return [explore_config(study, team, run, "", backend=study.backend, feedback="none") for run in runs(study)
            for team in study.teams]


def result_row(config: TrialConfig, summary: dict) -> dict:
    params: ExploreParams = config.params
    metrics = summary.get("metrics") or {}
    _, _, bogs, world, repeat = config.run_id.rsplit("_", 4)
    return {"team": params.team, "density": params.density, "bogs": bogs == "bog", "world": int(world[1:]),
            "repeat": int(repeat[1:]), "seed": config.seed, "world_seed": params.world_seed,
            "status": summary["status"], "finished": bool(summary.get("completed", False)),
            **{key: metrics.get(key) for key in MEASURED + ("map_accuracy",)},
            "partly_explored": (metrics.get("status") or {}).get("PE"),
            "unexplored": (metrics.get("status") or {}).get("UE"),
            "boggy_environments": len(metrics.get("boggy_environments") or ()),
            "bogs_found": len(metrics.get("bogs_found") or ()), "real_time_factor": summary.get("real_time_factor")}


def run_study(study: ExplorationStudy) -> Path:
    began = time.perf_counter()
    configs = trial_configs(study)
    summaries = run_trials(configs, workers=study.workers, backend="ray" if study.ray else "process",
                           journal=study.out / JOURNAL_NAME, resume=study.resume)
    rows = [result_row(c, s) for c, s in zip(configs, summaries)]
    return write_results(study, rows, time.perf_counter() - began)


def write_results(study: ExplorationStudy, rows: list[dict], wall_s: float) -> Path:
    """``results.csv``, ``report.md`` and ``exploration.png`` in ``study.out``."""
    study.out.mkdir(parents=True, exist_ok=True)
    write_csv(study.out / "results.csv", COLUMNS, rows)
    plot_metrics(study.out / "exploration.png", rows, study)
    write_atomic(study.out / "report.md", report(study, rows, wall_s).encode())
    return study.out


# -- statistics -----------------------------------------------------------------------------------------------------
def pair_key(row: dict) -> tuple:
    return row["density"], row["bogs"], row["world"], row["repeat"]


def paired(rows: list[dict], key: str, team: str, baseline: str, **where) -> tuple[list[float], list[float]]:
    """``key`` of ``team`` and of ``baseline`` over the runs (same world and seed) both ended validly."""
    return paired_by(rows, key, {"team": team, **where}, {"team": baseline, **where})


def paired_by(rows: list[dict], key: str, first: dict, second: dict) -> tuple[list[float], list[float]]:
    """``key`` of the rows matching ``first`` and of those matching ``second`` (column -> value), over the pair
    keys (world and seed) where both ended validly."""
    def values(where: dict) -> dict:
        return {pair_key(r): r[key] for r in rows if r["status"] in VALID and r[key] is not None
                and all(r[k] == v for k, v in where.items())}
    a, b = values(first), values(second)
    keys = sorted(set(a) & set(b))
    return [a[k] for k in keys], [b[k] for k in keys]


def judged(ratio: float, thesis: float) -> str:
    """**yes** when the change (ratio - 1) has the thesis's sign and half to twice its size, **partly** for another
    change of that sign, **no** otherwise (the formation study's criterion); the table adds "not decided" at
    p >= 0.05."""
    if math.isnan(ratio):
        return "n/a"
    change, expected = ratio - 1, thesis - 1
    if change * expected <= 0:
        return "**no**"
    return "yes" if 0.5 <= change / expected <= 2.0 else "partly"


def claims(rows: list[dict], teams: tuple[str, ...], ran_to_met: bool = True) -> list[Finding]:
    """§8.3's ratios, then (when the runs were not cut short of MET) what it says of [1 1]'s share and of the
    runs reaching MET."""
    found = [ratio_finding(f"[{team}] vs [{baseline}]: {NAME[key]}", thesis, *paired(rows, key, team, baseline),
                           f"[{team}]/[{baseline}]")
             for team, baseline, key, thesis in THESIS if team in teams and baseline in teams]
    if not ran_to_met:
        return found
    if "1 1" in teams:
        shares = [r["explored_share"] for r in rows if r["team"] == "1 1" and r["status"] in VALID]
        mean = float(np.mean(shares)) if shares else math.nan
        verdict = "n/a" if math.isnan(mean) else "yes" if 0.7 <= mean <= 0.9 else "**no**"
        found.append(Finding("[1 1] explores at most about 80 % (mean PAE)", "about 80 %",
                             f"{100 * mean:.1f} % ({len(shares)} runs)", verdict))
    dense = [r for r in rows if r["density"] == 0.15 and r["status"] in VALID
             and not (r["team"] == "1 5" and not r["bogs"])]
    if dense:
        at_met = sum(not r["finished"] for r in dense)
        found.append(Finding("at 15 % density the runs reach MET, but [1 5] in worlds without bogs", "all of them",
                             f"{at_met} of {len(dense)}", verdict_of_share(at_met, len(dense))))
    return found


def ratio_finding(claim: str, thesis: float, a: list[float], b: list[float], label: str) -> Finding:
    """The thesis's ratio of means beside teamsim's over the pairs (a, b), with its interval and p, judged."""
    ratio, low, high = ratio_ci(a, b)
    return Finding(claim, f"x {thesis:.3g}", f"x {ratio:.3g} ({len(a)} pairs)", judged(ratio, thesis),
                   paired_t_test(a, b)[1], ratio_text(label, ratio, low, high))


def verdict_of_share(held: int, of: int) -> str:
    return "yes" if held == of else "partly" if held else "**no**"


def valid_runs(rows: list[dict], team: str, density: float, bogs: bool) -> list[dict]:
    return [r for r in rows if r["team"] == team and r["density"] == density and r["bogs"] == bogs
            and r["status"] in VALID]


def mean_sem(values: list[float]) -> tuple[float, float]:
    if not values:
        return math.nan, math.nan
    sem = float(np.std(values, ddof=1) / math.sqrt(len(values))) if len(values) > 1 else 0.0
    return float(np.mean(values)), sem


def causes(rows: list[dict], teams: tuple[str, ...]) -> list[str]:
    """Per team: how many runs finished before MET, when, and the environments they left partly explored or
    unexplored (what the ratios against [1 1] turn on: §6.4.2 never offers a PE environment again to the explorer
    that left it, so a lone explorer ends with them)."""
    lines = []
    for team in teams:
        ran = [r for r in rows if r["team"] == team and r["status"] in VALID]
        done = [r for r in ran if r["finished"]]
        if not ran:
            continue
        times = [r["exploration_time"] for r in done]
        left = [r["partly_explored"] for r in ran if r["partly_explored"] is not None]
        lines.append(f"- [{team}]: {len(done)} of {len(ran)} runs finished before MET"
                     + (f" (ET {min(times):.0f}-{max(times):.0f} s)" if times else "")
                     + (f", leaving {np.mean(left):.1f} of the environments partly explored on average"
                        if left else "")
                     + f", {sum(r['unexplored'] or 0 for r in ran)} unexplored in all.")
    return lines


# -- report ---------------------------------------------------------------------------------------------------------
def report(study: ExplorationStudy, rows: list[dict], wall_s: float) -> str:
    total = len(rows)
    trial_s = sum(r["exploration_time"] / r["real_time_factor"] for r in rows
                  if r["exploration_time"] and r["real_time_factor"])
    lines = ["# Exploration without feedback (Chand §8.2-8.3, Table 8.1 level 1.1) re-run in teamsim", "",
             f"{study.worlds} worlds x {study.repeats} repeats per environment type (the thesis: 10 x 10), study "
             f"seed {study.seed}, {study.backend} backend, feedback off. Teams "
             f"{', '.join(f'[{t}]' for t in study.teams)}"
             f", the same worlds and trial seeds for each. " + (
                 f"MET {team_duration(1):g} s for [1 1], {team_duration(3):g} s for the larger teams. "
                 if study.duration is None else f"Runs cut at {study.duration:g} s (not the thesis's MET). ") +
             "Per-run rows: `results.csv`.", "",
             f"Wall time: {wall_s / 60:.1f} min for this invocation (resumed: the trials it ran) on "
             f"{'Ray' if study.ray else f'{study.workers or default_workers()} worker processes'}; {total} runs, the "
             f"trials' own time summed: {trial_s / 60:.1f} min.", "",
             "## Per team and environment", "",
             "Means with their standard errors; `at MET`: runs that had not finished by MET (or by the cut).", "",
             "| team | density | bogs | runs | ET (s) | PAE (%) | ER (1e-4/s) | at MET | map accuracy (%) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for team in study.teams:
        for density in study.densities:
            for bogs in study.bogs:
                runs_here = valid_runs(rows, team, density, bogs)
                if not runs_here:
                    continue
                et, et_se = mean_sem([r["exploration_time"] for r in runs_here])
                pae, pae_se = mean_sem([100 * r["explored_share"] for r in runs_here])
                er, er_se = mean_sem([1e4 * r["exploration_rate"] for r in runs_here])
                acc = np.mean([100 * r["map_accuracy"] for r in runs_here])
                at_met = sum(not r["finished"] for r in runs_here)
                lines.append(f"| [{team}] | {100 * density:.0f} % | {'yes' if bogs else 'no'} | {len(runs_here)} | "
                             f"{et:.0f} ± {et_se:.0f} | {pae:.1f} ± {pae_se:.1f} | {er:.2f} ± {er_se:.2f} | "
                             f"{at_met} | {acc:.1f} |")
    invalid = [r for r in rows if r["status"] not in VALID]
    if invalid:
        lines += ["", f"Runs left out ({len(invalid)}): " + ", ".join(
            f"[{r['team']}] {100 * r['density']:.0f} % {'bogs ' if r['bogs'] else ''}world {r['world']} repeat "
            f"{r['repeat']}: {r['status']}" for r in invalid)]
    lines += ["", "## Against the thesis (§8.3)", "",
              "Ratios team/baseline of the means over all environment types, paired run by run.", ""]
    lines += table(claims(rows, study.teams, study.duration is None),
                   " (the change has the thesis's sign and half to twice its size)")
    lines += ["", "## Measured causes", ""] + causes(rows, study.teams) + [
        "", "§6.4.2 never offers a partly explored environment again to the explorer that left it: a lone explorer "
        "ends with them, a larger team hands them to another explorer. A team that finishes before MET has its ET "
        "shortened and its PAE capped by what it left, which is what the ratios against [1 1] turn on."]
    lines += ["", "![ET, PAE and ER per team and density (Figs 8.2-8.6)](exploration.png)", "",
              "## Why teamsim may differ", "", DIFFERENCES]
    return "\n".join(lines) + "\n"


DIFFERENCES = """\
- The thesis gives no world generator beyond "random, evenly spaced" obstacles at a density, nor the obstacle size,
  the bog shapes, the start positions or the robots of [1 1] and [1 3]; teamsim's are in `tasks/worlds/exploration`
  and docs/explore.md.
- Its explorers' thresholds (P_s, NS_min, NS_max, NS_sen, EA_T, the bog-detection PWM levels, "persistent poor
  progress") are not given; teamsim's choices are in docs/decisions.md ("Exploration").
- The kinematic backend has no contacts, as the thesis's MATLAB simulation had none; positioning and IR noise are
  teamsim's models.
"""


# -- figures --------------------------------------------------------------------------------------------------------
COLOURS = {"1 1": "tab:red", "1 3": "tab:blue", "1 5": "tab:green"}


def plot_metrics(path: Path, rows: list[dict], study: ExplorationStudy) -> None:
    """ET, PAE and ER against density, one line per team, solid without bogs and dashed with (Figs 8.2-8.6)."""
    fig, axes = pyplot().subplots(1, 3, figsize=(14, 4.2))
    x = [100 * d for d in study.densities]
    for ax, key in zip(axes, MEASURED):
        for team in study.teams:
            for bogs in study.bogs:
                stats = [mean_sem([r[key] for r in valid_runs(rows, team, d, bogs)]) for d in study.densities]
                ax.errorbar(x, [m for m, _ in stats], yerr=[s for _, s in stats], color=COLOURS.get(team),
                            linestyle="--" if bogs else "-", marker="o", capsize=3,
                            label=f"[{team}]{' bogs' if bogs else ''}")
        ax.set(xlabel="obstacle density (%)", ylabel=LABEL[key], xticks=x)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(f"Exploration without feedback: means ± s.e., {study.worlds} worlds x {study.repeats} repeats per "
                 "environment type")
    fig.tight_layout()
    save_figure(fig, path)
