"""Chand's modified A* over an occupancy grid (§3.2.2, eq. 3.1-3.8), and a plain textbook A* to check it against.

Costs (maximised nowhere, minimised everywhere):
  (3.1) f(x) = g(x) + h(x)
  (3.3) g(x) = g(x_par) + d_n(x, x_par) c_m(x)   if p_i(x) < P_T, else infinite (the cell is impassable)
  (3.4) h(x) = d_n(x, x_goal) c_m(x)             under the same condition; d_n is Manhattan (§4.7) or Euclidean
  (3.5) c_p(x) = (1 - w_p2) p_i(x)  if p_i(x) = 0.5 (unexplored)
               = (1 - w_p1) p_i(x)  if p_cmin <= p_i(x) <= p_cmax
               = p_i(x)             otherwise
        [RECON] the thesis prints the last case as "p_cmax < p_i(x) < p_cmin", which is empty for p_cmin < p_cmax;
        it can only mean "outside the critical band", which is how it is coded.
  (3.6) w_new = w_old f_w if the progress d_prog < d_progmin, else w_init   (unknown environments only)
  (3.7) c_m(x) = 1 + w_pi c_p(x) + w_prc c_prc(x)
  (3.8) c_prc(x) = (1/r) sum_i c_p(x_i), the mean probability cost over a clearance of r nodes around x.
        [RECON] "r nodes around x" is read as the square window reaching r nodes out on every side; the 1/r is its
        normaliser (the count of its cells that lie inside the grid).

The search is eight-connected (four adjacent and four diagonal neighbours, §4.3). A diagonal step may not cut the
corner of an impassable cell (a choice the thesis does not make: a robot cannot squeeze between two cells that
touch only at a corner). When the goal cannot be reached the planner returns the partial path that ends at the
expanded cell closest to the goal (§3.2.2); the robot carries on reactively from its end.

(3.4) multiplies the distance by the cost of the cell being scored, so it over-estimates and the search is not
guaranteed optimal; ``heuristic="octile"`` swaps in the admissible octile distance (every step costs at least its
length, since c_m >= 1), with which the path is least-cost. The thesis's robot size enters only through c_prc; a
planner may also inflate impassable cells by the robot's radius (``inflation_cells``), as §4.2 assumes of its maps.

Implementation: the cost maps, the heuristic and the partial-path choice are numpy array operations over flat
cell indices into a grid padded with an impassable border, so expanding a cell needs no bounds checks. With the
thesis's heuristics the search is A*'s binary heap, one cell at a time, compiled (numba; ``_heap_kernel``: the same
heap of (f, cell) and the same relaxations as the pure-Python loop it replaced, so the same path, cost and
expansions, checked on recorded plans); with the admissible octile heuristic, whose least cost does not depend on
the expansion order, it expands cells in vectorised batches (``_wavefront_search``), which was several times faster
than the pure-Python heap (the compiled heap is now faster again: 0.2 against 2 ms on the explorers' 64 x 64 maps;
the batches stay, as the paths they choose among equal-cost ones are their own). ``reference_astar`` is a
deliberately plain dict-and-set A* kept as the test oracle and the benchmark baseline.
"""
from __future__ import annotations

import heapq
import math
from dataclasses import dataclass, replace

import numpy as np
from numba import njit

from teamsim.controllers.navigation.occupancy_grid import OccupancyGrid

SQRT2 = math.sqrt(2.0)
HEURISTICS = ("manhattan", "euclidean", "octile")


@dataclass(frozen=True)
class PlannerParams:
    # §3.2.2 gives no value for P_T, p_cmin, p_cmax, the initial w_p1, w_p2, or r; these are chosen.
    occupied_threshold: float = 0.7  # P_T: one near IR hit on an unexplored cell (0.5 -> 0.83) blocks it
    critical_min: float = 0.2  # p_cmin: lower edge of the favoured ("critical") probability band
    critical_max: float = 0.6  # p_cmax: upper edge of that band
    weight_critical: float = 0.0  # w_p1 (3.5); 0 in known environments (§3.2.2)
    weight_unexplored: float = 0.0  # w_p2 (3.5); 0 in known environments (§3.2.2)
    weight_probability: float = 0.5  # w_pi (3.7), §3.2.2
    weight_clearance: float = 0.5  # w_prc (3.7), §3.2.2
    clearance_nodes: int = 2  # r (3.8): the clearance window reaches this many nodes out
    heuristic: str = "manhattan"  # d_n in (3.4): Manhattan as in §4.7; or "euclidean"; or admissible "octile"


@dataclass(frozen=True)
class WeightAdaptation:
    """(3.6): how the exploration weights w_p1, w_p2 change with progress in unknown environments."""
    # Not given in the thesis; chosen.
    initial_critical: float = 0.3  # w_p1 when progress is good
    initial_unexplored: float = 0.5  # w_p2 when progress is good: unexplored cells cost (1 - 0.5) 0.5 = 0.25
    factor: float = 1.5  # f_w: poor progress makes unexplored and uncertain cells cheaper still
    min_progress: float = 0.5  # d_progmin, m of progress towards the goal between re-plans


def adapt_weights(params: PlannerParams, progress: float, adaptation: WeightAdaptation) -> PlannerParams:
    """(3.6) applied to w_p1 and w_p2; the weights are unit-interval values (§3.2.2), so they are clipped to 1."""
    if progress < adaptation.min_progress:
        return replace(params, weight_critical=min(params.weight_critical * adaptation.factor, 1.0),
                       weight_unexplored=min(params.weight_unexplored * adaptation.factor, 1.0))
    return replace(params, weight_critical=adaptation.initial_critical,
                   weight_unexplored=adaptation.initial_unexplored)


def probability_cost(probabilities: np.ndarray, params: PlannerParams) -> np.ndarray:
    """c_p (3.5)."""
    p = np.asarray(probabilities, float)
    unexplored = p == 0.5  # unexplored cells hold exactly 0.5; any Bayes update (6.5) moves a cell off it
    critical = (p >= params.critical_min) & (p <= params.critical_max)
    return np.where(unexplored, (1.0 - params.weight_unexplored) * p,
                    np.where(critical, (1.0 - params.weight_critical) * p, p))


def window_mean(values: np.ndarray, radius: int) -> np.ndarray:
    """Mean of ``values`` over the (2 radius + 1)^2 square around each cell, counting only cells inside the
    grid (an integral image of the zero-padded grid, so the cost does not grow with the radius)."""
    rows, cols = values.shape
    span = 2 * radius + 1
    integral = np.zeros((rows + span, cols + span))
    np.cumsum(np.pad(values, radius).cumsum(axis=0), axis=1, out=integral[1:, 1:])
    total = (integral[span:, span:] - integral[:-span, span:] - integral[span:, :-span] + integral[:-span, :-span])

    def inside(n):  # cells of each window that lie in the grid, along one axis
        index = np.arange(n)
        return np.minimum(index + radius, n - 1) - np.maximum(index - radius, 0) + 1

    return total / (inside(rows)[:, None] * inside(cols)[None, :])


def cost_multiplier(probabilities: np.ndarray, params: PlannerParams) -> np.ndarray:
    """c_m (3.7), with c_prc (3.8) the window mean of c_p."""
    cp = probability_cost(probabilities, params)
    return 1.0 + params.weight_probability * cp + params.weight_clearance * window_mean(cp, params.clearance_nodes)


def distance_transform(mask: np.ndarray, max_distance: float) -> np.ndarray:
    """Euclidean distance, in cells, from every cell to the nearest ``True`` cell; ``inf`` beyond ``max_distance``.

    Exact within the cap: first the distance along each row to the nearest marked cell (running maxima and minima
    of marked column indices), then for each cell the minimum of dy^2 + row_distance^2 over the rows dy away,
    for |dy| up to the cap."""
    mask = np.asarray(mask, bool)
    rows, cols = mask.shape
    far = cols + int(max_distance) + 2  # further than any capped distance
    index = np.arange(cols)
    left = np.maximum.accumulate(np.where(mask, index, -far), axis=1)
    right = np.minimum.accumulate(np.where(mask, index, cols + far)[:, ::-1], axis=1)[:, ::-1]
    along_row = np.minimum(index - left, right - index).astype(float)
    squared = along_row ** 2
    best = squared.copy()
    for dy in range(1, min(int(max_distance), rows - 1) + 1):
        np.minimum(best[dy:], squared[:-dy] + dy * dy, out=best[dy:])
        np.minimum(best[:-dy], squared[dy:] + dy * dy, out=best[:-dy])
    distance = np.sqrt(best)
    return np.where(distance <= max_distance, distance, np.inf)


@dataclass(frozen=True)
class CostMaps:
    blocked: np.ndarray  # bool: p_i >= P_T, or within the inflation radius of such a cell
    multiplier: np.ndarray  # c_m (3.7) of every cell


def cost_maps(probabilities: np.ndarray, params: PlannerParams, inflation_cells: float = 0.0) -> CostMaps:
    p = np.asarray(probabilities, float)
    occupied = p >= params.occupied_threshold
    blocked = distance_transform(occupied, inflation_cells) <= inflation_cells if inflation_cells > 0 else occupied
    return CostMaps(blocked, cost_multiplier(p, params))


@dataclass(frozen=True)
class PathResult:
    cells: np.ndarray  # (n, 2) int (row, col) from the start to the path's end
    cost: float  # g at the path's end (3.3)
    reached: bool  # False: a partial path ending at the expanded cell nearest the goal
    expanded: int  # cells taken off the open list

    @property
    def length(self) -> float:
        """Geometric length in cells (steps of 1 and sqrt 2)."""
        return float(np.hypot(*np.diff(self.cells, axis=0).T).sum()) if len(self.cells) > 1 else 0.0


def _heuristic_map(shape: tuple[int, int], goal: tuple[int, int], multiplier: np.ndarray, kind: str) -> np.ndarray:
    dr = np.abs(np.arange(shape[0]) - goal[0])[:, None].astype(float)
    dc = np.abs(np.arange(shape[1]) - goal[1])[None, :].astype(float)
    if kind == "manhattan":
        return (dr + dc) * multiplier
    if kind == "euclidean":
        return np.hypot(dr, dc) * multiplier
    if kind == "octile":
        return np.maximum(dr, dc) + (SQRT2 - 1.0) * np.minimum(dr, dc)
    raise ValueError(f"heuristic {kind!r} is not one of {HEURISTICS}")


@dataclass(frozen=True)
class _Padded:
    """The search's view of a grid: flat arrays over the grid padded with an impassable border, so a neighbour
    index never needs a bounds check."""
    width: int  # padded row length
    blocked: np.ndarray  # bool, flat; the start is passable whatever its cost map says
    multiplier: np.ndarray  # c_m, flat
    h: np.ndarray  # heuristic, flat
    source: int
    target: int

    @property
    def straight(self) -> tuple[int, ...]:
        return (-self.width, self.width, -1, 1)

    @property
    def diagonal(self) -> tuple[tuple[int, int, int], ...]:
        """A diagonal step and the two straight cells whose corner it would cut."""
        w = self.width
        return ((-w - 1, -w, -1), (-w + 1, -w, 1), (w - 1, w, -1), (w + 1, w, 1))


def _padded(costs: CostMaps, start: tuple[int, int], goal: tuple[int, int], heuristic: str) -> _Padded:
    rows, cols = costs.blocked.shape
    blocked = np.ones((rows + 2, cols + 2), bool)
    blocked[1:-1, 1:-1] = costs.blocked
    blocked[start[0] + 1, start[1] + 1] = False
    multiplier = np.zeros((rows + 2, cols + 2))
    multiplier[1:-1, 1:-1] = costs.multiplier
    h = np.zeros((rows + 2, cols + 2))
    h[1:-1, 1:-1] = _heuristic_map((rows, cols), goal, costs.multiplier, heuristic)
    width = cols + 2
    return _Padded(width, blocked.ravel(), multiplier.ravel(), h.ravel(), (start[0] + 1) * width + start[1] + 1,
                   (goal[0] + 1) * width + goal[1] + 1)


def astar(costs: CostMaps, start: tuple[int, int], goal: tuple[int, int], heuristic: str = "manhattan") -> PathResult:
    """A* from ``start`` to ``goal`` (row, col) over precomputed cost maps. The start is passable whatever its
    cost map says: the robot is standing on it.

    With the admissible octile heuristic the least cost does not depend on the order cells are expanded in, and
    the search expands them in vectorised batches (``_wavefront_search``); with the thesis's heuristics, which
    may over-estimate, the path depends on that order, so they keep A*'s one cell at a time (``_heap_search``).
    """
    grid = _padded(costs, start, goal, heuristic)
    search = _wavefront_search if heuristic == "octile" else _heap_search
    g, parent, closed, expanded = search(grid)
    closed &= ~grid.blocked
    reached = bool(closed[grid.target])
    end = grid.target if reached else _closest_expanded(closed, grid.width, goal)
    cells = []
    node = end
    while node != -1:
        cells.append(divmod(node, grid.width))
        node = int(parent[node])
    path = np.array(cells[::-1], dtype=int) - 1
    return PathResult(path, float(g[end]), reached, expanded)


def _heap_search(grid: _Padded) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """A* with a binary heap: (g, parent, expanded mask, expansions); compiled (``_heap_kernel``)."""
    return _heap_kernel(np.ascontiguousarray(grid.blocked), np.ascontiguousarray(grid.multiplier),
                        np.ascontiguousarray(grid.h), grid.source, grid.target, grid.straight, grid.diagonal)


@njit("b1(f8[::1], i8[::1], i8, i8, f8)", cache=True)
def _improves(g, parent, node, neighbour, step):
    """(3.3): whether g(node) + ``step`` beats ``neighbour``'s g; if so it becomes its g, through ``node``."""
    g_new = g[node] + step
    if g_new < g[neighbour]:
        g[neighbour] = g_new
        parent[neighbour] = node
        return True
    return False


@njit("Tuple((f8[::1], i8[::1], b1[::1], i8))(b1[::1], f8[::1], f8[::1], i8, i8, UniTuple(i8, 4), "
      "UniTuple(UniTuple(i8, 3), 4))", cache=True)
def _heap_kernel(blocked, multiplier, h, source, target, straight, diagonal):  # noqa: PLR0913
    """The search of ``_heap_search``: the open list a binary heap of (f, cell) (numba's ``heapq`` is a copy of
    CPython's, so cells come off in the same order: the least f first, the lower flat index on a tie); a cell is
    expanded the first time it comes off; ``straight`` and ``diagonal`` are ``_Padded``'s moves, in its order."""
    done = blocked.copy()  # closed or impassable: one test instead of two in the inner loop
    g = np.full(blocked.shape[0], np.inf)
    parent = np.full(blocked.shape[0], -1, np.int64)
    g[source] = 0.0
    heap = [(h[source], source)]
    expanded = 0
    while len(heap):
        node = heapq.heappop(heap)[1]
        if done[node]:
            continue
        done[node] = True
        expanded += 1
        if node == target:
            break
        for move in straight:  # d_n = 1
            nb = node + move
            if not done[nb] and _improves(g, parent, node, nb, multiplier[nb]):
                heapq.heappush(heap, (g[nb] + h[nb], nb))  # f (3.1)
        for move, side_a, side_b in diagonal:  # d_n = sqrt 2, not cutting the corner of an impassable cell
            nb = node + move
            if (not (done[nb] or blocked[node + side_a] or blocked[node + side_b])
                    and _improves(g, parent, node, nb, SQRT2 * multiplier[nb])):
                heapq.heappush(heap, (g[nb] + h[nb], nb))
    return g, parent, done, expanded


WAVEFRONT_BAND = 1.0  # f-width of a batch, about one straight step's cost (a tuning choice: wider, fewer rounds)


def _wavefront_search(grid: _Padded) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Label-correcting A* in batches, numpy throughout: each round expands every open cell whose f lies within
    ``WAVEFRONT_BAND`` of the least and relaxes all their neighbours at once; a cell whose g drops later is opened
    again. The search stops when no open cell's f is below the goal's g: with an admissible heuristic no open
    cell can then lead to a cheaper path, so the goal's g is the least cost, as one-at-a-time A* finds it.
    Returns (g, parent, expanded mask, expansions counting re-expansions)."""
    rows = grid.blocked.size // grid.width
    free = ~grid.blocked.reshape(rows, grid.width)
    moves = np.array(grid.straight + tuple(m for m, _, _ in grid.diagonal))
    step_length = np.array([1.0] * 4 + [SQRT2] * 4)
    # allowed[cell, k]: move k enters a free cell without cutting a blocked corner (border cells never expand).
    shifted = {(dr, dc): free[1 + dr:rows - 1 + dr, 1 + dc:grid.width - 1 + dc]
               for dr in (-1, 0, 1) for dc in (-1, 0, 1)}
    allowed = np.zeros((rows, grid.width, 8), bool)
    for k, (dr, dc) in enumerate(((-1, 0), (1, 0), (0, -1), (0, 1), (-1, -1), (-1, 1), (1, -1), (1, 1))):
        allowed[1:-1, 1:-1, k] = shifted[dr, dc] & shifted[dr, 0] & shifted[0, dc]
    allowed = allowed.reshape(-1, 8)

    g = np.full(grid.blocked.size, np.inf)
    parent = np.full(grid.blocked.size, -1, np.int64)
    closed = np.zeros(grid.blocked.size, bool)
    latest = np.zeros(grid.blocked.size, np.int64)  # scratch for _unique
    g[grid.source] = 0.0
    open_cells, open_f = np.array([grid.source]), grid.h[[grid.source]]
    expanded = 0
    while open_cells.size:
        f_min = open_f.min()
        if g[grid.target] <= f_min:
            closed[grid.target] = True  # as good as expanded: the goal's g is final
            break
        take = open_f <= f_min + WAVEFRONT_BAND
        batch, batch_f = open_cells[take], open_f[take]
        open_cells, open_f = open_cells[~take], open_f[~take]
        batch = batch[batch_f == g[batch] + grid.h[batch]]  # an entry whose cell's g has dropped since is stale
        closed[batch] = True
        expanded += batch.size
        ok = allowed[batch]
        neighbours = batch[:, None] + moves
        candidate = (g[batch][:, None] + step_length * grid.multiplier[neighbours])[ok]
        parents = np.repeat(batch, ok.sum(axis=1))
        neighbours = neighbours[ok]
        better = candidate < g[neighbours]
        neighbours, candidate, parents = neighbours[better], candidate[better], parents[better]
        np.minimum.at(g, neighbours, candidate)
        best = candidate == g[neighbours]  # the winning relaxation of each improved cell (ties: any of them)
        neighbours = _unique(neighbours[best], latest)
        parent[neighbours] = parents[best][latest[neighbours]]
        open_cells = np.concatenate([open_cells, neighbours])
        open_f = np.concatenate([open_f, g[neighbours] + grid.h[neighbours]])
    return g, parent, closed, expanded


def _unique(cells: np.ndarray, scratch: np.ndarray) -> np.ndarray:
    """``cells`` with repeats dropped (the last of each kept), in linear time: ``scratch`` is any int array as
    long as the grid."""
    order = np.arange(cells.size)
    scratch[cells] = order
    return cells[scratch[cells] == order]


def _closest_expanded(closed: np.ndarray, width: int, goal: tuple[int, int]) -> int:
    """Flat index of the expanded cell nearest the goal (Euclidean; the first in index order on a tie)."""
    expanded = np.flatnonzero(closed)
    row, col = np.divmod(expanded, width)
    return int(expanded[np.argmin((row - 1 - goal[0]) ** 2 + (col - 1 - goal[1]) ** 2)])


def modified_astar(probabilities: np.ndarray, start: tuple[int, int], goal: tuple[int, int],
                   params: PlannerParams = PlannerParams(), inflation_cells: float = 0.0) -> PathResult:
    """Chand's modified A* (3.1)-(3.8) on a grid of occupancy probabilities."""
    return astar(cost_maps(probabilities, params, inflation_cells), start, goal, params.heuristic)


def plan_on_grid(grid: OccupancyGrid, start_xy: tuple[float, float], goal_xy: tuple[float, float],
                 params: PlannerParams, robot_radius: float) -> tuple[np.ndarray, PathResult]:
    """Plan between two world points on an occupancy grid, impassable cells inflated by the robot's radius.
    Returns the path's cell centres in world coordinates, (n, 2), and the search result. Points off the grid are
    moved to its nearest cell."""
    def cell(xy):
        row, col = grid.world_to_cell(xy[0], xy[1])
        return int(np.clip(row, 0, grid.shape[0] - 1)), int(np.clip(col, 0, grid.shape[1] - 1))

    result = modified_astar(grid.probabilities, cell(start_xy), cell(goal_xy), params,
                            inflation_cells=robot_radius / grid.resolution)
    x, y = grid.cell_to_world(result.cells[:, 0], result.cells[:, 1])
    return np.column_stack([x, y]), result


def reference_astar(blocked: np.ndarray, multiplier: np.ndarray, start: tuple[int, int],
                    goal: tuple[int, int]) -> tuple[list[tuple[int, int]], float] | None:
    """Textbook A* with dicts and sets and the admissible octile heuristic: the same step costs, neighbours and
    corner rule as ``astar``, nothing clever. Returns (path, cost), or None if the goal cannot be reached."""
    blocked, multiplier = np.asarray(blocked).tolist(), np.asarray(multiplier).tolist()
    start, goal = tuple(start), tuple(goal)
    rows, cols = len(blocked), len(blocked[0])

    def passable(cell):
        r, c = cell
        return 0 <= r < rows and 0 <= c < cols and (not blocked[r][c] or cell == start)

    def octile(cell):
        dr, dc = abs(cell[0] - goal[0]), abs(cell[1] - goal[1])
        return max(dr, dc) + (SQRT2 - 1.0) * min(dr, dc)

    g = {start: 0.0}
    came_from = {}
    closed = set()
    open_heap = [(octile(start), start)]
    while open_heap:
        _, cell = heapq.heappop(open_heap)
        if cell in closed:
            continue
        if cell == goal:
            path = [cell]
            while path[-1] in came_from:
                path.append(came_from[path[-1]])
            return path[::-1], g[goal]
        closed.add(cell)
        r, c = cell
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                if dr == 0 and dc == 0:
                    continue
                nb = (r + dr, c + dc)
                if nb in closed or not passable(nb):
                    continue
                if dr and dc and not (passable((r + dr, c)) and passable((r, c + dc))):
                    continue
                step = SQRT2 if dr and dc else 1.0
                candidate = g[cell] + step * multiplier[nb[0]][nb[1]]
                if candidate < g.get(nb, math.inf):
                    g[nb] = candidate
                    came_from[nb] = cell
                    heapq.heappush(open_heap, (candidate + octile(nb), nb))
    return None
