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
from dataclasses import dataclass

import numpy as np

from teamsim.controllers.base import Command, Observation
from teamsim.controllers.skills.follow_surface import FollowParams, FollowRight
from teamsim.controllers.skills.goto import DriveParams, steer_to, turn_to
from teamsim.positioning import wrap_angle

QUADRANTS = ("lower-left", "lower-right", "upper-left", "upper-right")
UNVISITED, VISITED, BLOCKED = 0, 1, 2
HEADINGS = ((1, 0), (0, 1), (-1, 0), (0, -1))  # east, north, west, south: index + 1 turns left


@dataclass(frozen=True)
class FloorParams:
    cell: float = 0.4  # m: the grid's cell, the cleaner's width
    leave: float = 2.0  # m: the perimeter circuit ends back within ``home`` of its start after driving this far
    home: float = 0.5
    arrive: float = 0.2  # m: a cell is reached (and visited) when its centre is this near
    cell_timeout: float = 10.0  # s to reach the next cell before it counts as inaccessible
    bump: float = 0.08  # m from the rim: something this near ahead ends the way to the current target
    sense_range: float = 0.3  # m from the rim: lower-ring readings nearer than this mark the cell they end in
    follow: FollowParams = FollowParams(gap=0.1, speed=0.25)
    drive: DriveParams = DriveParams(cruise=0.3, turn_rate=1.0, slow_radius=0.3)


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


class CleanFloor:
    """The behaviour set's competences: perimeter circuit (once), then the coverage of the quadrant it is given.
    ``bounds`` persists between activations; ``completed`` names the quadrants this robot finished."""

    def __init__(self, bearings: np.ndarray, low_ring: np.ndarray, rim: float, params: FloorParams = FloorParams()):
        self.params = params
        self.rim = rim  # m from the centre to the ring
        self.low = low_ring  # indices of the lower ring in the observation's IR arrays
        self.low_bearings = np.asarray(bearings)[low_ring]
        self.follow = FollowRight(self.low_bearings, params.follow)
        self.bounds: tuple[float, float, float, float] | None = None
        self.grid: CoverageGrid | None = None
        self.quadrant: str | None = None
        self.completed: list[str] = []
        self._circuit_start: np.ndarray | None = None
        self._extents: np.ndarray | None = None
        self._path = 0.0  # m driven since the circuit began
        self._turned = 0.0  # rad turned since the circuit began (left positive)
        self._last_heading = 0.0
        self._last_position = np.zeros(2)
        self._away: float | None = None  # heading to leave a circled obstacle on
        self._target: tuple[int, int] | None = None
        self._target_since = 0.0

    @property
    def finding_dimensions(self) -> bool:
        return self.bounds is None

    def start(self, quadrant: str, time: float) -> None:
        self.quadrant, self._target = quadrant, None

    def __call__(self, obs: Observation, pose: np.ndarray) -> Command:
        if self.bounds is None:
            return self._circuit(obs, pose)
        return self._cover(obs, pose)

    # -- the perimeter circuit ---------------------------------------------------------------------------------
    def _circuit(self, obs: Observation, pose: np.ndarray) -> Command:
        """Straight on to the first surface, then follow it round with it on the right. A loop that turned left in
        all went round the room's walls: it is complete back where it began, or once past a fifth corner (a
        circuit begun on an obstacle off the wall never comes back to its start). One that turned right (by
        1.5 pi) went round an obstacle, which the robot leaves, turning left, to find a wall."""
        p = self.params
        ranges = obs.ir_range[self.low]
        if self._circuit_start is None:
            if self._away is not None:  # turn away from the obstacle just circled, to the left
                omega = turn_to(pose, self._away, p.drive, tolerance=0.15)
                if omega is not None:
                    return self._clean(0.0, omega)
                self._away = None
            if ranges[self.follow.front].min(initial=math.inf) >= p.follow.ahead + 0.05:
                return self._clean(p.follow.speed, 0.0)
            self._circuit_start, self._extents = pose[:2].copy(), np.array([pose[0], pose[0], pose[1], pose[1]])
            self._path, self._turned, self._last_heading, self._last_position = 0.0, 0.0, pose[2], pose[:2].copy()
        x, y = pose[:2]
        e = self._extents
        self._extents = np.array([min(e[0], x), max(e[1], x), min(e[2], y), max(e[3], y)])
        self._turned += wrap_angle(pose[2] - self._last_heading)
        self._last_heading = pose[2]
        self._path += float(np.hypot(*(pose[:2] - self._last_position)))
        self._last_position = pose[:2].copy()
        gone = float(np.hypot(*(pose[:2] - self._circuit_start)))
        closed = self._path > p.leave and gone < p.home
        if self._turned < -1.5 * math.pi or self._turned > 2.5 * math.pi or closed:
            if self._turned > math.pi:
                self.bounds = tuple(float(v) for v in self._extents)
                self.grid = CoverageGrid(self.bounds, p.cell)
            else:
                self._away = wrap_angle(pose[2] + math.pi / 2)
            self._circuit_start = None
            return self._clean(0.0, 0.0)
        return self._clean(*self.follow(ranges))

    # -- quadrant coverage ---------------------------------------------------------------------------------------
    def _cover(self, obs: Observation, pose: np.ndarray) -> Command:
        p, grid = self.params, self.grid
        self._mark_obstacles(obs, pose)
        here = grid.cell_of(*pose[:2])
        if np.hypot(*(grid.centre(here) - pose[:2])) < p.arrive:
            grid.state[here] = VISITED
        region = grid.quadrant(self.quadrant)
        if self._target is not None:
            reached = np.hypot(*(grid.centre(self._target) - pose[:2])) < p.arrive
            late = obs.time - self._target_since > p.cell_timeout
            if reached:
                grid.state[self._target] = VISITED
            elif late:
                grid.state[self._target] = BLOCKED
            if reached or grid.state[self._target] == BLOCKED:
                self._target = None
        if self._target is None:
            heading = round(pose[2] / (math.pi / 2)) % 4  # the grid direction the robot faces
            self._target = next_cell(grid, region, here, heading)
            self._target_since = obs.time
            if self._target is None:
                self.completed.append(self.quadrant)
                return self._clean(0.0, 0.0)
        if obs.ir_range[self.low][self.follow.front].min() < p.bump:  # something in the way: that cell is out
            if np.hypot(*(grid.centre(self._target) - pose[:2])) < 1.5 * grid.step.max():
                grid.state[self._target] = BLOCKED
            self._target = None
            return self._clean(-0.1, 0.0)
        v, omega = steer_to(pose, grid.centre(self._target), p.drive, 0.0) or (0.0, 0.0)
        return self._clean(max(v, 0.1) if abs(omega) < 0.5 else v, omega)  # no creeping up on a cell centre

    def _mark_obstacles(self, obs: Observation, pose: np.ndarray) -> None:
        """Cells (not yet visited) in which a lower-ring reading within ``sense_range`` ends are inaccessible."""
        grid, ranges = self.grid, obs.ir_range[self.low]
        near = ranges < self.params.sense_range
        if not near.any():
            return
        bearings = pose[2] + self.low_bearings[near]
        reach = self.rim + ranges[near] + grid.step.min() / 4  # a little way into the obstacle
        points = pose[:2] + reach[:, None] * np.stack([np.cos(bearings), np.sin(bearings)], axis=1)
        cells = np.round((points - grid.origin) / np.maximum(grid.step, 1e-9)).astype(int)
        inside = (cells >= 0).all(axis=1) & (cells < np.array(grid.shape)).all(axis=1)
        for i, j in cells[inside]:
            if grid.state[i, j] == UNVISITED:
                grid.state[i, j] = BLOCKED

    def done_with(self, quadrant: str) -> bool:
        return quadrant in self.completed

    @staticmethod
    def _clean(v: float, omega: float) -> Command:
        return Command(v=v, omega=omega, extras={"cleaner": 1.0})
