"""``teamsim study two-tier-astar``: Chand's chapter 4 experiments re-run (§4.6, Figs 4.9-4.22).

A worker plans from near the top-left corner of a global map to near its bottom-right corner, either with the
memory-constrained two-tiered A* (``teamsim.controllers.navigation.two_tier_astar``) for a local-map size, a number Q of
local-map memories and a higher-level cost method, or with the non-memory-constrained ("Inf") modified A* over the
whole map. Each plan gives its planning time (measured), the map data received from the manager, the transmission
time of that data at the worker's effective 5.5 Mbit/s (§4.6.3) and the path length. Every planner runs on the
same worlds, so comparisons are paired (two-sided t-test over worlds, p <= 0.05, as §4.6).

§4.6's setup: global maps of 10^4 to 5 x 10^6 nodes at 10 cm (78 KB to 38.15 MB at 8 bytes a node), rectilinear
random obstacles at 5-25 % density, a 15 cm worker, local maps of 64 KB to 8 MB, Q = 1, 5, 15, cost methods 1 and 2,
30 worlds per density (10 at 25 % in the two largest sizes), each world repeated 10 times. Choices where the
thesis is silent, all [RECON]:
  - worlds are square (side round(sqrt(nodes))); obstacles are axis-aligned rectangles with sides drawn uniformly
    from 0.3 m to 1.2 m, at uniform positions (they may overlap), added until the occupied share reaches the
    density; start and goal are 0.5 m in from their corners, each with a 1 m square kept clear;
  - the non-memory-constrained planner receives the whole global map once: it too plans on the manager's data,
    and §4.6.3 compares overall times "inclusive of data communication delay" (with the map already on board
    there would be no memory constraint to compare against);
  - a deterministic planner repeated on one world only re-times it, so each world is planned once (``--trials``
    sets the number of worlds);
  - Q = 5 and 15 are run with cost method 1 on the 64-256 KB local maps, as Figs 4.18-4.22 compare them;
    every local-map size runs both cost methods with Q = 1 (Figs 4.9-4.17).

The default is a reduced grid (the 3.81 MB and 7.63 MB worlds, 5, 15 and 25 % density, 64-256 KB local maps, Q = 1
and 5, three worlds per cell); ``full`` runs §4.6's whole grid, which takes hours.
"""
from __future__ import annotations

import math
import time
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from teamsim.controllers.navigation.astar import modified_astar
from teamsim.controllers.navigation.two_tier_astar import (TwoTierParams, local_map_node_budget, partition_global_map,
                                                           transmission_time, two_tier_astar)
from teamsim.files import write_atomic, write_csv
from teamsim.plots import grouped_bars
from teamsim.rng import RandomStreams
from teamsim.stats import paired_t_test, ratio_ci
from teamsim.sweep import JOURNAL_NAME, run_trials
from teamsim.tasks.studies.findings import interval_text

RESOLUTION = 0.1  # m per node (§4.6)
BYTES_PER_NODE = 8  # Mem_MNode (§4.6)
WORLD_NODES = (10_000, 50_000, 100_000, 500_000, 1_000_000, 5_000_000)  # 78 KB ... 38.15 MB (§4.6)
LOCAL_MAP_KB = (64, 128, 256, 512, 1024, 2048, 4096, 8192)  # Mem_LMapMax (§4.6)
DENSITIES = (0.05, 0.10, 0.15, 0.20, 0.25)
MEMORIES = (1, 5, 15)
SMALL_LOCAL_MAPS = (64, 128, 256)  # the sizes §4.6.3-4.6.5 compare overall times for
LARGE_WORLD = 500_000  # nodes: "the global map is at least 3.81 MB" (§4.6.1), where the orderings are claimed
COLUMNS = ("world", "nodes", "side", "density", "trial", "seed", "planner", "local_map_kb", "memories",
           "cost_method", "row_col", "local_maps", "reached", "planning_time", "bytes_received",
           "transmission_time", "overall_time", "path_length", "fetches", "backtracks", "expansions")

# §4.6.2: cost method 2 over cost method 1 on the 64-256 KB local maps, per global map size (nodes).
THESIS_CM2_TIME = {500_000: "+16-65 %", 1_000_000: "+25-160 %", 5_000_000: "+40-280 %"}
THESIS_CM2_DATA = {500_000: "+5-90 %", 1_000_000: "+20-70 %", 5_000_000: "+40-360 %"}


def world_label(nodes: int) -> str:
    """The thesis's name of a global map size: its memory at 8 bytes a node."""
    size = nodes * BYTES_PER_NODE / 1024
    return f"{int(size)} KB" if size < 1024 else f"{size / 1024:.2f} MB"


def local_map_label(kb: int) -> str:
    return f"{kb} KB" if kb < 1024 else f"{kb // 1024} MB"


@dataclass(frozen=True)
class GridWorldParams:
    # Not given by the thesis (§4.6 says only "randomly positioned", "rectilinear"); chosen.
    side_range: tuple[float, float] = (0.3, 1.2)  # m, obstacle rectangle sides
    corner_margin: float = 0.5  # m from the map's edges to the start and the goal
    clear: float = 1.0  # m, side of the square kept free at each corner


@dataclass(frozen=True)
class GridWorld:
    probabilities: np.ndarray  # occupancy probabilities: 0.95 occupied, 0.05 free (the clamps of §3.2.1)
    start: tuple[int, int]
    goal: tuple[int, int]

    @property
    def density(self) -> float:
        return float((self.probabilities > 0.5).mean())


def grid_world(nodes: int, density: float, rng: np.random.Generator,
               params: GridWorldParams = GridWorldParams()) -> GridWorld:
    """A square global map of about ``nodes`` nodes with random rectangles covering ``density`` of it."""
    side = round(math.sqrt(nodes))
    lo, hi = (round(s / RESOLUTION) for s in params.side_range)
    clear = round(params.clear / RESOLUTION)
    occupied = np.zeros((side, side), bool)
    target = density * occupied.size
    covered = 0
    while covered < target:
        height, width = (int(v) for v in rng.integers(lo, hi + 1, size=2))
        row, col = (int(v) for v in rng.integers(0, side - np.array([height, width]) + 1))
        if (row < clear and col < clear) or (row + height > side - clear and col + width > side - clear):
            continue  # it would cover the start's or the goal's corner
        block = occupied[row:row + height, col:col + width]
        covered += block.size - int(np.count_nonzero(block))
        block[:] = True
    margin = round(params.corner_margin / RESOLUTION)
    return GridWorld(np.where(occupied, 0.95, 0.05), (margin, margin), (side - 1 - margin, side - 1 - margin))


@dataclass(frozen=True)
class Planner:
    """One planner configuration: the monolithic modified A* (``local_map_kb`` 0) or the two-tiered A*."""
    local_map_kb: int = 0
    memories: int = 0
    cost_method: int = 0

    @property
    def monolithic(self) -> bool:
        return self.local_map_kb == 0


MONOLITHIC = Planner()


@dataclass(frozen=True)
class TwoTierStudy:
    world_nodes: tuple[int, ...] = (500_000, 1_000_000)
    densities: tuple[float, ...] = (0.05, 0.15, 0.25)
    local_map_kb: tuple[int, ...] = SMALL_LOCAL_MAPS
    memories: tuple[int, ...] = (1, 5)
    cost_methods: tuple[int, ...] = (1, 2)
    trials: int | None = 3  # worlds per (size, density); None: the thesis's 30 (10 at 25 % in the two largest)
    seed: int = 0

    def planners(self) -> tuple[Planner, ...]:
        """The monolithic planner; every local-map size with each cost method and Q = 1; and the other Q with
        cost method 1 on the 64-256 KB local maps."""
        planners = [MONOLITHIC] + [Planner(kb, 1, cm) for kb in self.local_map_kb for cm in self.cost_methods]
        planners += [Planner(kb, q, 1) for q in self.memories if q != 1 for kb in self.local_map_kb
                     if kb in SMALL_LOCAL_MAPS]
        return tuple(planners)

    def worlds(self, nodes: int, density: float) -> int:
        if self.trials is not None:
            return self.trials
        return 10 if density >= 0.25 and nodes >= 1_000_000 else 30  # §4.6


def plan(full: bool = False, trials: int | None = None, seed: int = 0) -> TwoTierStudy:
    """The reduced default or §4.6's full grid."""
    if full:
        return TwoTierStudy(WORLD_NODES, DENSITIES, LOCAL_MAP_KB, MEMORIES, (1, 2), trials, seed)
    return TwoTierStudy(trials=trials or 3, seed=seed)


@dataclass(frozen=True)
class WorldJob:
    """One world and every planner on it (what a worker process runs). ``mission`` and ``seed`` let
    ``run_trials`` name a job whose worker died."""
    nodes: int
    density: float
    trial: int
    seed: int
    planners: tuple[Planner, ...]
    mission: str = "two-tier-astar"


def world_rng(seed: int, nodes: int, density: float, trial: int) -> np.random.Generator:
    return RandomStreams(seed).get("two-tier", str(nodes), f"{density:g}", str(trial))


def jobs(study: TwoTierStudy) -> list[WorldJob]:
    planners = study.planners()
    return [WorldJob(nodes, density, trial, study.seed, planners) for nodes in study.world_nodes
            for density in study.densities for trial in range(study.worlds(nodes, density))]


def run_planner(world: GridWorld, planner: Planner, params: TwoTierParams = TwoTierParams()) -> dict:
    """Plan once; the measured and derived figures of one results row."""
    if planner.monolithic:
        began = time.perf_counter()
        result = modified_astar(world.probabilities, world.start, world.goal, params.lower_level)
        planning = time.perf_counter() - began
        received = world.probabilities.size * BYTES_PER_NODE
        return {"row_col": max(world.probabilities.shape), "local_maps": 1, "reached": result.reached,
                "planning_time": planning, "bytes_received": received,
                "transmission_time": transmission_time(received, params.link_rate),
                "path_length": result.length * RESOLUTION, "fetches": 1, "backtracks": 0,
                "expansions": result.expanded}
    partition = partition_global_map(*world.probabilities.shape,
                                     local_map_node_budget(planner.local_map_kb * 1024, BYTES_PER_NODE))
    result = two_tier_astar(world.probabilities, world.start, world.goal, partition,
                            TwoTierParams(memories=planner.memories, cost_method=planner.cost_method,
                                          bytes_per_node=BYTES_PER_NODE, lower_level=params.lower_level))
    return {"row_col": partition.row_col, "local_maps": len(partition.dims), "reached": result.reached,
            "planning_time": result.planning_time, "bytes_received": result.bytes_fetched,
            "transmission_time": result.transmission_time, "path_length": result.length * RESOLUTION,
            "fetches": result.fetches, "backtracks": result.backtracks, "expansions": result.expansions}


def run_world(job: WorldJob) -> dict:
    """Every planner on one world: {"status", "rows"} (the form ``run_trials`` collects)."""
    world = grid_world(job.nodes, job.density, world_rng(job.seed, job.nodes, job.density, job.trial))
    warm = grid_world(2_500, job.density, world_rng(job.seed, 0, job.density, job.trial))
    for planner in (MONOLITHIC, Planner(1, 1, 1)):  # a process's first plans pay for imports and caches
        run_planner(warm, planner)
    rows = []
    for planner in job.planners:
        figures = run_planner(world, planner)
        rows.append({"world": world_label(job.nodes), "nodes": job.nodes, "side": world.probabilities.shape[0],
                     "density": job.density, "trial": job.trial, "seed": job.seed,
                     "planner": "monolithic" if planner.monolithic else "two-tier",
                     "local_map_kb": planner.local_map_kb, "memories": planner.memories,
                     "cost_method": planner.cost_method, **figures,
                     "overall_time": figures["planning_time"] + figures["transmission_time"]})
    return {"status": "completed", "rows": rows}


def run_study(study: TwoTierStudy, out: Path, workers: int = 1, resume: bool = False) -> dict:
    """Run the study; write ``results.csv``, ``report.md`` and the plots into ``out``. Planning times are wall
    times, so more than one worker on a busy machine makes them noisier (the default is one)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    began = time.perf_counter()
    world_jobs = jobs(study)
    results = run_trials(world_jobs, workers=workers, run=run_world, journal=out / JOURNAL_NAME, resume=resume)
    wall = time.perf_counter() - began
    rows = [row for result in results for row in result.get("rows", [])]
    failed = [f"{world_label(j.nodes)} {j.density:.0%} world {j.trial}: {r.get('error')}"
              for j, r in zip(world_jobs, results) if "rows" not in r]
    write_csv(out / "results.csv", COLUMNS, rows, float_format=".6g")
    write_atomic(out / "report.md", report(study, rows, failed, wall, workers, out).encode())
    return {"report": out / "report.md", "results": out / "results.csv", "rows": len(rows), "wall_s": wall}


# ====================================================================== analysis and report


class Results:
    """The rows indexed by world cell and planner, with paired comparisons over the worlds of a cell."""

    def __init__(self, rows: list[dict]):
        self.cells: dict[tuple, dict[int, dict]] = defaultdict(dict)
        for row in rows:
            planner = Planner(row["local_map_kb"], row["memories"], row["cost_method"])
            self.cells[(row["nodes"], row["density"], planner)][row["trial"]] = row

    def mean(self, nodes: int, density: float, planner: Planner, metric: str) -> float:
        values = [r[metric] for r in self.cells.get((nodes, density, planner), {}).values() if r["reached"]]
        return float(np.mean(values)) if values else math.nan

    def paired(self, nodes: int, density: float, a: Planner, b: Planner, metric: str) -> tuple[list, list]:
        """``metric`` of a and of b over the worlds where both reached the goal, in world order."""
        rows_a, rows_b = self.cells.get((nodes, density, a), {}), self.cells.get((nodes, density, b), {})
        both = [t for t in sorted(set(rows_a) & set(rows_b)) if rows_a[t]["reached"] and rows_b[t]["reached"]]
        return [rows_a[t][metric] for t in both], [rows_b[t][metric] for t in both]

    def compare(self, nodes: int, density: float, a: Planner, b: Planner, metric: str) -> tuple[float, float, int]:
        """(mean of a / mean of b, paired two-sided p, worlds) over the worlds where both reached the goal."""
        xa, xb = self.paired(nodes, density, a, b, metric)
        if not xa:
            return math.nan, math.nan, 0
        return float(np.mean(xa) / np.mean(xb)) if np.mean(xb) > 0 else math.nan, paired_t_test(xa, xb)[1], len(xa)


@dataclass
class Claim:
    claim: str
    thesis: str
    most: bool = False  # the thesis claims it of most cells ("generally", "rarely"), not of every one
    teamsim: str = "not measured"
    agree: int = 0
    total: int = 0
    significant: int = 0  # cells where the difference is significant (p <= 0.05)
    ratios: list = field(default_factory=list)
    cause: str = ""  # why teamsim differs, when it does

    @property
    def verdict(self) -> str:
        if self.total == 0:
            return "not measured"
        if self.agree == self.total or (self.most and 2 * self.agree >= self.total):
            return "yes"
        return "partly" if 2 * self.agree >= self.total and not self.most else "**no**"

    def tally(self, results: Results, cells, metric: str, agrees) -> None:
        """Count the cells (nodes, density, planner a, planner b) where ``agrees(ratio, p, nodes, density, a)``,
        a/b being the ratio of ``metric``; cells nobody measured are skipped."""
        for n, d, a, b in cells:
            ratio, p, _ = results.compare(n, d, a, b, metric)
            if np.isfinite(ratio):
                self.ratios.append(ratio)
                self.total += 1
                self.agree += bool(agrees(ratio, p, n, d, a))
                self.significant += p <= 0.05

    @property
    def ratio_range(self) -> str:
        return f"{min(self.ratios):.2f}-{max(self.ratios):.2f}" if self.ratios else "n/a"


def claims(study: TwoTierStudy, results: Results) -> list[Claim]:
    """The chapter 4 orderings, each counted over the cells (global size x density x ...) where the thesis makes
    it: the global maps of at least 3.81 MB and, unless said otherwise, the 64-256 KB local maps; with the
    causes of disagreement, from what was measured."""
    large = [n for n in study.world_nodes if n >= LARGE_WORLD]
    small = [kb for kb in study.local_map_kb if kb in SMALL_LOCAL_MAPS]
    cells = [(n, d) for n in large for d in study.densities]
    share = _planning_share(results)
    found = []

    if {1, 2} <= set(study.cost_methods):
        cm_cells = [(n, d, Planner(kb, 1, 2), Planner(kb, 1, 1)) for n, d in cells for kb in small]
        for metric, text, thesis in (("planning_time", "planning time", THESIS_CM2_TIME),
                                     ("expansions", "planning work (node expansions)", THESIS_CM2_TIME),
                                     ("bytes_received", "map data received", THESIS_CM2_DATA)):
            claim = Claim(f"cost method 1 cheaper than 2: {text}", "CM2/CM1 " + ", ".join(
                f"{world_label(n)}: {v}" for n, v in thesis.items()) + " (p < 0.01 for 64-256 KB)")
            claim.tally(results, cm_cells, metric, lambda ratio, *_: ratio > 1)
            claim.teamsim = (f"CM2/CM1 {claim.ratio_range}; higher in {claim.agree} of {claim.total} cells, "
                             f"significantly in {claim.significant}")
            claim.cause = (
                "the direction mostly agrees but the effect is smaller. CM2's g' is a path's cost, its length times "
                "the mean c_m along it; with free cells at p = 0.05 and w_pi = w_prc = 0.5, c_m is about 1.05-1.3, "
                "so CM2 over-weights g' against the Euclidean h' by only 5-30 % and widens the higher-level search "
                "a little; where both methods expand the same local maps the figures are equal."
                + (f" Planning times here are tens of milliseconds ({share}) measured on a shared machine over few "
                   "worlds, so their ratios are noisy; the expansions count the same work without the noise."
                   if metric == "planning_time" else ""))
            found.append(claim)
        path = Claim("cost methods 1 and 2 give similar path lengths",
                     "no significant difference in most cells (Figs 4.15-4.17(c))", most=True)
        path.tally(results, cm_cells, "path_length", lambda ratio, p, *_: not p <= 0.05)
        path.teamsim = f"CM2/CM1 {path.ratio_range}; not significant in {path.agree} of {path.total}"
        found.append(path)

    if 64 in small:
        best = Claim("64 KB local maps do best (overall time)",
                     "128 KB / 64 KB and 256 KB / 64 KB > 1 for every global size, density and Q (Fig 4.21)")
        best.tally(results, [(n, d, Planner(kb, q, 1), Planner(64, q, 1)) for n, d in cells for q in study.memories
                             for kb in small if kb != 64], "overall_time", lambda ratio, *_: ratio > 1)
        best.teamsim = f"ratios {best.ratio_range}; above 1 in {best.agree} of {best.total}"
        best.cause = (
            "64 KB maps hold 90 x 90 nodes, so a route crosses many more of them; at high density the paths "
            "through them wind, cost method 1's g' (path length) then outgrows the straight-line h', and the "
            "higher level expands a wide band of maps, fetching every neighbour of each (see the fetches column). "
            "Overall time here is almost all transmission, so the larger maps win where they fetch less data.")
        found.append(best)

    versus = Claim("memory-constrained vs monolithic overall time (CM1)",
                   "3.81 and 7.63 MB: worse at <= 15 %, better or comparable at >= 20 %; 38.15 MB: better or "
                   "comparable for 64 and 128 KB, 256 KB worse at <= 15 % (Figs 4.18-4.20)")

    def as_thesis(ratio, p, n, d, planner):
        expected_not_worse = d >= 0.20 - 1e-9 or (n >= 5_000_000 and planner.local_map_kb <= 128)
        return (ratio < 1 or not p <= 0.05) == expected_not_worse

    versus.tally(results, [(n, d, Planner(kb, q, 1), MONOLITHIC) for n, d in cells for q in study.memories
                           for kb in small], "overall_time", as_thesis)
    data = [results.compare(n, d, Planner(kb, q, 1), MONOLITHIC, "bytes_received")[0]
            for n, d in cells for q in study.memories for kb in small]
    data = [v for v in data if np.isfinite(v)]
    versus.teamsim = f"two-tier / monolithic {versus.ratio_range}; as the thesis says in {versus.agree} of " \
                     f"{versus.total} cells"
    biggest = max(study.world_nodes)
    monolithic = np.nanmean([results.mean(biggest, d, MONOLITHIC, "planning_time") for d in study.densities])
    versus.cause = (
        f"overall time here is almost all transmission ({share}): the monolithic modified A* with (3.4)'s "
        "heuristic, which multiplies the Manhattan distance by c_m, is close to a greedy search and plans a "
        f"{world_label(biggest)} map in {monolithic:.2f} s on average, so the exit points' smaller search saves "
        "next to nothing. What decides is the data: the two-tiered planner fetches every unclosed neighbour of "
        "each map it expands, and fetches again what it evicted, receiving "
        + (f"{min(data):.2f}-{max(data):.2f}" if data else "n/a")
        + " times the whole global map that the monolithic planner is charged once. In MATLAB (§4.6: 'lengthy "
        "planning times') planning dominated, and there exit points pay off at high density.")
    found.append(versus)

    for metric, text in (("planning_time", "planning time"), ("expansions", "planning work (node expansions)")):
        trend = Claim(f"{text} grows with obstacle density (CM1, Q = 1)",
                      "'generally proportional to obstacle density', clearest for 64-128 KB maps (Figs 4.9-4.14(a))",
                      most=True)
        low, high = min(study.densities), max(study.densities)
        if low < high:
            for n in study.world_nodes:
                for kb in study.local_map_kb:
                    before, after = (results.mean(n, d, Planner(kb, 1, 1), metric) for d in (low, high))
                    if np.isfinite(before) and np.isfinite(after):
                        trend.total += 1
                        trend.agree += after > before
            trend.teamsim = (f"higher at {high:.0%} than at {low:.0%} in {trend.agree} of {trend.total} "
                             "(size, local map)")
            trend.cause = f"planning times are milliseconds ({share}) and noisy on a shared machine." \
                if metric == "planning_time" else "expansions count the work itself, with no machine noise."
        found.append(trend)

    others = [q for q in study.memories if q != 1]
    if others:
        quantity = Claim("more local-map memories: overall time rarely differs significantly",
                         "38.15 MB: Q = 1 vs 5, 5 vs 15, 1 vs 15 significant in 1 of 45 cells (Fig 4.22)", most=True)
        quantity.tally(results, [(n, d, Planner(kb, q, 1), Planner(kb, 1, 1)) for n, d in cells for kb in small
                                 for q in others], "overall_time", lambda ratio, p, *_: not p <= 0.05)
        quantity.teamsim = (f"Q = {'/'.join(map(str, others))} over Q = 1: {quantity.ratio_range}; not significant "
                            f"in {quantity.agree} of {quantity.total}")
        quantity.cause = (
            "more memories save the maps that Q = 1 evicts and fetches again, as in the thesis (its ratios also "
            "fall as Q grows, 'because less data is transmitted'). Here overall time is almost all transmission of "
            "data that depends on the world alone, so that saving is the same in every world and comes out "
            "significant even over few worlds; in the thesis, planning-time variation masked it.")
        found.append(quantity)

    big = [kb for kb in study.local_map_kb if kb >= 512]
    if big and small:
        sizes = Claim("small local maps (64, 128 KB) plan faster and receive less than large ones",
                      "when the global map is at least 3.81 MB (Figs 4.12-4.14(a), (b))")
        for metric in ("planning_time", "expansions", "bytes_received"):
            sizes.tally(results, [(n, d, Planner(kb, 1, 1), Planner(other, 1, 1)) for n, d in cells
                                  for kb in small if kb <= 128 for other in big
                                  if other * 1024 <= n * BYTES_PER_NODE],  # a larger map is no constraint
                        metric, lambda ratio, *_: ratio < 1)
        sizes.teamsim = f"smaller in {sizes.agree} of {sizes.total} (size, density, metric, pair) cells"
        sizes.cause = f"planning times are milliseconds ({share}); the data received follows the fetch counts."
        found.append(sizes)
    return found


def _planning_share(results: Results) -> str:
    """How much of the two-tiered planners' overall time was planning, as a phrase."""
    rows = [r for cell in results.cells.values() for r in cell.values() if r["planner"] == "two-tier"]
    if not rows:
        return "no two-tiered plans"
    share = [r["planning_time"] / r["overall_time"] for r in rows if r["overall_time"] > 0]
    return f"planning is {100 * min(share):.1f}-{100 * max(share):.1f} % of the two-tiered overall times"


def _planner_label(planner: Planner) -> str:
    if planner.monolithic:
        return "monolithic (Inf)"
    return f"{local_map_label(planner.local_map_kb)}, Q {planner.memories}, CM{planner.cost_method}"


def report(study: TwoTierStudy, rows: list[dict], failed: list[str], wall: float, workers: int, out: Path) -> str:
    results = Results(rows)
    planners = study.planners()
    found = claims(study, results)
    lines = ["# Two-tiered memory-constrained A* (Chand ch.4) re-run in teamsim", "",
             f"Global maps {', '.join(world_label(n) for n in study.world_nodes)}; densities "
             f"{', '.join(f'{d:.0%}' for d in study.densities)}; local maps "
             f"{', '.join(local_map_label(k) for k in study.local_map_kb)}; Q {', '.join(map(str, study.memories))}; "
             f"cost methods {', '.join(map(str, study.cost_methods))}; "
             + (f"{study.trials} worlds per size and density" if study.trials is not None else
                "30 worlds per size and density (10 at 25 % in the two largest sizes)")
             + f" (the thesis: 30, each planned 10 times); seed {study.seed}. {len(rows)} plans in {wall:.0f} s on "
             f"{workers} worker{'s' if workers > 1 else ''}. Per-plan rows: `results.csv`.", "",
             "Overall time = planning time (measured here, in Python) + transmission time of the map data received "
             "at 5.5 Mbit/s (§4.6.3). The monolithic planner is charged the whole global map. Ratios are of means "
             "over the worlds where both planners reached the goal, in the paired comparisons with their 95 % "
             "confidence interval (Fieller's, paired); p is the paired two-sided t-test over those worlds.", "",
             "## Orderings against the thesis", "",
             "| claim | thesis | teamsim | reproduced |", "|---|---|---|---|"]
    for claim in found:
        lines.append(f"| {claim.claim} | {claim.thesis} | {claim.teamsim} | {claim.verdict} |")
    disagreements = [c for c in found if c.verdict not in ("yes", "not measured")]
    if disagreements:
        lines += ["", "Where teamsim does not reproduce the thesis, and why:", ""]
        lines += [f"- **{c.claim}**: {c.cause or 'cause not established.'}" for c in disagreements]
    lines += ["", "![overall time](overall_time.png)", "", "![planning time](planning_time.png)", "",
              "## Per planner", "",
              "Means over the worlds where the planner reached the goal (reached: of all worlds).", "",
              "| global map | density | planner | reached | planning (s) | expansions | data (MB) | transmission (s) | "
              "overall (s) | path (m) | fetches |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for n in study.world_nodes:
        for d in study.densities:
            for planner in planners:
                cell = results.cells.get((n, d, planner), {})
                if not cell:
                    continue
                reached = sum(r["reached"] for r in cell.values())

                def m(metric, scale=1.0):
                    return results.mean(n, d, planner, metric) * scale

                lines.append(f"| {world_label(n)} | {d:.0%} | {_planner_label(planner)} | {reached}/{len(cell)} | "
                             f"{m('planning_time'):.3f} | {m('expansions'):.0f} | "
                             f"{m('bytes_received', 2 ** -20):.2f} | "
                             f"{m('transmission_time'):.2f} | {m('overall_time'):.2f} | {m('path_length'):.1f} | "
                             f"{m('fetches'):.0f} |")
    lines += ["", "## Paired comparisons", "",
              "| global map | density | comparison | planning time | p | expansions | p | data | p | path length | p | "
              "overall | p |", "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for n in study.world_nodes:
        for d in study.densities:
            for a, b in _comparisons(study):
                metrics = ("planning_time", "expansions", "bytes_received", "path_length", "overall_time")
                figures = [results.compare(n, d, a, b, metric) for metric in metrics]
                if all(count == 0 for _, _, count in figures):
                    continue
                intervals = [interval_text(*ratio_ci(*results.paired(n, d, a, b, metric))[1:]) for metric in metrics]
                cells = " | ".join(" ".join(filter(None, (f"{ratio:.2f}", interval))) + f" | {p:.3f}"
                                   for (ratio, p, _), interval in zip(figures, intervals))
                lines.append(f"| {world_label(n)} | {d:.0%} | {_planner_label(a)} / {_planner_label(b)} | {cells} |")
    if failed:
        lines += ["", f"{len(failed)} worlds failed:", ""] + [f"- {f}" for f in failed]
    lines += ["", "## Choices", "", "Where §4.6 is silent (see `tasks/studies/two_tier_astar.py` and "
              "`controllers/navigation/two_tier_astar.py`): square worlds; obstacles are overlapping rectangles "
              "0.3-1.2 m a side; start and goal 0.5 m in from their corners; the 15 cm worker is 2 nodes in radius "
              "(exit points need 5 free boundary nodes); the lower level and the monolithic planner use the "
              "Manhattan heuristic (§4.7) and no obstacle inflation; Q = 5 and 15 run with cost method 1 on 64-256 KB "
              "maps only."]
    _plots(study, results, out)
    return "\n".join(lines) + "\n"


def _comparisons(study: TwoTierStudy) -> list[tuple[Planner, Planner]]:
    """CM2 / CM1 (Q = 1) for every local map; two-tier / monolithic (CM1, every Q) and 128, 256 KB / 64 KB
    (CM1, every Q) for the small local maps."""
    pairs = []
    if {1, 2} <= set(study.cost_methods):
        pairs += [(Planner(kb, 1, 2), Planner(kb, 1, 1)) for kb in study.local_map_kb]
    small = [kb for kb in study.local_map_kb if kb in SMALL_LOCAL_MAPS]
    for q in study.memories:
        pairs += [(Planner(kb, q, 1), MONOLITHIC) for kb in small]
        if 64 in small:
            pairs += [(Planner(kb, q, 1), Planner(64, q, 1)) for kb in small if kb != 64]
    return pairs


def _plots(study: TwoTierStudy, results: Results, out: Path) -> None:
    """Mean overall and planning times per global map and density: the monolithic planner and each local-map
    size (cost method 1, Q = 1), as Figs 4.9-4.14 draw them."""
    groups = [(n, d) for n in study.world_nodes for d in study.densities]
    labels = [f"{world_label(n)} {d:.0%}" for n, d in groups]
    planners = [MONOLITHIC] + [Planner(kb, 1, 1) for kb in study.local_map_kb]
    for metric, title in (("overall_time", "Overall time (planning + transmission at 5.5 Mbit/s), cost method 1, Q 1"),
                          ("planning_time", "Planning time, cost method 1, Q 1")):
        series = {("Inf" if p.monolithic else local_map_label(p.local_map_kb)):
                  [results.mean(n, d, p, metric) for n, d in groups] for p in planners}
        grouped_bars(out / f"{metric}.png", title, labels, series, "s")

