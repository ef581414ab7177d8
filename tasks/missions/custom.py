"""A scene described in code: a room, robots at given poses, pucks, boxes, obstacles and bogs, with the
controller of each robot supplied by the caller. The contact-behaviour regression tests and the per-robot
benchmarks are built on it; users can script their own experiments with it.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from teamsim.config import TrialConfig
from teamsim.models.arenas import Bog, Box, add_bog, walled_room
from teamsim.models.objects import BoxDims, PuckDims, box, place, place_puck
from teamsim.scene import RobotSlot, Scene


@dataclass
class CustomParams:
    room: tuple[float, float] = (8.0, 8.0)
    robots: list[RobotSlot] = field(default_factory=list)
    pucks: list[tuple[float, float]] = field(default_factory=list)
    boxes: list[tuple[float, float, float]] = field(default_factory=list)  # x, y, yaw of long heavy boxes
    obstacles: tuple[Box, ...] = ()
    bogs: list[Bog] = field(default_factory=list)
    puck_dims: PuckDims = PuckDims()
    box_dims: BoxDims = BoxDims()


class CustomMission:
    name = "custom"
    summary = "a scene described in code (tests, benchmarks, scripted experiments)"
    Params = CustomParams
    default_duration = 10.0

    def __init__(self, controller_for: Callable):
        """``controller_for(robot_model, rng)`` returns the controller of each robot."""
        self.controller_for = controller_for

    def build(self, params: CustomParams, rng: np.random.Generator, newcomers, physics_dt: float) -> Scene:
        arena = walled_room(*params.room, obstacles=params.obstacles, physics_dt=physics_dt)
        for k, (x, y) in enumerate(params.pucks):
            place_puck(arena, f"puck{k}", params.puck_dims, x, y)
        for k, (x, y, yaw) in enumerate(params.boxes):
            place(arena, box(f"box{k}", params.box_dims), x, y, yaw)
        for k, bog in enumerate(params.bogs):
            add_bog(arena, bog, f"bog{k}")
        return Scene(arena=arena, robots=list(params.robots), bogs=list(params.bogs), params=params)

    def controller(self, robot, scene, rng):
        return self.controller_for(robot, rng)

    def done(self, world) -> bool:
        return False

    def outcome(self, world) -> tuple[bool, dict]:
        return True, {"distance_m": world.odometry()}


def custom_config(params: CustomParams, seed: int = 0, **kwargs) -> TrialConfig:
    return TrialConfig(mission="custom", params=params, seed=seed, **kwargs)
