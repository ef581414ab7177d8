"""What a mission is: it sets up the world (arena and team), gives each robot a controller, says when the
trial is over and whether it succeeded, and measures it.
"""
from __future__ import annotations

from typing import Any, ClassVar, Protocol

import numpy as np

from teamsim.controllers.base import Controller
from teamsim.models.robot import RobotModel
from teamsim.scene import Scene


class Mission(Protocol):
    name: ClassVar[str]
    summary: ClassVar[str]
    Params: ClassVar[type]
    default_duration: ClassVar[float]

    def build(self, params: Any, rng: np.random.Generator, newcomers: list[tuple[str, str]],
              physics_dt: float) -> Scene:
        """The arena and the team; ``newcomers`` are (name, kind) pairs that join later (add-robot faults)."""

    def controller(self, robot: RobotModel, scene: Scene, rng: np.random.Generator) -> Controller:
        """The controller that drives ``robot`` in ``scene`` (whose ``params`` and ``info`` it may use)."""

    def done(self, world: Any) -> bool:
        """True when the mission has ended before its time limit."""

    def outcome(self, world: Any) -> tuple[bool, dict]:
        """(completed, metrics) measured from the world at the end of the trial."""

    # Optional, for missions whose robots take roles at run time (bounding overwatch elects leaders, Parker
    # §6.3): ``fault_roles: dict[str, str]`` (role -> meaning) are the roles a fault may name as ``@ROLE``, and
    # ``role_holder(world, role) -> str | None`` names the live robot holding one now (None: vacant; the fault
    # then waits). The world asks when the fault is due (teamsim.faults).


class ScenarioMission:
    """A mission whose worlds are scenarios (``teamsim.scenario``): ``scenario`` describes the world its
    parameters give, ``scene`` builds a described world, and ``build`` is the two in turn, so a run from the
    parameters and a run from the exported scenario are the same trial. ``Task`` and ``Controller`` are the
    classes of the scenario's ``task`` section and of each robot's ``controller`` settings.

    Subclasses provide ``scenario(params, rng, newcomers) -> Scenario`` and ``scene(scenario, newcomers,
    physics_dt) -> Scene`` (``teamsim.scenario.scene_of`` builds the common part)."""
    Task: ClassVar[type]
    Controller: ClassVar[type]

    def build(self, params: Any, rng: np.random.Generator, newcomers: list[tuple[str, str]],
              physics_dt: float) -> Scene:
        return self.scene(self.scenario(params, rng, newcomers), newcomers, physics_dt)
