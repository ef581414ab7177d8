"""The explorer (Chand §6.2, Fig 6.3): ask for a local environment, drive to its centre along the planner's path,
cover it by the waypoints of (6.1)-(6.2), map it from its IR readings by (6.3)-(6.5), and watch for bogs.

- **Travel and coverage** use the ch.3 navigation with a map (HRDU, ``dynamic_window``): the planner's path is
  followed to the environment's centre; each coverage waypoint is reached along a plan of the explorer's own on
  its own map, which favours unexplored cells (3.5) and is re-made on poor progress (3.6). Persistent poor progress
  (no ``progress`` m closer in ``give_up`` s) marks a waypoint inaccessible; on the way to an environment it asks
  for a new path, and the second time for a new environment; inside the environment, with its centre out of reach
  or mapped occupied, coverage starts from where it is.
- **Mapping**: every reading updates the explorer's own map and an outgoing map of the evidence gathered since the
  last update sent; every ``map_period`` s the outgoing local maps that changed go to the manager (8 KB each) and
  are reset to 0.5, so that the manager's (6.15) counts each reading once.
- **Bogs**: high drive effort while moving, for ``bog_time`` s. Every explorer reports the bog; one that cannot cross
  bogs also reverses along its own trail to ``back_out_distance`` from where the bog slowed it, and on until the
  ground is firm (the thesis: to the first node of its current path, which may lie far back), sends the
  manager the cells it mapped from inside the bog to be reset to unexplored (0.5), and asks for a non-boggy
  environment (§6.2.2).
- **Feedback** (§5.6.1, Table 5.30): it counts its achievements per T_m for the manager's monitor.
Thresholds the thesis does not give are in ``ExplorerParams`` and docs/decisions.md ("Exploration").
"""
from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from teamsim.controllers.exploration.bogs import keep_out
from teamsim.controllers.exploration.territory import SMALL_MESSAGE, Territory
from teamsim.controllers.exploration.waypoints import WaypointParams, coverage_waypoints
from teamsim.controllers.navigation.dynamic_window import HRDU
from teamsim.network import Packet

TRAIL_TICKS = 1200  # the last two minutes of poses at 10 Hz


@dataclass(frozen=True)
class ExplorerParams:
    # Not given by the thesis (spec §8); chosen.
    map_period: float = 5.0  # s between map updates to the manager
    waypoint_reach: float = 0.6  # m: a waypoint is visited once the robot's centre is this close
    progress: float = 0.5  # m closer to the current goal that counts as progress
    give_up: float = 45.0  # s without progress: persistent poor progress (§6.2)
    bog_effort: float = 0.25  # drive effort (share of the motors' limit) that is "abnormally high" (measured in
    # physics: at most 0.09 on firm ground, accelerating; in a bog 0.3 (tracked, full speed) to 1.0 (diffdrive)) ...
    bog_speed: float = 0.002  # ... while the robot still creeps (m/s; stalled against a box it reads 0) ...
    bog_turn: float = 0.1  # ... and hardly turns (rad/s; a tracked robot's skid turn takes up to 0.8 effort) ...
    bog_time: float = 1.5  # ... for this long: a bog
    back_out_limit: float = 60.0  # s of reversing at most; it also stops when something behind stalls it
    back_out_distance: float = 2.0  # m from where the bog slowed it (as the crow flies) to reverse to along its
    # trail, then on straight back until the ground is firm: ...
    firm_speed: float = 0.1  # ... moving at this share of v_max or more, with an effort under bog_effort per unit
    # of that share (firm ground measured at most about 0.1 per unit cruising; bogs 0.3 (tracked) to 10 (diffdrive))
    waypoints: WaypointParams = WaypointParams()


@dataclass
class Achievement:
    """Table 5.30's explorer measures since the last report."""
    waypoint_generations: int = 0
    local_path_plans: int = 0
    bytes: int = 0
    area_explored_cells: int = 0
    area_explored_accurately_cells: int = 0
    distance_m: float = 0.0

    def by_category(self) -> dict[str, list[float]]:
        return {"plan": [self.waypoint_generations, self.local_path_plans], "comm": [self.bytes],
                "sense": [self.area_explored_cells, self.area_explored_accurately_cells], "act": [self.distance_m]}


@dataclass
class Assignment:
    environment: int
    path: np.ndarray  # the planner's, (n, 2) world points to the environment's centre


@dataclass
class _Bog:
    entered: float  # s, when the slow, hard driving began
    first_node: tuple[float, float]
    mapped_from: list = field(default_factory=list)  # robot positions since entering, for the cells to reset
    beyond: bool = False  # past first_node on ground still boggy: straight back until it is firm


class Explorer:
    """One robot's explorer role. ``navigator`` is its HRDU (own map: ``navigator.grid``); ``manager`` the robot
    that keeps the global information."""

    def __init__(self, name: str, territory: Territory, navigator: HRDU, *, manager: str, bog_capable: bool,
                 radius: float, params: ExplorerParams = ExplorerParams()):
        self.name = name
        self.territory = territory
        self.nav = navigator
        self.manager = manager
        self.bog_capable = bog_capable
        self.radius = radius
        self.params = params
        self.outgoing = territory.unexplored_map(navigator.grid.params)  # mapped as its own map is
        self.dirty: set[int] = set()
        self.sensing_range = params.waypoints.sensing_range(territory.resolution)
        self.state = "request"  # request, wait, travel, explore, back-out, finished
        self.assignment: Assignment | None = None
        self.waypoints: list[tuple[float, float]] = []
        self.progress_mark = (0.0, math.inf)  # (time, distance to goal) at the last progress
        self.poor_paths = 0  # path requests on the way to the current environment
        self.bog: _Bog | None = None
        self.slow_since: float | None = None
        self.last_map_sent = 0.0
        self.achievement = Achievement()
        self.explored_before = 0
        self.confident_before = 0
        self.outbox: list[Packet] = []
        self.environments_done: list[int] = []
        self.trail: deque = deque(maxlen=TRAIL_TICKS)  # (time, x, y), for backing out of a bog
        self.bogs_met: list[tuple[float, float, float]] = []  # (x, y, heading) where a bog turned it back

    # -- messages -----------------------------------------------------------------------------------------------
    def send(self, kind: str, payload: dict, size: int = SMALL_MESSAGE, to: str | None = None) -> None:
        self.outbox.append(Packet(kind, payload, size, to or self.manager))
        self.achievement.bytes += size

    def receive(self, kind: str, payload: dict, size: int) -> None:
        self.achievement.bytes += size
        if kind == "plan" and self.state in ("wait", "travel"):
            self._start_travel(payload["environment"], np.asarray(payload["path"], float))
        elif kind == "finished":
            self.state = "finished"
        elif kind == "wake" and self.state == "finished":
            self.state = "request"  # an environment it could take is open again

    # -- one control tick ---------------------------------------------------------------------------------------
    def step(self, obs) -> tuple[float, float, str]:
        """(v, omega, behaviour) for this tick; packets to send are left in ``outbox``."""
        if obs.pose is None:
            return 0.0, 0.0, "explorer: no fix"
        pose = self._pose(obs)
        self.trail.append((obs.time, pose[0], pose[1]))
        self._count_distance(obs)
        command = self._decide(obs, pose)
        self._map(obs, self._pose(obs))
        if obs.time - self.last_map_sent >= self.params.map_period:
            self.send_map(obs.time)
        return command

    def _pose(self, obs) -> tuple[float, float, float]:
        """The navigator's estimate (the last fix advanced by odometry) if it ran this tick, else the fix."""
        if self.nav.pose_estimate is not None and self.nav.tracker.time == obs.time:
            return self.nav.pose_estimate
        return obs.pose.x, obs.pose.y, obs.pose.heading

    def _decide(self, obs, pose) -> tuple[float, float, str]:
        if self.state != "back-out" and self._bogged(obs):
            return self._enter_bog(obs, pose)
        if self.state == "back-out":
            return self._back_out(obs, pose)
        if self.state == "request":
            self.send("request", {"kind": "environment", "position": pose[:2], "bog_capable": self.bog_capable})
            self.state = "wait"
        if self.state in ("wait", "finished"):
            return 0.0, 0.0, f"explorer: {self.state}"
        return self._drive(obs, pose)

    def _drive(self, obs, pose) -> tuple[float, float, str]:
        command = self.nav(obs)
        centre = (pose[0], pose[1])
        goal = self.nav.goal
        distance = math.dist(centre, goal)
        if distance <= self.progress_mark[1] - self.params.progress:
            self.progress_mark = (obs.time, distance)
        stuck = obs.time - self.progress_mark[0] >= self.params.give_up
        if self.state == "travel":
            if self._near(centre, goal) or command.behaviour == "arrived" or self._centre_blocked(centre, stuck):
                self._start_exploring(obs.time, centre)
            elif stuck:
                self._travel_stuck(obs.time, centre)
        elif self.state == "explore":
            if self._near(centre, goal) or command.behaviour == "arrived" or stuck or self._occupied(goal):
                self._next_waypoint(obs.time)
        environment = self.assignment.environment if self.assignment else "-"
        return command.v, command.omega, f"explorer: {self.state} E{environment}"

    def _near(self, centre, goal) -> bool:
        return math.dist(centre, goal) <= self.params.waypoint_reach

    def _centre_blocked(self, centre, stuck: bool) -> bool:
        """Inside its environment, with the centre mapped occupied (a box on it, or a robot standing at the base)
        or out of reach (persistent poor progress): coverage starts from where it is, as it would at the centre.
        Asking for another path or environment instead left such environments partly explored (docs/decisions.md,
        "Exploration", travel)."""
        inside = self.territory.environment_of(*centre) == self.assignment.environment
        return inside and (stuck or self._occupied(self.nav.goal))

    def _avoid_bogs(self) -> None:
        """Its own plans (HRDU's re-plans on its own map, which the planner's avoidance does not reach) keep out
        of the bogs it met, from where it stands now (``bogs``)."""
        if self.bogs_met and self.trail:
            _, x, y = self.trail[-1]
            grid = self.nav.grid
            self.nav.keep_out = keep_out(self.bogs_met, (x, y), self.radius, grid.origin, grid.resolution, grid.shape)

    def _occupied(self, point) -> bool:
        """The explorer's own map says the waypoint lies in an obstacle: it cannot be reached."""
        grid = self.nav.grid
        row, col = self.territory.cell_of(*point)
        return bool(grid.probabilities[row, col] >= self.nav.planner.occupied_threshold)

    def _start_travel(self, environment: int, path: np.ndarray) -> None:
        if self.assignment is None or self.assignment.environment != environment:
            self.poor_paths = 0
        self.assignment = Assignment(environment, path)
        self.state = "travel"
        self._avoid_bogs()
        self.nav.retarget(self.territory.centre(environment), path if len(path) > 1 else None)
        self.progress_mark = (-math.inf, math.inf)

    def _travel_stuck(self, now: float, centre) -> None:
        """Persistent poor progress on the way: a new path, then a new environment (§6.2)."""
        self.poor_paths += 1
        kind = "path" if self.poor_paths == 1 else "environment"
        self.send("request", {"kind": kind, "position": centre, "bog_capable": self.bog_capable,
                              "give_up": self.assignment.environment})
        self.state = "wait"

    def _start_exploring(self, now: float, centre) -> None:
        lo, hi = self.territory.bounds(self.assignment.environment)
        self.waypoints = [tuple(p) for p in coverage_waypoints(lo, hi, self.sensing_range, centre)]
        self.achievement.waypoint_generations += 1
        self.state = "explore"
        self._next_waypoint(now)

    def _next_waypoint(self, now: float) -> None:
        while self.waypoints and self._occupied(self.waypoints[0]):
            self.waypoints.pop(0)
        if not self.waypoints:
            self._finish_environment(now)
            return
        plans = self.nav.replans
        self._avoid_bogs()
        self.nav.retarget(self.waypoints.pop(0))
        self.achievement.local_path_plans += 1 + self.nav.replans - plans
        self.progress_mark = (now, math.inf)

    def _finish_environment(self, now: float) -> None:
        """Last waypoint: exploration complete, the map to the manager, then a new environment (§6.2)."""
        environment = self.assignment.environment
        self.send_map(now)
        self.send("done", {"environment": environment})
        self.environments_done.append(environment)
        self.assignment = None
        self.state = "request"

    # -- mapping ------------------------------------------------------------------------------------------------
    def _map(self, obs, pose) -> None:
        """(6.3)-(6.5) into the outgoing map. The navigator's HRDU maps its own grid as it decides; when it did so
        this tick, from the same pose, its evidence is applied here as it is (the same reading on the same frame)."""
        shared = self.nav.last_evidence
        if shared is not None and shared.time == obs.time and shared.pose == tuple(pose) \
                and self.nav.radius == self.radius:
            self.outgoing.apply(shared)
        else:
            self.outgoing.update(pose, obs.ir_range, obs.ir_bearings, sensor_radius=self.nav.sensor_radius,
                                 centre_offset=self.nav.offset, footprint_radius=self.radius)
        reach = self.radius + self.outgoing.params.range_max
        for dx in (-reach, reach):
            for dy in (-reach, reach):
                self.dirty.add(self.territory.environment_of(pose[0] + dx, pose[1] + dy))
        if self.bog is not None:
            self.bog.mapped_from.append((pose[0], pose[1]))

    def send_map(self, now: float) -> None:
        """The changed local maps since the last update, 8 KB each, then a fresh outgoing map."""
        self.last_map_sent = now
        if not self.dirty:
            return
        maps = {}
        for environment in sorted(self.dirty):
            rows, cols = self.territory.slices(environment)
            maps[environment] = self.outgoing.probabilities[rows, cols].copy()
        self.send("map", {"maps": maps}, size=len(maps) * self.territory.local_map_bytes())
        self.outgoing.probabilities[:] = self.outgoing.params.p_unexplored
        self.dirty.clear()

    def _count_distance(self, obs) -> None:
        if obs.velocity is not None:
            self.achievement.distance_m += abs(obs.velocity[0]) * self.nav.window.dt

    def report(self) -> dict[str, list[float]]:
        """This interval's achievement (Table 5.30), and a fresh count. Area explored is read off its own map:
        cells that left 0.5, and ("accurately") cells whose probability has left the (0.2, 0.8) band."""
        p = self.nav.grid.probabilities
        explored = int(np.count_nonzero(np.abs(p - 0.5) > 1e-6))
        confident = int(np.count_nonzero((p <= 0.2) | (p >= 0.8)))
        # (a bog's reset can take cells back: an interval explores no less than nothing)
        self.achievement.area_explored_cells = max(explored - self.explored_before, 0)
        self.achievement.area_explored_accurately_cells = max(confident - self.confident_before, 0)
        self.explored_before, self.confident_before = explored, confident
        out = self.achievement.by_category()
        self.achievement = Achievement()
        return out

    # -- bogs ---------------------------------------------------------------------------------------------------
    def _bogged(self, obs) -> bool:
        """Abnormally high drive effort while moving and hardly turning, held for ``bog_time`` (§6.2's PWM effort
        at low velocity: a wheeled robot creeps, a tracked one keeps its speed at high effort; a stall against a
        box, at zero speed, is not a bog, nor is a tracked robot's skid turn)."""
        p = self.params
        effort = obs.drive_effort
        slow = (effort is not None and obs.velocity is not None and effort >= p.bog_effort
                and abs(obs.velocity[0]) >= p.bog_speed and abs(obs.velocity[1]) <= p.bog_turn)
        if not slow:
            self.slow_since = None
            return False
        if self.slow_since is None:
            self.slow_since = obs.time
        return obs.time - self.slow_since >= p.bog_time and self.bog is None

    def _enter_bog(self, obs, pose) -> tuple[float, float, str]:
        environment = self.territory.environment_of(pose[0], pose[1])
        reversing = obs.velocity is not None and obs.velocity[0] < 0
        met = (pose[0], pose[1], pose[2] + (math.pi if reversing else 0.0))  # the way it was going
        self.send("bog", {"environment": environment, "position": met[:2], "heading": met[2]})
        self.bog = _Bog(self.slow_since, self._before_bog(self.slow_since, pose), [(pose[0], pose[1])])
        if self.bog_capable:
            return self._drive(obs, pose)
        self.bogs_met.append(met)
        self.state = "back-out"
        self.back_out_since = obs.time
        self.stalled_since = None
        return self._back_out(obs, pose)

    def _before_bog(self, entered: float, pose) -> tuple[float, float]:
        """Where to reverse to: the latest point of the robot's own trail ``back_out_distance`` away from where
        the bog slowed it (as the crow flies: a trail that curved in leaves it nearer the bog than its length says);
        straight back that far if the trail does not lead away (a robot that has stood still)."""
        trail = [(t, x, y) for t, x, y in self.trail if t <= entered] or list(self.trail)[:1]
        _, *slowed = trail[-1]
        for _, x, y in reversed(trail):
            if math.dist((x, y), slowed) >= self.params.back_out_distance:
                break
        if math.dist((x, y), pose[:2]) < self.params.back_out_distance / 2:
            x = pose[0] - self.params.back_out_distance * math.cos(pose[2])
            y = pose[1] - self.params.back_out_distance * math.sin(pose[2])
        return x, y

    def _back_out(self, obs, pose) -> tuple[float, float, str]:
        """Reverse towards the point before the bog, steering the tail at it; reached on ground that is still
        boggy (the robot had crept along inside the bog before the sign held), on straight back until the ground is
        firm. Ends there, or stalled, or after ``back_out_limit`` s."""
        target = self.bog.first_node
        moving = obs.velocity is not None and abs(obs.velocity[0]) >= self.params.bog_speed
        self.stalled_since = None if moving else (self.stalled_since or obs.time)
        blocked = self.stalled_since is not None and obs.time - self.stalled_since >= self.params.bog_time
        reached = self.bog.beyond or math.dist(pose[:2], target) <= self.params.waypoint_reach
        if (reached and self._firm(obs)) or blocked or obs.time - self.back_out_since >= self.params.back_out_limit:
            return self._left_bog(obs.time)
        limits = self.nav.window.limits
        if reached:
            self.bog.beyond = True
            return -0.6 * limits.v_max, 0.0, "explorer: back out of bog"
        behind = math.atan2(target[1] - pose[1], target[0] - pose[0]) - (pose[2] + math.pi)
        error = math.atan2(math.sin(behind), math.cos(behind))
        return -0.6 * limits.v_max, float(np.clip(1.5 * error, -limits.omega_max, limits.omega_max)), \
            "explorer: back out of bog"

    def _firm(self, obs) -> bool:
        """Firm ground under the moving robot: its drive effort per unit of speed (|v| / v_max) is under what a
        bog takes. Without an effort reading, taken as firm."""
        if obs.drive_effort is None or obs.velocity is None:
            return True
        share = abs(obs.velocity[0]) / self.nav.window.limits.v_max
        return share >= self.params.firm_speed and obs.drive_effort < self.params.bog_effort * share

    def _left_bog(self, now: float) -> tuple[float, float, str]:
        """Out: what it mapped from inside the bog is reset to unexplored, here and at the manager (§6.2.2), and
        it asks for a non-boggy environment."""
        reach = self.radius + self.outgoing.params.range_max
        cells = set()
        for x, y in self.bog.mapped_from:
            rows, cols = self.nav.grid.window(x, y, reach)
            cells.update((int(r), int(c)) for r in rows for c in cols)
        rows, cols = (np.array(v, int) for v in zip(*cells)) if cells else (np.zeros(0, int),) * 2
        self.nav.grid.probabilities[rows, cols] = 0.5
        self.outgoing.probabilities[rows, cols] = 0.5
        self.send("reset", {"rows": rows, "cols": cols}, size=SMALL_MESSAGE + 8 * len(rows))
        self.send("request", {"kind": "environment", "position": self.bog.mapped_from[-1], "bog_capable": False,
                              "give_up": self.assignment.environment if self.assignment else None, "bog": True})
        self.bog = None
        self.slow_since = None
        self.assignment = None
        self.state = "wait"
        self.nav.state = type(self.nav.state)()
        return 0.0, 0.0, "explorer: wait"
