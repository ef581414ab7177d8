"""Random obstacle worlds of Chand's navigation experiments (§3.6.2): 15 m x 15 m, evenly distributed rectilinear
obstacles at 5, 10, 15 and 20 % density, the robot crossing from the top-left corner to the bottom-right (Fig 3.9).

The thesis gives neither the obstacles' sizes nor how they were spread, only that they were "evenly distributed"
and automatically generated. Here (choices, in ``NavWorldParams``):
  - obstacles are axis-aligned boxes with half-sides drawn uniformly from ``half_size_range``: 1 m to 2 m across,
    large enough that the IR ring cannot miss one well inside its range (a box 1 m wide spans the 36 degrees
    between adjacent beams of a ten-sensor ring out to 1.6 m from its centre);
  - the world is divided into a square grid of strata, about one per obstacle expected, visited in a random order
    again and again; each visit tries to drop one box at a uniform position in its stratum that keeps clear of
    the start's and the goal's discs and leaves ``min_gap`` to the walls and to every box it does not overlap
    (a jittered grid: even, yet random). Boxes that overlap or touch make one larger obstacle;
  - ``min_gap`` is Table 3.1's largest robot's diameter (Robot C, 1.34 m): no gap between obstacles is too
    narrow for any of the robots' bodies, though Robot C (1.54 m with its safety margin) and the tricycle, which
    needs room to turn, still meet tight places and do worse at high density, as in the thesis. The thesis's
    results call for such worlds: Robot C reached the goal in 80 % of its 20 % worlds, A and B in more than 88 %
    of all of them. An earlier reading, boxes kept 0.7 m apart (Robot B's diameter) and never overlapping, left
    most gaps narrower than A or C with their safety margins: in the first ten such layouts at 20 % density only
    one had a way through for Robot C's body and four for Robot A with its margin, and FRC reached the goal with
    A in none of ten (docs/navigation.md). Wider gaps between boxes that may not overlap cannot reach 15 % at
    all: the layouts jam, which is also why the thesis found even distributions "computationally difficult" at
    higher densities;
  - boxes are added until the covered fraction of the occupancy raster is as close to the density as one more
    box could bring it;
  - a layout is kept only if a circle of ``passage_radius`` (Robot C's) can get from the start to the goal:
    merged obstacles can still close every way through, and a world with none measures the world, not the
    controller (at 20 % about one layout in fifteen is dropped for this).
Density is measured on the occupancy raster (a cell is occupied when its centre lies in a box), which is also
the known map the deliberative planners get. The world is centred on the origin, as ``walled_room`` builds it.

``kinematic_run`` drives a navigation controller through a world without physics (ideal IR ranges by ray casting,
unicycle or bicycle kinematics): the smoke test of the controllers and the timing of their decisions.
"""
from __future__ import annotations

import functools
import math
import time as time_module
from dataclasses import dataclass

import numpy as np
from numba import njit

from teamsim.config import ConfigError
from teamsim.controllers.base import Observation
from teamsim.controllers.navigation.astar import modified_astar
from teamsim.controllers.navigation.occupancy_grid import OccupancyGrid
from teamsim.controllers.skills.locomotion import SlewLimiter, next_steer
from teamsim.models.arenas import Box
from teamsim.models.robot import DriveLimits
from teamsim.positioning import PoseFix
from teamsim.scenario import Obstacle

DENSITIES = (0.05, 0.10, 0.15, 0.20)  # §3.6.2


@dataclass(frozen=True)
class NavWorldParams:
    size: float = 15.0  # m, side of the square world (§3.6.2)
    resolution: float = 0.1  # m, occupancy raster cell
    half_size_range: tuple[float, float] = (0.5, 1.0)  # m, obstacle half-sides: not given, chosen
    min_gap: float = 1.34  # m, least gap between boxes that do not overlap, and to a wall (see above)
    corner_margin: float = 1.5  # m from each wall to the start and the goal
    clear_radius: float = 1.2  # m around the start and the goal kept free of obstacles
    attempts: int = 20  # placements tried per stratum visit before moving on
    max_rounds: int = 10  # passes over the strata before a layout is given up
    passage_radius: float = 0.67  # m, the circle that must fit from the start to the goal (Robot C, Table 3.1)
    layouts: int = 200  # layouts tried before giving up on a density


@dataclass(frozen=True)
class NavWorld:
    boxes: tuple[Box, ...]
    occupancy: np.ndarray  # bool (rows, cols), row along world y, column along x
    origin: tuple[float, float]  # world position of the raster's lower-left corner
    resolution: float
    size: float
    start: tuple[float, float, float]  # x, y, heading (facing the goal)
    goal: tuple[float, float]

    @functools.cached_property
    def box_corners(self) -> tuple[np.ndarray, np.ndarray]:
        """The boxes' lower-left and upper-right corners, (boxes, 2) each."""
        lo = np.array([[b.x - b.half_x, b.y - b.half_y] for b in self.boxes]).reshape(-1, 2)
        hi = np.array([[b.x + b.half_x, b.y + b.half_y] for b in self.boxes]).reshape(-1, 2)
        return lo, hi

    @functools.cached_property
    def box_extents(self) -> tuple[np.ndarray, np.ndarray]:
        """The boxes' centres and half-sides, (boxes, 2) each."""
        centres = np.array([[b.x, b.y] for b in self.boxes]).reshape(-1, 2)
        halves = np.array([[b.half_x, b.half_y] for b in self.boxes]).reshape(-1, 2)
        return centres, halves

    @property
    def density(self) -> float:
        return float(self.occupancy.mean())

    def known_map(self) -> OccupancyGrid:
        """The occupancy raster as a known map, for HRDK."""
        return OccupancyGrid.known(self.origin, self.resolution, self.occupancy)

    def unexplored_map(self) -> OccupancyGrid:
        """An unexplored map of the same extent, for HRDU."""
        return OccupancyGrid.unexplored(self.origin, self.resolution, self.occupancy.shape)


def cell_centres(size: float, resolution: float) -> np.ndarray:
    """The centres of a square raster's cells along either axis, the world centred on the origin."""
    return -size / 2 + (np.arange(round(size / resolution)) + 0.5) * resolution


def covered_cells(obstacle: Obstacle, centres: np.ndarray) -> np.ndarray:
    """(rows, cols) bool: the cells whose centre lies in the obstacle (row along world y, column along x); the
    occupancy raster, and with it the density, is the union of its obstacles' covered cells."""
    return obstacle.distance(centres[None, :], centres[:, None]) <= 0


class DensityFill:
    """An occupancy raster filled box by box until it is as near a density as one more box could bring it."""

    def __init__(self, centres: np.ndarray, density: float):
        self.centres = centres
        self.occupancy = np.zeros((len(centres), len(centres)), bool)
        self.target = density * self.occupancy.size
        self.boxes: list[Box] = []

    def offer(self, box: Box, covered: np.ndarray) -> bool:
        """Add ``box`` (its cells ``covered``) unless it overshoots; True once the fill is done."""
        added = np.count_nonzero(covered & ~self.occupancy)  # an overlapping box adds only its new cells
        if added == 0:
            return False
        occupied = np.count_nonzero(self.occupancy)
        if abs(occupied + added - self.target) >= abs(occupied - self.target):
            return True
        self.occupancy |= covered
        self.boxes.append(box)
        return False

    @property
    def layout(self) -> tuple[tuple[Box, ...], np.ndarray]:
        return tuple(self.boxes), self.occupancy


def random_world(density: float, rng: np.random.Generator, params: NavWorldParams = NavWorldParams()) -> NavWorld:
    """A world of the given obstacle density (a fraction), reproducible from ``rng``."""
    return first_passable(density, rng, params, _layout)


def first_passable(density: float, rng: np.random.Generator, params, layout) -> NavWorld:
    """The first of up to ``params.layouts`` layouts drawn by ``layout(density, rng, params, (start, goal))`` that
    reaches the density and lets a circle of ``params.passage_radius`` from the start to the goal; a layout that
    jams short of the density (None) or leaves no passage is dropped and the next drawn. If none does, the density
    is out of reach: ConfigError naming it."""
    half = params.size / 2
    start = (-half + params.corner_margin, half - params.corner_margin)
    goal = (half - params.corner_margin, -half + params.corner_margin)
    heading = math.atan2(goal[1] - start[1], goal[0] - start[0])
    for _ in range(params.layouts):
        drawn = layout(density, rng, params, (start, goal))
        if drawn is None:
            continue
        boxes, occupancy = drawn
        world = NavWorld(boxes, occupancy, (-half, -half), params.resolution, params.size,
                         (start[0], start[1], heading), goal)
        if has_passage(world, params.passage_radius):
            return world
    raise ConfigError(f"density={density:g}: no world of {density:.0%} obstacle density with a passage for a "
                      f"{params.passage_radius} m circle in {params.layouts} layouts; allowed: a lower density")


def _layout(density: float, rng: np.random.Generator, params: NavWorldParams,
            keep_clear) -> tuple[tuple[Box, ...], np.ndarray] | None:
    """Boxes dropped stratum by stratum until the density is reached, with their occupancy raster; None if the
    layout jams first."""
    half = params.size / 2
    centres = cell_centres(params.size, params.resolution)
    lo, hi = params.half_size_range
    mean_area = 4 * ((lo + hi) / 2) ** 2
    strata = max(1, round(math.sqrt(density * params.size ** 2 / mean_area)))
    stratum = params.size / strata
    fill = DensityFill(centres, density)
    for _ in range(params.max_rounds):
        for k in rng.permutation(strata * strata):
            row, col = divmod(int(k), strata)
            footprint = _place(rng, params, (-half + col * stratum, -half + row * stratum), stratum,
                               centres, fill.boxes, keep_clear)
            if footprint is not None and fill.offer(*footprint):
                return fill.layout
    return None


def _place(rng: np.random.Generator, params: NavWorldParams, corner: tuple[float, float], stratum: float,
           centres: np.ndarray, boxes: list[Box], keep_clear) -> tuple[Box, np.ndarray] | None:
    """A box centred in the stratum with lower-left ``corner``, ``min_gap`` inside the world, clear of the start
    and the goal, and either overlapping or ``min_gap`` from every box in ``boxes``; with its raster footprint.
    None if no attempt fits."""
    inside = params.size / 2 - params.min_gap
    for _ in range(params.attempts):
        hx, hy = rng.uniform(*params.half_size_range, size=2)
        x = corner[0] + rng.uniform(0, stratum)
        y = corner[1] + rng.uniform(0, stratum)
        if abs(x) + hx > inside or abs(y) + hy > inside:
            continue
        if any(math.hypot(max(abs(px - x) - hx, 0.0), max(abs(py - y) - hy, 0.0)) < params.clear_radius
               for px, py in keep_clear):
            continue
        if any(0 < math.hypot(max(abs(b.x - x) - hx - b.half_x, 0.0), max(abs(b.y - y) - hy - b.half_y, 0.0))
               < params.min_gap for b in boxes):
            continue
        return Box(float(x), float(y), float(hx), float(hy)), covered_cells(Obstacle("box", x, y, hx, hy), centres)
    return None


def has_passage(world: NavWorld, radius: float) -> bool:
    """Whether a circle of ``radius`` can get from the start to the goal without touching a box or a wall:
    A* on the occupancy raster bordered by the walls, occupied cells inflated by the radius and one cell more
    (a box's edge can lie up to a cell beyond the centres of the cells it covers)."""
    walled = np.pad(world.occupancy, 1, constant_values=True)
    grid = world.known_map()

    def cell(xy):  # in the walled raster, one cell in from the unwalled one
        row, col = grid.world_to_cell(xy[0], xy[1])
        return int(row) + 1, int(col) + 1

    return modified_astar(walled.astype(float), cell(world.start), cell(world.goal),
                          inflation_cells=radius / world.resolution + 1).reached


def ray_ranges(world: NavWorld, origins: np.ndarray, directions: np.ndarray, max_range: float) -> np.ndarray:
    """Ideal range readings: distance from each origin (n, 2) along its unit direction (n, 2) to the first box
    face or wall, ``inf`` beyond ``max_range`` (slab intersection, compiled: one ray and one box at a time)."""
    lo, hi = world.box_corners
    return _ray_ranges(np.ascontiguousarray(origins, dtype=float), np.ascontiguousarray(directions, dtype=float),
                       lo, hi, world.size / 2, max_range)


@njit("f8(f8, f8)", cache=True)
def _minimum(a, b):  # np.minimum: a NaN wins
    return a if a <= b or a != a else b


@njit("f8(f8, f8)", cache=True)
def _maximum(a, b):  # np.maximum
    return a if a >= b or a != a else b


@njit("f8(f8, f8)", cache=True)
def _fmin(a, b):  # np.fmin (np.nanmin of two): a NaN loses
    return a if a <= b or b != b else b


@njit("f8(f8, f8)", cache=True)
def _fmax(a, b):  # np.fmax (np.nanmax of two)
    return a if a >= b or b != b else b


@njit("f8[::1](f8[:, ::1], f8[:, ::1], f8[:, ::1], f8[:, ::1], f8, f8)", cache=True, error_model="numpy")
def _ray_ranges(origins, directions, lo, hi, half, max_range):  # noqa: PLR0913
    """The slab test as numpy wrote it over all rays and boxes at once (a ray that does not move along an axis has
    an infinite inverse there, and 0 x inf is NaN: NaN is handled as numpy's minimum, maximum, nanmin and nanmax
    handle it), so that the readings are the same to the bit."""
    out = np.empty(origins.shape[0])
    for i in range(origins.shape[0]):
        ox, oy = origins[i, 0], origins[i, 1]
        ix, iy = 1.0 / directions[i, 0], 1.0 / directions[i, 1]
        boxes = math.inf
        for b in range(lo.shape[0]):
            x1, x2 = (lo[b, 0] - ox) * ix, (hi[b, 0] - ox) * ix
            y1, y2 = (lo[b, 1] - oy) * iy, (hi[b, 1] - oy) * iy
            near = _fmax(_minimum(x1, x2), _minimum(y1, y2))
            far = _fmin(_maximum(x1, x2), _maximum(y1, y2))
            if near <= far and near >= 0:
                boxes = _minimum(boxes, near)
        wall = _fmin(_maximum((-half - ox) * ix, (half - ox) * ix), _maximum((-half - oy) * iy, (half - oy) * iy))
        distance = _minimum(boxes, wall)
        out[i] = distance if distance < max_range else math.inf
    return out


def clearance(world: NavWorld, x: float, y: float) -> float:
    """Distance from a point to the nearest box or wall. ``math.hypot`` of the nearest few boxes (by the compiled
    offsets) gives the result to the bit, whatever the compiled hypot rounds differently."""
    walls = world.size / 2 - max(abs(x), abs(y))
    centres, halves = world.box_extents
    if not len(centres):
        return walls
    dx, dy = _nearest_offsets(x, y, centres, halves)
    return min(walls, min(map(math.hypot, dx, dy)))


@njit("UniTuple(f8[::1], 2)(f8, f8, f8[:, ::1], f8[:, ::1])", cache=True)
def _nearest_offsets(x, y, centres, halves):
    """The offsets (dx, dy) from the point to the boxes whose distance is within a relative 1e-9 of the least."""
    n = centres.shape[0]
    dx, dy, approx = np.empty(n), np.empty(n), np.empty(n)
    least = math.inf
    for k in range(n):
        dx[k] = max(abs(x - centres[k, 0]) - halves[k, 0], 0.0)
        dy[k] = max(abs(y - centres[k, 1]) - halves[k, 1], 0.0)
        approx[k] = math.hypot(dx[k], dy[k])
        least = min(least, approx[k])
    near = approx <= least * (1 + 1e-9)
    return dx[near], dy[near]


@dataclass(frozen=True)
class KinematicRobot:
    """What a physics-free run needs of a robot: its drive, its enclosing circle and its IR ring (evenly spaced
    over 360 degrees from straight ahead, on the circle, as ``add_ir_ring`` builds them)."""
    kind: str  # "tricycle" or a differential kind
    limits: DriveLimits
    radius: float  # enclosing circle, m
    ir_count: int
    ir_range: float = 1.5
    centre_offset: float = 0.0  # the circle's centre ahead of the pose's reference point
    sensor_radius: tuple[float, ...] = ()  # each sensor's distance from the centre; () puts them on the circle
    wheelbase: float = 0.5  # tricycle only, as TricycleDims assumes
    steer_max: float = math.radians(60)
    steer_rate_max: float = 1.0


@dataclass(frozen=True)
class KinematicRun:
    reached: bool  # the controller reported "arrived"
    collided: bool  # the enclosing circle touched a box or wall (and the run ended there: on_contact="end")
    time: float  # s simulated
    min_clearance: float  # m, between the enclosing circle and the nearest box or wall
    decision_times: np.ndarray  # s of wall time per controller call
    travelled: float = 0.0  # m along the path of the pose's reference point
    touches: int = 0  # control ticks whose motion was refused because it would have touched (on_contact="stop")
    pose: tuple[float, float, float] = (0.0, 0.0, 0.0)  # where the run ended


class KinematicBody:
    """One robot's pose and drive in a physics-free world: ideal IR ranges, and motion from the slewed command.

    The command is clipped and slewed by the drive limits as the locomotion does; a tricycle's front wheel turns as
    the locomotion turns it (``locomotion.next_steer``) and the robot then follows the bicycle model, a
    differential drive the unicycle model. ``speed_scale`` slows the motion (a bog: the robot's traversability)."""

    def __init__(self, robot: KinematicRobot, pose: tuple[float, float, float], control_dt: float = 0.1,
                 substeps: int = 5):
        self.robot = robot
        self.x, self.y, self.heading = pose
        self.steer = 0.0
        self.control_dt, self.substeps = control_dt, substeps
        self.slew = SlewLimiter(robot.limits, control_dt)
        self.bearings = 2 * np.pi * np.arange(robot.ir_count) / robot.ir_count
        self.sensor_radius = np.asarray(robot.sensor_radius or (robot.radius,) * robot.ir_count, float)
        self.velocity = (0.0, 0.0)  # odometry of the last tick's motion
        self._rays = self._ranges = self._gap = None  # (pose, ...) of the last pose sensed, or checked

    def centre(self, x: float, y: float, heading: float) -> tuple[float, float]:
        offset = self.robot.centre_offset
        return x + offset * math.cos(heading), y + offset * math.sin(heading)

    def rays(self) -> tuple[np.ndarray, np.ndarray]:
        """Each IR sensor's position and unit direction in the world, (n, 2) each."""
        origins, directions = self._pose_rays()
        return origins.copy(), directions.copy()

    def _pose_rays(self) -> tuple[np.ndarray, np.ndarray]:
        """``rays()`` as kept for the current pose (not to be changed)."""
        pose = (self.x, self.y, self.heading)
        if self._rays is None or self._rays[0] != pose:
            angles = self.heading + self.bearings
            directions = np.empty((len(angles), 2))
            np.cos(angles, out=directions[:, 0])
            np.sin(angles, out=directions[:, 1])
            origins = self.sensor_radius[:, None] * directions
            origins += self.centre(*pose)
            self._rays = pose, origins, directions
        return self._rays[1], self._rays[2]

    def ranges(self, world: NavWorld, rays: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
        """Ideal readings along ``rays`` (default: this pose's, ``rays()``, kept for the pose: a robot standing
        still reads the same)."""
        if rays is not None:
            return ray_ranges(world, *rays, self.robot.ir_range)
        pose = (self.x, self.y, self.heading)
        if self._ranges is None or self._ranges[0] is not world or self._ranges[1] != pose:
            self._ranges = world, pose, ray_ranges(world, *self._pose_rays(), self.robot.ir_range)
        return self._ranges[2].copy()

    def motion(self, command, speed_scale: float = 1.0) -> tuple[float, float, float, tuple[float, float]]:
        """Where this tick's command would take the robot, and the odometry it would read."""
        robot = self.robot
        v, omega = self.slew(command.v, command.omega)
        turn_rate = omega
        if robot.kind == "tricycle":
            self.steer = next_steer(self.steer, v, omega, (command.v, command.omega), robot, self.control_dt)
            turn_rate = v * math.tan(self.steer) / robot.wheelbase
        v, turn_rate = v * speed_scale, turn_rate * speed_scale
        dt = self.control_dt / self.substeps
        nx, ny, nheading = self.x, self.y, self.heading
        for _ in range(self.substeps):
            nx += v * dt * math.cos(nheading)
            ny += v * dt * math.sin(nheading)
            nheading += turn_rate * dt
        nheading = (nheading + math.pi) % (2 * math.pi) - math.pi
        return nx, ny, nheading, (v, turn_rate)

    def gap(self, world: NavWorld, x: float, y: float, heading: float) -> float:
        """Clearance between the enclosing circle at that pose and the nearest box or wall (the last pose's kept:
        a robot standing still asks again)."""
        pose = (x, y, heading)
        if self._gap is None or self._gap[0] is not world or self._gap[1] != pose:
            self._gap = world, pose, clearance(world, *self.centre(x, y, heading)) - self.robot.radius
        return self._gap[2]

    def move(self, x: float, y: float, heading: float, velocity: tuple[float, float]) -> float:
        """Take the pose; the distance moved."""
        moved = math.hypot(x - self.x, y - self.y)
        self.x, self.y, self.heading, self.velocity = x, y, heading, velocity
        return moved

    def halt(self) -> None:
        """A refused motion: the drive stops."""
        self.slew.reset()
        self.velocity = (0.0, 0.0)


def kinematic_run(world: NavWorld, controller, robot: KinematicRobot, duration: float,
                  control_dt: float = 0.1, substeps: int = 5, on_contact: str = "end") -> KinematicRun:
    """Drive ``controller`` (through a ``KinematicBody``) from the world's start with ideal IR ranges and exact
    positioning fixes every control tick.

    ``on_contact`` says what a motion that would make the enclosing circle touch a box or wall does: "end" ends
    the run there as a collision; "stop" refuses that tick's motion and halts the robot (v = omega = 0), the way a
    bumper stops a real robot and a touch stops (but does not end) a physics run. Each observation carries the
    odometry of the last tick's motion (``Observation.velocity``): zero after a halt."""
    if on_contact not in ("end", "stop"):
        raise ValueError(f"on_contact={on_contact!r}: allowed: end, stop")
    body = KinematicBody(robot, world.start, control_dt, substeps)
    decision_times = []
    min_clearance = math.inf
    travelled, touches = 0.0, 0
    steps = round(duration / control_dt)

    def run(reached: bool, collided: bool, time_end: float) -> KinematicRun:
        return KinematicRun(reached, collided, time_end, min_clearance, np.array(decision_times), travelled,
                            touches, (body.x, body.y, body.heading))

    for tick in range(steps):
        time_now = tick * control_dt
        ranges = body.ranges(world)
        observation = Observation(time=time_now, robot="kinematic", ir_raw=ranges, ir_range=ranges,
                                  ir_bearings=body.bearings, pose=PoseFix(body.x, body.y, body.heading, time_now),
                                  velocity=body.velocity)
        began = time_module.perf_counter()
        command = controller(observation)
        decision_times.append(time_module.perf_counter() - began)
        if command.behaviour == "arrived":
            return run(True, False, time_now)
        nx, ny, nheading, velocity = body.motion(command)
        gap = body.gap(world, nx, ny, nheading)
        if gap < 0 and on_contact == "stop":
            touches += 1
            body.halt()
            continue
        travelled += body.move(nx, ny, nheading, velocity)
        min_clearance = min(min_clearance, gap)
        if gap < 0:
            return run(False, True, time_now + control_dt)
    return run(False, False, steps * control_dt)
