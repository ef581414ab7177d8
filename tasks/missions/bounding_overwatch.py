"""``bounding-overwatch``: Parker's bounding overwatch, in physics (§6.3, Figs 6-14 and 6-15; spec §4.4).

Eight robots, four differential-drive and four tricycles (Chand's robots A and B: two kinds, as Parker's
"two types"), stand in a line across the west end of an open field, kinds in a random order. Under ALLIANCE
(:mod:`teamsim.controllers.behaviours.bounding_overwatch`) they split into groups A and B with two of each kind,
drive to their group's gathering point, elect a leader per group, and then bound along the route in turn: bound
k goes to ``task.route[k]``, A making the even bounds and B the odd ones, while the other group overwatches. The
default route zig-zags east between two lanes (A's waypoints on the north lane, B's on the south), so the groups
leapfrog past each other. The mission completes when the leader of the last bound has reached the route's final
waypoint and announced the bound complete.

Faults: ``kill:@leader@T`` (or ``remove``) kills whoever leads the group whose turn it is to bound at T
(``@leader:A``, ``@leader:B``: that group's leader; :meth:`BoundingOverwatchMission.role_holder`): its group hears
nothing from it for tau, a new leader emerges and the bounding goes on. ``kill:ROBOT@T`` names a robot. Measures: each
robot's group and kind, join decisions, leaders over time, bounds (group, leader, start, end), completion time
and final positions (docs/bounding-overwatch.md).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import cv2
import numpy as np

from teamsim.config import ConfigError, RadioConfig, setting
from teamsim.controllers.behaviours.bounding_overwatch import GROUPS, OverwatchParams, OverwatchRobot, robot_rates
from teamsim.models.robot import RobotModel, TricycleSpec, team_names
from teamsim.scenario import Arena, RobotEntry, Scenario, scene_of
from teamsim.scene import Scene
from teamsim.tasks.base import ScenarioMission

KINDS = ("diffdrive", "tricycle")
SPACING = 1.6  # m between neighbours on the start line (a tricycle is 1 m across and turns ahead of itself)
GROUP_RGBA = {"A": (0.95, 0.55, 0.1, 0.9), "B": (0.1, 0.75, 0.85, 0.9)}
MARGIN = 0.6  # m: gathering points and waypoints lie this far inside the walls at least
PANEL_PERIOD = 0.5  # s between redraws of the video's map panel
PANEL_SCALE = 22  # pixels per m of the map panel


@dataclass
class BoundingOverwatchParams:
    per_kind: int = setting(4, lo=1, hi=6, meaning="robots of each kind, diffdrive and tricycle (Fig. 6-15: 4)")
    waypoints: int = setting(5, lo=2, hi=12, meaning="waypoints on the default route: one bound each")
    bound: float = setting(4.0, lo=1.0, hi=50.0, meaning="m east between consecutive waypoints of the default "
                                                         "route")
    lane: float = setting(2.5, lo=1.0, hi=20.0, meaning="m north (group A) and south (B) of the centre line of "
                                                        "the gathering points and waypoints")
    rho: float = setting(1.0, lo=0.0, open_lo=True, hi=100.0, meaning="broadcasts per second per robot (sets "
                                                                      "radio.rate_hz; tau is 3 periods)")
    behaviour: OverwatchParams = field(default_factory=OverwatchParams, metadata={
        "meaning": "the behaviours' constants (`OverwatchParams` in "
                   "`teamsim.controllers.behaviours.bounding_overwatch`)"})


@dataclass
class BoundingOverwatchTask:
    route: list[tuple[float, float]] = field(default_factory=list, metadata={
        "meaning": "waypoints (x, y), m: bound k goes to route[k], group A the even bounds, B the odd; at least "
                   "two", "lo": -1000.0, "hi": 1000.0})
    gather: list[tuple[float, float]] = field(default_factory=list, metadata={
        "meaning": "the gathering points (x, y) of groups A and B, m: exactly two", "lo": -1000.0, "hi": 1000.0})


@dataclass
class OverwatchSettings:
    """One robot's bounding-overwatch controller."""
    priority: int = setting(0, lo=0, hi=1000, meaning="fixed robot priority (0 first): breaks leader ties, orders "
                                                      "the follow wedge")
    leader_delay: float | None = setting(None, lo=0.01, hi=1e4, meaning="theta / delta_fast of emerge-leader, s "
                                                                        "(null: leader_delay + leader_step x "
                                                                        "priority)")
    behaviour: OverwatchParams = field(default_factory=OverwatchParams, metadata={
        "meaning": "the behaviours' constants"})


def default_layout(params: BoundingOverwatchParams) -> tuple[tuple[float, float], list, list, float]:
    """(arena size, gathering points, route, start-line x) of the default field."""
    count = 2 * params.per_kind
    length = round(10.5 + params.waypoints * params.bound, 3)
    width = round(max(2 * params.lane + 7.0, count * SPACING + 2.0), 3)
    start_x = -length / 2 + 1.0
    gx = start_x + 7.0
    gather = [(gx, params.lane), (gx, -params.lane)]
    route = [(gx + (k + 1) * params.bound, params.lane if k % 2 == 0 else -params.lane)
             for k in range(params.waypoints)]
    return (length, width), gather, route, start_x


class BoundingOverwatchMission(ScenarioMission):
    name = "bounding-overwatch"
    summary = ("Parker's bounding overwatch: two kinds of robot split into two groups that leapfrog along a route, "
               "ALLIANCE")
    Params = BoundingOverwatchParams
    Task = BoundingOverwatchTask
    Controller = OverwatchSettings
    default_duration = 900.0  # s: the default route takes 200-300 s (docs/bounding-overwatch.md)
    video_speedup = 4.0
    # Roles a fault may strike (``kill:@leader@300``), resolved by role_holder when the fault is due
    fault_roles = {"leader": "the leader of the group whose turn it is to bound (leading it, or about to)",
                   "leader:A": "group A's leader", "leader:B": "group B's leader"}

    @staticmethod
    def radio_of(params: BoundingOverwatchParams, radio: RadioConfig) -> RadioConfig:
        return replace(radio, rate_hz=params.rho)

    def scenario(self, params: BoundingOverwatchParams, rng: np.random.Generator, newcomers) -> Scenario:
        if newcomers:
            raise ConfigError(f"--fault add-robot:{newcomers[0][0]}: the bounding overwatch team is fixed at the "
                              "start (Parker §6.3); allowed faults: kill, remove, revive, and the sensor faults")
        size, gather, route, start_x = default_layout(params)
        count = 2 * params.per_kind
        kinds = [KINDS[int(k)] for k in rng.permutation([0] * params.per_kind + [1] * params.per_kind)]
        robots = {}
        for k, name in enumerate(team_names(count)):
            y = round((count - 1) / 2 * SPACING - k * SPACING, 3)
            robots[name] = RobotEntry(kinds[k], (start_x, y, 0.0), controller=OverwatchSettings(
                priority=k, behaviour=params.behaviour))
        return Scenario(mission=self.name, arena=Arena(size=size), robots=robots,
                        task=BoundingOverwatchTask(route=route, gather=gather))

    def check_scenario(self, scenario: Scenario) -> None:
        """Two or more wheeled robots of the two kinds with distinct priorities; a route of two waypoints or more
        and two gathering points, inside the arena."""
        task, robots = scenario.task, scenario.robots
        if len(task.route) < 2:
            raise ConfigError(f"task.route: needs at least two waypoints (one bound per group); got "
                              f"{len(task.route)}")
        if len(task.gather) != 2:
            raise ConfigError(f"task.gather: needs exactly two gathering points (groups A and B); got "
                              f"{len(task.gather)}")
        hx, hy = scenario.arena.size[0] / 2 - MARGIN, scenario.arena.size[1] / 2 - MARGIN
        for where, points in (("route", task.route), ("gather", task.gather)):
            for k, (x, y) in enumerate(points):
                if abs(x) > hx or abs(y) > hy:
                    raise ConfigError(f"task.{where}[{k}]: ({x:g}, {y:g}) is outside the field; x must be in "
                                      f"[{-hx:g}, {hx:g}], y in [{-hy:g}, {hy:g}]")
        if len(robots) < 2:
            raise ConfigError(f"robots: bounding overwatch needs at least two robots (one per group); got "
                              f"{len(robots)}")
        seen: dict[int, str] = {}
        for name, robot in robots.items():
            if robot.kind not in KINDS:
                raise ConfigError(f"robots.{name}.kind={robot.kind!r}: bounding overwatch is done by wheeled robots; "
                                  f"allowed: {', '.join(KINDS)}")
            priority = robot.controller.priority
            if priority in seen:
                raise ConfigError(f"robots.{name}.controller.priority={priority}: robots.{seen[priority]} has it "
                                  "too; priorities must differ (they break ties)")
            seen[priority] = name

    def scene(self, scenario: Scenario, newcomers, physics_dt: float) -> Scene:
        scene = scene_of(scenario, newcomers, physics_dt)
        task, body = scenario.task, scene.arena.worldbody
        for group, (x, y) in zip(GROUPS, task.gather):  # Fig. 6-15's triangles: the gathering points
            body.add("geom", name=f"gather{group}", type="cylinder", pos=[x, y, 0.003], size=[0.35, 0.003],
                     rgba=list(GROUP_RGBA[group]), contype=0, conaffinity=0)
        for k, (x, y) in enumerate(task.route):
            body.add("geom", name=f"waypoint{k}", type="cylinder", pos=[x, y, 0.003], size=[0.25, 0.003],
                     rgba=list(GROUP_RGBA[GROUPS[k % 2]]), contype=0, conaffinity=0)
            body.add("geom", name=f"flag{k}", type="cylinder", pos=[x, y, 0.4], size=[0.02, 0.4],
                     rgba=list(GROUP_RGBA[GROUPS[k % 2]]), contype=0, conaffinity=0)
        scene.info.update(brains={}, finished=None)
        return scene

    def controller(self, robot: RobotModel, scene: Scene, rng: np.random.Generator):
        scenario = scene.scenario
        settings, task = scenario.robots[robot.name].controller, scenario.task
        delay = settings.leader_delay if settings.leader_delay is not None else \
            robot_rates(settings.priority, settings.behaviour)
        brain = OverwatchRobot(robot.name, robot.kind, task.route, task.gather, settings.priority, delay, rng,
                               settings.behaviour, tau=scenario.radio.timeout, omega_max=robot.limits.omega_max,
                               point_turns=not isinstance(robot.drive, TricycleSpec))
        scene.info["brains"][robot.name] = brain
        return brain

    def role_holder(self, world, role: str) -> str | None:
        """The live robot that holds ``role`` (one of :attr:`fault_roles`) now, or None (no leader elected yet, or
        the last one dead and no successor yet, or the route done). A group's leader is the robot that takes itself
        for one; two that claimed within one radio period both do until they hear each other (§6.3 gives no rule):
        the earlier claim, then the higher priority, is the one its group keeps, as :meth:`Knowledge.leader` says."""
        brains = world.scene.info["brains"]
        if role == "leader":
            done = len({r.bound for r in self.bounds(world) if r.end is not None})
            if done >= len(world.scene.scenario.task.route):
                return None
            group = GROUPS[done % 2]
        else:
            group = role.partition(":")[2]
        claims = [(b.k.me.leader_since, b.k.me.priority, name) for name, b in brains.items()
                  if world.robots[name].active and b.group == group and b.is_leader]
        return min(claims)[2] if claims else None

    # -- the video's map ----------------------------------------------------------------------------------------------
    def video_panel(self, world) -> np.ndarray | None:
        """A top-down map beside the 3-D view: the route (each waypoint in its group's colour), every robot as a dot
        in its group's colour (grey before it joins, a cross when dead), leaders ringed, and the bound under way."""
        info = world.scene.info
        if world.time < info.get("panel_time", -math.inf) + PANEL_PERIOD:
            return None
        info["panel_time"] = world.time
        scenario = world.scene.scenario
        (sx, sy), k = scenario.arena.size, PANEL_SCALE
        image = np.full((int(sy * k) + 40, int(sx * k), 3), 235, np.uint8)

        def px(x, y):
            return int((x + sx / 2) * k), int((sy / 2 - y) * k) + 40

        cv2.rectangle(image, px(-sx / 2, sy / 2), px(sx / 2, -sy / 2), (90, 90, 90), 2)
        bgr = {g: tuple(int(255 * c) for c in GROUP_RGBA[g][2::-1]) for g in GROUPS}
        route = scenario.task.route
        for j, (x, y) in enumerate(route):
            cv2.circle(image, px(x, y), 6, bgr[GROUPS[j % 2]], 2, cv2.LINE_AA)
            cv2.putText(image, str(j), (px(x, y)[0] + 8, px(x, y)[1] - 6), cv2.FONT_HERSHEY_SIMPLEX, 0.4, (60,) * 3, 1)
        for g, (x, y) in zip(GROUPS, scenario.task.gather):
            cx, cy = px(x, y)
            cv2.fillPoly(image, [np.array([(cx, cy - 8), (cx - 7, cy + 5), (cx + 7, cy + 5)])], bgr[g])
        brains = info["brains"]
        leading = []
        for name, robot in world.robots.items():
            x, y = world.pose(robot)[:2]
            brain = brains.get(name)
            group = brain.group if brain is not None else None
            colour = bgr.get(group, (150, 150, 150))
            centre = px(x, y)
            if not robot.active:
                cv2.drawMarker(image, centre, (40, 40, 40), cv2.MARKER_TILTED_CROSS, 14, 2)
                continue
            cv2.circle(image, centre, 7 if robot.model.kind == "tricycle" else 5, colour, -1, cv2.LINE_AA)
            if brain is not None and brain.k.me.leader_since is not None and brain.is_leader:
                cv2.circle(image, centre, 11, (30, 30, 30), 2, cv2.LINE_AA)
                if brain.k.me.leading is not None:
                    leading.append(f"bound {brain.k.me.leading}: {group} led by {name}")
        done = sum(1 for r in self.bounds(world) if r.end is not None and r.bound is not None)
        text = leading[0] if leading else f"{done}/{len(route)} bounds"
        cv2.putText(image, f"t={world.time:5.1f}s  {text}", (8, 26), cv2.FONT_HERSHEY_SIMPLEX, 0.6, (20,) * 3, 1,
                    cv2.LINE_AA)
        return cv2.cvtColor(image, cv2.COLOR_BGR2RGB)

    # -- measures ---------------------------------------------------------------------------------------------------
    @staticmethod
    def bounds(world) -> list:
        """Every bound record of every robot, by start time."""
        return sorted((r for b in world.scene.info["brains"].values() for r in b.bound_log), key=lambda r: r.start)

    def done(self, world) -> bool:
        info = world.scene.info
        if info["finished"] is None:
            last = len(world.scene.scenario.task.route) - 1
            ends = [r.end for b in info["brains"].values() for r in b.bound_log if r.bound == last and r.end]
            info["finished"] = min(ends) if ends else None
        return info["finished"] is not None

    def outcome(self, world) -> tuple[bool, dict]:
        scenario, brains = world.scene.scenario, world.scene.info["brains"]
        complete = self.done(world)
        gone = {}  # robot -> when a kill or remove took it (a fault by role: the robot it struck)
        for fault, struck in zip(world.schedule, world.struck):
            if fault.kind in ("kill", "remove") and struck is not None:
                gone.setdefault(struck[0], struck[1])
        groups = {n: [b.group, b.k.me.kind] for n, b in brains.items()}
        kinds = {g: {k: sum(1 for grp, kind in groups.values() if grp == g and kind == k) for k in KINDS}
                 for g in GROUPS}
        leaders = sorted(([r.group, r.robot, round(r.start, 2),
                           round(r.end, 2) if r.end is not None else gone.get(r.robot)]
                          for b in brains.values() for r in b.leaderships), key=lambda row: row[2])
        bounds = [[r.bound, r.group, r.robot, round(r.start, 2), None if r.end is None else round(r.end, 2)]
                  for r in self.bounds(world)]
        completed = sorted({row[0]: row for row in bounds if row[4] is not None}.values())
        alternated = [row[0] for row in completed] == list(range(len(completed))) and all(
            row[1] == GROUPS[row[0] % 2] for row in completed)
        metrics = {
            "mission_time_s": round(world.time, 3),
            "completion_time_s": None if world.scene.info["finished"] is None else
            round(world.scene.info["finished"], 2),
            "groups": groups,
            "group_kinds": kinds,
            "balanced": all(abs(kinds["A"][k] - kinds["B"][k]) <= 1 for k in KINDS),
            "joins": {n: [[g, round(t, 2)] for g, t in b.joins] for n, b in brains.items()},
            "switches": sum(max(0, len(b.joins) - 1) for b in brains.values()),
            "leaders": leaders,
            "bounds": bounds,
            "bounds_completed": len(completed),
            "route_length": len(scenario.task.route),
            "alternated": alternated,
            "final_positions": {n: [round(float(v), 3) for v in world.pose(r)[:2]] for n, r in world.robots.items()},
            "final_behaviour": {n: r.behaviour if r.active else "dead" for n, r in world.robots.items()},
            "gone": gone,
        }
        return complete, metrics
