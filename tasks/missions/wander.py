"""``wander``: the smoke mission. N robots (differential-drive by default) wander with IR obstacle avoidance in a walled
room for a fixed time. It completes when the time runs out with the physics stable; it measures how far each
robot went and how much of the time robots spent touching walls, obstacles or each other.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from teamsim.config import ConfigError, setting
from teamsim.controllers.skills.wander import WanderController, WanderParams as BehaviourParams
from teamsim.models import ROBOT_KINDS
from teamsim.models.robot import RobotModel, team_names
from teamsim.scenario import Arena, BoxObstacle, RobotEntry, Scenario, scene_of
from teamsim.scene import Scene
from teamsim.tasks.base import ScenarioMission

CELL = 1.6  # m; spawn grid pitch, wide enough for the largest robot (0.6 m enclosing radius) plus clearance


@dataclass
class WanderParams:
    robots: int = setting(3, lo=1, hi=200, meaning="number of robots")
    room_size: float = setting(0.0, lo=0.0, hi=200.0,
                               meaning="side of the square room, m (0: sized for the team and obstacles, >= 6 m)")
    obstacles: int = setting(3, lo=0, hi=100, meaning="static box obstacles placed at random")
    kind: str = setting("diffdrive", choices=ROBOT_KINDS, meaning="robot kind of the team")

    def side(self, team_size: int) -> float:
        """The room's side: as set, or enough spawn cells for the team and obstacles with a third spare."""
        cells_per_row = math.ceil(math.sqrt(1.5 * (team_size + self.obstacles)))
        return self.room_size or max(6.0, CELL * cells_per_row)

    def check(self) -> None:
        side = self.side(self.robots)
        cells = int(side / CELL) ** 2
        if self.robots + self.obstacles > cells:
            raise ConfigError(f"robots={self.robots}, obstacles={self.obstacles}: a {side:g} m room has room for "
                              f"{cells} robots and obstacles together; raise room_size")


@dataclass
class WanderTask:
    """wander has no settings of its own in a scenario: the trial is the room, the team and the time."""


class WanderMission(ScenarioMission):
    name = "wander"
    summary = "N robots (differential-drive by default) wander with IR obstacle avoidance in a walled room"
    Params = WanderParams
    Task = WanderTask
    Controller = BehaviourParams  # each robot's wander settings, scaled to its drive and IR range when it starts
    default_duration = 60.0

    def scenario(self, params: WanderParams, rng: np.random.Generator, newcomers: list[tuple[str, str]]) -> Scenario:
        team = [(name, params.kind) for name in team_names(params.robots)]
        taken = [name for name, _ in newcomers if name in dict(team)]
        if taken:
            raise ConfigError(f"--fault add-robot:{taken[0]}: robot {taken[0]!r} is already in the team")
        side = params.side(len(team) + len(newcomers))
        per_row = int(side / CELL)
        offset = -side / 2 + (side - per_row * CELL) / 2 + CELL / 2
        cells = [(offset + i * CELL, offset + j * CELL) for i in range(per_row) for j in range(per_row)]
        needed = len(team) + len(newcomers) + params.obstacles
        if needed > len(cells):
            raise ConfigError(f"wander: {needed} robots and obstacles do not fit a {side:g} m room; raise room_size")
        order = rng.permutation(len(cells))[:needed]
        chosen = [cells[k] for k in order]
        obstacles = [BoxObstacle(x, y, *rng.uniform(0.15, 0.45, size=2), yaw=float(rng.uniform(0, math.pi)))
                     for x, y in chosen[:params.obstacles]]
        robots = {name: RobotEntry(kind, (x, y, float(rng.uniform(-math.pi, math.pi))), controller=BehaviourParams())
                  for (name, kind), (x, y) in zip(team + newcomers, chosen[params.obstacles:])}
        return Scenario(mission=self.name, arena=Arena(size=(side, side), boxes=obstacles), robots=robots,
                        task=WanderTask())

    def scene(self, scenario: Scenario, newcomers: list[tuple[str, str]], physics_dt: float) -> Scene:
        return scene_of(scenario, newcomers, physics_dt)

    def controller(self, robot: RobotModel, scene: Scene, rng: np.random.Generator):
        limits = robot.limits
        settings = scene.scenario.robots[robot.name].controller
        behaviour = settings.for_robot(limits.v_max, limits.omega_max, robot.ir.max_range)
        return WanderController(robot.ir_bearings, rng, behaviour)

    def done(self, world) -> bool:
        return False

    def outcome(self, world) -> tuple[bool, dict]:
        distance = world.odometry()
        touching = world.contact_fraction()
        metrics = {
            "distance_m": distance,
            "mean_distance_m": float(np.mean(list(distance.values()))) if distance else 0.0,
            "touching_fraction": touching,
        }
        return True, metrics
