"""The *clean-floor* behaviour set (Parker §6.2.1, Fig. 6-10): circle the room to learn its size, then clean a quadrant.

The room is rectangular and of unknown size. A robot that does not yet know it follows the walls round (wall on
the right, cleaning as it goes) and takes the extremes of its own positions as the reachable rectangle. That
rectangle is laid with a coarse grid of cleaner-wide cells, each unvisited, visited or inaccessible, and split into
four quadrants. A quadrant is cleaned by Parker's rule, verbatim (:func:`next_cell`): turn right if the cell on
the right is unvisited, else go straight if the cell in front is, else left if the left one is, else head for the
nearest unvisited, unoccupied cell, and if there is none the quadrant is complete. The robot marks its own cell
visited and, from its lower IR ring or a cell it cannot reach in time, a cell inaccessible. The coarse grid and
the rule give the thesis's "snaking" coverage.
"""
from __future__ import annotations

import math
import heapq
from dataclasses import dataclass, replace

import numpy as np

from teamsim.controllers.base import Command, Observation
from teamsim.controllers.skills.follow_surface import FollowParams, FollowRight
from teamsim.controllers.skills.goto import AvoidObstacles, DriveParams, steer_to, turn_to
from teamsim.positioning import wrap_angle

QUADRANTS = ("lower-left", "lower-right", "upper-left", "upper-right")
UNVISITED, VISITED, BLOCKED = 0, 1, 2
BLOCKED_COST = 25.0  # steps a planned path pays to cross a cell marked inaccessible
HEADINGS = ((1, 0), (0, 1), (-1, 0), (0, -1))  # east, north, west, south: index + 1 turns left


@dataclass(frozen=True)
class FloorParams:
    cell: float = 0.3  # m: the grid's cell, 3/4 of the cleaner's width (neighbouring legs overlap; positions are noisy)
    leave: float = 2.0  # m: the perimeter circuit ends back within ``home`` of its start after driving this far
    home: float = 0.5
    home_stall: float = 30.0  # s: the way back to the start that gets no ``headway`` nearer in this long is blocked
    headway: float = 0.1  # m
    least_perimeter: float = 8.0  # m: no room is smaller round than this (a janitor needs a room 2 m across),
    wall_range: float = 0.8  # m from the rim: readings this near, round the circuit, find the walls
    least_side: float = 2.0  # m: nor are the extents of the robot's centre going round it (a pocket among obstacles)
    side_share: float = 0.5  # a circuit has driven along this share of each side of its room
    loops: int = 3  # closed loops that missed a side before the widest of them counts as the room
    arrive: float = 0.2  # m: a cell is reached (and visited) when its centre is this near
    cell_timeout: float = 8.0  # s (and timeout_per_metre of its distance) to reach a cell before it counts as
    timeout_per_metre: float = 8.0  # inaccessible
    bump: float = 0.08  # m from the rim: something this near ahead ends the way to the current target
    sense_range: float = 0.3  # m from the rim: lower-ring readings nearer than this mark the cell they end in
    follow: FollowParams = FollowParams(gap=0.1, speed=0.25)
    drive: DriveParams = DriveParams(cruise=0.3, turn_rate=1.0, slow_radius=0.05, turn_in_place=0.6)


class CoverageGrid:
    """The coarse grid over the reachable rectangle (xmin, xmax, ymin, ymax) of robot centres."""

    def __init__(self, bounds: tuple[float, float, float, float], cell: float):
        xmin, xmax, ymin, ymax = bounds
        self.shape = (max(1, round((xmax - xmin) / cell) + 1), max(1, round((ymax - ymin) / cell) + 1))
        self.origin = np.array([xmin, ymin])
        self.step = np.array([(xmax - xmin) / max(self.shape[0] - 1, 1), (ymax - ymin) / max(self.shape[1] - 1, 1)])
        self.state = np.full(self.shape, UNVISITED, np.int8)

    def centre(self, cell: tuple[int, int]) -> np.ndarray:
        return self.origin + self.step * np.asarray(cell)

    def cell_of(self, x: float, y: float) -> tuple[int, int]:
        i, j = np.round((np.array([x, y]) - self.origin) / np.maximum(self.step, 1e-9)).astype(int)
        return int(np.clip(i, 0, self.shape[0] - 1)), int(np.clip(j, 0, self.shape[1] - 1))

    def quadrant(self, name: str) -> np.ndarray:
        """Mask of the cells of quadrant ``name`` (the grid split at its middle; the middle row and column go
        to the lower and left quadrants)."""
        nx, ny = self.shape
        i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij")
        left, lower = i < (nx + 1) // 2, j < (ny + 1) // 2
        return {"lower-left": left & lower, "lower-right": ~left & lower, "upper-left": left & ~lower,
                "upper-right": ~left & ~lower}[name]

    def inside(self, cell: tuple[int, int]) -> bool:
        return 0 <= cell[0] < self.shape[0] and 0 <= cell[1] < self.shape[1]


def next_cell(grid: CoverageGrid, region: np.ndarray, cell: tuple[int, int], heading: int) -> tuple[int, int] | None:
    """Parker's coverage rule (§6.2.1): the next cell to go to from ``cell`` facing ``heading`` (index into
    :data:`HEADINGS`), or None when no unvisited, unoccupied cell of ``region`` can be reached."""
    def open_(c):
        return grid.inside(c) and region[c] and grid.state[c] == UNVISITED

    for turn in (-1, 0, 1):  # right, straight, left
        dx, dy = HEADINGS[(heading + turn) % 4]
        neighbour = (cell[0] + dx, cell[1] + dy)
        if open_(neighbour):
            return neighbour
    return nearest_unvisited(grid, region, cell)


def nearest_unvisited(grid: CoverageGrid, region: np.ndarray, start: tuple[int, int]) -> tuple[int, int] | None:
    """The unvisited cell of ``region`` nearest ``start`` in a straight line (the robot heads for it; a cell it
    cannot reach in time is then marked inaccessible), or None."""
    cells = np.argwhere(region & (grid.state == UNVISITED))
    if len(cells) == 0:
        return None
    k = int(np.argmin(np.hypot(*(cells - np.asarray(start)).T)))
    return int(cells[k][0]), int(cells[k][1])


def shortest_path(grid: CoverageGrid, start: tuple[int, int], goal: tuple[int, int]) -> list:
    """Cells from next to ``start`` to ``goal`` (4-connected, Dijkstra): a step into a cell known to be inaccessible
    costs ``BLOCKED_COST`` steps, so a way round is taken where there is one, and a robot hemmed in by marks (a
    teammate standing by it, a reading from a wall) can still get out. ``[goal]`` when it is in ``goal``'s cell."""
    cost = {start: 0.0}
    previous = {start: None}
    heap = [(0.0, start)]
    while heap:
        d, c = heapq.heappop(heap)
        if c == goal:
            break
        if d > cost[c]:
            continue
        for dx, dy in HEADINGS:
            n = (c[0] + dx, c[1] + dy)
            if not grid.inside(n):
                continue
            step = BLOCKED_COST if grid.state[n] == BLOCKED and n != goal else 1.0
            if d + step < cost.get(n, math.inf):
                cost[n], previous[n] = d + step, c
                heapq.heappush(heap, (d + step, n))
    path, c = [], goal
    while c != start:
        path.append(c)
        c = previous[c]
    return path[::-1] or [goal]


class CleanFloor:
    """The behaviour set's competences: perimeter circuit (once), then the coverage of the quadrant it is given.
    ``bounds`` persists between activations; ``completed`` names the quadrants this robot finished."""

    def __init__(self, bearings: np.ndarray, low_ring: np.ndarray, rim: float, rng: np.random.Generator,
                 params: FloorParams = FloorParams()):
        self.params = params
        front = np.abs(np.angle(np.exp(1j * np.asarray(bearings)))) < math.radians(50)
        # Avoid-obstacles on what is ahead only: cells along a wall put the side sensors that near it.
        self._avoid = AvoidObstacles((), bearings, (), rng, replace(params.drive, avoid_range=params.bump))
        self.ahead = front
        self.rim = rim  # m from the centre to the ring
        self.low = low_ring  # indices of the lower ring in the observation's IR arrays
        self.low_bearings = np.asarray(bearings)[low_ring]
        self.follow = FollowRight(self.low_bearings, params.follow)
        self.bounds: tuple[float, float, float, float] | None = None
        self.grid: CoverageGrid | None = None
        self.quadrant: str | None = None
        self.completed: list[str] = []
        self.verified: list[str] = []  # quadrants it covered again to verify them
        self._verifying = False
        self._circuit_start: np.ndarray | None = None
        self._extents: np.ndarray | None = None
        self._path = 0.0  # m driven since the circuit began
        self._turned = 0.0  # rad turned since the circuit began (left positive)
        self._last_heading = 0.0
        self._last_position = np.zeros(2)
        self._away: float | None = None  # heading to leave a circled obstacle on, or to face the first wall
        self.home: np.ndarray | None = None  # the robot's start pose (set on its first step if not given)
        self._homed = False
        self._nearest_home: float | None = None  # m: the nearest the way back to the start has come (this activation)
        self._headway_at = 0.0  # s: when it last came ``headway`` nearer
        self._wall_hits: list[np.ndarray] = []
        self._track: list[np.ndarray] = []  # the robot's positions round the circuit
        self._short_loops: list[tuple[float, float, float, float]] = []  # rooms of loops that missed a side
        self._target: tuple[int, int] | None = None
        self._deadline = 0.0  # a target not reached by then is inaccessible
        self._route: list = []  # cells to the target

    @property
    def finding_dimensions(self) -> bool:
        return self.bounds is None

    def start(self, quadrant: str, time: float, verify: bool = False) -> None:
        """Clean ``quadrant``; ``verify``: again, every cell of it unvisited (and unmarked) once more."""
        self.quadrant, self._target, self._verifying = quadrant, None, verify
        self._nearest_home = None  # (the way back is timed while this behaviour runs)
        if verify and self.grid is not None:
            self.grid.state[self.grid.quadrant(quadrant)] = UNVISITED

    def __call__(self, obs: Observation, pose: np.ndarray) -> Command:
        if self.bounds is None:
            return self._circuit(obs, pose)
        return self._cover(obs, pose)

    # -- the perimeter circuit ---------------------------------------------------------------------------------
    def _circuit(self, obs: Observation, pose: np.ndarray) -> Command:
        """Back to the start (the robots start beside a wall, on their left, as Parker's start in a corner), straight
        to that wall, then follow it round with it on the right. A loop that turned left in all went round the
        room: it ends back where it began, or once past a fifth corner (a circuit begun on an obstacle off the
        wall never comes back to its start), and counts (:meth:`_loop_room`) if it has driven along the four
        sides of its rectangle (a U-turn at a teammate by the wall turns as far as two corners; a loop begun
        mid-room can cut through the obstacles), is room-sized and holds the start (a pocket among obstacles
        does not). One that turned right (by 1.5 pi) went
        round an obstacle, which the robot leaves, turning left, to find a wall. A way back to the start that gets
        no nearer it for ``home_stall`` is blocked, and the circuit begins at what is in the way."""
        p = self.params
        ranges = obs.ir_range[self.low]
        if self.home is None:
            self.home = pose.copy()
        if not self._homed and self._blocked_home(obs.time, pose):
            # Something stands between the robot and its start and avoid-obstacles only rocks it there: the circuit
            # begins at what is in the way (docs/decisions.md, janitorial, "The way back to the start").
            self._homed, self._away = True, None
        if not self._homed:  # back to the start, beside a wall, and face that wall (on the left at the start)
            detour = self.avoid(obs)
            if detour is not None:
                return self._clean(*detour)
            move = steer_to(pose, self.home[:2], p.drive, p.home)
            if move is not None:
                return self._clean(*move)
            self._homed, self._away = True, wrap_angle(self.home[2] + math.pi / 2)
        if self._circuit_start is None:
            if self._away is not None:  # turn away from the obstacle just circled, to the left
                omega = turn_to(pose, self._away, p.drive, tolerance=0.15)
                if omega is not None:
                    return self._clean(0.0, omega)
                self._away = None
            if ranges[self.follow.front].min(initial=math.inf) >= p.follow.ahead + 0.05:
                return self._clean(p.follow.speed, 0.0)
            self._circuit_start, self._extents = pose[:2].copy(), np.array([pose[0], pose[0], pose[1], pose[1]])
            self._wall_hits, self._track = [], []
            self._path, self._turned, self._last_heading, self._last_position = 0.0, 0.0, pose[2], pose[:2].copy()
        x, y = pose[:2]
        e = self._extents
        self._extents = np.array([min(e[0], x), max(e[1], x), min(e[2], y), max(e[3], y)])
        self._wall_hits.append(self._hits(ranges, pose, p.wall_range))
        self._track.append(pose[:2].copy())
        self._turned += wrap_angle(pose[2] - self._last_heading)
        self._last_heading = pose[2]
        self._path += float(np.hypot(*(pose[:2] - self._last_position)))
        self._last_position = pose[:2].copy()
        gone = float(np.hypot(*(pose[:2] - self._circuit_start)))
        closed = self._path > p.leave and gone < p.home
        round_room = self._turned > 2.5 * math.pi and self._path > p.least_perimeter \
            and (self._went_round(self._room_bounds())  # (not spinning on the spot, nor turning back at a teammate)
                 or self._turned > 6.5 * math.pi)  # three laps: what kept it off a side is there for good
        if self._turned < -1.5 * math.pi or round_room or closed:
            bounds = self._loop_room(checked=round_room)
            if bounds is not None:
                self.bounds = bounds
                self.grid = CoverageGrid(self.bounds, p.cell)
            else:
                self._away = wrap_angle(pose[2] + math.pi / 2)
            self._circuit_start = None
            return self._clean(0.0, 0.0)
        return self._clean(*self.follow(ranges))

    def _loop_room(self, checked: bool) -> tuple[float, float, float, float] | None:
        """The room the loop just ended went round, or None if it is not one. ``checked``: it was ended by its turning
        and has already been judged to have driven along every side. A loop back at its start that missed a side
        went through the obstacles (r2, seed 244: begun at a can mid-room, it cut past the obstacles and
        took the room without its east strip for the room): the robot leaves it for a wall, and only after
        ``loops`` such loops takes the widest of them (docs/decisions.md, janitorial, the perimeter circuit)."""
        p, e = self.params, self._extents
        bounds = self._room_bounds()
        inside = bounds[0] - p.home <= self.home[0] <= bounds[1] + p.home and \
            bounds[2] - p.home <= self.home[1] <= bounds[3] + p.home  # the room holds the start
        if not (self._turned > math.pi and min(e[1] - e[0], e[3] - e[2]) > p.least_side and inside):
            return None
        if checked or self._went_round(bounds):
            return bounds
        self._short_loops.append(bounds)
        if len(self._short_loops) < p.loops:
            return None
        return max(self._short_loops, key=lambda b: (b[1] - b[0]) * (b[3] - b[2]))

    def _blocked_home(self, time: float, pose: np.ndarray) -> bool:
        """Whether the way back to the start has come no ``headway`` nearer it for ``home_stall`` s."""
        p = self.params
        gone = float(np.hypot(*(pose[:2] - self.home[:2])))
        if self._nearest_home is None or gone < self._nearest_home - p.headway:
            self._nearest_home, self._headway_at = gone, time
        return time - self._headway_at > p.home_stall

    def _went_round(self, bounds: tuple[float, float, float, float]) -> bool:
        """Whether the circuit drove along every side of ``bounds``: for each, ``side_share`` of its cell-long
        stretches hold a position within ``home`` of it. Left turns alone are no proof: a U-turn where a teammate
        stood by the wall counts as two corners (r2, seed 228: a circuit of the room's lower half, 2.5 pi
        turned, was taken for the room and its upper quadrants, the middle of the room, cleaned in a minute)."""
        p, track = self.params, np.asarray(self._track)
        x0, x1, y0, y1 = bounds
        for line, across, lo, hi in ((y0, 1, x0, x1), (y1, 1, x0, x1), (x0, 0, y0, y1), (x1, 0, y0, y1)):
            along = track[np.abs(track[:, across] - line) < p.home, 1 - across]
            n = max(1, round((hi - lo) / p.cell))
            stretches = np.unique(np.clip(((along - lo) / max(hi - lo, 1e-9) * n).astype(int), 0, n - 1))
            if len(stretches) < p.side_share * n:
                return False
        return True

    def _room_bounds(self) -> tuple[float, float, float, float]:
        """Where the robot's centre can go: the walls, as the extremes (1st and 99th percentiles, against IR noise)
        of the lower ring's near readings round the circuit, less the rim and the following gap. The robot's own
        extremes fall short of a wall wherever it went round a teammate in its way."""
        hits = np.concatenate(self._wall_hits)
        (x0, y0), (x1, y1) = np.percentile(hits, 1, axis=0), np.percentile(hits, 99, axis=0)
        inset = self.rim + self.params.follow.gap
        return (float(x0 + inset), float(x1 - inset), float(y0 + inset), float(y1 - inset))

    def _hits(self, ranges: np.ndarray, pose: np.ndarray, within: float) -> np.ndarray:
        """World points where the lower ring's readings nearer than ``within`` end."""
        near = ranges < within
        bearings = pose[2] + self.low_bearings[near]
        reach = self.rim + ranges[near]
        return pose[:2] + reach[:, None] * np.stack([np.cos(bearings), np.sin(bearings)], axis=1)

    # -- quadrant coverage ---------------------------------------------------------------------------------------
    def _cover(self, obs: Observation, pose: np.ndarray) -> Command:
        """The next cell by the coverage rule, reached along a shortest path round the cells known inaccessible
        (replanned when one on it turns out to be); a cell not reached in time, or bumped into next door, is
        inaccessible."""
        p, grid = self.params, self.grid
        self._mark_obstacles(obs, pose)
        here = grid.cell_of(*pose[:2])
        if np.hypot(*(grid.centre(here) - pose[:2])) < p.arrive:
            grid.state[here] = VISITED
        if self._target is not None and (grid.state[self._target] != UNVISITED or obs.time > self._deadline):
            if grid.state[self._target] == UNVISITED:
                grid.state[self._target] = BLOCKED  # not reached in time
            self._target = None
        if self._target is None:
            heading = round(pose[2] / (math.pi / 2)) % 4  # the grid direction the robot faces
            self._target = next_cell(grid, grid.quadrant(self.quadrant), here, heading)
            if self._target is None:
                (self.verified if self._verifying else self.completed).append(self.quadrant)
                return self._clean(0.0, 0.0)
            self._route = shortest_path(grid, here, self._target)
            self._deadline = obs.time + p.cell_timeout + p.timeout_per_metre * grid.step.mean() * len(self._route)
        if any(grid.state[c] == BLOCKED for c in self._route[1:]):  # (the next step may be the way out)
            self._route = shortest_path(grid, here, self._target)
        while len(self._route) > 1 and np.hypot(*(grid.centre(self._route[0]) - pose[:2])) < p.arrive:
            self._route.pop(0)
        waypoint = self._route[0]
        detour = self.avoid(obs)
        if detour is not None:  # something in the way: the cell next door is out, a far one is gone round
            if np.hypot(*(grid.centre(waypoint) - pose[:2])) < 1.5 * grid.step.max():
                grid.state[waypoint] = BLOCKED
            return self._clean(*detour)
        v, omega = steer_to(pose, grid.centre(waypoint), p.drive, 0.0) or (0.0, 0.0)
        return self._clean(max(v, 0.1) if abs(omega) < 0.5 else v, omega)  # no creeping up on a cell centre

    def avoid(self, obs: Observation) -> tuple[float, float] | None:
        """Avoid-obstacles (:class:`AvoidObstacles`) on what is ahead only: along a wall the side sensors are that
        near it all the time."""
        return self._avoid(replace(obs, ir_range=np.where(self.ahead, obs.ir_range, np.inf)))

    def _mark_obstacles(self, obs: Observation, pose: np.ndarray) -> None:
        """Cells (not yet visited) where the robot would not fit, from the lower ring: those whose centre lies
        within the robot's radius of a reading nearer than ``sense_range``."""
        grid = self.grid
        for hit in self._hits(obs.ir_range[self.low], pose, self.params.sense_range):
            lo = np.floor((hit - self.rim - grid.origin) / np.maximum(grid.step, 1e-9)).astype(int)
            for i in range(max(lo[0], 0), min(lo[0] + 3, grid.shape[0])):
                for j in range(max(lo[1], 0), min(lo[1] + 3, grid.shape[1])):
                    if grid.state[i, j] == UNVISITED and np.hypot(*(grid.centre((i, j)) - hit)) < self.rim:
                        grid.state[i, j] = BLOCKED

    @staticmethod
    def _clean(v: float, omega: float) -> Command:
        return Command(v=v, omega=omega, extras={"cleaner": 1.0})
