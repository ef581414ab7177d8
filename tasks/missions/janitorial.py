"""``janitorial``: Parker's janitorial service, in physics (§6.2; spec §4.3).

Three janitors (:mod:`teamsim.models.janitor`) clean a rectangular room of unknown size: they empty the garbage
cans (each carries an emitter at one of a few frequencies), dust the low furniture (lower than the janitors'
upper IR ring) and clean the floor. No robot can do everything: r1 = {empty-garbage, dust-furniture}, r2 =
{empty-garbage, clean-floor}, r3 = {dust-furniture, clean-floor} (the example of Fig. 6-12). Their control is
ALLIANCE with one motivational behaviour per task choosing sub-tasks (:mod:`teamsim.controllers.behaviours.
janitorial.robot`). The room (size drawn from the seed), its tall obstacles, the cans and the furniture come from
the scenario; ``rho`` is Parker's broadcast rate (0: no messages at all).

It completes when every can is emptied, every object dusted and ``floor_share`` of the reachable floor cleaned,
judged from the world's ground truth (:mod:`teamsim.tasks.worlds.janitorial`). Dynamic events: a can may appear
mid-mission (``task.cans[k].appears``) or be emptied by someone else (``emptied_at``); ``break-gripper`` disables a
robot's tools (it fails to empty), and ``add-robot:NAME@T,kind=janitor`` brings a janitor with every tool in.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np

from teamsim.config import ConfigError, RadioConfig, setting
from teamsim.controllers.behaviours.janitorial.robot import JanitorParams, JanitorRobot
from teamsim.models.janitor import TASKS, JanitorDims
from teamsim.models.robot import RobotModel
from teamsim.positioning import wrap_angle
from teamsim.scenario import MAX_EXTENT, Arena, BoxObstacle, FaultEntry, RobotEntry, Scenario, scene_of
from teamsim.scene import Scene
from teamsim.tasks.base import ScenarioMission
from teamsim.tasks.missions.janitorial_figures import floor_image, write_floor
from teamsim.tasks.worlds.janitorial import Can, Cans, Floor, Furniture, detector_levels, rasterise

TEAM = {"r1": ("empty-garbage", "dust-furniture"), "r2": ("empty-garbage", "clean-floor"),
        "r3": ("dust-furniture", "clean-floor")}  # Fig. 6-12
FREQUENCY_RGBA = [(0.9, 0.2, 0.2, 1), (0.2, 0.5, 0.95, 1), (0.95, 0.8, 0.1, 1), (0.6, 0.3, 0.85, 1),
                  (0.2, 0.8, 0.6, 1), (1.0, 0.5, 0.1, 1)]
FURNITURE_RGBA = (0.55, 0.35, 0.2, 1)
DIMS = JanitorDims()  # the janitors' dimensions: the tools' footprints the ground truth measures
GAP = 0.7  # m kept free between things in the room and from the walls: room for a janitor to pass and circle
FLOOR_CELL = 0.05  # m: the ground-truth floor raster
# Layouts drawn before giving up: about 7 % of draws fit the default's eight things 0.7 m apart (only rooms from
# about 5.9 x 4.5 m do), so 50 left 4 % of seeds with no layout (seed 204); 400 leave about 1e-12.
LAYOUT_ATTEMPTS = 400
PANEL_PERIOD = 2.0  # s between redraws of the video's floor panel


@dataclass
class JanitorialParams:
    rho: float | None = setting(None, lo=0.0, hi=100.0, meaning="rho, broadcasts per second per robot (§6.2.3: 0, "
                                                                "0.1, 0.5, 2); 0: no messages; null: the radio's rate")
    size_x: tuple[float, float] = setting((5.0, 7.0), lo=3.0, hi=30.0, meaning="range the room's length is drawn "
                                                                              "from, m (unknown to the robots)")
    size_y: tuple[float, float] = setting((4.0, 5.5), lo=3.0, hi=30.0, meaning="range the room's width is drawn "
                                                                              "from, m")
    cans: int = setting(3, lo=0, hi=12, meaning="garbage cans (Fig. 6-12: 3)")
    objects: int = setting(3, lo=0, hi=12, meaning="dustable objects (Fig. 6-12: 3)")
    obstacles: int = setting(2, lo=0, hi=12, meaning="tall obstacles (not dustable)")
    frequencies: int = setting(3, lo=1, hi=len(FREQUENCY_RGBA), meaning="emitter frequencies spread over the cans")


@dataclass
class CanEntry:
    x: float = setting(0.0, lo=-MAX_EXTENT, hi=MAX_EXTENT, meaning="centre x, m")
    y: float = setting(0.0, lo=-MAX_EXTENT, hi=MAX_EXTENT, meaning="centre y, m")
    frequency: str = setting("f1", meaning="its emitter's frequency (one of task.frequencies)")
    appears: float = setting(0.0, lo=0.0, hi=1e7, meaning="s: a can added mid-mission is outside the room until then")
    emptied_at: float | None = setting(None, lo=0.0, hi=1e7, meaning="s: someone else empties it then (it falls "
                                                                     "silent); null: never")


@dataclass
class FurnitureEntry:
    x: float = setting(0.0, lo=-MAX_EXTENT, hi=MAX_EXTENT, meaning="centre x, m")
    y: float = setting(0.0, lo=-MAX_EXTENT, hi=MAX_EXTENT, meaning="centre y, m")
    half_x: float = setting(0.3, lo=0.05, hi=5.0, meaning="half length, m")
    half_y: float = setting(0.3, lo=0.05, hi=5.0, meaning="half width, m")
    yaw: float = setting(0.0, lo=-math.tau, hi=math.tau, meaning="rad")


@dataclass
class JanitorialTask:
    cans: list[CanEntry] = field(default_factory=list, metadata={"meaning": "garbage cans"})
    furniture: list[FurnitureEntry] = field(default_factory=list, metadata={"meaning": "dustable objects"})
    frequencies: tuple[str, ...] = setting(("f1", "f2", "f3"), meaning="the emitter frequencies in use; a garbage "
                                                                       "robot has two detectors for each")
    objects_known: int | None = setting(None, lo=0, hi=100, meaning="the number of dustable objects the robots are "
                                                                    "told (§6.2.1); null: as many as there are")
    can_radius: float = setting(0.15, lo=0.05, hi=1.0, meaning="m")
    can_height: float = setting(0.5, lo=0.4, hi=2.0, meaning="m (taller than the upper IR ring: not dustable)")
    furniture_height: float = setting(0.2, lo=0.1, hi=0.3, meaning="m (between the janitors' IR rings, 0.06 and "
                                                                   "0.35 m)")
    empty_time: float = setting(5.0, lo=0.1, hi=600.0, meaning="s the emptier must be held at a can")
    dust_share: float = setting(0.75, lo=0.05, hi=1.0, meaning="share of an object's accessible sides the duster "
                                                               "must pass")
    floor_share: float = setting(0.95, lo=0.05, hi=1.0, meaning="share of the reachable floor to clean")
    sound_noise: float = setting(0.2, lo=0.0, hi=1.0, meaning="relative noise on each detector (Parker's "
                                                              "simulator: about 20 %, §2.1)")


@dataclass
class JanitorSettings:
    tools: tuple[str, ...] = setting(TASKS, meaning=f"the tasks it has tools for: {', '.join(TASKS)}")
    behaviour: JanitorParams = field(default_factory=JanitorParams, metadata={
        "meaning": "ALLIANCE rates and behaviour constants (`JanitorParams`)"})


class JanitorialMission(ScenarioMission):
    name = "janitorial"
    summary = "Parker's janitorial service: three janitors empty cans, dust furniture and clean the floor, ALLIANCE"
    Params = JanitorialParams
    Task = JanitorialTask
    Controller = JanitorSettings
    default_duration = 2400.0  # s: the dev seeds 1-6 completed in 614-1973 s (docs/janitorial.md)
    video_speedup = 4.0

    # -- the world ------------------------------------------------------------------------------------------------
    @staticmethod
    def radio_of(params: JanitorialParams, radio: RadioConfig) -> RadioConfig:
        return dataclasses.replace(radio, rate_hz=params.rho) if params.rho else radio

    def scenario(self, params: JanitorialParams, rng: np.random.Generator, newcomers) -> Scenario:
        for name, (lo, hi) in (("size_x", params.size_x), ("size_y", params.size_y)):
            if lo > hi:
                raise ConfigError(f"{name}=[{lo:g}, {hi:g}]: the lower end must not exceed the upper")
        for _ in range(LAYOUT_ATTEMPTS):  # a layout that boxes itself in is drawn again, room size and all
            size = (float(rng.uniform(*params.size_x)), float(rng.uniform(*params.size_y)))
            hx, hy = size[0] / 2, size[1] / 2
            starts = {name: (-hx + 0.5 + 0.65 * k, -hy + 0.5, math.pi / 2) for k, name in enumerate(TEAM)}
            taken = [(x, y, 0.4) for x, y, _ in starts.values()] + [(-hx + 1.0, -hy + 1.0, 1.2)]  # the start corner
            placed = _Placer(size, rng, taken)
            try:
                obstacles = [placed.box(0.15, 0.4) for _ in range(params.obstacles)]
                furniture = [placed.box(0.2, 0.4) for _ in range(params.objects)]
                can_spots = [placed.disc(0.15) for _ in range(params.cans)]
                break
            except _NoRoom:
                continue
        else:
            raise ConfigError(f"cans={params.cans}, objects={params.objects}, obstacles={params.obstacles}: no layout "
                              f"in {LAYOUT_ATTEMPTS} draws keeps {GAP:g} m between them in rooms of size_x "
                              f"{list(params.size_x)}, size_y {list(params.size_y)}; ask for fewer or a larger room")
        frequencies = tuple(f"f{k + 1}" for k in range(params.frequencies))
        order = rng.permutation(len(can_spots))
        cans = [CanEntry(x, y, frequencies[int(order[k]) % len(frequencies)]) for k, (x, y) in enumerate(can_spots)]
        robots = {name: RobotEntry("janitor", starts[name], controller=JanitorSettings(tools)) for name, tools in
                  TEAM.items()}
        for k, (name, kind) in enumerate(newcomers):
            if name in robots:
                raise ConfigError(f"--fault add-robot:{name}: robot {name!r} is already in the team")
            robots[name] = RobotEntry(kind, (-hx + 0.5, -hy + 1.3 + 0.65 * k, math.pi / 2),
                                      controller=JanitorSettings())  # (the west wall on its left, as the team's)
        faults = [FaultEntry("radio-off", name, 0.0) for name in robots] if params.rho == 0 else []
        arena = Arena(size=size, boxes=[BoxObstacle(x, y, h1, h2, 0.3, yaw) for x, y, h1, h2, yaw in obstacles])
        return Scenario(mission=self.name, arena=arena, robots=robots, faults=faults, task=JanitorialTask(
            cans=cans, furniture=[FurnitureEntry(*f) for f in furniture], frequencies=frequencies))

    def check_scenario(self, scenario: Scenario) -> None:
        task, (hx, hy) = scenario.task, (scenario.arena.size[0] / 2, scenario.arena.size[1] / 2)
        for name, robot in scenario.robots.items():
            if robot.kind != "janitor":
                raise ConfigError(f"robots.{name}.kind={robot.kind!r}: the janitorial mission is done by janitors; "
                                  "allowed: janitor")
            for tool in robot.controller.tools:
                if tool not in TASKS:
                    raise ConfigError(f"robots.{name}.controller.tools: unknown task {tool!r}; allowed: "
                                      f"{', '.join(TASKS)}")
        for k, can in enumerate(task.cans):
            margin = task.can_radius
            if abs(can.x) > hx - margin or abs(can.y) > hy - margin:
                raise ConfigError(f"task.cans[{k}]: ({can.x:g}, {can.y:g}) is outside the room; x must be in "
                                  f"[{margin - hx:g}, {hx - margin:g}], y in [{margin - hy:g}, {hy - margin:g}]")
            if can.frequency not in task.frequencies:
                raise ConfigError(f"task.cans[{k}].frequency={can.frequency!r}: not one of task.frequencies; "
                                  f"allowed: {', '.join(task.frequencies)}")
        for k, f in enumerate(task.furniture):
            reach = math.hypot(f.half_x, f.half_y)
            if abs(f.x) > hx - reach or abs(f.y) > hy - reach:
                raise ConfigError(f"task.furniture[{k}]: ({f.x:g}, {f.y:g}) puts the object outside the room")

    def scene(self, scenario: Scenario, newcomers, physics_dt: float) -> Scene:
        scene = scene_of(scenario, newcomers, physics_dt)
        task, body = scenario.task, scene.arena.worldbody
        colours = dict(zip(task.frequencies, FREQUENCY_RGBA))
        for k, can in enumerate(task.cans):
            z = task.can_height / 2 if can.appears <= 0 else -task.can_height  # under the floor until it appears
            body.add("geom", name=f"can{k}", type="cylinder", pos=[can.x, can.y, z],
                     size=[task.can_radius, task.can_height / 2], rgba=[0.3, 0.32, 0.35, 1])
            body.add("geom", name=f"emitter{k}", type="sphere", pos=[can.x, can.y, z + task.can_height / 2],
                     size=[0.05], rgba=list(colours[can.frequency]), contype=0, conaffinity=0)
        for k, f in enumerate(task.furniture):
            body.add("geom", name=f"furniture{k}", type="box", pos=[f.x, f.y, task.furniture_height / 2],
                     size=[f.half_x, f.half_y, task.furniture_height / 2], euler=[0, 0, f.yaw],
                     rgba=list(FURNITURE_RGBA))
        size = scenario.arena.size
        boxes = [(b.x, b.y, b.half_x, b.half_y, b.yaw) for b in scenario.arena.boxes]
        furniture = [(f.x, f.y, f.half_x, f.half_y, f.yaw) for f in task.furniture]
        discs = [(c.x, c.y, task.can_radius) for c in task.cans]
        floor = Floor(size, FLOOR_CELL, rasterise(size, FLOOR_CELL, boxes + furniture, discs))
        starts = np.array([r.pose[:2] for n, r in scenario.robots.items() if n not in dict(newcomers)])
        floor.settle_reachable(DIMS.radius + 0.02, starts, DIMS.cleaner_half_depth)
        cans = Cans([Can(c.x, c.y, task.can_radius, c.frequency, c.appears) for c in task.cans], task.empty_time,
                    reach=0.05)
        scene.info.update(
            floor=floor, cans=cans, brains={}, time=0.0, sound={},
            furniture=Furniture(furniture, floor, spacing=0.1, reach=0.06, share=task.dust_share,
                                clearance=2 * DIMS.radius + 0.05))
        return scene

    def controller(self, robot: RobotModel, scene: Scene, rng: np.random.Generator):
        scenario = scene.scenario
        settings, task = scenario.robots[robot.name].controller, scenario.task
        objects = task.objects_known if task.objects_known is not None else len(task.furniture)
        brain = JanitorRobot(robot, tuple(settings.tools), tuple(task.frequencies), objects, rng, settings.behaviour,
                             tau=scenario.radio.timeout)
        scene.info["brains"][robot.name] = brain
        return brain

    # -- the mission's own sensors: the sound detectors ------------------------------------------------------------
    def sense(self, world, name: str) -> dict:
        robot = world.robots[name]
        if "emptier" not in robot.model.effectors:
            return {}
        info, task = world.scene.info, world.scene.scenario.task
        if name not in info["sound"]:  # (setdefault would build a generator every call)
            info["sound"][name] = world.streams.get("robot", name, "sound")
        rng = info["sound"][name]
        x, y, yaw = world.pose(robot)
        angles = np.array([yaw + math.pi / 4, yaw - math.pi / 4])  # left, right
        axes = np.stack([np.cos(angles), np.sin(angles)], axis=1)
        ears = np.array([x, y]) + robot.model.footprint_radius * axes
        return {"sound": {f: tuple(float(v) for v in detector_levels(
            ears, axes, info["cans"].sources(f, world.time), 1.0, 1.0, task.sound_noise, rng))
            for f in task.frequencies}}

    # -- the ground truth, once a control period ---------------------------------------------------------------------
    def _measure(self, world) -> None:
        info, task = world.scene.info, world.scene.scenario.task
        dt, info["time"] = world.time - info["time"], world.time
        for k, (entry, can) in enumerate(zip(task.cans, info["cans"].cans)):
            if can.appears > 0 and world.time >= can.appears and world.model.geom(f"can{k}").pos[2] < 0:
                for part, z in ((f"can{k}", task.can_height / 2), (f"emitter{k}", task.can_height)):
                    world.model.geom(part).pos[2] = z
            if entry.emptied_at is not None and world.time >= entry.emptied_at and can.emptied_at is None:
                can.emptied_at, can.emptied_by = world.time, "event"
        for name, robot in world.robots.items():
            if not robot.active:
                continue
            tools, data = robot.effector_positions, world.data
            if tools.get("emptier", 0.0) > 0.8:
                info["cans"].hold(name, data.site(f"{name}/emptier_tip").xpos[:2], dt, world.time)
            if tools.get("duster", 0.0) > 0.8:
                info["furniture"].sweep(data.body(f"{name}/duster").xpos[:2], data.site(f"{name}/duster_tip").xpos[:2],
                                        world.time)
            if tools.get("cleaner", 0.0) > 0.8:
                info["floor"].clean(data.site(f"{name}/cleaner").xpos[:2], world.pose(robot)[2],
                                    DIMS.cleaner_half_depth, DIMS.cleaner_half_width)

    # -- pictures ------------------------------------------------------------------------------------------------------
    @staticmethod
    def _floor_state(world) -> tuple:
        """What the floor pictures show: (info, can colours by frequency, live robots' positions, time)."""
        task = world.scene.scenario.task
        robots = {n: world.pose(r)[:2] for n, r in world.robots.items() if r.active}
        return world.scene.info, dict(zip(task.frequencies, FREQUENCY_RGBA)), robots, world.time

    def video_panel(self, world) -> np.ndarray | None:
        """The floor as cleaned so far, the dusted furniture and the emptied cans, beside the 3-D view."""
        info = world.scene.info
        if world.time < info.get("panel_time", -math.inf) + PANEL_PERIOD:
            return None
        info["panel_time"] = world.time
        return cv2.cvtColor(floor_image(*self._floor_state(world)), cv2.COLOR_BGR2RGB)

    def write_outputs(self, world, run_dir: Path) -> None:
        """``floor.png``: the floor, furniture and cans as the mission ended."""
        write_floor(run_dir / "floor.png", *self._floor_state(world))

    def complete(self, world) -> bool:
        info, task = world.scene.info, world.scene.scenario.task
        return (info["cans"].all_emptied() and info["furniture"].all_dusted()
                and info["floor"].share_cleaned() >= task.floor_share)

    def done(self, world) -> bool:
        self._measure(world)
        return self.complete(world)

    def outcome(self, world) -> tuple[bool, dict]:
        info = world.scene.info
        cans, furniture, floor = info["cans"], info["furniture"], info["floor"]
        robots = world.robot_summary()
        metrics = {
            "mission_time_s": round(world.time, 3),
            "cans_emptied": sum(c.emptied_at is not None for c in cans.cans),
            "cans": len(cans.cans),
            "can_log": [[c.frequency, c.emptied_by, None if c.emptied_at is None else round(c.emptied_at, 1)]
                        for c in cans.cans],
            "objects_dusted": sum(t is not None for t in furniture.done_at),
            "objects": len(furniture.done_at),
            "dusted_share": [round(furniture.fraction(k), 3) for k in range(len(furniture.done_at))],
            "floor_cleaned": round(floor.share_cleaned(), 4),
            "quadrants": {n: list(b.floor.completed) for n, b in info["brains"].items() if hasattr(b, "floor")},
            "dusted_by": {n: len(b.dust.finished) for n, b in info["brains"].items() if hasattr(b, "dust")},
            "task_time_s": {n: {k: round(v, 1) for k, v in r["task_time_s"].items()} for n, r in robots.items()},
        }
        return self.complete(world), metrics


class _NoRoom(Exception):
    """No spot left for the next thing."""


class _Placer:
    """Things dropped at random in the room, each ``GAP`` clear of the walls and of everything placed before."""

    def __init__(self, size: tuple[float, float], rng: np.random.Generator, taken: list[tuple[float, float, float]]):
        self.half, self.rng, self.taken = np.array(size) / 2, rng, list(taken)

    def _spot(self, radius: float) -> tuple[float, float]:
        for _ in range(500):
            x, y = self.rng.uniform(-self.half + radius + GAP, self.half - radius - GAP)
            if all(math.hypot(x - a, y - b) >= radius + r + GAP for a, b, r in self.taken):
                self.taken.append((x, y, radius))
                return float(x), float(y)
        raise _NoRoom()

    def box(self, lo: float, hi: float) -> tuple[float, float, float, float, float]:
        hx, hy = self.rng.uniform(lo, hi, size=2)
        yaw = float(self.rng.uniform(-math.pi, math.pi))
        x, y = self._spot(math.hypot(hx, hy))
        return x, y, float(hx), float(hy), wrap_angle(yaw)

    def disc(self, radius: float) -> tuple[float, float]:
        return self._spot(radius)
