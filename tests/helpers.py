"""Shared test helpers: small trial configurations and a scripted mission for tests that need exact control."""
from __future__ import annotations

import teamsim  # noqa: F401  (chooses the GL backend before mujoco is imported)
from teamsim.config import TrialConfig
from teamsim.controllers.base import Command
from teamsim.tasks import MISSIONS
from teamsim.tasks.missions.wander import WanderMission


def wander_config(tmp_path, **overrides) -> TrialConfig:
    mission = MISSIONS["wander"]
    params = mission.Params(**overrides.pop("params", {}))
    return TrialConfig(mission="wander", params=params, out=str(tmp_path), **overrides)


class ScriptedController:
    """Drives a fixed (v, omega), records every observation, and broadcasts its own name."""

    def __init__(self, v: float, omega: float):
        self.v, self.omega = v, omega
        self.observations = []

    def __call__(self, observation) -> Command:
        self.observations.append(observation)
        return Command(v=self.v, omega=self.omega, behaviour="scripted", broadcast={"from": observation.robot})


class ScriptedMission(WanderMission):
    """The wander arena and team, with every robot under a ScriptedController."""

    def __init__(self, v: float = 0.2, omega: float = 0.0):
        self.v, self.omega = v, omega
        self.controllers: dict[str, ScriptedController] = {}

    def controller(self, robot, scene, rng):
        self.controllers[robot.name] = ScriptedController(self.v, self.omega)
        return self.controllers[robot.name]


def advance_seconds(world, seconds: float) -> None:
    """Run the control loop of ``world`` for ``seconds`` of simulated time."""
    end = world.step + round(seconds / world.physics_dt)
    while world.step < end:
        world.tick()
        world.advance(min(world.steps_per_tick, end - world.step))
