"""``formation``: Parker's keeping formation, in physics (ch.7, §7.2; spec §4.5).

A line of robots (4 by default, 1-14) drives side by side while its leader follows a route of waypoints, each
robot keeping the same left and right neighbours (:mod:`teamsim.controllers.behaviours.formation`: the line, the
four strategies I-IV of KEEP_FORMATION, follow-route and avoid-obstacles). The route, drawn from the seed, has
``turns`` sharp corners or as many smooth arcs; static obstacles stand just outside the band the line sweeps
(they matter once the line breaks), and an optional second team crosses the route's middle leg when the line
gets there. Each robot senses its neighbours' (and from strategy II the leader's) relative poses locally, with
the positioning model's noise, every positioning period (:meth:`FormationMission.sense`).

Metric (§7.2): ``fe_t``, the sum over non-leaders of the distance to the proper place given the leader's current
pose (``leader + o_i`` across its heading), sampled at integer seconds; the normalised cumulative formation error
``cum_fe / t_max``; and the mission time ``t_max``: when the leader has reached the last waypoint and every robot
is within ``task.settle`` of its place. §7.2 does not say which way the line is laid across the leader: the
"route reading" (``fe_route``, ``normalised_error_route``) lays it across the leader's current leg of the route
instead of its heading (docs/decisions.md, "Keeping formation"). Also measured: seconds a follower spent turned
round (heading more than 120 degrees off the leader's) and seconds the line's left-to-right order was broken.
With robots killed or removed, all of it is over the living robots, with the living robot nearest the leader's
place acting as leader (:meth:`FormationMission.living`; docs/decisions.md, "Keeping formation": a failed robot).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np

from teamsim.config import ConfigError, RadioConfig, setting
from teamsim.controllers.behaviours.formation import (SIGNAL, STRATEGIES, Crossing, KeepFormation,
                                                      KeepFormationParams, Lanes, Line, RouteLeader, normal)
from teamsim.models.robot import RobotModel
from teamsim.positioning import wrap_angle
from teamsim.scenario import Arena, BoxObstacle, RobotEntry, Scenario, Spot, scene_of
from teamsim.scene import Scene
from teamsim.tasks.base import ScenarioMission
from teamsim.tasks.missions.formation_figures import panel_image, write_formation

NAMES = "ABCDEFGHIJKLMN"  # Fig. 7-1 names the line A, B, C, D from the left
MAX_ROBOTS = len(NAMES)  # §7.2: "1 to 14 robots"
KINDS = ("diffdrive", "tracked")  # differential drives: the pose estimate reads their wheel encoders
# Parker's simulated robots have no published dimensions: Chand's differential-drive robot, smaller and quicker to
# turn (docs/decisions.md, "Keeping formation").
ROBOT = {"radius": 0.25, "omega_max": 1.0, "accel_max": 0.4, "angular_accel_max": 1.5}
SHARP = (math.radians(80), math.radians(110))  # range of a corner's turn
ARC_STEP = math.radians(30)  # a smooth turn is an arc with a waypoint at least every 30 degrees
MARGIN = 3.0  # m of room beyond the band the line sweeps
PLACEMENT_ATTEMPTS = 60
TURNED_ROUND = math.radians(120)


@dataclass
class FormationParams:
    strategy: str = setting("IV", choices=STRATEGIES, meaning="KEEP_FORMATION strategy (§7.2): I local only, II + the "
                                                             "line relative to the leader, III + the next waypoint, "
                                                             "IV + the full route")
    robots: int = setting(4, lo=1, hi=MAX_ROBOTS, meaning="robots in the line (Fig. 7-1: 4; §7.2: 1 to 14)")
    spacing: float = setting(1.2, lo=0.6, hi=5.0, meaning="m between neighbours' centres")
    route: str = setting("sharp", choices=("sharp", "smooth"), meaning="the route's turns: corners of 80-110 degrees, "
                                                                       "or arcs of the same turn")
    turns: int = setting(3, lo=0, hi=8, meaning="turns along the route")
    leg: tuple[float, float] = setting((7.0, 10.0), lo=3.0, hi=50.0, meaning="range a leg's length is drawn from, m")
    smooth_radius: float = setting(2.0, lo=0.5, hi=20.0, meaning="m, the radius of a smooth turn's arc")
    obstacles: int = setting(2, lo=0, hi=20, meaning="static box obstacles just outside the band the line sweeps")
    crossing: int = setting(0, lo=0, hi=4, meaning="robots of a second team crossing the route's middle leg")
    radio_hz: float = setting(1.0, lo=0.01, hi=100.0, meaning="broadcasts per second (the leader's announcements)")


@dataclass
class FormationTask:
    strategy: str = setting("IV", choices=STRATEGIES, meaning="KEEP_FORMATION strategy (§7.2)")
    line: tuple[str, ...] = setting(("A", "B", "C", "D"), meaning="the line's robots, left to right")
    leader: str = setting("B", meaning="the group leader, one of the line (Fig. 7-1: B)")
    spacing: float = setting(1.2, lo=0.1, hi=20.0, meaning="m between neighbours' centres")
    route: list[Spot] = field(default_factory=list, metadata={"meaning": "the leader's waypoints, start first (at "
                                                                         "least two)"})
    settle: float = setting(0.5, lo=0.05, hi=10.0, meaning="m: the mission ends once the leader has reached the last "
                                                           "waypoint and every robot is this near its place")


@dataclass
class FormationSettings:
    route: list[Spot] = field(default_factory=list, metadata={"meaning": "a crossing robot's own route (empty for "
                                                                         "robots of the line)"})
    start_at: float = setting(0.0, lo=0.0, hi=1e6, meaning="s a crossing robot waits before it sets off")
    behaviour: KeepFormationParams = field(default_factory=KeepFormationParams, metadata={
        "meaning": "the formation behaviours' constants (`KeepFormationParams`)"})


def draw_route(rng: np.random.Generator, params: FormationParams) -> np.ndarray:
    """Waypoints from (0, 0) heading east: ``turns`` turns of 80-110 degrees alternating in side (the first side
    drawn), legs drawn from ``leg``; a smooth route replaces each corner by an arc of ``smooth_radius``."""
    lo, hi = params.leg
    if lo > hi:
        raise ConfigError(f"leg=[{lo:g}, {hi:g}]: the lower end must not exceed the upper")
    corners, heading, side = [np.zeros(2)], 0.0, float(rng.choice((-1.0, 1.0)))
    turns = []
    for _ in range(params.turns + 1):
        corners.append(corners[-1] + rng.uniform(lo, hi) * np.array([math.cos(heading), math.sin(heading)]))
        turn = side * float(rng.uniform(*SHARP))
        turns.append(turn)
        heading, side = heading + turn, -side
    if params.route == "sharp":
        return np.array(corners)
    points = [corners[0]]
    for k in range(1, len(corners) - 1):
        points += arc(corners[k - 1], corners[k], corners[k + 1], params.smooth_radius)
    return np.array(points + [corners[-1]])


def arc(before: np.ndarray, corner: np.ndarray, after: np.ndarray, radius: float) -> list[np.ndarray]:
    """Waypoints of the arc of ``radius`` tangent to both legs at ``corner``, one every ``ARC_STEP`` or less."""
    u1 = (corner - before) / np.linalg.norm(corner - before)
    u2 = (after - corner) / np.linalg.norm(after - corner)
    turn = wrap_angle(math.atan2(u2[1], u2[0]) - math.atan2(u1[1], u1[0]))
    tangent = radius * math.tan(abs(turn) / 2)
    start = corner - tangent * u1
    centre = start + math.copysign(radius, turn) * normal(math.atan2(u1[1], u1[0]))
    steps = max(2, math.ceil(abs(turn) / ARC_STEP))
    begin = math.atan2(start[1] - centre[1], start[0] - centre[0])
    return [centre + radius * np.array([math.cos(begin + turn * j / steps), math.sin(begin + turn * j / steps)])
            for j in range(steps + 1)]


def segment_distance(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    t = float(np.clip(np.dot(point - a, b - a) / max(np.dot(b - a, b - a), 1e-12), 0.0, 1.0))
    return float(np.linalg.norm(point - a - t * (b - a)))


class FormationMission(ScenarioMission):
    name = "formation"
    summary = "Parker's keeping formation: a side-by-side line follows its leader's route, strategies I-IV"
    Params = FormationParams
    Task = FormationTask
    Controller = FormationSettings
    default_duration = 600.0
    video_speedup = 2.0

    # -- the world -----------------------------------------------------------------------------------------------------
    @staticmethod
    def radio_of(params: FormationParams, radio: RadioConfig) -> RadioConfig:
        return dataclasses.replace(radio, rate_hz=params.radio_hz)

    def scenario(self, params: FormationParams, rng: np.random.Generator, newcomers) -> Scenario:
        if newcomers:
            raise ConfigError(f"--fault add-robot:{newcomers[0][0]}: the formation's line is fixed at the start; "
                              "allowed faults: kill, remove, revive, blind-ir, radio-off, radio-on, break-motor, slow")
        route = draw_route(rng, params)
        names = tuple(NAMES[:params.robots])
        line = Line(names, names[(len(names) - 1) // 2], params.spacing)
        heading = math.atan2(*(route[1] - route[0])[::-1])
        robots = {n: RobotEntry("diffdrive", (*(route[0] + line.offset(n) * normal(heading)), heading),
                                options=dict(ROBOT), controller=FormationSettings()) for n in names}
        robots.update(self._crossing(params, route, line, rng))
        band = (line.offset(names[0]), -line.offset(names[-1]))  # m the line reaches left and right of the route
        obstacles = self._obstacles(params, route, band, robots, rng)
        points = np.array([p for p in route] + [r.pose[:2] for r in robots.values()]
                          + [(b.x, b.y) for b in obstacles])
        low, high = points.min(axis=0) - max(band) - MARGIN, points.max(axis=0) + max(band) + MARGIN
        shift = -(low + high) / 2  # the room is centred on the origin
        route = route + shift
        robots = {n: dataclasses.replace(r, pose=(r.pose[0] + shift[0], r.pose[1] + shift[1], r.pose[2]),
                                         controller=dataclasses.replace(r.controller, route=[
                                             Spot(p.x + shift[0], p.y + shift[1]) for p in r.controller.route]))
                  for n, r in robots.items()}
        obstacles = [dataclasses.replace(b, x=b.x + shift[0], y=b.y + shift[1]) for b in obstacles]
        size = tuple(float(v) for v in high - low)
        task = FormationTask(params.strategy, names, line.leader, params.spacing,
                             [Spot(float(x), float(y)) for x, y in route])
        return Scenario(mission=self.name, arena=Arena(size=size, boxes=obstacles), robots=robots, task=task)

    @staticmethod
    def _crossing(params: FormationParams, route: np.ndarray, line: Line, rng) -> dict[str, RobotEntry]:
        """A second team, side by side, that crosses the middle of the route's middle leg at right angles, setting
        off so as to get there when the line does at cruise speed."""
        if params.crossing == 0:
            return {}
        k = (len(route) - 1) // 2
        middle = (route[k] + route[k + 1]) / 2
        along = np.linalg.norm(np.diff(route[:k + 1], axis=0), axis=1).sum() + np.linalg.norm(middle - route[k])
        leg = math.atan2(*(route[k + 1] - route[k])[::-1])
        heading = leg + float(rng.choice((-1.0, 1.0))) * math.pi / 2
        way = np.array([math.cos(heading), math.sin(heading)])
        run = max(line.offset(line.names[0]), -line.offset(line.names[-1])) + 4.0  # m from its start to the leg
        cruise = KeepFormationParams().cruise
        start_at = max(0.0, along / cruise - run / cruise)
        team = {}
        for j in range(params.crossing):
            side = (j - (params.crossing - 1) / 2) * 1.0 * normal(heading)
            start, end = middle - run * way + side, middle + run * way + side
            team[f"X{j + 1}"] = RobotEntry("diffdrive", (float(start[0]), float(start[1]), heading),
                                           options=dict(ROBOT), controller=FormationSettings(
                                               route=[Spot(*map(float, start)), Spot(*map(float, end))],
                                               start_at=round(start_at, 1)))
        return team

    @staticmethod
    def _obstacles(params: FormationParams, route: np.ndarray, band: tuple[float, float],
                   robots: dict[str, RobotEntry], rng) -> list[BoxObstacle]:
        """Boxes just outside the band the line sweeps, clear of every leg's band and of the robots' starts and
        routes (so they stand in the way only of a line out of formation)."""
        legs = list(zip(route[:-1], route[1:]))
        paths = [[np.array([p.x, p.y]) for p in r.controller.route] for r in robots.values() if r.controller.route]
        placed: list[BoxObstacle] = []
        for _ in range(params.obstacles):
            for _ in range(PLACEMENT_ATTEMPTS):
                a, b = legs[int(rng.integers(len(legs)))]
                side = float(rng.choice((-1.0, 1.0)))
                half = rng.uniform(0.2, 0.4, size=2)
                reach = float(np.hypot(*half))
                lateral = (band[0] if side > 0 else band[1]) + ROBOT["radius"] + reach + rng.uniform(0.3, 1.0)
                direction = (b - a) / np.linalg.norm(b - a)
                centre = a + rng.uniform(0.2, 0.8) * (b - a) + side * lateral * np.array([-direction[1], direction[0]])
                clear = min(segment_distance(centre, p, q) - max(band) for p, q in legs)
                crossing = min([segment_distance(centre, *path) for path in paths] or [math.inf])
                starts = min(math.dist(centre, r.pose[:2]) for r in robots.values())
                others = min([math.dist(centre, (o.x, o.y)) for o in placed] or [math.inf])
                if clear > reach + ROBOT["radius"] + 0.25 and crossing > reach + 1.5 and starts > reach + 1.0 \
                        and others > reach + 1.0:
                    placed.append(BoxObstacle(float(centre[0]), float(centre[1]), float(half[0]), float(half[1]),
                                              0.3, float(rng.uniform(-math.pi, math.pi))))
                    break
        return placed

    def check_scenario(self, scenario: Scenario) -> None:
        task = scenario.task
        if len(task.route) < 2:
            raise ConfigError(f"task.route: a route needs at least two waypoints; got {len(task.route)}")
        for k, (a, b) in enumerate(zip(task.route, task.route[1:])):
            if math.dist((a.x, a.y), (b.x, b.y)) < 0.5:
                raise ConfigError(f"task.route[{k + 1}]: within 0.5 m of the waypoint before it; waypoints must be "
                                  "at least 0.5 m apart")
        if not 1 <= len(task.line) <= MAX_ROBOTS or len(set(task.line)) != len(task.line):
            raise ConfigError(f"task.line: 1 to {MAX_ROBOTS} distinct robots (§7.2); got {len(task.line)}")
        if task.leader not in task.line:
            raise ConfigError(f"task.leader={task.leader!r}: must be one of task.line ({', '.join(task.line)})")
        for name in task.line:
            if name not in scenario.robots:
                raise ConfigError(f"task.line: {name!r} is not in robots; allowed: {', '.join(scenario.robots)}")
        for name, robot in scenario.robots.items():
            if robot.kind not in KINDS:
                raise ConfigError(f"robots.{name}.kind={robot.kind!r}: the formation is kept by differential drives; "
                                  f"allowed: {', '.join(KINDS)}")
            if name not in task.line and len(robot.controller.route) < 2:
                raise ConfigError(f"robots.{name}.controller.route: a robot outside task.line crosses on its own "
                                  f"route of at least two waypoints; got {len(robot.controller.route)}")

    def scene(self, scenario: Scenario, newcomers, physics_dt: float) -> Scene:
        scene = scene_of(scenario, newcomers, physics_dt)
        task, body = scenario.task, scene.arena.worldbody
        route = np.array([(p.x, p.y) for p in task.route])
        for k, (a, b) in enumerate(zip(route[:-1], route[1:])):  # the route painted on the floor (no contacts)
            centre, length = (a + b) / 2, float(np.linalg.norm(b - a))
            body.add("geom", name=f"route{k}", type="box", pos=[*centre, 0.002], size=[length / 2, 0.03, 0.001],
                     euler=[0, 0, math.atan2(*(b - a)[::-1])], rgba=[0.95, 0.85, 0.2, 1], contype=0, conaffinity=0)
        for k, p in enumerate(route):
            body.add("geom", name=f"waypoint{k}", type="cylinder", pos=[*p, 0.003], size=[0.12, 0.002],
                     rgba=[0.9, 0.4, 0.1, 1], contype=0, conaffinity=0)
        line = Line(tuple(task.line), task.leader, task.spacing)
        scene.info.update(line=line, route=route, brains={}, sensed={}, sense_rng={}, errors=[], distances=[],
                          route_errors=[], lanes=Lanes(route), leg=0, tracks={n: [] for n in scenario.robots},
                          turned_round_s=0, order_broken_s=0)
        return scene

    def controller(self, robot: RobotModel, scene: Scene, rng: np.random.Generator):
        scenario, info = scene.scenario, scene.info
        settings, task, line = scenario.robots[robot.name].controller, scenario.task, info["line"]
        if robot.name not in line.names:
            alone = Line((robot.name,), robot.name, task.spacing)
            route = np.array([(p.x, p.y) for p in settings.route])
            brain = Crossing(RouteLeader(robot, alone, "II", settings.behaviour, rng, route, announce=False), robot,
                             settings.start_at)
        elif robot.name == line.leader:
            brain = RouteLeader(robot, line, task.strategy, settings.behaviour, rng, info["route"])
        else:
            brain = KeepFormation(robot, line, task.strategy, settings.behaviour, rng, info["route"])
        info["brains"][robot.name] = brain
        return brain

    # -- local sensing of teammates ------------------------------------------------------------------------------------
    def sense(self, world, name: str) -> dict:
        """The relative poses (dx, dy in this robot's frame, dheading, time) of the teammates it senses, refreshed
        every positioning period with the positioning model's noise (still or moving, as the pair is)."""
        info = world.scene.info
        line: Line = info["line"]
        if name not in line.names:
            return {}
        cfg = world.positioning.config
        half = np.array(world.scene.scenario.arena.size) / 2
        last = info["sensed"].get(name)
        if last is not None and world.time < last[0] + cfg.period - 1e-9:
            return {SIGNAL: last[1]}
        if name not in info["sense_rng"]:  # (setdefault would build a generator every call)
            info["sense_rng"][name] = world.streams.get("robot", name, "formation")
        rng = info["sense_rng"][name]
        me = world.robots[name]
        x, y, yaw = world.pose(me)
        c, s = math.cos(yaw), math.sin(yaw)
        readings = {}
        brain = info["brains"].get(name)  # whom it looks for: its neighbours, re-linked past failed ones
        whom = brain.sensing() if brain is not None else line.sensed(name, world.scene.scenario.task.strategy)
        for other in whom:
            robot = world.robots[other]
            ox, oy, oyaw = world.pose(robot)
            if abs(ox) > half[0] or abs(oy) > half[1]:  # taken out of the arena (remove): out of sight
                continue
            moving = max(world.speed(me), world.speed(robot)) > cfg.moving_speed
            noise = rng.normal(0.0, cfg.noise_moving if moving else cfg.noise_still, 2)
            dx, dy = ox - x, oy - y
            readings[other] = (c * dx + s * dy + noise[0], -s * dx + c * dy + noise[1],
                               wrap_angle(oyaw - yaw + rng.normal(0.0, cfg.heading_noise)), world.time)
        info["sensed"][name] = (world.time, readings)
        return {SIGNAL: readings}

    # -- the metric, at integer seconds --------------------------------------------------------------------------------
    @staticmethod
    def living(world) -> Line:
        """The line as it is: its failed (killed or removed) robots marked, so the living robot nearest the
        leader's place acts as leader (:attr:`Line.acting`)."""
        line: Line = world.scene.info["line"]
        failed = frozenset(n for n in line.names if not world.robots[n].active)
        return dataclasses.replace(line, failed=failed) if failed else line

    def places(self, world, across: float | None = None) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """(true position, proper place) of every living robot of the line: the place given the (acting) leader's
        current pose, across its heading or, given ``across``, across that heading (the route reading: the
        leader's leg). A failed robot has no place to be in; an acting leader's own place is offset from the
        leader's, which the others' are taken from."""
        line = self.living(world)
        if line.acting is None:
            return {}
        lead = world.pose(world.robots[line.acting])
        side = normal(lead[2] if across is None else across)
        origin = lead[:2] if line.acting == line.leader else lead[:2] - line.offset(line.acting) * side
        return {n: (world.pose(world.robots[n])[:2], origin + line.offset(n) * side)
                for n in line.names if n not in line.failed}

    def _measure(self, world) -> None:
        info = world.scene.info
        if world.time + 1e-6 < len(info["errors"]):
            return
        line = self.living(world)  # failed robots have no place: the metric is over the living (the acting leader's
        acting = line.acting      # place is the leader's offset; it is no follower)
        for name, robot in world.robots.items():
            info["tracks"][name].append([round(float(v), 3) for v in world.pose(robot)])
        if acting is None:
            info["errors"].append(0.0)
            info["distances"].append({})
            info["route_errors"].append(0.0)
            return
        lead = line.lead({acting: world.pose(world.robots[acting])})
        info["leg"] = info["lanes"].leg_of(info["leg"], lead[:2], float(lead[2]), 1.0)
        places = self.places(world)
        distances = {n: float(np.linalg.norm(p - q)) for n, (p, q) in places.items() if n != acting}
        info["errors"].append(sum(distances.values()))
        info["distances"].append(distances)
        info["route_errors"].append(sum(float(np.linalg.norm(p - q)) for n, (p, q) in self.places(
            world, info["lanes"].headings[info["leg"]]).items() if n != acting))
        headings = [world.pose(world.robots[n])[2] for n in places if n != acting]
        info["turned_round_s"] += any(abs(wrap_angle(h - lead[2])) > TURNED_ROUND for h in headings)
        lateral = [float(np.dot(places[n][0] - lead[:2], normal(lead[2]))) for n in places]
        info["order_broken_s"] += any(a <= b for a, b in zip(lateral, lateral[1:]))

    def complete(self, world) -> bool:
        """The (acting) leader has finished its route and stands at its place at the route's end, and every
        living robot of the line is at its place: with robots failed, the living ones stand in their order
        with the failed ones' places empty (docs/decisions.md, "Keeping formation")."""
        info, task = world.scene.info, world.scene.scenario.task
        line = self.living(world)
        leader = info["brains"].get(line.acting) if line.acting is not None else None
        if leader is None or leader.finished_at is None:
            return False
        places = self.places(world)
        route = info["route"]
        end = route[-1] + line.offset(line.acting) * normal(math.atan2(*(route[-1] - route[-2])[::-1]))
        return (np.linalg.norm(places[line.acting][0] - end) <= task.settle
                and all(np.linalg.norm(p - q) <= task.settle for p, q in places.values()))

    def done(self, world) -> bool:
        self._measure(world)
        return self.complete(world)

    def outcome(self, world) -> tuple[bool, dict]:
        info = world.scene.info
        completed = self.complete(world)
        t_max = max(world.time, 1e-9)
        errors = info["errors"]
        per_robot = {n: round(float(np.mean([d[n] for d in info["distances"] if n in d])), 3)
                     for n in dict.fromkeys(n for d in info["distances"] for n in d)}  # (while it lived, led not)
        metrics = {
            "strategy": world.scene.scenario.task.strategy,
            "mission_time_s": round(world.time, 3),
            "cum_fe": round(float(sum(errors)), 3),
            "normalised_error": round(float(sum(errors)) / t_max, 4),
            "normalised_error_route": round(float(sum(info["route_errors"])) / t_max, 4),
            "max_fe": round(float(max(errors, default=0.0)), 3),
            "mean_distance_m": per_robot,
            "turned_round_s": int(info["turned_round_s"]),
            "order_broken_s": int(info["order_broken_s"]),
            "fe": [round(e, 3) for e in errors],
            "fe_route": [round(e, 3) for e in info["route_errors"]],
        }
        return completed, metrics

    # -- pictures ------------------------------------------------------------------------------------------------------
    def video_panel(self, world) -> np.ndarray | None:
        """The route from above, each robot and its proper place, and fe_t, beside the 3-D view (every second)."""
        info = world.scene.info
        if info.get("panel_at") == len(info["errors"]):
            return None
        info["panel_at"] = len(info["errors"])
        return cv2.cvtColor(panel_image(world.scene.scenario, info, self.places(world), world.time), cv2.COLOR_BGR2RGB)

    def write_outputs(self, world, run_dir: Path) -> None:
        """``formation.png``: the paths from above and the formation error over time."""
        write_formation(run_dir / "formation.png", world.scene.scenario, world.scene.info)

