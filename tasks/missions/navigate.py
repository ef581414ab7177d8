"""``navigate``: one robot crosses one of Chand's random obstacle worlds from corner to corner (§3.6).

The world is drawn from the trial seed at the requested density; the robot (a Table 3.1 robot by letter, or any
wheeled kind) starts in the top-left corner facing the goal in the bottom-right one, driven by one of the
navigation methods (FRC, RFRC, ODW, ODWDS, HRDK, HRDU). The trial ends when the robot stops at the goal or at
the time limit (§3.6.2: 300 s at 5 and 10 % density, 450 s at 15 and 20 %). Metrics are the thesis's: NT
(navigation time), PI (path index: the modified A*'s optimal path length on the known map over the length
travelled), AV (average velocity over v_gmax) and success.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from teamsim.config import ConfigError, setting
from teamsim.controllers.navigation import dynamic_window as dw
from teamsim.controllers.navigation.astar import PlannerParams, plan_on_grid
from teamsim.models import ROBOT_KINDS, build_robot
from teamsim.models.arenas import Box
from teamsim.models.robot import RobotModel, TricycleSpec
from teamsim.scenario import (MAX_EXTENT, Arena, BoxObstacle, RobotEntry, Scenario, image_boxes, obstacles,
                              scene_of)
from teamsim.scene import Scene
from teamsim.tasks.base import ScenarioMission
from teamsim.tasks.worlds.navigation import (KinematicRobot, NavWorld, NavWorldParams, cell_centres, covered_cells,
                                             kinematic_run, random_world)
from teamsim.tasks.missions.looping import failure_kind
from teamsim.tasks.worlds.uniform_boxes import uniform_world

# Table 3.1's simulated robots: kind and the dimensions that differ from the kind's defaults.
TABLE_3_1 = {
    "A": ("tricycle", {}),  # pentagon, 0.5 m, v_gmax 0.5 m/s
    "B": ("diffdrive", {"radius": 0.35}),  # circle, 0.35 m, 0.5 m/s
    "C": ("tracked", {"radius": 0.67, "v_max": 0.3}),  # rectangle, 0.67 m, 0.3 m/s
}
METHODS = {"FRC": dw.FRC, "RFRC": dw.RFRC, "ODW": dw.ODW, "ODWDS": dw.ODWDS, "HRDK": dw.HRDK, "HRDU": dw.HRDU,
           "FRC-printed": dw.PrintedFRC}
THESIS_METHODS = ("FRC", "RFRC", "ODW", "ODWDS", "HRDK", "HRDU")  # §3.6.2's six, the study's default
NAV_KINDS = ("tricycle", "diffdrive", "tracked")
GOAL_TOLERANCE = 0.5  # m beyond the footprint: "at the goal" (§3.6.2)
STILL = 0.02  # m/s below which a robot stands still


def robot_of(name: str) -> tuple[str, dict]:
    """(kind, builder options) for a Table 3.1 letter or a robot kind."""
    return TABLE_3_1[name] if name in TABLE_3_1 else (name, {})


def time_limit(density: float) -> float:
    """§3.6.2: 300 s for the 5 and 10 % worlds, 450 s for 15 and 20 %."""
    return 300.0 if density <= 0.10 + 1e-9 else 450.0


WORLD_FAMILIES = ("strata", "uniform")  # random_world, uniform_world


@dataclass
class NavigateParams:
    robot: str = setting("B", choices=(*TABLE_3_1, *NAV_KINDS), meaning="Table 3.1 robot A, B, C, or a kind")
    controller: str = setting("FRC", choices=tuple(METHODS), meaning="navigation method (§3.6.2)")
    density: float = setting(0.10, lo=0.0, hi=0.30, meaning="obstacle density of the 15 m world (§3.6.2)")
    world_seed: int = setting(-1, lo=-1, hi=2**31 - 1, meaning="world layout seed (-1: the trial seed)")
    worlds: str = setting("strata", choices=WORLD_FAMILIES,
                          meaning="world family: strata (even, gaps >= Robot C's diameter) or uniform (anywhere)")

    def check(self) -> None:
        if self.robot in ROBOT_KINDS and self.robot not in NAV_KINDS:
            raise ConfigError(f"robot={self.robot}: navigate drives {', '.join(NAV_KINDS)} (or A, B, C)")


@dataclass
class NavigateTask:
    """navigate's own scenario settings."""
    goal: tuple[float, float] = setting((0.0, 0.0), lo=-MAX_EXTENT, hi=MAX_EXTENT, meaning="goal x, y, m")
    time_limit: float = setting(450.0, lo=0.0, open_lo=True, hi=1e7,
                                meaning="s; the trial ends then (§3.6.2: 300 s at 5 and 10 % density, 450 s above)")
    map_resolution: float = setting(0.1, lo=0.01, hi=1.0,
                                    meaning="m per cell of the known map (HRDK, path index) and the density raster")


@dataclass
class NavigationSettings:
    """The navigating robot's controller."""
    method: str = setting("FRC", choices=tuple(METHODS), meaning="navigation method (§3.6.2)")


def draw_world(params: NavigateParams, rng: np.random.Generator) -> NavWorld:
    """The trial's world from its family: ``random_world`` (strata) or ``uniform_world``."""
    if params.worlds == "uniform":
        return uniform_world(params.density, rng)
    return random_world(params.density, rng, NavWorldParams())


class NavigateMission(ScenarioMission):
    name = "navigate"
    summary = "one robot crosses a random obstacle world corner to corner (Chand §3.6)"
    Params = NavigateParams
    Task = NavigateTask
    Controller = NavigationSettings
    default_duration = 450.0

    def scenario(self, params: NavigateParams, rng: np.random.Generator, newcomers) -> Scenario:
        if params.world_seed >= 0:
            rng = np.random.default_rng(params.world_seed)
        world = draw_world(params, rng)
        kind, options = robot_of(params.robot)
        boxes = [BoxObstacle(**dataclasses.asdict(box)) for box in world.boxes]
        return Scenario(mission=self.name, arena=Arena(size=(world.size, world.size), boxes=boxes),
                        robots={"red": RobotEntry(kind, world.start, dict(options),
                                                  NavigationSettings(params.controller))},
                        task=NavigateTask(world.goal, time_limit(params.density), world.resolution))

    def check_scenario(self, scenario: Scenario) -> None:
        """One robot of a navigating kind, in a square arena (Chand's worlds are square), with the goal inside."""
        robots = scenario.robots
        if len(robots) != 1:
            raise ConfigError(f"robots: navigate drives exactly one robot; got {len(robots)} ({', '.join(robots)})")
        (name, robot), = robots.items()
        if robot.kind not in NAV_KINDS:
            raise ConfigError(f"robots.{name}.kind={robot.kind!r}: navigate drives {', '.join(NAV_KINDS)}")
        sx, sy = scenario.arena.size
        if sx != sy:
            raise ConfigError(f"arena.size=[{sx:g}, {sy:g}]: navigate's worlds are square; allowed: equal sides")
        if max(map(abs, scenario.task.goal)) > sx / 2:
            raise ConfigError(f"task.goal={list(scenario.task.goal)}: must lie inside the arena, "
                              f"x and y in [{-sx / 2:g}, {sx / 2:g}]")

    def scene(self, scenario: Scenario, newcomers, physics_dt: float) -> Scene:
        scene = scene_of(scenario, newcomers, physics_dt)
        goal = scenario.task.goal
        scene.arena.worldbody.add("site", name="goal", pos=[*goal, 0.01], size=[0.3, 0.005], type="cylinder",
                                  rgba=[0.1, 0.8, 0.2, 0.6])
        name = next(iter(scenario.robots))
        scene.info.update(nav_world=nav_world_of(scenario), time_limit=scenario.task.time_limit, robot=name)
        return scene

    def controller(self, robot: RobotModel, scene: Scene, rng: np.random.Generator):
        settings, world = scene.scenario.robots[robot.name].controller, scene.info["nav_world"]
        controller = navigation_controller(settings.method, robot, world)
        scene.info["controller"] = controller
        return controller

    def done(self, world) -> bool:
        return self._arrived(world) or world.time >= world.scene.info["time_limit"]

    def _arrived(self, world) -> bool:
        """The navigation controller says when its robot has stopped at the goal (§3.6.2). A robot driven by
        anything else (an agent of ``teamsim.env``) has arrived when it stands still within the goal's tolerance."""
        info = world.scene.info
        robot = world.robots[info["robot"]]
        if robot.controller is info["controller"]:
            return bool(info["controller"].arrived)
        x, y, _ = world.pose(robot)
        near = math.dist((x, y), info["nav_world"].goal) <= GOAL_TOLERANCE + robot.model.footprint_radius
        return near and world.speed(robot) < STILL

    def progress(self, world) -> float:
        """The share of the start-goal distance covered, in [0, 1] (the reward of ``teamsim.env``)."""
        nav_world = world.scene.info["nav_world"]
        x, y, _ = world.pose(world.robots[world.scene.info["robot"]])
        start = math.dist(nav_world.start[:2], nav_world.goal)
        return min(1.0, max(0.0, 1.0 - math.dist((x, y), nav_world.goal) / start)) if start > 0 else 1.0

    def outcome(self, world) -> tuple[bool, dict]:
        name = world.scene.info["robot"]
        robot = world.robots[name]
        metrics = nav_metrics(world.scene.info["nav_world"], robot.model, self._arrived(world), world.pose(robot),
                              float(world.odometry()[name]), world.time, world.scene.info["controller"].trail)
        return metrics["success"], metrics


def centre_offset(robot: RobotModel) -> float:
    """How far the robot's physical centre lies ahead of its pose's reference point: the tricycle's pose is its
    rear axle, its pentagon's centre half a wheelbase ahead."""
    return robot.drive.wheelbase / 2 if isinstance(robot.drive, TricycleSpec) else 0.0


def navigation_controller(method: str, robot: RobotModel, world: NavWorld):
    """The navigation method ``method`` for ``robot`` in ``world`` (HRDK gets the known map, HRDU an unexplored
    one)."""
    offset = centre_offset(robot)
    kwargs = {}
    if isinstance(robot.drive, TricycleSpec):
        kwargs.update(centre_offset=offset, steering=robot.drive)
    # The pentagon's and the rectangle's sensors sit on their sides, nearer the centre than the enclosing
    # circle (by up to 19 % of its radius on the pentagon, 37 % on Robot C's rectangle).
    kwargs["sensor_radius"] = ir_sensor_radii(robot, offset)
    if method == "HRDK":
        kwargs["known_map"] = world.known_map()
    elif method == "HRDU":
        kwargs["grid"] = world.unexplored_map()
    return METHODS[method](robot.limits, robot.kind, robot.footprint_radius, world.goal, **kwargs)


def nav_metrics(nav_world: NavWorld, robot: RobotModel, arrived: bool, pose, travelled: float,
                nav_time: float, trail: list) -> dict:
    """§3.6.2's measures of one trial: success (stopped at the goal), NT, PI (planned over travelled length, on
    success) and AV (mean speed over v_gmax); for a failure, how it failed (``looping.failure_kind``) from the
    controller's ``trail`` of (time, x, y)."""
    x, y = pose[0], pose[1]
    reached = arrived and math.dist((x, y), nav_world.goal) <= GOAL_TOLERANCE + robot.footprint_radius
    planned = optimal_path_length(nav_world, robot.footprint_radius)
    trail = np.asarray(trail, float).reshape(-1, 3)
    failure = {"failure": "", "loop_period": None, "loop_diameter": None} if reached else \
        failure_kind(trail[:, 0], trail[:, 1:], robot.limits.v_max)
    return failure | {
        "success": bool(reached),
        "nav_time": round(nav_time, 3),
        "path_length": round(travelled, 3),
        "planned_length": round(planned, 3),
        "path_index": round(planned / travelled, 4) if reached and travelled > 0 else 0.0,
        "avg_velocity": round(travelled / nav_time / robot.limits.v_max, 4) if nav_time > 0 else 0.0,
        "density": round(nav_world.density, 4),
        "final_distance_to_goal": round(math.dist((x, y), nav_world.goal), 3),
    }


def nav_world_of(scenario: Scenario) -> NavWorld:
    """The navigation world of a scenario: its obstacles (boxes, image, cylinders) rasterised at the task's map
    resolution (a cell is occupied when its centre lies in an obstacle, as ``random_world`` measures density),
    the robot's start and the goal."""
    size, resolution = scenario.arena.size[0], scenario.task.map_resolution
    centres = cell_centres(size, resolution)
    occupancy = np.zeros((len(centres), len(centres)), bool)
    for obstacle in obstacles(scenario.arena):
        occupancy |= covered_cells(obstacle, centres)
    boxes = [*scenario.arena.boxes, *(b for b, _ in image_boxes(scenario.arena))]
    robot = next(iter(scenario.robots.values()))
    return NavWorld(tuple(Box(**dataclasses.asdict(b)) for b in boxes), occupancy, (-size / 2, -size / 2),
                    resolution, size, robot.pose, scenario.task.goal)


def ir_sensor_radii(robot: RobotModel, centre_offset: float) -> np.ndarray:
    """Each IR sensor's distance from the robot's physical centre (``centre_offset`` ahead of the robot frame's
    origin), from its site in the robot's model, in the order of the robot's readings."""
    xy = np.array([robot.mjcf.find("site", name).pos[:2] for name in robot.ir_sensors], float)
    return np.hypot(xy[:, 0] - centre_offset, xy[:, 1])


def optimal_path_length(nav_world, robot_radius: float) -> float:
    """Length (m) of the modified A*'s path on the known map (clearance cost included, as §3.6.2's PI uses)."""
    path, result = plan_on_grid(nav_world.known_map(), nav_world.start[:2], nav_world.goal, PlannerParams(),
                                robot_radius)
    return float(np.hypot(*np.diff(path, axis=0).T).sum()) if result.reached else math.nan


# -- without physics -------------------------------------------------------------------------------------------------
def kinematic_robot(robot: RobotModel) -> KinematicRobot:
    """The physics-free stand-in of a robot model: its drive limits, enclosing circle, IR ring with the sensors
    where the model puts them, and (a tricycle) its wheelbase and steering limits."""
    offset = centre_offset(robot)
    radii = tuple(float(r) for r in ir_sensor_radii(robot, offset))
    if isinstance(robot.drive, TricycleSpec):
        return KinematicRobot("tricycle", robot.limits, robot.footprint_radius, len(radii), centre_offset=offset,
                              sensor_radius=radii, wheelbase=robot.drive.wheelbase, steer_max=robot.drive.steer_max,
                              steer_rate_max=robot.drive.steer_rate_max)
    return KinematicRobot(robot.kind, robot.limits, robot.footprint_radius, len(radii), sensor_radius=radii)


def kinematic_metrics(world: NavWorld, model: RobotModel, method: str, duration: float) -> dict:
    """``nav_metrics`` of ``model`` driven by ``method`` through ``world`` without physics, with ``touches``."""
    controller = navigation_controller(method, model, world)
    run = kinematic_run(world, controller, kinematic_robot(model), duration, on_contact="stop")
    metrics = nav_metrics(world, model, run.reached, run.pose, run.travelled, run.time, controller.trail)
    return metrics | {"touches": run.touches}


def kinematic_trial(config) -> dict:
    """A navigate trial without physics (``teamsim.tasks.worlds.navigation.kinematic_run``): the same world, robot
    dimensions, controller and measures as in physics, with ideal IR ranges and exact positioning. A motion that
    would touch an obstacle is refused and the robot halted (a touch stops, not ends, a physics run too); the
    number of such ticks is reported as ``touches``. Returns a summary shaped like ``run_trial``'s."""
    params: NavigateParams = config.params
    params.check()
    rng = np.random.default_rng(params.world_seed if params.world_seed >= 0 else config.seed)
    kind, options = robot_of(params.robot)
    metrics = kinematic_metrics(draw_world(params, rng), build_robot(kind, "red", **options), params.controller,
                                time_limit(params.density))
    return {"mission": "navigate", "seed": config.seed, "run_id": config.run_id,
            "status": "completed" if metrics["success"] else "failed", "completed": metrics["success"],
            "sim_time_s": metrics["nav_time"], "metrics": metrics}
