"""Getting FRC out of the pockets it circles in (issue 22; docs/navigation.md, "Why FRC circles").

FRC as printed (§3.6.2) is purely reactive: its direction sensor sees 1.5 m (d_obmax) and its obstacle memory
lasts seconds. Where the way to the goal is blocked by boxes it cannot see past, the sensor sends it round the
clear side, the goal-directedness term of (3.10) brings it back to the same blocked gap once the boxes drop out
of sight, and the robot drives the same 1-5 m loop every 15-40 s for good. Breaking it needs memory, so this
adds the smallest piece of it that the thesis itself uses for poor progress (the progress check of (3.6),
re-planning in HRDU and §6.2):
  - every IR hit is kept, for good, as an occupied cell of a world-frame grid (``HitMap``);
  - the robot is **trapped** when ``period`` seconds have passed since its distance to the goal last fell by
    ``progress`` (d_progmin of (3.6)) below its best, or when it has stood ``standstill`` seconds;
  - trapped, it plans a path to the goal with the modified A* (3.1)-(3.8) on the hits, unseen cells free,
    obstacles inflated as HRD inflates them, or by the footprint alone where that leaves no way (from the
    nearest cell outside the inflation when the robot stands beside a box), and follows it as HRD follows its
    plans (``path_following``), re-planning every ``replan`` seconds with what it has since seen, until its
    distance to the goal falls by ``progress`` below its best: then it is FRC again. A differential drive first
    turns in place to face each new plan (``TrapEscape.turn_first``), a tricycle in legs (``multi_point_turn``).
The thresholds are choices (docs/decisions.md, "FRC's trap escape").
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from teamsim.controllers.navigation.astar import PlannerParams, cost_maps, plan_on_grid
from teamsim.controllers.navigation.occupancy_grid import OccupancyGrid
from teamsim.controllers.navigation.path_following import PathFollower, PathFollowing


@dataclass(frozen=True)
class EscapeParams:
    period: float = 30.0  # s without progress that make a trap (about two laps of the loops seen)
    progress: float = 0.5  # m, d_progmin of (3.6)
    replan: float = 20.0  # s between plans while escaping
    facing: float = math.radians(30)  # a differential drive turns in place towards a new plan until within this
    turning: float = 15.0  # s: and for no longer (a half turn at B's limits takes about 10 s)
    multi_point_turning: float = 60.0  # s: a tricycle's multi-point turn, for no longer (a few legs of 10-15 s)
    resolution: float = 0.1  # m, the hit grid's cell (the study's map resolution)
    margin: float = 3.0  # m of free cells planned around the hits, the robot and the goal
    standstill: float = 10.0  # s standing that also make a trap
    still_radius: float = 0.05  # m: the centre moving no further than this counts as standing,
    still_turn: float = 0.5  # rad: and turning no further than this (a point turn is not standing)


class HitMap:
    """World-frame cells where the IR has ever seen an obstacle."""

    def __init__(self, resolution: float):
        self.resolution = resolution
        self.cells: set[tuple[int, int]] = set()

    def add(self, points: np.ndarray) -> None:
        """Add obstacle points (m, 2), world frame."""
        self.cells.update(map(tuple, np.floor(np.asarray(points) / self.resolution).astype(int).tolist()))

    def grid(self, *keep: tuple[float, float], margin: float) -> OccupancyGrid:
        """A known-map grid of the hits, spanning them and the ``keep`` points with ``margin`` round them."""
        res = self.resolution
        points = np.array([*((c[0] * res, c[1] * res) for c in self.cells), *keep]).reshape(-1, 2)
        lo = np.floor((points.min(axis=0) - margin) / res).astype(int)
        hi = np.floor((points.max(axis=0) + margin) / res).astype(int)
        occupied = np.zeros((hi[1] - lo[1] + 1, hi[0] - lo[0] + 1), bool)
        if self.cells:
            cells = np.array(list(self.cells)) - lo
            occupied[cells[:, 1], cells[:, 0]] = True
        return OccupancyGrid.known((lo[0] * res, lo[1] * res), res, occupied)


class TrapEscape:
    """The trap detector and the escape plan of one robot driving to ``goal``; ``clearance`` is the planning
    inflation beyond the footprint radius, as HRD's."""

    def __init__(self, goal: tuple[float, float], radius: float, params: EscapeParams = EscapeParams(),
                 following: PathFollowing = PathFollowing(), multi_point: bool = False):
        self.goal = goal
        self.turn_limit = params.multi_point_turning if multi_point else params.turning
        self.radius = radius
        self.params = params
        self.following = following
        self.hits = HitMap(params.resolution)
        self.best = math.inf  # distance to the goal at the last progress
        self.best_time = 0.0
        self.still_at, self.still_heading, self.still_since = (math.inf, math.inf), 0.0, 0.0  # standing since
        self.follower: PathFollower | None = None
        self.planned_at = -math.inf
        self.escapes = 0  # plans made
        self.turning = False  # turning in place towards a new plan
        self.turn_started = -math.inf

    @property
    def escaping(self) -> bool:
        return self.follower is not None

    def waypoint(self, time: float, centre: tuple[float, float], heading: float = 0.0) -> tuple[float, float]:
        """Where to aim: the goal, or while escaping the escape path's look-ahead point. ``heading`` (rad) tells a
        turn on the spot from standing."""
        distance = math.dist(centre, self.goal)
        if (math.dist(centre, self.still_at) > self.params.still_radius
                or abs(math.remainder(heading - self.still_heading, math.tau)) > self.params.still_turn):
            self.still_at, self.still_heading, self.still_since = centre, heading, time
        if distance <= self.best - self.params.progress or self.best == math.inf:
            self.best, self.best_time = distance, time
            self.follower = None
        elif self._trapped(time) and (not self.escaping or time - self.planned_at >= self.params.replan):
            self._plan(time, centre)
        return self.goal if self.follower is None else self.follower.waypoint(centre, self.goal)

    def _trapped(self, time: float) -> bool:
        """No progress for ``period`` s, or no motion for ``standstill`` s (the centre within ``still_radius`` of
        where it stood, the heading within ``still_turn``): a tricycle wedged between boxes rocks a millimetre at a
        time and need not wait a period."""
        return (time - self.best_time >= self.params.period
                or time - self.still_since >= self.params.standstill)

    def turn_first(self, heading: float, time: float) -> bool:
        """Whether to turn towards the plan's way before driving on (``heading``: the bearing of its look-ahead
        point, relative to the robot): on the spot, or a tricycle in legs; from a new plan while not already
        turning, until facing it, for at most ``turning`` seconds (``multi_point_turning`` for a tricycle) from the
        turn's start, which a re-plan meanwhile does not move. A slow robot with a small angular
        acceleration otherwise prefers speed to turning (the speed term of (3.35) varies more across its window
        than the heading term) and, next to boxes, can lock into a tight circle that only just clears them. The
        controller turns towards this bearing itself, not the direction sensor's theta_tmod: turned towards
        theta_tmod, which can lie more than ``facing`` away from it, a robot stood until the limit, then drove
        for a few seconds until the next plan, and stood again (in physics: issue 22, "Physics spot check")."""
        self.turning = (self.turning and self.escaping and abs(heading) > self.params.facing
                        and time - self.turn_started < self.turn_limit)
        return self.turning

    def stop_turning(self) -> None:
        """End the turn towards the plan early (a multi-point turn with no room for either leg)."""
        self.turning = False

    def _plan(self, time: float, centre: tuple[float, float]) -> None:
        """Plan with HRD's inflation (footprint radius plus clearance); where that leaves no way through, with the
        footprint radius alone (the worlds guarantee only a way for the largest robot's own circle)."""
        grid = self.hits.grid(centre, self.goal, margin=self.params.margin)
        for inflation in (self.radius + self.following.clearance, self.radius):
            start = self._free_start(grid, centre, inflation)
            path, result = plan_on_grid(grid, start, self.goal, PlannerParams(), inflation)
            if result.reached:
                break
        self.follower = PathFollower(np.vstack([centre, path]), result.reached, grid.resolution, self.following)
        self.planned_at = time
        self.escapes += 1
        if not self.turning:  # a re-plan during a turn does not restart its clock
            self.turning, self.turn_started = True, time

    def _free_start(self, grid: OccupancyGrid, centre: tuple[float, float], inflation: float) -> tuple[float, float]:
        """Where the plan starts: the robot's centre, or, when that lies within the planning inflation of a hit
        (beside a box), the nearest cell centre that does not; the dynamic window takes the robot there."""
        blocked = cost_maps(grid.probabilities, PlannerParams(), inflation / grid.resolution).blocked
        row, col = (int(i) for i in grid.world_to_cell(*centre))
        if not blocked[row, col]:
            return centre
        free_rows, free_cols = np.nonzero(~blocked)
        x, y = grid.cell_to_world(free_rows, free_cols)
        nearest = int(np.argmin(np.hypot(x - centre[0], y - centre[1])))
        return float(x[nearest]), float(y[nearest])
