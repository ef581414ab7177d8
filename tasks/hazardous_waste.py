"""``hazardous-waste``: Parker's flagship cleanup mission, in physics (§3.8, ch.5; spec §4.1).

A 26 ft x 12 ft room (7.92 m x 3.66 m) with its entrance in the middle of the west wall. Ten pucks lie in a
square at the centre of the front third (the third nearest the entrance); the goal is the back centre, by the
east wall. R-2s start by the entrance, told only that much: they find the locations themselves (by their
extents, :mod:`teamsim.controllers.cleanup`), carry the pucks in their grippers under ALLIANCE, and report
progress from the entrance every ``report_interval``. Teams: {red, green} or {red, blue, green}; blue's and
green's side IR do not work (a ``blind-ir`` fault on the side sensors from t = 0), so only red has the methodical
find in its repertoire (§3.8.2).

It completes when ``completion`` of the pucks (8 of 10) lie in the goal zone, after any report the delivering
robot then makes (ch.5: "if the robot delivering the 8th puck decides to report, completion waits for that
report"). The goal zone, drawn on the floor, is the back sixth of the room across the middle half of its width:
the thesis gives no size. Measures: time; energy by Parker's count (a unit per second while any motor runs) and as
mechanical work; transports, pucks per transport, reports and reports per move; who ran find-locations.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from teamsim.config import setting
from teamsim.controllers.cleanup import FIND, METHODICAL, MOVE, REPORT, WANDER, CleanupParams, CleanupRobot
from teamsim.faults import Fault
from teamsim.models.arenas import walled_room
from teamsim.models.objects import PuckDims, place, puck
from teamsim.models.robot import RobotModel
from teamsim.tasks.base import RobotSlot, Scene

FOOT = 0.3048
ROOM = (26 * FOOT, 12 * FOOT)  # Parker §2.2.3: the 26 x 12 ft work area
TEAMS = {2: ("red", "green"), 3: ("red", "blue", "green")}
SIDE_IR_WORKS = ("red",)  # §3.8.1: blue's and green's side IR are dysfunctional
SIDE_IR = "ir_left+ir_right"  # the blind-ir fault's sensor prefixes for the side sensors
# The goal zone (the thesis gives no size): the back sixth of the room's length (as deep as the spill's centre
# lies from the entrance) across the middle half of its width.
GOAL_DEPTH, GOAL_WIDTH = ROOM[0] / 6, ROOM[1] / 2
START_X = 0.75  # m from the west wall: clear of a robot following that wall
START_GAP = 0.6  # m between robots at the start, across the entrance


@dataclass
class HazardousWasteParams:
    robots: int = setting(3, choices=(2, 3), meaning="team size: 2 = {red, green}, 3 = {red, blue, green}")
    pucks: int = setting(10, lo=1, hi=30, meaning="pucks in the spill (§3.8: 10)")
    completion: float = setting(0.8, lo=0.0, open_lo=True, hi=1.0,
                                meaning="fraction of the pucks at the goal that completes the mission (ch.5: 80 %)")
    report_interval: float = setting(240.0, lo=1.0, meaning="s between team progress reports ('about every "
                                                            "4 minutes', §3.8)")
    spill_size: float = setting(0.4, lo=0.1, hi=1.5, meaning="side of the square the pucks are scattered in, m")

    @property
    def target(self) -> int:
        return math.ceil(self.completion * self.pucks - 1e-9)


class HazardousWasteMission:
    name = "hazardous-waste"
    summary = "Parker's cleanup: R-2s find a puck spill, carry it to the goal and report, under ALLIANCE"
    Params = HazardousWasteParams
    default_duration = 1800.0
    video_speedup = 4.0  # a mission takes minutes: its video plays four simulated seconds a second

    def build(self, params: HazardousWasteParams, rng: np.random.Generator, newcomers, physics_dt: float) -> Scene:
        length, width = ROOM
        arena = walled_room(length, width, physics_dt=physics_dt)
        west = -length / 2
        arena.worldbody.add("geom", name="entrance", type="box", pos=[west - 0.05, 0, 0.5],
                            size=[0.055, 0.4, 0.002], rgba=[0.2, 0.6, 0.9, 1], contype=0, conaffinity=0)
        goal = self.goal_zone()
        arena.worldbody.add("geom", name="goal_zone", type="box", pos=[goal[0], goal[1], 0.0008],
                            size=[GOAL_DEPTH / 2, GOAL_WIDTH / 2, 0.0008], rgba=[0.3, 0.75, 0.35, 0.6],
                            contype=0, conaffinity=0)
        for k, (x, y) in enumerate(self.spill_layout(params, rng)):
            place(arena, puck(f"puck{k}"), x, y)
        team = TEAMS[params.robots]
        ys = (np.arange(len(team)) - (len(team) - 1) / 2) * START_GAP
        slots = [RobotSlot(name, "r2", west + START_X, float(y), 0.0) for name, y in zip(team, ys)]
        slots += [RobotSlot(name, kind, west + START_X, 0.0, 0.0, dormant=True) for name, kind in newcomers]
        faults = [Fault("blind-ir", name, 0.0, {"sensors": SIDE_IR}) for name in team if name not in SIDE_IR_WORKS]
        return Scene(arena=arena, robots=slots, params=params, faults=faults,
                     info={"pucks": [f"puck{k}/puck" for k in range(params.pucks)], "controllers": {}})

    @staticmethod
    def spill_centre() -> tuple[float, float]:
        return -ROOM[0] / 2 + ROOM[0] / 6, 0.0

    @staticmethod
    def goal_zone() -> tuple[float, float]:
        return ROOM[0] / 2 - GOAL_DEPTH / 2, 0.0

    def spill_layout(self, params: HazardousWasteParams, rng: np.random.Generator) -> list[tuple[float, float]]:
        """Puck centres scattered uniformly in the spill square, at least a puck's diameter plus 1 cm apart."""
        cx, cy = self.spill_centre()
        gap = 2 * PuckDims().radius + 0.01
        points: list[np.ndarray] = []
        while len(points) < params.pucks:
            p = np.array([cx, cy]) + rng.uniform(-0.5, 0.5, size=2) * params.spill_size
            if all(np.hypot(*(p - q)) >= gap for q in points):
                points.append(p)
        return [(float(x), float(y)) for x, y in points]

    def controller(self, robot: RobotModel, scene: Scene, rng: np.random.Generator):
        params = CleanupParams(report_interval=scene.params.report_interval)
        brain = CleanupRobot(robot, rng, params, methodical=robot.name in SIDE_IR_WORKS)
        scene.info["controllers"][robot.name] = brain
        return brain

    # -- measures -------------------------------------------------------------------------------------------
    @staticmethod
    def pucks_at_goal(world) -> int:
        gx, gy = HazardousWasteMission.goal_zone()
        count = 0
        for body in world.scene.info["pucks"]:
            x, y = world.data.body(body).xpos[:2]
            count += abs(x - gx) <= GOAL_DEPTH / 2 and abs(y - gy) <= GOAL_WIDTH / 2
        return count

    def done(self, world) -> bool:
        if self.pucks_at_goal(world) < world.scene.params.target:
            return False
        brains = world.scene.info["controllers"]
        return not any(r.active and (brains[n].active == REPORT or brains[n].knowledge.report_due(world.time))
                       for n, r in world.robots.items() if n in brains)

    def outcome(self, world) -> tuple[bool, dict]:
        brains = world.scene.info["controllers"]
        at_goal = self.pucks_at_goal(world)
        transports = sum(b.knowledge.transports for b in brains.values())
        reports = sum(b.knowledge.reports for b in brains.values())
        robots = world.robot_summary()
        find_sets = (METHODICAL, WANDER)
        metrics = {
            "pucks_at_goal": at_goal,
            "target": world.scene.params.target,
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
                              "located": b.knowledge.located} for n, b in brains.items()},
            "task_time_s": {task: round(sum(r["task_time_s"].get(s, 0.0) for r in robots.values()
                                            for s in sets), 3)
                            for task, sets in ((FIND, find_sets), (MOVE, (MOVE,)), (REPORT, (REPORT,)))},
        }
        return at_goal >= world.scene.params.target, metrics
