"""Harness for contact-behaviour regression tests: a scripted scene stepped through the full World.

Import it as ``from tests.contact.harness import make_world, run_for, ...`` (tests is a package).
"""
from __future__ import annotations

import numpy as np

import teamsim  # noqa: F401  (GL backend before mujoco)
from teamsim.controllers.base import Command
from teamsim.scene import RobotSlot
from teamsim.tasks.missions.custom import CustomMission, CustomParams, custom_config
from teamsim.world import World

__all__ = ["Scripted", "RobotSlot", "CustomParams", "make_world", "run_for", "body_pose"]


class Scripted:
    """A controller that returns whatever ``policy(observation)`` says and keeps every observation.

    ``policy`` returns a Command, or a (v, omega) pair, or (v, omega, extras)."""

    def __init__(self, policy):
        self.policy = policy
        self.observations = []

    def __call__(self, observation) -> Command:
        self.observations.append(observation)
        out = self.policy(observation)
        if isinstance(out, Command):
            return out
        v, omega, *extras = out
        return Command(v=v, omega=omega, behaviour="scripted", extras=extras[0] if extras else {})


def make_world(params: CustomParams, policies: dict, seed: int = 0, **config) -> World:
    """A World of the custom scene ``params``; ``policies`` maps robot name -> policy (see Scripted)."""
    controllers = {name: Scripted(policy) for name, policy in policies.items()}
    mission = CustomMission(lambda robot, rng: controllers[robot.name])
    world = World(custom_config(params, seed=seed, **config), mission)
    world.controllers = controllers
    return world


def run_for(world: World, seconds: float, until=None) -> None:
    """Step the control loop for ``seconds`` (or until ``until(world)`` is true at a tick)."""
    end = world.step + round(seconds / world.physics_dt)
    while world.step < end:
        world.tick()
        if until is not None and until(world):
            return
        world.advance(min(world.steps_per_tick, end - world.step))


def body_pose(world: World, body: str) -> np.ndarray:
    """World position (x, y, z) of a named body, e.g. 'puck0/puck' (kinematics refreshed first)."""
    import mujoco
    mujoco.mj_kinematics(world.model, world.data)
    return world.data.xpos[mujoco.mj_name2id(world.model, mujoco.mjtObj.mjOBJ_BODY, body)].copy()
