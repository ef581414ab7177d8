"""``explore``: Chand's multi-robot map building and exploration (ch.6), the application his thesis builds towards.

A team drawn from Table 5.22's robots enters an unknown 38.4 m world of 16 local environments with obstacles and
bogs (``tasks/worlds/exploration``). The ch.5 allocation (``allocation.devolution``) gives the management tasks
(M1 global information, M2 feedback) to their robots and the worker tasks to planners (W1) and explorers (W2), in
the quantities of the team ``[planners explorers]``; a robot may hold several (MT-SR). The roles then run as in
§6.2-6.4 (``controllers/exploration``) over an 802.11 network (``teamsim.network``: Table 5.22's bandwidth and
range per robot). Only robots given a role are put in the world.

The trial ends when no explorer has work left (every environment explored, partly explored for good or out of
reach) or at MET (§8.2: 15000 s for [1 1], 5000 s otherwise). Measures (§8.1, eq. 8.1): ET, the exploration time;
PAE, the share of the world explored (the mean of (6.17) over the environments of the manager's map); ER =
PAE / ET; beyond the thesis, map accuracy (explored cells whose side of 0.5 matches the true world) and bogs
found. Two backends run the same world, controllers and measures: ``physics`` (MuJoCo) and ``kinematic``
(``tasks/worlds/kinematic_team``: no contacts, as the thesis simulated; for studies).
"""
from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from teamsim.config import ConfigError, setting
from teamsim.controllers.allocation.devolution import Allocation, allocate
from teamsim.controllers.allocation.feedback_coordination import FeedbackCoordinator
from teamsim.controllers.allocation.spec import FeedbackSpec, RobotSpec, load_robots, load_tasks
from teamsim.controllers.exploration.explorer import Explorer, ExplorerParams
from teamsim.controllers.exploration.global_map import EXPLORED_THRESHOLD
from teamsim.controllers.exploration.manager import EXPLORER, PLANNER, FeedbackSystem, GlobalInfo
from teamsim.controllers.exploration.planner import Planner
from teamsim.controllers.exploration.team import Addresses, TeamRobot
from teamsim.controllers.exploration.territory import Territory
from teamsim.controllers.navigation.dynamic_window import HRDU, Replanning
from teamsim.controllers.navigation.occupancy_grid import MappingParams
from teamsim.models import build_robot
from teamsim.models.robot import RobotModel, TricycleSpec
from teamsim.network import Network, NetworkConfig
from teamsim.rng import RandomStreams
from teamsim.scenario import Arena, BogZone, BoxObstacle, RobotEntry, Scenario, resolve, scene_of
from teamsim.scene import Scene
from teamsim.tasks.base import ScenarioMission
from teamsim.tasks.missions.explore_figures import panel_image, write_coverage, write_map
from teamsim.tasks.missions.navigate import centre_offset, ir_sensor_radii, kinematic_robot, nav_world_of
from teamsim.tasks.worlds.exploration import ExploreWorldParams, explore_world
from teamsim.tasks.worlds.kinematic_team import KinematicTeam, Member
from teamsim.tasks.worlds.navigation import KinematicBody

KIND_OF_TYPE = {"tricycle-pentagon": "tricycle", "differential-circular": "diffdrive",
                "differential-rectangular": "tracked"}
TABLE_5_22 = tuple(f"Robot{k}" for k in range(1, 9))
MET = {1: 15000.0}  # §8.2: maximum exploration time by explorers; 5000 s for larger teams
MET_LARGER = 5000.0
# RA' per 60 s (Table 5.31), for Robot4 (tracked, 0.4 m/s) and Robot2 (wheeled, 0.5 m/s); other robots scale the
# row of their drive by their speed (docs/decisions.md, "Exploration": the thesis calibrates only these two).
EXPECTED_PER_MINUTE = {
    "tracked": {"speed": 0.4, "plan": [0.1473, 2.8], "comm": [5270.0], "sense": [349.0, 349.0], "act": [15.26]},
    "wheeled": {"speed": 0.5, "plan": [0.1584, 3.01], "comm": [8580.0], "sense": [382.0, 381.0], "act": [18.27]},
}
PLANNER_PER_MINUTE = {"plan": [0.442, 0.442], "comm": [10380.0]}  # Robot4 on W1, Table 5.31
NETWORK = NetworkConfig()  # the link's defaults: 5 ms latency, no loss
MAPPING = MappingParams(hit_cell="beyond")  # cells occupied when their centre is, as the true raster counts
# Table 8.1's levels: none (level 1), task scores only (level 2), the whole feedback coordination (level 3)
FEEDBACK_MODES = ("full", "scores", "none")  # not on/off: YAML would read those as booleans
# The explorers' feedback settings Table 8.1 varies; "table" keeps thesis_tasks.toml's (Table 5.29's)
WEIGHT_SETS = {"W1": (0.0, 0.0, 0.5, 0.5), "W2": (0.1, 0.1, 0.4, 0.4), "W3": (0.2, 0.2, 0.3, 0.3),
               "W4": (0.25, 0.25, 0.25, 0.25)}  # WS over [plan, comm, sense, act]
POOR_THRESHOLDS = {"none": -1.0, "P1": 0.75, "P2": 0.65, "P3": 0.55, "P4": 0.45}  # OTES_T (5.20)
PARTIAL_THRESHOLDS = {"none": -1.0, "F1": 0.05, "F2": 0.15, "F3": 0.2, "F4": 0.25}  # TES_T (5.19)
TEAM_FORM = re.compile(r"^\[?\s*(\d+)[\s,]+(\d+)\s*\]?$")


@dataclass
class ExploreParams:
    team: str = setting("1 3", meaning="[planners explorers]: 1 1, 1 3 or 1 5 in §8.2")
    robots: str = setting(",".join(TABLE_5_22), meaning="Table 5.22 robots to allocate from, comma-separated")
    density: float = setting(0.05, lo=0.0, hi=0.15, meaning="obstacle density (§8.2: 0.05, 0.10, 0.15)")
    bog_share: float = setting(0.05, lo=0.0, hi=0.30, meaning="boggy share of the area (§8.2: 0 or about 0.05)")
    size: float = setting(38.4, lo=1.0, hi=200.0, meaning="side of the square world, m (§8.2)")
    divisions: int = setting(4, lo=1, hi=16, meaning="local environments per side (§8.2: 4, so 16)")
    resolution: float = setting(0.3, lo=0.05, hi=1.0, meaning="map cell, m (§8.2)")
    t_m: float = setting(60.0, lo=1.0, hi=3600.0, meaning="feedback period T_m, s (§8.2: 60, 180, 300)")
    explored_threshold: float = setting(EXPLORED_THRESHOLD, lo=0.0, hi=1.0, meaning="EA_T of (6.18), not given")
    world_seed: int = setting(-1, lo=-1, hi=2**31 - 1, meaning="world layout seed (-1: the trial seed)")
    backend: str = setting("physics", choices=("physics", "kinematic"),
                           meaning="physics (MuJoCo) or kinematic (no contacts, for studies)")
    feedback: str = setting("full", choices=FEEDBACK_MODES,
                            meaning="full: the ch.5 feedback coordination every T_m; scores: task scores only, no "
                                    "reallocation (Table 8.1 level 2); none: no feedback (level 1)")
    weights: str = setting("table", choices=("table", *WEIGHT_SETS), meaning="the explorers' WS (Table 8.1)")
    poor: str = setting("table", choices=("table", *POOR_THRESHOLDS), meaning="the explorers' OTES_T (Table 8.1)")
    partial: str = setting("table", choices=("table", *PARTIAL_THRESHOLDS),
                           meaning="the explorers' TES_T (Table 8.1)")
    latency: float = setting(NETWORK.latency, lo=0.0, hi=60.0,
                             meaning="802.11 delay after a packet's last byte is on air, s (not given)")
    loss: float = setting(NETWORK.loss, lo=0.0, hi=1.0, meaning="probability a packet is lost, per receiver")

    def team_sizes(self) -> tuple[int, int]:
        match = TEAM_FORM.match(self.team.strip())
        if match is None or int(match[1]) < 1 or int(match[2]) < 1:
            raise ConfigError(f"team={self.team!r}: write it [planners explorers], e.g. '1 3', both at least 1")
        return int(match[1]), int(match[2])

    def robot_ids(self) -> list[str]:
        ids = [r.strip() for r in self.robots.split(",") if r.strip()]
        unknown = [r for r in ids if r not in TABLE_5_22]
        if unknown or not ids:
            raise ConfigError(f"robots={self.robots!r}: allowed: Table 5.22's {', '.join(TABLE_5_22)}")
        return ids

    def world_params(self) -> ExploreWorldParams:
        return ExploreWorldParams(size=self.size, resolution=self.resolution, divisions=self.divisions,
                                  density=self.density, bog_share=self.bog_share)

    def check(self) -> None:
        self.team_sizes()
        self.robot_ids()
        self.world_params().check()


@dataclass
class ExploreTask:
    """explore's own scenario settings: the team and the territorial division."""
    planners: int = setting(1, lo=1, hi=8, meaning="W1 robots (§8.2: 1)")
    explorers: int = setting(3, lo=1, hi=8, meaning="W2 robots (§8.2: 1, 3 or 5)")
    divisions: int = setting(4, lo=1, hi=16, meaning="local environments per side")
    resolution: float = setting(0.3, lo=0.05, hi=1.0, meaning="map cell, m")
    t_m: float = setting(60.0, lo=1.0, hi=3600.0, meaning="feedback period T_m, s")
    explored_threshold: float = setting(EXPLORED_THRESHOLD, lo=0.0, hi=1.0, meaning="EA_T of (6.18)")
    backend: str = setting("physics", choices=("physics", "kinematic"), meaning="physics or kinematic")
    feedback: str = setting("full", choices=FEEDBACK_MODES, meaning="full, scores (no reallocation) or none")
    weights: str = setting("table", choices=("table", *WEIGHT_SETS), meaning="the explorers' WS")
    poor: str = setting("table", choices=("table", *POOR_THRESHOLDS), meaning="the explorers' OTES_T")
    partial: str = setting("table", choices=("table", *PARTIAL_THRESHOLDS), meaning="the explorers' TES_T")
    latency: float = setting(NETWORK.latency, lo=0.0, hi=60.0, meaning="802.11 delay after the last byte, s")
    loss: float = setting(NETWORK.loss, lo=0.0, hi=1.0, meaning="probability a packet is lost, per receiver")

    def network_config(self) -> NetworkConfig:
        return dataclasses.replace(NETWORK, latency=self.latency, loss=self.loss)


@dataclass
class ExplorerSettings:
    """A robot's capability data row (Table 5.22) is looked up by its name; nothing to set per robot."""


# -- the team ------------------------------------------------------------------------------------------------------
def team_allocation(robot_ids: list[str], planners: int, explorers: int) -> Allocation:
    """The ch.5 devolution over these robots with the worker quantities overridden by hand, as §8.2 did."""
    specs = {r.id: r for r in load_robots()}
    tasks = []
    for task in load_tasks():
        count = {PLANNER: planners, EXPLORER: explorers}.get(task.id)
        tasks.append(task if count is None else dataclasses.replace(task, quantity=(count, count, count)))
    allocation = allocate(tasks, [specs[r] for r in robot_ids])
    if allocation.unassigned:
        raise ConfigError(f"robots: no robot among {', '.join(robot_ids)} can take management task "
                          f"{allocation.unassigned[0]} (it needs a PC-class processor)")
    for task, missing in allocation.shortfall.items():
        if missing:
            name = {PLANNER: "planners", EXPLORER: "explorers"}[task]
            raise ConfigError(f"team: {len(allocation.workers[task])} of the robots {', '.join(robot_ids)} can be "
                              f"{name}, the team asks for {len(allocation.workers[task]) + missing}")
    return allocation


def robot_options(spec: RobotSpec) -> dict:
    """The model's dimensions from the robot's Table 5.22 row."""
    return {"radius": spec.radius, "v_max": spec.speed, "traversability": spec.traversability,
            "ir_count": int(spec.ir_quantity), "ir_range": spec.ir_range}


def expected_achievement(specs: dict[str, RobotSpec], t_m: float) -> dict:
    """RA' per T_m for every robot and worker task (Table 5.31, scaled by speed and T_m)."""
    expected = {}
    for robot, spec in specs.items():
        row = EXPECTED_PER_MINUTE["tracked" if KIND_OF_TYPE[spec.type] == "tracked" else "wheeled"]
        scale = t_m / 60.0
        speed = spec.speed / row["speed"]
        explorer = {cat: [v * scale * (speed if cat in ("sense", "act") else 1.0) for v in row[cat]]
                    for cat in ("plan", "comm", "sense", "act")}
        expected[robot] = {EXPLORER: explorer,
                           PLANNER: {cat: [v * scale for v in values] for cat, values in PLANNER_PER_MINUTE.items()}}
    return expected


def exploration_rate(spec: RobotSpec, t_m: float) -> float:
    """E_o of (5.23), cells/s: the explorer's RA' for area over T_m."""
    return expected_achievement({spec.id: spec}, t_m)[spec.id][EXPLORER]["sense"][0] / t_m


# -- the mission ---------------------------------------------------------------------------------------------------
class ExploreMission(ScenarioMission):
    name = "explore"
    summary = "a Table 5.22 team maps an unknown world with bogs: manager, planners, explorers (Chand ch.6)"
    Params = ExploreParams
    Task = ExploreTask
    Controller = ExplorerSettings
    default_duration = MET_LARGER  # a [1 1] team's is longer: ``duration_of``
    video_speedup = 20.0

    def scenario(self, params: ExploreParams, rng: np.random.Generator, newcomers) -> Scenario:
        params.check()
        planners, explorers = params.team_sizes()
        ids = params.robot_ids()
        allocation = team_allocation(ids, planners, explorers)
        members = [r for r in ids if r in team_members(allocation)]
        if params.world_seed >= 0:
            rng = np.random.default_rng(params.world_seed)
        world = explore_world(params.world_params(), rng)
        specs = {r.id: r for r in load_robots()}
        poses = world.start_poses([specs[r].radius for r in members])
        robots = {r: RobotEntry(KIND_OF_TYPE[specs[r].type], pose, robot_options(specs[r]), ExplorerSettings())
                  for r, pose in zip(members, poses)}
        boxes = [BoxObstacle(**dataclasses.asdict(box)) for box in world.nav.boxes]
        bogs = [BogZone(**dataclasses.asdict(bog)) for bog in world.bogs]
        return Scenario(mission=self.name, arena=Arena(size=(params.size, params.size), boxes=boxes, bogs=bogs),
                        robots=robots, task=ExploreTask(
                            planners=planners, explorers=explorers, divisions=params.divisions,
                            resolution=params.resolution, t_m=params.t_m, explored_threshold=params.explored_threshold,
                            backend=params.backend, feedback=params.feedback, weights=params.weights,
                            poor=params.poor, partial=params.partial, latency=params.latency, loss=params.loss))

    def duration_of(self, params: ExploreParams) -> float:
        """MET for the team (§8.2): 15000 s for one explorer, 5000 s for more."""
        return team_duration(params.team_sizes()[1])

    def check_scenario(self, scenario: Scenario) -> None:
        sx, sy = scenario.arena.size
        if sx != sy:
            raise ConfigError(f"arena.size=[{sx:g}, {sy:g}]: explore's worlds are square; allowed: equal sides")
        task = scenario.task
        ExploreWorldParams(size=sx, resolution=task.resolution, divisions=task.divisions).check()
        scenario_allocation(scenario)

    def scene(self, scenario: Scenario, newcomers, physics_dt: float) -> Scene:
        scene = scene_of(scenario, newcomers, physics_dt)
        specs = {r.id: r for r in load_robots()}
        scene.network = {name: (specs[name].bandwidth * 1e6, specs[name].comm_range) for name in scenario.robots}
        scene.network_config = scenario.task.network_config()
        scene.info.update(team_setup(scenario))
        return scene

    def controller(self, robot: RobotModel, scene: Scene, rng: np.random.Generator):
        return team_controller(robot.name, robot, scene.info)

    def done(self, world) -> bool:
        info = world.scene.info
        sample_progress(info, world.time,
                        lambda: {r.name: world.pose(r)[:2] for r in world.robots.values() if r.active})
        return exploration_over(info)

    def write_outputs(self, world, run_dir: Path) -> None:
        write_figures(world.scene.info, run_dir)

    def fault_targets(self, scenario: Scenario, faults: list) -> list:
        """Faults may name a robot by its role: manager, feedback, planner, explorer, plannerN, explorerN."""
        return fault_targets(faults, scenario_allocation(scenario), list(scenario.robots))

    def video_panel(self, world) -> np.ndarray | None:
        """The manager's global map as it grows, beside the top-down view: redrawn every ``PANEL_PERIOD`` s."""
        info = world.scene.info
        global_info: GlobalInfo | None = info["team"].get("global_info")
        if global_info is None or world.time < info.get("panel_time", -math.inf) + PANEL_PERIOD:
            return None
        info["panel_time"] = world.time
        roles = {name: robot.roles for name, robot in info["team"]["robots"].items()}
        return panel_image(global_info, info["territory"], info.get("trails", {}), roles, world.time)

    def without_physics(self, config) -> bool:
        task = config.scenario.task if config.scenario is not None else config.params
        return task.backend == "kinematic"

    def run_without_physics(self, config, run_dir: Path) -> dict:
        """The kinematic backend's trial, with map.png and coverage.png."""
        result = kinematic_trial(config)
        write_figures(result.pop("info"), run_dir)
        team = result.pop("team")
        result["robots"] = {name: {"distance_m": round(m.travelled, 2), "touches": m.touches, "alive": m.alive}
                            for name, m in team.members.items()}
        return result

    def outcome(self, world) -> tuple[bool, dict]:
        return exploration_outcome(world.scene.info, world.time)


def role_names(allocation: Allocation) -> dict[str, str]:
    """The names a fault may give a robot by: manager (M1), feedback (M2), planner and explorer (the first
    explorer that is not also a planner), planner1.., explorer1.. in allocation order."""
    planners, explorers = allocation.workers[PLANNER], allocation.workers[EXPLORER]
    names = {"manager": allocation.managers["M1"], "feedback": allocation.managers["M2"],
             "planner": planners[0], "explorer": next((r for r in explorers if r not in planners), explorers[0])}
    names |= {f"planner{k}": r for k, r in enumerate(planners, 1)}
    names |= {f"explorer{k}": r for k, r in enumerate(explorers, 1)}
    return names


def fault_targets(faults, allocation: Allocation, robots: list[str]) -> list:
    """Faults with role names replaced by the robot holding the role; a name that is neither is an error, naming the
    fault by its place in the whole schedule (the scenario's, then the command line's) as the scenario's check does."""
    names = role_names(allocation)
    out = []
    for k, fault in enumerate(faults):
        if fault.robot not in robots and fault.robot not in names:
            raise ConfigError(f"faults[{k}] {fault.kind}:{fault.robot}@{fault.time:g}: no robot or role "
                              f"{fault.robot!r}; robots: {', '.join(robots)}; roles: {', '.join(names)}")
        out.append(dataclasses.replace(fault, robot=names.get(fault.robot, fault.robot)))
    return out


def scenario_allocation(scenario: Scenario) -> Allocation:
    """The devolution over a scenario's robots, in its task's quantities; ConfigError for no robots or one that is
    not one of Table 5.22's (the allocation knows only their specifications)."""
    if not scenario.robots:
        raise ConfigError("robots: a scenario needs at least one robot")
    unknown = [name for name in scenario.robots if name not in TABLE_5_22]
    if unknown:
        raise ConfigError(f"robots.{unknown[0]}: explore's robots are Table 5.22's, named {', '.join(TABLE_5_22)}")
    return team_allocation(list(scenario.robots), scenario.task.planners, scenario.task.explorers)


def explorer_feedback(allocation: Allocation, task: ExploreTask) -> FeedbackSpec:
    """The explorers' feedback weights and thresholds: the task table's, with the task's Table 8.1 choices."""
    spec = allocation.tasks[EXPLORER].feedback
    return dataclasses.replace(
        spec, ws=WEIGHT_SETS.get(task.weights, spec.ws),
        otes_threshold=POOR_THRESHOLDS.get(task.poor, spec.otes_threshold),
        tes_threshold=PARTIAL_THRESHOLDS.get(task.partial, spec.tes_threshold))


def team_members(allocation: Allocation) -> set[str]:
    return set(allocation.managers.values()) | {r for robots in allocation.workers.values() for r in robots}


def team_setup(scenario: Scenario) -> dict:
    """What every robot's controller is built from, and what the outcome reads: the territory, the allocation,
    the true world, and a slot for the manager's state."""
    task = scenario.task
    specs = {r.id: r for r in load_robots()}
    allocation = scenario_allocation(scenario)
    territory = Territory(scenario.arena.size[0], task.resolution, task.divisions)
    truth = nav_world_of(dataclasses.replace(scenario, task=_RasterTask(task.resolution)))
    bogs = scenario.arena.bogs
    return {"territory": territory, "allocation": allocation, "specs": {r: specs[r] for r in scenario.robots},
            "task": task, "truth": truth.occupancy, "bogs": bogs, "team": {}}


@dataclass
class _RasterTask:
    """What ``nav_world_of`` reads of a task: the raster's resolution, and a goal it does not need here."""
    map_resolution: float
    goal: tuple[float, float] = (0.0, 0.0)


def team_controller(name: str, robot: RobotModel, info: dict) -> TeamRobot:
    """The controller of one team robot, with the roles the allocation gave it."""
    allocation: Allocation = info["allocation"]
    territory: Territory = info["territory"]
    task = info["task"]
    specs: dict[str, RobotSpec] = info["specs"]
    m1, m2 = allocation.managers["M1"], allocation.managers["M2"]
    addresses = Addresses(manager=m1, feedback=m2)
    global_info = feedback = None
    if name == m1:
        explorers = allocation.workers[EXPLORER]
        global_info = GlobalInfo(name, territory, explorers=explorers, planners=allocation.workers[PLANNER],
                                 task_scores={t: dict(s) for t, s in allocation.task_scores.items()},
                                 bog_capable={r: specs[r].traversability >= 1.0 for r in specs},
                                 radii={r: specs[r].radius for r in specs},
                                 rates={r: exploration_rate(specs[r], task.t_m) for r in specs}, t_m=task.t_m,
                                 explored_threshold=task.explored_threshold)
        info["team"]["global_info"] = global_info
    if name == m2:
        coordinator = FeedbackCoordinator(allocation, expected_achievement(specs, task.t_m),
                                          feedback={EXPLORER: explorer_feedback(allocation, task)},
                                          detect_failures=task.feedback == "full")
        feedback = FeedbackSystem(name, coordinator, task.t_m, enabled=task.feedback != "none")
        info["team"]["feedback"] = feedback
    spec = specs[name]
    offset = centre_offset(robot)

    def make_explorer() -> Explorer:
        kwargs = {"sensor_radius": ir_sensor_radii(robot, offset)}
        if isinstance(robot.drive, TricycleSpec):
            kwargs.update(centre_offset=offset, steering=robot.drive)
        navigator = HRDU(robot.limits, robot.kind, robot.footprint_radius, (0.0, 0.0),
                         grid=territory.unexplored_map(MAPPING), replanning=Replanning(turn_to_path=True), **kwargs)
        return Explorer(name, territory, navigator, manager=m1, bog_capable=spec.traversability >= 1.0,
                        radius=robot.footprint_radius, params=ExplorerParams())

    def make_planner() -> Planner:
        return Planner(name, territory, manager=m1)

    tasks = frozenset(t for t, robots in allocation.workers.items() if name in robots)
    controller = TeamRobot(name, addresses, t_m=task.t_m, global_info=global_info, feedback=feedback,
                           make_explorer=make_explorer, make_planner=make_planner, tasks=tasks)
    info["team"].setdefault("robots", {})[name] = controller
    return controller


def exploration_over(info: dict) -> bool:
    """No explorer has work left: each is finished or gone, and no environment is being explored."""
    global_info: GlobalInfo | None = info["team"].get("global_info")
    if global_info is None:
        return False
    working = [e for e in global_info.explorers if e not in global_info.finished]
    return not working and "assigned" not in global_info.status


COVERAGE_PERIOD = 30.0  # s between samples of the explored share, for coverage.png
TRAIL_PERIOD = 1.0  # s between samples of each robot's position, for map.png
PANEL_PERIOD = 2.0  # s of simulated time between redraws of the video's map panel


def sample_progress(info: dict, time: float, positions) -> None:
    """Now and then: the explored share (coverage.png) and each robot's position (map.png); ``positions()`` gives
    the live robots' (x, y), read only when a sample is due."""
    samples = info.setdefault("coverage", [])
    global_info = info["team"].get("global_info")
    if global_info is not None and (not samples or time >= samples[-1][0] + COVERAGE_PERIOD):
        samples.append((time, global_info.explored_share()))
    trails = info.setdefault("trails", {})
    if time >= info.get("trail_time", -math.inf) + TRAIL_PERIOD:
        info["trail_time"] = time
        for name, (x, y) in positions().items():
            trails.setdefault(name, []).append((float(x), float(y)))


def write_figures(info: dict, run_dir: Path) -> None:
    """map.png and coverage.png of a finished trial."""
    global_info: GlobalInfo = info["team"]["global_info"]
    write_map(run_dir / "map.png", global_info.global_map, info["territory"], global_info.status,
              global_info.boggy, info.get("trails", {}), info["bogs"])
    shown = ("bog", "explorer removed", "planner removed", "finished")
    write_coverage(run_dir / "coverage.png", info.get("coverage", []),
                   [e for e in global_info.log if e["event"] in shown])


def exploration_outcome(info: dict, time: float) -> tuple[bool, dict]:
    """§8.1's ET, PAE and ER (8.1), map accuracy, bogs found, reallocations."""
    global_info: GlobalInfo = info["team"]["global_info"]
    feedback: FeedbackSystem = info["team"]["feedback"]
    territory: Territory = info["territory"]
    share = global_info.explored_share()
    completed = exploration_over(info)
    p = global_info.global_map
    explored = np.abs(p - 0.5) > 1e-6
    correct = (p > 0.5) == info["truth"]
    accuracy = float(correct[explored].mean()) if explored.any() else 0.0
    true_boggy = boggy_environments(info["bogs"], territory)
    found = {e for e, boggy in enumerate(global_info.boggy) if boggy}
    flags = [{"t": round(t, 1), "robot": robot, "task": task, "flag": flag}
             for t, step in feedback.steps for (robot, task), flag in step.flags.items()]
    return completed, {
        "exploration_time": round(time, 1),
        "explored_share": round(share, 4),
        "exploration_rate": round(share / time, 8) if time > 0 else 0.0,
        "map_accuracy": round(accuracy, 4),
        "explored_cells": int(explored.sum()),
        "status": {s: global_info.status.count(s) for s in ("UE", "assigned", "PE", "E")},
        "boggy_environments": sorted(true_boggy),
        "bogs_found": sorted(found),
        "reallocations": sum(step.reallocated for _, step in feedback.steps),
        "feedback_flags": flags,
        "roles": {name: robot.roles for name, robot in info["team"]["robots"].items()},
        "log": global_info.log,
    }


def boggy_environments(bogs, territory: Territory) -> frozenset[int]:
    """Environments any bog zone reaches into (the manager's terrain map marks a whole local map, §6.1)."""
    return frozenset().union(*(territory.overlapping((b.x - b.half_x, b.y - b.half_y), (b.x + b.half_x, b.y + b.half_y))
                               for b in bogs))


def team_duration(explorers: int) -> float:
    """MET (§8.2)."""
    return MET.get(explorers, MET_LARGER)


# -- without physics -------------------------------------------------------------------------------------------------
def kinematic_team(scenario: Scenario, seed: int, faults=()) -> tuple[KinematicTeam, dict]:
    """The scenario's world, team and controllers in the kinematic backend, and the setup ``team_setup`` makes."""
    info = team_setup(scenario)
    streams = RandomStreams(seed)
    members = {}
    for name, entry in scenario.robots.items():
        model = build_robot(entry.kind, name, **entry.options)
        members[name] = Member(KinematicBody(kinematic_robot(model), entry.pose), team_controller(name, model, info),
                               model.traversability)
    specs = info["specs"]
    network = Network(scenario.task.network_config(),
                      {n: (specs[n].bandwidth * 1e6, specs[n].comm_range) for n in members},
                      {n: streams.get("robot", n, "radio") for n in members})
    world = nav_world_of(dataclasses.replace(scenario, task=_RasterTask(scenario.task.resolution)))
    return KinematicTeam(world, scenario.arena.bogs, members, network, list(faults)), info


def kinematic_trial(config, duration: float | None = None) -> dict:
    """An explore trial without physics: the same scenario (from the same seed), controllers and measures.
    Returns a summary shaped like ``run_trial``'s, with the team for the figures under ``"team"``."""
    config = resolve(config, ExploreMission())
    scenario = config.scenario
    team, info = kinematic_team(scenario, config.seed, config.faults)
    duration = duration or config.duration
    while team.time < duration - 1e-9 and not exploration_over(info):
        team.tick()
        sample_progress(info, team.time,
                        lambda: {n: (m.body.x, m.body.y) for n, m in team.members.items() if m.alive})
    completed, metrics = exploration_outcome(info, team.time)
    return {"mission": "explore", "seed": config.seed, "run_id": config.run_id,
            "status": "completed" if completed else "failed", "completed": completed,
            "sim_time_s": round(team.time, 3), "metrics": metrics, "team": team, "info": info}
