"""``box-pushing``: Parker's box pushing demonstration, in physics (§6.1; spec §4.2).

A long heavy box (:class:`teamsim.models.objects.BoxDims`: one R-2 at its middle cannot slide it) lies across
Parker's 26 x 12 ft room near the west wall, its length across the room. An R-2 ("red") faces its left end and
another R-2 ("green") or Genghis-II ("genghis") its right end (left and right as seen from behind the box,
looking east). They push the ends in turn under ALLIANCE (:mod:`teamsim.controllers.behaviours.box_pushing`),
and the box crosses the room through the contact forces of their pushes. The mission completes when the box's
centre has advanced ``advance`` m along its starting normal (3 m by default, past the middle of the room, which two
R-2s take about 8 minutes over; the thesis says only "across a room").

Parker's experiments are faults: ``remove:green@T`` takes an R-2 away (§6.1.2 "seized and switched off"),
``revive:green@T`` brings it back, ``add-robot:genghis@T,kind=genghis2`` brings Genghis-II in. A robot that
enters (or is put back) is set down behind whichever end of the box has no robot near it, facing the box
(:meth:`BoxPushingMission.entry_pose`). Measures: the box's advance and heading drift, and every push (who,
which end, when its set was activated and when it was complete), from which ``teamsim study box-pushing``
computes takeover pauses and push rates.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np

from teamsim.config import ConfigError, setting
from teamsim.controllers.behaviours.box_pushing import (ENDS, LEFT, OPPOSITE, RIGHT, BoxPushParams,
                                                        GenghisBoxPusher, R2BoxPusher)
from teamsim.models.genghis2 import Genghis2Dims
from teamsim.models.objects import BoxDims
from teamsim.models.r2 import R2Dims
from teamsim.models.robot import RobotModel
from teamsim.positioning import wrap_angle
from teamsim.scenario import Arena, HeavyBox, Objects, RobotEntry, Scenario, scene_of
from teamsim.scene import Scene
from teamsim.tasks.base import ScenarioMission

FOOT = 0.3048
ROOM = (26 * FOOT, 12 * FOOT)  # Parker §2.2.3: the 26 x 12 ft work area
BOX_START = 1.0  # m from the west wall to the box's back face
KINDS = ("r2", "genghis2")
# How far a robot's centre stands back from the box's face: its enclosing circle clear of the box by 1 cm (the
# R-2's fingertips are then 6 cm from it, Genghis-II's whiskers 5 cm).
STAND_BACK = {"r2": math.hypot(R2Dims().back_x, R2Dims().width / 2) + 0.01,
              "genghis2": math.hypot(Genghis2Dims().length, Genghis2Dims().width) / 2 + 0.01}
CLEAR = 0.6  # m: an end with a live robot nearer than this is taken, when a robot enters
WAIT_BACK = 0.8  # m: how much further back than its teammate a robot entering a full team waits ...
WALL_GAP = 0.03  # m: ... if the room allows, its enclosing circle this clear of the wall (the box starts near one)


@dataclass
class BoxPushingParams:
    right: str = setting("r2", choices=KINDS, meaning="who faces the right end at the start: an R-2 (green) or "
                                                      "Genghis-II (genghis); red, an R-2, faces the left end")
    advance: float = setting(3.0, lo=0.1, hi=100.0, meaning="m the box's centre must advance (across the room)")
    behaviour: BoxPushParams = field(default_factory=BoxPushParams, metadata={
        "meaning": "the box-pushing behaviours' constants (`BoxPushParams` in "
                   "`teamsim.controllers.behaviours.box_pushing`)"})


@dataclass
class BoxPushingTask:
    advance: float = setting(3.0, lo=0.1, hi=100.0, meaning="m the box's centre must advance along its starting "
                                                             "normal for the mission to complete")


@dataclass
class PusherSettings:
    """One robot's box-pushing controller."""
    end: str = setting(LEFT, choices=ENDS, meaning="the end of the box the robot faces at the start")
    acquires: bool | None = setting(None, meaning="it can acquire the other end (Fig. 6-1; null: by kind, R-2 yes, "
                                                  "Genghis-II no, §6.1.1)")
    behaviour: BoxPushParams = field(default_factory=BoxPushParams, metadata={
        "meaning": "the box-pushing behaviours' constants"})


def behind_end(box: tuple[float, float, float], dims: BoxDims, end: str, kind: str,
               inset: float) -> tuple[float, float, float]:
    """The pose facing ``end`` of a box at (x, y, yaw), ``STAND_BACK`` behind its back face, ``inset`` in from the
    end (where the robot pushes: ``BoxPushParams.end_inset``). The box's length lies along its local y; it is
    pushed along its local +x, so its left end is at +y."""
    x, y, yaw = box
    normal, along = np.array([math.cos(yaw), math.sin(yaw)]), np.array([-math.sin(yaw), math.cos(yaw)])
    sign = 1.0 if end == LEFT else -1.0
    centre = (np.array([x, y]) + along * sign * (dims.length / 2 - inset)
              - normal * (dims.depth / 2 + STAND_BACK[kind]))
    return float(centre[0]), float(centre[1]), yaw


def reach_to_walls(x: float, y: float, heading: float, margin: float, room: tuple[float, float]) -> float:
    """How far a point at (x, y) can move along ``heading`` and stay ``margin`` inside the walls of a ``room``
    centred on the origin, m (0 if it is not that far inside now)."""
    reach = math.inf
    for at, step, half in ((x, math.cos(heading), room[0] / 2), (y, math.sin(heading), room[1] / 2)):
        if abs(step) > 1e-9:
            reach = min(reach, (math.copysign(max(half - margin, 0.0), step) - at) / step)
    return max(0.0, reach)


class BoxPushingMission(ScenarioMission):
    name = "box-pushing"
    summary = "Parker's box pushing: two R-2s (or an R-2 and Genghis-II) push a long box's ends in turn, ALLIANCE"
    Params = BoxPushingParams
    Task = BoxPushingTask
    Controller = PusherSettings
    # One R-2 alone (the survivor of a kill or removal) advances the box 2.0 mm/s, two 7.7 mm/s (measured, seed 0,
    # kill:green@124.4): a lone R-2 needs about 1500 s for the 3 m, so a fault early in the run needs this long
    # (docs/box-pushing.md, "Faults"; docs/decisions.md).
    default_duration = 1800.0
    video_speedup = 4.0  # a mission takes minutes: its video plays four simulated seconds a second

    def scenario(self, params: BoxPushingParams, rng: np.random.Generator, newcomers) -> Scenario:
        dims = BoxDims()
        box = (-ROOM[0] / 2 + BOX_START + dims.depth / 2, 0.0, 0.0)
        team = {"red": ("r2", LEFT), ("green" if params.right == "r2" else "genghis"): (params.right, RIGHT)}
        inset = params.behaviour.end_inset
        robots = {name: RobotEntry(kind, behind_end(box, dims, end, kind, inset), controller=PusherSettings(
            end, behaviour=params.behaviour)) for name, (kind, end) in team.items()}
        for k, (name, kind) in enumerate(newcomers):  # a start pose by the east wall, never used: entry_pose
            if name in robots:                        # sets them down at a free end when they join
                raise ConfigError(f"--fault add-robot:{name}: robot {name!r} is already in the team")
            robots[name] = RobotEntry(kind, (ROOM[0] / 2 - 0.5, ROOM[1] / 2 - 0.5 - 0.6 * k, 0.0),
                                      controller=PusherSettings(RIGHT, behaviour=params.behaviour))
        return Scenario(mission=self.name, arena=Arena(size=ROOM), robots=robots,
                        objects=Objects(boxes=[HeavyBox(box[0], box[1], box[2])], box=dims),
                        task=BoxPushingTask(advance=params.advance))

    def check_scenario(self, scenario: Scenario) -> None:
        """One box, R-2s and Genghis-IIs only, Genghis-II never acquiring, and room for the box to advance."""
        boxes = scenario.objects.boxes
        if len(boxes) != 1:
            raise ConfigError(f"objects.boxes: box pushing needs exactly one box; got {len(boxes)}")
        for name, robot in scenario.robots.items():
            if robot.kind not in KINDS:
                raise ConfigError(f"robots.{name}.kind={robot.kind!r}: box pushing is done by R-2s and Genghis-II; "
                                  f"allowed: {', '.join(KINDS)}")
            if robot.kind == "genghis2" and robot.controller.acquires:
                raise ConfigError(f"robots.{name}.controller.acquires=true: Genghis-II cannot acquire the other end "
                                  "of the box (§6.1.1); allowed: false or null")
        box, dims, hx, hy = boxes[0], scenario.objects.box, scenario.arena.size[0] / 2, scenario.arena.size[1] / 2
        x, y = box.x + scenario.task.advance * math.cos(box.yaw), box.y + scenario.task.advance * math.sin(box.yaw)
        reach = (abs(dims.depth / 2 * math.cos(box.yaw)) + abs(dims.length / 2 * math.sin(box.yaw)),
                 abs(dims.depth / 2 * math.sin(box.yaw)) + abs(dims.length / 2 * math.cos(box.yaw)))
        if abs(x) + reach[0] > hx or abs(y) + reach[1] > hy:
            raise ConfigError(f"task.advance={scenario.task.advance:g}: the box would leave the "
                              f"{scenario.arena.size[0]:g} x {scenario.arena.size[1]:g} m room before it advanced "
                              f"that far; allowed: up to about {self.room_ahead(scenario):.2f} m")

    @staticmethod
    def room_ahead(scenario: Scenario) -> float:
        """How far the box can advance along its normal before its front face meets a wall, m."""
        box, dims = scenario.objects.boxes[0], scenario.objects.box
        return reach_to_walls(box.x, box.y, box.yaw, dims.depth / 2, scenario.arena.size)

    def scene(self, scenario: Scenario, newcomers, physics_dt: float) -> Scene:
        scene = scene_of(scenario, newcomers, physics_dt)
        box = scenario.objects.boxes[0]
        scene.info.update(brains=[], ends={}, waiting=set(), start=(box.x, box.y, box.yaw))
        return scene

    def controller(self, robot: RobotModel, scene: Scene, rng: np.random.Generator):
        settings = scene.scenario.robots[robot.name].controller
        end = scene.info["ends"].get(robot.name, settings.end)
        params = settings.behaviour
        waiting = robot.name in scene.info.get("waiting", ())
        if robot.kind == "genghis2":
            brain = GenghisBoxPusher(robot, end, params, waiting=waiting)
        else:
            patience = {"r2": params.r2_patience, "genghis2": params.genghis_patience}
            teammates = {n: patience[r.kind] for n, r in scene.scenario.robots.items() if n != robot.name}
            brain = R2BoxPusher(robot, end, params, teammates, acquires=settings.acquires is not False,
                                waiting=waiting)
        scene.info["brains"].append(brain)
        return brain

    # -- the box ----------------------------------------------------------------------------------------------
    @staticmethod
    def box_pose(world) -> tuple[float, float, float]:
        body = world.data.body("box0/box")
        mat = body.xmat.reshape(3, 3)
        return float(body.xpos[0]), float(body.xpos[1]), math.atan2(mat[1, 0], mat[0, 0])

    def advance(self, world) -> float:
        """How far the box's centre has moved along its starting normal, m."""
        x0, y0, yaw0 = world.scene.info["start"]
        x, y, _ = self.box_pose(world)
        return (x - x0) * math.cos(yaw0) + (y - y0) * math.sin(yaw0)

    def progress(self, world) -> float:
        """The box's advance out of the set distance, in [0, 1] (the reward of ``teamsim.env``)."""
        return min(1.0, max(0.0, self.advance(world) / world.scene.scenario.task.advance))

    def entry_pose(self, world, name: str) -> tuple[float, float, float]:
        """Where a robot joining (add-robot) or put back (revive after remove) is set down: behind the end of the
        box with no live robot within ``CLEAR`` of its pushing spot (its own start end first), facing the box.
        Its controller is told that end, and whether it waits behind a teammate there (both ends taken)."""
        mujoco.mj_kinematics(world.model, world.data)
        box, robot = self.box_pose(world), world.robots[name]
        dims = world.scene.scenario.objects.box
        settings = world.scene.scenario.robots[name].controller
        own, inset = settings.end, settings.behaviour.end_inset
        others = [world.pose(r)[:2] for n, r in world.robots.items() if n != name and r.active]
        waiting = world.scene.info["waiting"]
        waiting.discard(name)
        for end in (own, OPPOSITE[own]):
            pose = behind_end(box, dims, end, robot.model.kind, inset)
            if all(math.dist(pose[:2], p) >= CLEAR for p in others):
                break
        else:  # both ends taken: wait behind its own end, WAIT_BACK further back or as far as the wall allows
            end, pose = own, behind_end(box, dims, own, robot.model.kind, inset)
            room = reach_to_walls(pose[0], pose[1], pose[2] + math.pi, STAND_BACK[robot.model.kind] + WALL_GAP,
                                  world.scene.scenario.arena.size)
            back = min(WAIT_BACK, room)
            pose = (pose[0] - back * math.cos(box[2]), pose[1] - back * math.sin(box[2]), box[2])
            waiting.add(name)
        world.scene.info["ends"][name] = end
        return pose

    # -- measures ---------------------------------------------------------------------------------------------
    def done(self, world) -> bool:
        return self.advance(world) >= world.scene.scenario.task.advance

    def outcome(self, world) -> tuple[bool, dict]:
        advance = self.advance(world)
        pushes = sorted((p for brain in world.scene.info["brains"] for p in brain.pushes), key=lambda p: p.completed)
        _, _, yaw = self.box_pose(world)
        per_robot = {}
        for p in pushes:
            counts = per_robot.setdefault(p.robot, dict.fromkeys(ENDS, 0))
            counts[p.end] += 1
        metrics = {
            "advance_m": round(advance, 4),
            "heading_drift_deg": round(math.degrees(wrap_angle(yaw - world.scene.info["start"][2])), 2),
            "mission_time_s": round(world.time, 3),
            "pushes": len(pushes),
            "pushes_per_robot": per_robot,
            "push_log": [[p.robot, p.end, round(p.activated, 2), round(p.completed, 2)] for p in pushes],
            "final_behaviour": {n: r.behaviour if r.active else "off" for n, r in world.robots.items()},
            "went_home_at": {n: r.controller.went_home_at for n, r in world.robots.items()
                             if getattr(r.controller, "went_home_at", None) is not None},
        }
        return advance >= world.scene.scenario.task.advance, metrics
