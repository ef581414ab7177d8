"""``hazardous-waste``: Parker's flagship cleanup mission, in physics (§3.8, ch.5; spec §4.1).

A 26 ft x 12 ft room (7.92 m x 3.66 m) with its entrance in the middle of the west wall. Ten pucks lie in a
square at the centre of the front third (the third nearest the entrance); the goal is the back centre, by the
east wall. R-2s start by the entrance, told only that much: they find the locations themselves (by their
extents, :mod:`teamsim.controllers.behaviours.cleanup`), carry the pucks in their grippers under ALLIANCE, and report
progress from the entrance every ``report_interval``. Teams: {red, green} or {red, blue, green}; blue's and
green's side IR do not work (a ``blind-ir`` fault on the side sensors from t = 0), so only red has the methodical
find in its repertoire (§3.8.2).

It completes when ``completion`` of the pucks (8 of 10) lie in the goal zone, after any report the delivering
robot then makes (ch.5: "if the robot delivering the 8th puck decides to report, completion waits for that
report"). The goal zone, drawn on the floor, is the back sixth of the room across the middle half of its width:
the thesis gives no size. Measures: time; energy by Parker's count (a unit per second while any motor runs) and as
mechanical work; transports, pucks per transport, reports and reports per move; who ran find-locations.

The mission describes its worlds as scenarios (:mod:`teamsim.scenario`): the room, the spill (``objects.pucks``),
the team with each robot's cleanup settings, the side-IR faults, and the goal zone and entrance (``task``), so a
cleanup can be exported, edited (another room, another spill, a fourth robot) and re-run.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from teamsim.config import ConfigError, setting
from teamsim.controllers.alliance.lalliance import TaskStatistics, load_statistics, save_statistics
from teamsim.controllers.behaviours.cleanup import FIND, METHODICAL, MOVE, REPORT, WANDER, CleanupParams, CleanupRobot
from teamsim.models.objects import PuckDims
from teamsim.models.robot import RobotModel
from teamsim.scenario import MAX_EXTENT, Arena, FaultEntry, Objects, RobotEntry, Scenario, Spot, scene_of
from teamsim.scene import Scene
from teamsim.tasks.base import ScenarioMission

FOOT = 0.3048
ROOM = (26 * FOOT, 12 * FOOT)  # Parker §2.2.3: the 26 x 12 ft work area
TEAMS = {2: ("red", "green"), 3: ("red", "blue", "green")}
SIDE_IR_WORKS = ("red",)  # §3.8.1: blue's and green's side IR are dysfunctional
SIDE_IR = "ir_left+ir_right"  # the blind-ir fault's sensor prefixes for the side sensors
# The goal zone (the thesis gives no size): the back sixth of the room's length (as deep as the spill's centre
# lies from the entrance) across the middle half of its width.
GOAL_SIZE = (ROOM[0] / 6, ROOM[1] / 2)
START_X = 0.75  # m from the west wall: clear of a robot following that wall
START_GAP = 0.6  # m between robots at the start, across the entrance
SPILL_DRAWS = 1000  # random spots tried per puck before the spill is declared too small for the pucks
ENTRANCE_HALF_WIDTH = 0.4  # m: the entrance marker drawn on the wall (a marker, not a gap: see docs/decisions.md)


@dataclass
class HazardousWasteParams:
    robots: int = setting(3, choices=(2, 3), meaning="team size: 2 = {red, green}, 3 = {red, blue, green}")
    pucks: int = setting(10, lo=1, hi=30, meaning="pucks in the spill (§3.8: 10)")
    completion: float = setting(0.8, lo=0.0, open_lo=True, hi=1.0,
                                meaning="fraction of the pucks at the goal that completes the mission (ch.5: 80 %)")
    report_interval: float = setting(240.0, lo=1.0, meaning="s between team progress reports ('about every "
                                                            "4 minutes', §3.8)")
    spill_size: float = setting(0.4, lo=0.1, hi=1.5, meaning="side of the square the pucks are scattered in, m")


@dataclass
class HazardousWasteTask:
    """The cleanup's own scenario settings: when it is done, and where the goal zone and entrance are drawn. The
    robots are told none of this: they find the locations themselves."""
    completion: float = setting(0.8, lo=0.0, open_lo=True, hi=1.0,
                                meaning="fraction of the pucks in the goal zone that completes the mission "
                                        "(ch.5: 80 %)")
    goal: tuple[float, float] = setting((ROOM[0] / 2 - GOAL_SIZE[0] / 2, 0.0), lo=-MAX_EXTENT, hi=MAX_EXTENT,
                                        meaning="centre of the goal zone x, y, m (the back centre, §3.8)")
    goal_size: tuple[float, float] = setting(GOAL_SIZE, lo=0.0, open_lo=True, hi=MAX_EXTENT,
                                             meaning="the goal zone's extent along x and y, m (not in the thesis: "
                                                     "the back sixth of the room across half its width)")
    entrance: tuple[float, float] = setting((-ROOM[0] / 2, 0.0), lo=-MAX_EXTENT, hi=MAX_EXTENT,
                                            meaning="where the entrance marker is drawn, x, y, m (drawn only: the "
                                                    "robots take their start as home and report there)")

    def target(self, pucks: int) -> int:
        """How many pucks in the goal zone complete the mission."""
        return math.ceil(self.completion * pucks - 1e-9)

    def in_goal(self, x: float, y: float) -> bool:
        return abs(x - self.goal[0]) <= self.goal_size[0] / 2 and abs(y - self.goal[1]) <= self.goal_size[1] / 2


@dataclass
class CleanupSettings:
    """One R-2's cleanup controller (:class:`teamsim.controllers.behaviours.cleanup.CleanupRobot`)."""
    methodical: bool = setting(True, meaning="the methodical find (wall-following with the side IR) is in its "
                                             "repertoire; §3.8.2: only red, whose side IR works")
    behaviour: CleanupParams = field(default_factory=CleanupParams, metadata={
        "meaning": "the cleanup behaviours' constants (`CleanupParams` in `teamsim.controllers.behaviours.cleanup`)"})
    learned: str = setting("", meaning="what it learned before: a run's `learned/ROBOT.json` (L-ALLIANCE's task "
                                       "times carry over from mission to mission, §4.4.2); empty: nothing")


def read_statistics(field_name: str, path: str, robot: str) -> TaskStatistics:
    """A robot's learned statistics from a file, or a one-line error naming the field."""
    try:
        statistics = load_statistics(path)
    except OSError as exc:
        raise ConfigError(f"{field_name}={path!r}: cannot read ({exc.strerror or exc})") from None
    except ValueError as exc:  # (json's decode errors are ValueErrors too)
        raise ConfigError(f"{field_name}={path!r}: {' '.join(str(exc).split())}") from None
    if statistics.robot != robot:
        raise ConfigError(f"{field_name}={path!r}: these are {statistics.robot}'s statistics, not {robot}'s")
    return statistics


class HazardousWasteMission(ScenarioMission):
    name = "hazardous-waste"
    summary = "Parker's cleanup: R-2s find a puck spill, carry it to the goal and report, under ALLIANCE"
    Params = HazardousWasteParams
    Task = HazardousWasteTask
    Controller = CleanupSettings
    default_duration = 1800.0
    video_speedup = 4.0  # a mission takes minutes: its video plays four simulated seconds a second

    def scenario(self, params: HazardousWasteParams, rng: np.random.Generator, newcomers) -> Scenario:
        west = -ROOM[0] / 2
        team = TEAMS[params.robots]
        taken = [name for name, _ in newcomers if name in team]
        if taken:
            raise ConfigError(f"--fault add-robot:{taken[0]}: robot {taken[0]!r} is already in the team")
        # The team stands in a row across the entrance; newcomers extend the row, alternately south and north.
        ys = (np.arange(len(team)) - (len(team) - 1) / 2) * START_GAP
        extra = [(k // 2 + 1) * START_GAP * (-1 if k % 2 == 0 else 1) for k in range(len(newcomers))]
        rows = [ys[0] + y if y < 0 else ys[-1] + y for y in extra]
        behaviour = CleanupParams(report_interval=params.report_interval)
        robots = {name: RobotEntry("r2", (west + START_X, float(y), 0.0),
                                   controller=CleanupSettings(name in SIDE_IR_WORKS, behaviour))
                  for name, y in zip(team, ys)}
        robots.update({name: RobotEntry(kind, (west + START_X, float(y), 0.0),
                                        controller=CleanupSettings(True, behaviour))
                       for (name, kind), y in zip(newcomers, rows)})
        pucks = [Spot(x, y) for x, y in self.spill_layout(params, rng)]
        blind = [FaultEntry("blind-ir", name, 0.0, {"sensors": SIDE_IR}) for name in team
                 if name not in SIDE_IR_WORKS]
        return Scenario(mission=self.name, arena=Arena(size=ROOM), objects=Objects(pucks=pucks), robots=robots,
                        task=HazardousWasteTask(completion=params.completion), faults=blind)

    @staticmethod
    def spill_layout(params: HazardousWasteParams, rng: np.random.Generator) -> list[tuple[float, float]]:
        """Puck centres scattered uniformly in the spill square at the centre of the front third, at least a
        puck's diameter plus 1 cm apart; ConfigError if ``SPILL_DRAWS`` draws per puck do not place them all (too
        many pucks for the square)."""
        centre = np.array([-ROOM[0] / 2 + ROOM[0] / 6, 0.0])
        gap = 2 * PuckDims().radius + 0.01
        points: list[np.ndarray] = []
        draws = 0
        while len(points) < params.pucks and draws < SPILL_DRAWS * params.pucks:
            draws += 1
            p = centre + rng.uniform(-0.5, 0.5, size=2) * params.spill_size
            if all(np.hypot(*(p - q)) >= gap for q in points):
                points.append(p)
        if len(points) < params.pucks:
            raise ConfigError(f"pucks={params.pucks}: that many pucks {gap:g} m apart do not fit in a spill of "
                              f"{params.spill_size:g} m (spill_size); allowed: fewer pucks or a larger spill_size")
        return [(float(x), float(y)) for x, y in points]

    def check_scenario(self, scenario: Scenario) -> None:
        """R-2s only (the cleanup needs a gripper), pucks to move, and a goal zone inside the room."""
        for name, robot in scenario.robots.items():
            if robot.kind != "r2":
                raise ConfigError(f"robots.{name}.kind={robot.kind!r}: the cleanup is done by R-2s; allowed: r2")
        if not scenario.objects.pucks:
            raise ConfigError("objects.pucks: the cleanup needs at least one puck")
        task, (hx, hy) = scenario.task, (scenario.arena.size[0] / 2, scenario.arena.size[1] / 2)
        for axis, (centre, size, half) in enumerate(zip(task.goal, task.goal_size, (hx, hy))):
            if abs(centre) + size / 2 > half + 1e-9:
                raise ConfigError(f"task.goal / task.goal_size: the goal zone must lie inside the arena, "
                                  f"{'xy'[axis]} in [{-half:g}, {half:g}]; it spans [{centre - size / 2:g}, "
                                  f"{centre + size / 2:g}]")

    def scene(self, scenario: Scenario, newcomers, physics_dt: float) -> Scene:
        scene = scene_of(scenario, newcomers, physics_dt)
        task, worldbody = scenario.task, scene.arena.worldbody
        # The entrance marker stands just outside the wall nearest it, on its outer face.
        hx, hy = scenario.arena.size[0] / 2, scenario.arena.size[1] / 2
        x, y = task.entrance
        thickness = scenario.arena.wall_thickness
        along_y = hx - abs(x) <= hy - abs(y)  # on the west or east wall
        pos = ([math.copysign(hx + thickness / 2, x), y] if along_y else [x, math.copysign(hy + thickness / 2, y)])
        size = [thickness / 2 + 0.005, ENTRANCE_HALF_WIDTH] if along_y else [ENTRANCE_HALF_WIDTH, thickness / 2 + 0.005]
        worldbody.add("geom", name="entrance", type="box", pos=[*pos, scenario.arena.wall_height],
                      size=[*size, 0.002], rgba=[0.2, 0.6, 0.9, 1], contype=0, conaffinity=0)
        worldbody.add("geom", name="goal_zone", type="box", pos=[*task.goal, 0.0008],
                      size=[task.goal_size[0] / 2, task.goal_size[1] / 2, 0.0008], rgba=[0.3, 0.75, 0.35, 0.6],
                      contype=0, conaffinity=0)
        scene.info.update(pucks=[f"puck{k}/puck" for k in range(len(scenario.objects.pucks))], controllers={},
                          target=task.target(len(scenario.objects.pucks)))
        return scene

    def controller(self, robot: RobotModel, scene: Scene, rng: np.random.Generator):
        settings = scene.scenario.robots[robot.name].controller
        learned = None
        if settings.learned:
            learned = read_statistics(f"robots.{robot.name}.controller.learned", settings.learned, robot.name)
        brain = CleanupRobot(robot, rng, settings.behaviour, methodical=settings.methodical, learned=learned)
        scene.info["controllers"][robot.name] = brain
        return brain

    def write_outputs(self, world, run_dir: Path) -> None:
        """Each robot's learned task times, ``learned/ROBOT.json``: readable, and the next mission's start."""
        (run_dir / "learned").mkdir(exist_ok=True)
        for name, brain in world.scene.info["controllers"].items():
            save_statistics(run_dir / "learned" / f"{name}.json", brain.learning.statistics)

    # -- measures -------------------------------------------------------------------------------------------
    @staticmethod
    def pucks_at_goal(world) -> int:
        task = world.scene.scenario.task
        return sum(task.in_goal(*world.data.body(body).xpos[:2]) for body in world.scene.info["pucks"])

    def progress(self, world) -> float:
        """Pucks in the goal out of the target, in [0, 1] (the reward of ``teamsim.env``)."""
        return min(1.0, self.pucks_at_goal(world) / world.scene.info["target"])

    def done(self, world) -> bool:
        if self.pucks_at_goal(world) < world.scene.info["target"]:
            return False
        brains = world.scene.info["controllers"]
        return not any(r.active and (brains[n].active == REPORT or brains[n].knowledge.report_due(world.time))
                       for n, r in world.robots.items() if n in brains)

    def outcome(self, world) -> tuple[bool, dict]:
        brains = world.scene.info["controllers"]
        at_goal = self.pucks_at_goal(world)
        target = world.scene.info["target"]
        transports = sum(b.knowledge.transports for b in brains.values())
        reports = sum(b.knowledge.reports for b in brains.values())
        robots = world.robot_summary()
        find_sets = (METHODICAL, WANDER)
        metrics = {
            "pucks_at_goal": at_goal,
            "target": target,
            "mission_time_s": round(world.time, 3),
            "energy_parker_units": round(sum(r["parker_energy_units"] for r in robots.values()), 3),
            "energy_j": round(sum(r["energy_j"] for r in robots.values()), 3),
            "transports": transports,
            "pucks_per_transport": round(at_goal / transports, 3) if transports else None,
            "reports": reports,
            "reports_per_move": round(reports / transports, 3) if transports else None,
            "find_locations_by": sorted(n for n, r in robots.items()
                                        if any(r["task_time_s"].get(s, 0) > 0 for s in find_sets)),
            "per_robot": {n: {"transports": b.knowledge.transports, "reports": b.knowledge.reports,
                              "escapes": b.unstick.escapes, "located": b.knowledge.located,
                              **believed_locations(b.knowledge)}
                          for n, b in brains.items()},
            "task_time_s": {task: round(sum(r["task_time_s"].get(s, 0.0) for r in robots.values()
                                            for s in sets), 3)
                            for task, sets in ((FIND, find_sets), (MOVE, (MOVE,)), (REPORT, (REPORT,)))},
        }
        return at_goal >= target, metrics


def believed_locations(knowledge) -> dict:
    """Where a robot believes the spill, the goal and the entrance are (m, rounded to the cm), if it found them or
    heard them: a goal believed short of the goal zone explains pucks delivered short of it."""
    if not knowledge.located:
        return {}
    return {k: [round(float(v), 2) for v in getattr(knowledge, k)] for k in ("spill", "goal", "entrance")}
