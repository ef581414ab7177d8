"""``teamsim study navigation``: Chand's chapter 3 experiments re-run in physics (§3.6, Figs 3.10-3.20).

Every (robot, density, controller) cell runs ``trials`` navigate trials. Trial k at a density uses the same
world for every robot and controller, so comparisons with FRC are paired, as the thesis's t-tests were. Each
cell reports NT (mean navigation time of successful runs), PI (mean path index of successful runs), SR
(success rate), AV (mean average velocity over v_gmax of successful runs) and OS = (SR + PI + AV) / 3 (3.41).
Against FRC it reports the ratio of mean per-trial OS (a failed trial scores PI = AV = 0) and of NT (trials
both finished), with paired two-sided t-test p-values.

Trials run without physics by default (``backend="kinematic"``: ideal IR ranges, exact positions, unicycle or
bicycle kinematics, ``teamsim.tasks.missions.navigate.kinematic_trial``), which is what the thesis's own simulations
were
(§3.6: MATLAB, no dynamics) and what lets the reduced default run in minutes; ``backend="physics"`` runs every
trial as a MuJoCo ``navigate`` mission (about four times slower).
"""
from __future__ import annotations

import csv
import dataclasses
import math
import time
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from teamsim.config import TrialConfig
from teamsim.files import write_atomic, write_csv
from teamsim.plots import grouped_bars
from teamsim.stats import paired_t_test, ratio_ci
from teamsim.sweep import JOURNAL_NAME, default_workers, run_trials
from teamsim.tasks.missions.navigate import (TABLE_3_1, THESIS_METHODS, WORLD_FAMILIES, NavigateParams,
                                            kinematic_trial, time_limit)
from teamsim.tasks.studies.findings import interval_text

COLUMNS = ("robot", "density", "controller", "trial", "seed", "world_seed", "success", "nav_time", "path_index",
           "avg_velocity", "path_length", "planned_length", "touches", "failure", "loop_period", "loop_diameter",
           "status")
BACKENDS = {"kinematic": kinematic_trial, "physics": None}  # None: run_trial, the MuJoCo mission

# What Figs 3.10-3.15 report for each method and robot (spec §2, table of reported numbers), for the report's
# cells; the thesis gives no per-cell values in its text.
THESIS_FIGURES = {
    ("FRC", "A"): "SR > 88 %; OS > 0.75", ("FRC", "B"): "PI > 0.83; SR > 88 %; OS > 0.86",
    ("FRC", "C"): "PI > 0.83; SR 80 % at 20 %; OS > 0.77",
    ("HRDK", "A"): "SR > 94 %; OS 0.73-0.97", ("HRDK", "B"): "PI > 0.89; SR > 94 %; OS 0.73-0.97",
    ("HRDK", "C"): "PI > 0.89; OS 0.73-0.97",
    ("HRDU", "A"): "NT 46-136 s; PI > 0.59; SR > 81 %; OS > 0.68",
    ("HRDU", "B"): "NT 46-136 s; PI > 0.80; SR 100 %; OS > 0.85",
    ("HRDU", "C"): "NT 46-136 s; PI > 0.74; SR > 65 %; OS > 0.77",
    ("ODW", "A"): "PI < 0.48; SR < 5 %; AV > 0.53", ("ODW", "B"): "PI < 0.48; AV > 0.53; OS > 0.5 only at 15-20 %",
    ("ODW", "C"): "PI < 0.48; SR < 5 %; AV > 0.53",
    ("ODWDS", "A"): "PI 0.28-0.50 at 15-20 %; AV > 0.70; OS > 0.51",
    ("ODWDS", "B"): "PI > 0.65; SR > 94 %; AV > 0.70; OS > 0.78", ("ODWDS", "C"): "PI > 0.65; AV > 0.70; OS > 0.64",
    ("RFRC", "A"): "SR >= 76 %; OS 0.70-0.94", ("RFRC", "B"): "PI > 0.81; SR > 91 %; OS 0.70-0.94",
    ("RFRC", "C"): "PI > 0.81; SR >= 75 %; OS 0.70-0.94",
}


@dataclass
class NavigationStudy:
    robots: tuple[str, ...] = tuple(TABLE_3_1)
    densities: tuple[float, ...] = (0.05, 0.10, 0.15, 0.20)
    controllers: tuple[str, ...] = THESIS_METHODS
    trials: int = 10  # the thesis ran 10 worlds x 10 repeats = 100 per cell; 10 is the reduced default
    workers: int | None = None
    out: Path = Path("renders/study-navigation")
    seed: int = 0
    backend: str = "kinematic"  # or "physics" (see the module's docstring)
    worlds: str = "strata"  # the world family, NavigateParams.worlds
    resume: bool = False  # continue the study in ``out`` from its journal (trials.jsonl), issue 29

    def __post_init__(self) -> None:
        if self.backend not in BACKENDS:
            raise ValueError(f"backend={self.backend!r}: allowed: {', '.join(BACKENDS)}")
        if self.worlds not in WORLD_FAMILIES:
            raise ValueError(f"worlds={self.worlds!r}: allowed: {', '.join(WORLD_FAMILIES)}")


def world_seed(study: NavigationStudy, density: float, trial: int) -> int:
    return study.seed * 100_000 + round(density * 100) * 1_000 + trial


def trial_seed(robot: str, density: float, controller: str, trial: int, base: int) -> int:
    return zlib.crc32(f"{base}/{robot}/{density:g}/{controller}/{trial}".encode())


def trial_configs(study: NavigationStudy) -> list[TrialConfig]:
    configs = []
    for robot in study.robots:
        for density in study.densities:
            for controller in study.controllers:
                for trial in range(study.trials):
                    params = NavigateParams(robot=robot, controller=controller, density=density,
                                            world_seed=world_seed(study, density, trial), worlds=study.worlds)
                    config = TrialConfig(mission="navigate", params=params, duration=time_limit(density),
                                         seed=trial_seed(robot, density, controller, trial, study.seed),
                                         out=str(study.out / "trials"),
                                         run_id=f"{robot}-{round(density * 100)}-{controller}-{trial}")
                    config.video.fps = 2  # the trajectory of a study trial is for inspection, not for video
                    configs.append(config)
    return configs


def result_row(config: TrialConfig, summary: dict) -> dict:
    params = config.params
    metrics = summary.get("metrics") or {}
    return {"robot": params.robot, "density": params.density, "controller": params.controller,
            "trial": int(config.run_id.rsplit("-", 1)[1]), "seed": config.seed, "world_seed": params.world_seed,
            "success": bool(metrics.get("success", False)), "nav_time": metrics.get("nav_time", math.nan),
            "path_index": metrics.get("path_index", math.nan), "avg_velocity": metrics.get("avg_velocity", math.nan),
            "path_length": metrics.get("path_length", math.nan),
            "planned_length": metrics.get("planned_length", math.nan), "touches": metrics.get("touches", ""),
            "failure": metrics.get("failure", ""), "loop_period": metrics.get("loop_period"),
            "loop_diameter": metrics.get("loop_diameter"), "status": summary.get("status")}


def trial_os(row: dict) -> float:
    """Per-trial overall score (3.41): success, and PI and AV when it succeeded."""
    if not row["success"]:
        return 0.0
    return (1.0 + row["path_index"] + row["avg_velocity"]) / 3


@dataclass
class Cell:
    rows: list = field(default_factory=list)

    def mean(self, key: str, successful_only: bool = True) -> float:
        values = [r[key] for r in self.rows if r["success"] or not successful_only]
        return float(np.mean(values)) if values else math.nan

    @property
    def sr(self) -> float:
        return float(np.mean([r["success"] for r in self.rows])) if self.rows else math.nan

    @property
    def os(self) -> float:
        pi, av = self.mean("path_index"), self.mean("avg_velocity")
        return (self.sr + (0.0 if math.isnan(pi) else pi) + (0.0 if math.isnan(av) else av)) / 3


def cells_of(rows: list[dict]) -> dict[tuple, Cell]:
    cells: dict[tuple, Cell] = {}
    for row in rows:
        cells.setdefault((row["robot"], row["density"], row["controller"]), Cell()).rows.append(row)
    return cells


def compare(cells: dict, robot: str, density: float, controller: str) -> dict:
    """Paired comparison of ``controller`` with FRC on the same worlds: OS and NT ratios with their 95 % confidence
    intervals (low, high) and p-values."""
    ours = {r["trial"]: r for r in cells[(robot, density, controller)].rows}
    frc = {r["trial"]: r for r in cells[(robot, density, "FRC")].rows}
    trials = sorted(set(ours) & set(frc))
    os_a, os_b = [trial_os(ours[t]) for t in trials], [trial_os(frc[t]) for t in trials]
    both = [t for t in trials if ours[t]["success"] and frc[t]["success"]]
    nt_a, nt_b = [ours[t]["nav_time"] for t in both], [frc[t]["nav_time"] for t in both]
    return {"os_ratio": float(np.mean(os_a) / np.mean(os_b)) if np.mean(os_b) > 0 else math.nan,
            "os_ci": ratio_ci(os_a, os_b)[1:], "os_p": paired_t_test(os_a, os_b)[1],
            "nt_ratio": float(np.mean(nt_a) / np.mean(nt_b)) if both else math.nan,
            "nt_ci": ratio_ci(nt_a, nt_b)[1:], "nt_p": paired_t_test(nt_a, nt_b)[1] if both else math.nan}


def run_study(study: NavigationStudy) -> Path:
    configs = trial_configs(study)
    began = time.perf_counter()
    summaries = run_trials(configs, workers=study.workers, run=BACKENDS[study.backend],
                           journal=study.out / JOURNAL_NAME, resume=study.resume)
    wall_s = time.perf_counter() - began
    rows = [result_row(c, s) for c, s in zip(configs, summaries)]
    study.out.mkdir(parents=True, exist_ok=True)
    write_results(study.out / "results.csv", rows)
    write_report(study, rows, wall_s)
    return study.out


def write_results(path: Path, rows: list[dict]) -> None:
    write_csv(path, COLUMNS, rows)


_NUMBERS = {"density": float, "trial": int, "seed": int, "world_seed": int, "nav_time": float, "path_index": float,
            "avg_velocity": float, "path_length": float, "planned_length": float, "touches": int,
            "loop_period": float, "loop_diameter": float}


def read_results(path: Path) -> list[dict]:
    """The rows of a ``results.csv`` as ``run_study`` made them, so that a report can be re-made from the file,
    or from the rows of several studies on the same worlds put together."""
    with open(path, newline="") as file:
        rows = list(csv.DictReader(file))
    for row in rows:
        row["success"] = row["success"] == "True"
        for key, number in _NUMBERS.items():
            row[key] = number(row[key]) if row[key] else None
    return rows


@dataclass(frozen=True)
class CellCheck:
    """One cell's test of a claim: teamsim's figure, its p-value, whether the thesis's criterion holds."""
    cell: str  # "A 15 %"
    figure: str
    p: float
    holds: bool

    def __str__(self) -> str:
        return f"{self.cell}: {self.figure} (p {self.p:.2g}) {'holds' if self.holds else 'does not'}"


@dataclass(frozen=True)
class Ordering:
    claim: str
    thesis: str  # the thesis's wording
    criterion: str  # what one cell must show, by the thesis's own criterion
    checks: tuple[CellCheck, ...]
    cause: str = ""  # why teamsim differs, shown when it does

    @property
    def held(self) -> int:
        return sum(c.holds for c in self.checks)

    @property
    def agrees(self) -> bool | None:  # None: not measured by this run
        return None if not self.checks else self.held == len(self.checks)

    @property
    def verdict(self) -> str:
        """yes where every cell holds the thesis's criterion, partly where some do, no where none does."""
        if not self.checks:
            return "not measured"
        return "yes" if self.agrees else "partly" if self.held else "**no**"

    @property
    def teamsim(self) -> str:
        return f"{self.held} of {len(self.checks)} cells" if self.checks else "n/a"


# Why teamsim can differ from the thesis on each ordering: what the investigation found (docs/navigation.md has
# the physics-free checks and the commands that measure them).
CAUSES = {
    "odw": "ODW has no direction sensor: it heads straight for the goal and trades heading against clearance "
           "through beta_1 alone. How badly that fails depends on how often the straight line is blocked by "
           "obstacles it cannot see round with 10-14 IR beams, i.e. on the worlds, whose obstacle sizes the thesis "
           "does not give.",
    "odwds": "ODWDS differs from FRC in v_obmax, reversing (3.23), the curvature checks and (3.38) against "
             "(3.35)-(3.37); with few trials the differences are within the spread of the worlds.",
    "hrdk": "HRDK plans on the known map with obstacles inflated by the robot's radius plus 0.2 m and then "
            "follows the path with FRC; where the planned passage is tight, FRC's safety margin and alpha_3 "
            "slow it and the detour lowers PI and AV, so HRDK can fall below FRC in a cell.",
    "rfrc": "RFRC drops alpha_3 (and, for the tricycle, DCF and CL_ob). Near obstacles alpha_3 scales every "
            "candidate of FRC by 0.01, which changes FRC's choices only against candidates that keep DC_cdmin "
            "clear; where those are rare, FRC creeps and RFRC does not. {sample_rfrc}",
    "success": "FRC is reactive and sees obstacles in only 10-14 directions. teamsim's FRC escapes the loops the "
               "printed method falls into (FRC-printed: looping beside boxes it cannot see past, "
               "docs/navigation.md); what remains, counted per cell below: the tricycle (A), which cannot turn on "
               "the spot, rocking to and fro or creeping where it must turn round between boxes; robots wandering "
               "where the only gaps admit their body but not their circle with the safety margin (1.2 m across "
               "for A, 1.54 m for C); and stalls. "
               "{sample_success}",
}


def at_most(count: int, trials: int, p: float) -> float:
    """Binomial: the chance of ``count`` or fewer successes in ``trials`` at success rate ``p``."""
    return sum(math.comb(trials, k) * p ** k * (1 - p) ** (trials - k) for k in range(count + 1))


def sample_notes(trials: int) -> dict[str, str]:
    """What one trial weighs at this sample size, for the causes above."""
    worst = math.floor(0.88 * trials)  # the most successes that still miss "> 88 %"
    miss = 1 - (1 - at_most(worst, trials, 0.92)) ** 4
    return {"sample_rfrc": f"With {trials} trials a cell, one failed trial moves a cell's OS ratio by about "
                           f"{1 / trials:.2g} (this check allows 0.1).",
            "sample_success": f"With {trials} trials a cell, one failure costs {100 / trials:.2g} "
                              f"point{'' if trials == 100 else 's'} of SR: a robot that arrives in 92 % of all "
                              f"worlds shows {worst} of {trials} or fewer in at least one of four cells "
                              f"{100 * miss:.0f} % of the time (binomial)."}


def binomial_p(successes: int, trials: int, bound: float, above: bool) -> float:
    """One-sided binomial p of a success count against a rate ``bound``: the chance, at that rate, of a count at
    least as far on the observed side (above or below it). Small p: the sample decides the cell."""
    if above:
        return 1.0 - at_most(successes - 1, trials, bound) if successes > 0 else 1.0
    return at_most(successes, trials, bound)


def orderings(study: NavigationStudy, cells: dict) -> list[Ordering]:
    """The chapter 3 claims (spec §7), each tested cell by cell by the thesis's own criterion."""
    causes = {name: cause.format(**sample_notes(study.trials)) for name, cause in CAUSES.items()}

    def name(robot, density):
        return f"{robot} {density:.0%}"

    def against_frc(controller, holds, densities=study.densities) -> tuple[CellCheck, ...]:
        checks = []
        for r in study.robots:
            for d in densities:
                if (r, d, controller) in cells and (r, d, "FRC") in cells:
                    vs = compare(cells, r, d, controller)
                    checks.append(CellCheck(name(r, d), f"OS ratio {vs['os_ratio']:.2f}", vs["os_p"],
                                            bool(holds(vs["os_ratio"], vs["os_p"]))))
        return tuple(checks)

    def success_rates(robot, controller, bound, above, densities=study.densities,
                      inclusive=False) -> tuple[CellCheck, ...]:
        checks = []
        for d in densities:
            if (robot, d, controller) in cells:
                cell = cells[(robot, d, controller)]
                wins, n = sum(r["success"] for r in cell.rows), len(cell.rows)
                rate = wins / n
                holds = (rate >= bound if inclusive else rate > bound) if above else rate < bound
                checks.append(CellCheck(name(robot, d), f"SR {wins}/{n}", binomial_p(wins, n, bound, holds == above),
                                        holds))
        return tuple(checks)

    claims = []
    if "ODW" in study.controllers:
        claims.append(Ordering("FRC >> ODW on overall score", "ODW's OS 37-74 % lower",
                               "ODW's OS at least 37 % lower (ratio <= 0.63), p < 0.05",
                               against_frc("ODW", lambda ratio, p: ratio <= 0.63 and p < 0.05), causes["odw"]))
        for robot in [r for r in ("A", "C") if r in study.robots]:
            claims.append(Ordering(f"ODW success rate of robot {robot}", "< 5 %", "SR < 5 %",
                                   success_rates(robot, "ODW", 0.05, above=False), causes["odw"]))
    if "ODWDS" in study.controllers:
        claims.append(Ordering("FRC > ODWDS on overall score", "FRC better by up to 27.5 % (all p < 0.01)",
                               "ratio < 1, p < 0.01",
                               against_frc("ODWDS", lambda ratio, p: ratio < 1 and p < 0.01), causes["odwds"]))
    if "HRDK" in study.controllers:
        claims.append(Ordering("HRDK >= FRC in known worlds", "OS ratio > 1 in all 12 cells, best +8 %",
                               "ratio > 1", against_frc("HRDK", lambda ratio, p: ratio > 1), causes["hrdk"]))
    if "RFRC" in study.controllers:
        low = [d for d in study.densities if d <= 0.10 + 1e-9]
        claims.append(Ordering("RFRC ~ FRC except at high density",
                               "no significant OS difference for B; worse for A, C at 15-20 %",
                               "at 5-10 %: no significant difference (p >= 0.05)",
                               against_frc("RFRC", lambda ratio, p: not p < 0.05, low), causes["rfrc"]))
    for robot in [r for r in ("A", "B") if r in study.robots]:
        checks = success_rates(robot, "FRC", 0.88, above=True)
        if checks:
            claims.append(Ordering(f"FRC success rate of robot {robot}", "> 88 %", "SR > 88 %", checks,
                                   causes["success"]))
    highest = [d for d in study.densities if abs(d - 0.20) < 1e-9]
    if "C" in study.robots and highest:
        checks = success_rates("C", "FRC", 0.80, above=True, densities=highest, inclusive=True)
        if checks:
            claims.append(Ordering("FRC success rate of robot C at 20 %", "80 %", "SR >= 80 %", checks,
                                   causes["success"]))
    return claims


FAILURES = ("looping", "wandered", "stalled")  # tasks.missions.looping.failure_kind


def failure_kinds(cell: Cell) -> str:
    """How the cell's failed trials failed, counted by kind; loops with their median period and diameter."""
    failed = [r for r in cell.rows if not r["success"]]
    parts = []
    for kind in FAILURES:
        of_kind = [r for r in failed if r["failure"] == kind]
        if not of_kind:
            continue
        detail = ""
        if kind == "looping":
            detail = (f" (period {np.median([r['loop_period'] for r in of_kind]):.0f} s, "
                      f"{np.median([r['loop_diameter'] for r in of_kind]):.1f} m across)")
        parts.append(f"{len(of_kind)} {kind}{detail}")
    return ", ".join(parts)


def write_report(study: NavigationStudy, rows: list[dict], wall_s: float | None = None) -> None:
    """report.md and os.png from the study's rows; ``wall_s``, the sweep's wall time, is quoted when given."""
    cells = cells_of(rows)
    found = orderings(study, cells)
    ran = f" {len(rows)} trials in {wall_s / 60:.0f} min on {study.workers or default_workers()} workers." \
        if wall_s is not None else ""
    lines = ["# Navigation study (Chand ch.3) re-run in teamsim", "",
             f"{study.trials} trials per cell (the thesis: 100), {study.backend} backend, {study.worlds} "
             f"worlds;{ran} robots "
             f"{', '.join(study.robots)}; densities "
             f"{', '.join(f'{d:.0%}' for d in study.densities)}; controllers {', '.join(study.controllers)}. "
             "Trial k at a density uses the same world for every robot and controller. FRC is teamsim's, with "
             "its trap escape; FRC-printed is the thesis's as printed (docs/navigation.md, \"Why FRC circles\"). "
             "Per-trial rows: `results.csv`.", "", "## Claims against the thesis", "",
             "Each claim is tested cell by cell (robot, density) by the thesis's own criterion: **yes** where every "
             "cell holds it, **partly** where some do, **no** where none does. p: paired two-sided t-test against "
             "FRC on the same worlds for scores, one-sided binomial against the bound for success rates; a cell "
             "with p >= 0.05 is not decided by this sample.", "",
             "| claim | thesis | criterion per cell | cells that hold | reproduced |", "|---|---|---|---|---|"]
    lines += [f"| {o.claim} | {o.thesis} | {o.criterion} | {o.teamsim} | {o.verdict} |" for o in found]
    lines += ["", "Per cell:", ""] + [f"- **{o.claim}**: " + "; ".join(map(str, o.checks)) for o in found
                                       if o.checks]
    causes = {}
    for o in found:
        if o.agrees is False:
            causes.setdefault(o.cause, []).append(o.claim)
    if causes:
        lines += ["", "Not reproduced, and why:", ""]
        lines += [f"- **{'; '.join(claims)}**: {cause}" for cause, claims in causes.items()]
    lines += ["", "![overall score](os.png)", "", "## Cells", "",
              "NT, PI and AV are means over successful trials; ratios and p-values are against FRC on the same "
              "worlds (paired two-sided t-test), each ratio of means with its 95 % confidence interval (Fieller's, "
              "paired). Failures over their last 200 s (`tasks/missions/looping.py`): "
              "stalled (mean speed under 10 % of v_max), looping (kept coming back to where it was: median period "
              "and largest extent, medians over the cell's loops) or wandered.", "",
              "| robot | density | controller | NT (s) | PI | SR | AV | OS | OS/FRC [95 % CI] | p | NT/FRC [95 % CI] | "
              "p | failures | thesis (Figs 3.10-3.15) |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for (robot, density, controller), cell in sorted(cells.items()):
        vs = compare(cells, robot, density, controller) if controller != "FRC" and (robot, density, "FRC") in cells \
            else {"os_ratio": math.nan, "os_ci": (math.nan,) * 2, "os_p": math.nan, "nt_ratio": math.nan,
                  "nt_ci": (math.nan,) * 2, "nt_p": math.nan}
        lines.append(f"| {robot} | {density:.0%} | {controller} | {cell.mean('nav_time'):.1f} | "
                     f"{cell.mean('path_index'):.2f} | {cell.sr:.0%} | {cell.mean('avg_velocity'):.2f} | "
                     f"{cell.os:.2f} | {_ratio(vs['os_ratio'], vs['os_ci'])} | {vs['os_p']:.3f} | "
                     f"{_ratio(vs['nt_ratio'], vs['nt_ci'])} | "
                     f"{vs['nt_p']:.3f} | {failure_kinds(cell)} | "
                     f"{THESIS_FIGURES.get((controller.removesuffix('-printed'), robot), '')} |")
    failures = [r for r in rows if r["status"] not in ("completed", "failed")]
    if failures:
        lines += ["", f"{len(failures)} trials ended in error or instability: see their summaries under trials/."]
    write_atomic(study.out / "report.md", ("\n".join(lines) + "\n").encode())
    groups = [f"{r} {d:.0%}" for r in study.robots for d in study.densities]
    series = {c: [cells[(r, d, c)].os if (r, d, c) in cells else math.nan for r in study.robots
                  for d in study.densities] for c in study.controllers}
    grouped_bars(study.out / "os.png", "Overall score OS = (SR + PI + AV) / 3 per robot and density", groups,
                 series, "OS", y_max=1.0)


def _ratio(ratio: float, interval: tuple[float, float]) -> str:
    """A ratio with its confidence interval beside it, when it has one."""
    return " ".join(filter(None, (f"{ratio:.2f}", interval_text(*interval))))


def study_from_args(**kwargs) -> NavigationStudy:
    return dataclasses.replace(NavigationStudy(), **{k: v for k, v in kwargs.items() if v is not None})
