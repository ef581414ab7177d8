"""Memory-constrained two-tiered A* (Chand ch.4, eq. 4.1-4.15, Figs 4.2-4.8).

A worker that cannot hold the global map plans over it anyway, fetching square local maps from the manager as it
needs them. A higher-level A* over local maps decides which to search; a lower-level A* searches the merged pair
of the current minimum-cost local map and one of its neighbours, from the end of the path through the current map
to an exit point of the neighbour. The global path is the concatenation of the per-local-map paths.

Memory (§4.2): the worker has Mem_LMapMaxTot bytes for Q local-map memories plus two more for the merged map,
  (4.1) Nodes_GMap = Rows_GMap x Cols_GMap
  (4.2) Mem_LMapMax = Mem_LMapMaxTot / (Q + 2)
  (4.3) Nodes_LMapMax = Mem_LMapMax / Mem_MNode
  (4.4) Nodes_LMap = RowCol_LMap^2, RowCol_LMap = floor(sqrt(Nodes_LMapMax))   (square local maps, Fig 4.2)
  (4.5) Mem_LMap = Nodes_LMap x Mem_MNode
Lower level (§4.3): (4.6)-(4.9) are the ch.3 costs of ``teamsim.controllers.navigation.astar`` with the raw p_i in place
of c_p, i.e. w_p1 = w_p2 = 0, and a Manhattan heuristic (§4.7).
Higher level (§4.4), over local-map indices x' and their four-connected neighbours:
  (4.10) g1'(x') = g1'(x'_par) + length(Path_LLA*(x'))    cost method 1
  (4.11) g2'(x') = g2'(x'_par) + f(x, x')                  cost method 2, f the lower-level path's cost
  (4.12) h'(x') = Euclidean distance from the last node of the path through x' to the final goal
  (4.13), (4.14) f' = g' + h'
  [RECON] "length" is taken as the path's geometric length in nodes (steps of 1 and sqrt 2), the unit h' is in;
  MATLAB's length() would count nodes, which differs only in weighting diagonal steps 1.
Exit points (§4.5, Fig 4.7): runs ("free-space clusters") of free cells along a local map's sides; a run of at
least 2 r + 1 cells (r the robot radius in cells: "wider than the robot's diameter") gives exit points at each end,
r cells in from it, and at its centre, duplicates dropped. They are ranked by
  (4.15) Utility_EP = k3 Dist_EP-Goal + k4 Dist_EP-Par, ascending (smallest first).
Choices where the thesis is silent, all [RECON]:
  - exit points are taken only on sides that border another local map, and not on the side shared with the map
    the search comes from (an exit back into it, or into the global boundary, leads nowhere);
  - when the merged map holds the final goal, the goal itself is tried first, then the exit points;
  - eviction removes the held local map with the highest f' (maps never given an f' count as infinitely costly;
    ties go to the highest index); the current map's data stays available in the merged-map memory;
  - with no path, the result is the partial path, over all backtracks, that ends closest to the goal;
  - a neighbour's g' is updated only when the new path is cheaper, as in A*;
  - backtracking (Fig 4.8) forgets the costs and paths of the maps it takes off CLOSED, so that they can be
    reached again by another route;
  - when the start and goal share a local map, that map is searched alone first.
Communication (§4.6.3): only transmission delay counts, at an effective 5.5 Mbit/s.
"""
from __future__ import annotations

import heapq
import math
import time
from dataclasses import dataclass, field

import numpy as np

from teamsim.controllers.navigation.astar import PlannerParams, modified_astar

EFFECTIVE_LINK_RATE = 5.5e6  # bit/s: a worker's 802.11b at 11 Mbit/s, halved (§4.6.3)


def local_map_memory(total_bytes: float, memories: int) -> float:
    """(4.2) Mem_LMapMax: Q memories for fetched maps plus two for the merged map."""
    return total_bytes / (memories + 2)


def local_map_node_budget(memory_bytes: float, bytes_per_node: int) -> int:
    """(4.3) Nodes_LMapMax."""
    return int(memory_bytes // bytes_per_node)


def transmission_time(bytes_received: float, link_rate: float = EFFECTIVE_LINK_RATE) -> float:
    """Seconds to receive map data: transmission delay only (§4.6.3)."""
    return bytes_received * 8.0 / link_rate


@dataclass(frozen=True)
class Partition:
    """Local maps of a global grid (Fig 4.2): 1-based indices, row-major, dimensions in the thesis's 1-based
    inclusive form [rowmin rowmax colmin colmax], and four-connected neighbours in ascending index order."""
    row_col: int  # RowCol_LMap
    rows_p: int  # Rows_P, partitions down the global map
    cols_p: int  # Cols_P, partitions across
    dims: dict[int, tuple[int, int, int, int]]
    neighbours: dict[int, tuple[int, ...]]

    def index_of(self, row: int, col: int) -> int:
        """Local map holding the global cell (row, col), 0-based."""
        return (row // self.row_col) * self.cols_p + col // self.row_col + 1

    def slices(self, index: int) -> tuple[slice, slice]:
        """0-based slices of the global map covered by a local map."""
        rmin, rmax, cmin, cmax = self.dims[index]
        return slice(rmin - 1, rmax), slice(cmin - 1, cmax)

    def nodes(self, index: int) -> int:
        rmin, rmax, cmin, cmax = self.dims[index]
        return (rmax - rmin + 1) * (cmax - cmin + 1)


def partition_global_map(rows_gmap: int, cols_gmap: int, nodes_lmap_max: int) -> Partition:
    """Fig 4.2: square local maps of floor(sqrt(Nodes_LMapMax)) nodes a side, the last row and column of them cut
    short by the global map's edge."""
    row_col = math.isqrt(nodes_lmap_max)
    rows_p, cols_p = math.ceil(rows_gmap / row_col), math.ceil(cols_gmap / row_col)
    dims, neighbours = {}, {}
    index = 1
    for row_p in range(rows_p):
        for col_p in range(cols_p):
            dims[index] = (row_p * row_col + 1, min((row_p + 1) * row_col, rows_gmap),
                           col_p * row_col + 1, min((col_p + 1) * row_col, cols_gmap))
            around = []
            if row_p > 0:
                around.append(index - cols_p)
            if col_p > 0:
                around.append(index - 1)
            if col_p < cols_p - 1:
                around.append(index + 1)
            if row_p < rows_p - 1:
                around.append(index + cols_p)
            neighbours[index] = tuple(around)
            index += 1
    return Partition(row_col, rows_p, cols_p, dims, neighbours)


def free_clusters(free: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) positions of each run of True in a 1-D boolean array."""
    padded = np.concatenate([[False], np.asarray(free, bool), [False]]).astype(np.int8)
    edges = np.diff(padded)
    return list(zip(np.flatnonzero(edges == 1).tolist(), (np.flatnonzero(edges == -1) - 1).tolist()))


def cluster_exit_points(first: int, last: int, radius_cells: int) -> tuple[int, ...]:
    """Exit points of one free-space cluster (Fig 4.7): none if it is narrower than 2 r + 1 cells, else its two
    ends, r cells in, and its centre, without duplicates."""
    if last - first + 1 < 2 * radius_cells + 1:
        return ()
    return tuple(sorted({first + radius_cells, (first + last) // 2, last - radius_cells}))


def _side_cells(partition: Partition, index: int, side: str) -> tuple[np.ndarray, np.ndarray]:
    """Global 0-based (rows, cols) of one side ("top" is the local map's first row, rowmin; "bottom", "left",
    "right") of a local map, in order along it."""
    rows, cols = partition.slices(index)
    along_rows = np.arange(rows.start, rows.stop)
    along_cols = np.arange(cols.start, cols.stop)
    if side == "top":
        return np.full_like(along_cols, rows.start), along_cols
    if side == "bottom":
        return np.full_like(along_cols, rows.stop - 1), along_cols
    if side == "left":
        return along_rows, np.full_like(along_rows, cols.start)
    return along_rows, np.full_like(along_rows, cols.stop - 1)


def _side_towards(partition: Partition, index: int, other: int) -> str:
    """The side of local map ``index`` that borders its neighbour ``other``."""
    if other == index - partition.cols_p:
        return "top"
    if other == index + partition.cols_p:
        return "bottom"
    return "left" if other == index - 1 else "right"


def exit_points(partition: Partition, index: int, local: np.ndarray, occupied_threshold: float,
                radius_cells: int, exclude_towards: int | None = None) -> list[tuple[int, int]]:
    """Global (row, col) exit points on the sides of local map ``index`` that border other local maps, except the
    side towards ``exclude_towards``. ``local`` is the local map's data (fetched from the manager)."""
    rows, cols = partition.slices(index)
    points = []
    for nb in partition.neighbours[index]:
        if nb == exclude_towards:
            continue
        side_rows, side_cols = _side_cells(partition, index, _side_towards(partition, index, nb))
        free = local[side_rows - rows.start, side_cols - cols.start] < occupied_threshold
        for first, last in free_clusters(free):
            points += [(int(side_rows[k]), int(side_cols[k])) for k in cluster_exit_points(first, last, radius_cells)]
    return points


def rank_exit_points(points: list[tuple[int, int]], goal: tuple[int, int], parent_end: tuple[int, int],
                     k3: float, k4: float) -> list[tuple[int, int]]:
    """(4.15), ascending utility; a stable sort keeps scan order on ties."""
    def utility(point):
        return k3 * math.dist(point, goal) + k4 * math.dist(point, parent_end)
    return sorted(points, key=utility)


def boundary_is_safe(partition: Partition, index: int, local: np.ndarray, other: int, other_local: np.ndarray,
                     occupied_threshold: float, radius_cells: int) -> bool:
    """§4.5: the border lines of two neighbouring local maps have a passage, free on both sides, wider than the
    robot's diameter (2 r + 1 cells or more)."""
    rows, cols = partition.slices(index)
    o_rows, o_cols = partition.slices(other)
    r, c = _side_cells(partition, index, _side_towards(partition, index, other))
    o_r, o_c = _side_cells(partition, other, _side_towards(partition, other, index))
    free = ((local[r - rows.start, c - cols.start] < occupied_threshold)
            & (other_local[o_r - o_rows.start, o_c - o_cols.start] < occupied_threshold))
    return any(last - first + 1 >= 2 * radius_cells + 1 for first, last in free_clusters(free))


@dataclass(frozen=True)
class TwoTierParams:
    memories: int = 1  # Q, local-map memories (§4.2); §4.6 tests 1, 5 and 15
    bytes_per_node: int = 8  # Mem_MNode: doubles, as in §4.6
    cost_method: int = 1  # 1: (4.10), path length; 2: (4.11), path cost. §4.6.2 recommends method 1
    radius_cells: int = 2  # robot radius in nodes: §4.6's 15 cm worker on a 10 cm grid, rounded up
    k3: float = 0.5  # (4.15) weight of an exit point's distance to the final goal
    k4: float = 0.5  # (4.15) weight of its distance from the end of the parent's path
    link_rate: float = EFFECTIVE_LINK_RATE  # bit/s (§4.6.3)
    lower_level: PlannerParams = PlannerParams()  # (4.6)-(4.9): w_p1 = w_p2 = 0 and Manhattan are its defaults


@dataclass(frozen=True)
class TwoTierResult:
    cells: np.ndarray  # (n, 2) global (row, col) from the start; partial if not ``reached``
    reached: bool
    local_maps: tuple[int, ...]  # the chain of local maps the path runs through
    bytes_fetched: int  # map data received from the manager
    fetches: int
    backtracks: int
    planning_time: float  # s, measured
    transmission_time: float  # s, of bytes_fetched at the link rate
    expansions: int  # nodes the lower level took off its open lists, over every local plan: planning work
    # that the machine's load does not change

    @property
    def overall_time(self) -> float:
        return self.planning_time + self.transmission_time

    @property
    def length(self) -> float:
        return float(np.hypot(*np.diff(self.cells, axis=0).T).sum()) if len(self.cells) > 1 else 0.0


@dataclass
class _MapMemories:
    """The worker's Q local-map memories, filled from the manager's global map."""
    global_map: np.ndarray
    partition: Partition
    capacity: int
    bytes_per_node: int
    held: dict = field(default_factory=dict)
    bytes_fetched: int = 0
    fetches: int = 0

    def get(self, index: int, costs: dict) -> np.ndarray:
        if index not in self.held:
            if len(self.held) >= self.capacity:
                costliest = max(self.held, key=lambda k: (costs.get(k, math.inf), k))
                del self.held[costliest]
            self.held[index] = self.global_map[self.partition.slices(index)].copy()
            self.bytes_fetched += self.held[index].size * self.bytes_per_node
            self.fetches += 1
        return self.held[index]


def _merge(partition: Partition, index: int, local: np.ndarray, other: int,
           other_local: np.ndarray) -> tuple[np.ndarray, tuple[int, int]]:
    """The merged local map of two neighbours and the global (row, col) of its first cell."""
    side = _side_towards(partition, index, other)
    first, second = (local, other_local) if side in ("bottom", "right") else (other_local, local)
    merged = np.concatenate([first, second], axis=0 if side in ("top", "bottom") else 1)
    rows, cols = partition.slices(index if side in ("bottom", "right") else other)
    return merged, (rows.start, cols.start)


def two_tier_astar(global_map: np.ndarray, start: tuple[int, int], goal: tuple[int, int], partition: Partition,
                   params: TwoTierParams = TwoTierParams()) -> TwoTierResult:
    """Plan from ``start`` to ``goal`` (global 0-based (row, col)) over the manager's ``global_map`` of occupancy
    probabilities, reading it only a local map at a time (Fig 4.6, with backtracking as in Fig 4.8)."""
    began = time.perf_counter()
    start, goal = (int(start[0]), int(start[1])), (int(goal[0]), int(goal[1]))
    threshold = params.lower_level.occupied_threshold
    memories = _MapMemories(global_map, partition, params.memories, params.bytes_per_node)
    first, final = partition.index_of(*start), partition.index_of(*goal)
    neighbours = {k: list(v) for k, v in partition.neighbours.items()}  # backtracking removes links

    def h(cell):  # (4.12)
        return math.dist(cell, goal)

    g = {first: 0.0}
    f = {first: h(start)}
    parent = {first: None}
    paths = {first: np.array([start])}
    open_heap = [(f[first], first)]
    closed: set[int] = set()
    found = None
    backtracks = 0
    best_partial = paths[first]
    expansions = 0

    if first == final:
        rows, cols = partition.slices(first)
        local = memories.get(first, f)
        result = modified_astar(local, (start[0] - rows.start, start[1] - cols.start),
                                (goal[0] - rows.start, goal[1] - cols.start), params.lower_level)
        expansions += result.expanded
        if result.reached:
            paths[first] = result.cells + (rows.start, cols.start)
            found = first

    while found is None:
        if not open_heap:
            # Fig 4.8: keep the partial path ending closest to the goal, and search again around its last map.
            best = min(paths, key=lambda k: (h(tuple(paths[k][-1])), k))
            chain = _chain(parent, best)
            partial = _concatenate(paths, chain)
            if h(tuple(partial[-1])) < h(tuple(best_partial[-1])):
                best_partial = partial
            for index in closed - set(chain):
                _forget(index, g, f, parent, paths)
            closed &= set(chain)
            above = parent[best]
            if above is None:
                break  # backtracked to the very first local map: there is no path
            backtracks += 1
            neighbours[above].remove(best)
            closed.discard(above)
            closed.discard(best)
            _forget(best, g, f, parent, paths)
            heapq.heappush(open_heap, (f[above], above))
            continue
        f_popped, current = heapq.heappop(open_heap)
        if current in closed or f_popped != f.get(current):
            continue  # an outdated entry: the map was re-costed or closed since
        closed.add(current)
        current_local = memories.get(current, f)
        current_end = tuple(int(v) for v in paths[current][-1])
        for nb in neighbours[current]:
            if nb in closed:
                continue
            nb_local = memories.get(nb, f)
            targets = rank_exit_points(
                exit_points(partition, nb, nb_local, threshold, params.radius_cells, exclude_towards=current),
                goal, current_end, params.k3, params.k4)
            if final in (current, nb):
                targets = [goal] + targets
            if not targets or not boundary_is_safe(partition, current, current_local, nb, nb_local, threshold,
                                                   params.radius_cells):
                continue
            merged, origin = _merge(partition, current, current_local, nb, nb_local)
            local_start = (current_end[0] - origin[0], current_end[1] - origin[1])
            for target in targets:
                result = modified_astar(merged, local_start, (target[0] - origin[0], target[1] - origin[1]),
                                        params.lower_level)
                expansions += result.expanded
                if result.reached:
                    break
            else:
                continue
            step_cost = result.length if params.cost_method == 1 else result.cost
            g_new = g[current] + step_cost
            if g_new < g.get(nb, math.inf):
                path = result.cells + origin
                g[nb], f[nb], parent[nb], paths[nb] = g_new, g_new + h(tuple(path[-1])), current, path
                heapq.heappush(open_heap, (f[nb], nb))
                if tuple(path[-1]) == goal:
                    found = nb
                    break

    if found is not None:
        chain = _chain(parent, found)
        cells = _concatenate(paths, chain)
    else:
        chain = ()
        cells = best_partial
    bytes_fetched = memories.bytes_fetched
    return TwoTierResult(cells, found is not None, tuple(chain), bytes_fetched, memories.fetches, backtracks,
                         time.perf_counter() - began, transmission_time(bytes_fetched, params.link_rate), expansions)


def _chain(parent: dict, index: int) -> list[int]:
    """Local maps from the first to ``index``."""
    chain = []
    while index is not None:
        chain.append(index)
        index = parent[index]
    return chain[::-1]


def _forget(index: int, *tables: dict) -> None:
    for table in tables:
        table.pop(index, None)


def _concatenate(paths: dict, chain: list[int]) -> np.ndarray:
    """The per-local-map paths joined end to start, the shared node kept once (§4.5)."""
    parts = [paths[chain[0]]]
    for index in chain[1:]:
        part = paths[index]
        parts.append(part[1:] if np.array_equal(part[0], parts[-1][-1]) else part)
    return np.concatenate(parts)
