"""The live viewer: a mission and its controllers in MuJoCo's own interactive viewer (``mujoco.viewer``, passive
mode), at real time or a chosen speed-up (issue 30).

Each robot's name and current behaviour float above it, and the top-left corner lists them with the clock. Space
pauses and resumes; the right arrow steps one control period while paused; the mouse looks around as in MuJoCo's
``simulate``. Faults fire as in ``teamsim run``. The run ends when the mission is done, at its duration, or when
the window is closed; nothing is written to disk (``teamsim run`` is the recorded, headless way).
"""
from __future__ import annotations

import os
import threading
import time
import warnings
from dataclasses import dataclass

import mujoco
import numpy as np

from teamsim.config import ConfigError, TrialConfig, validate
from teamsim.scenario import resolve
from teamsim.world import PhysicsUnstable, World

KEY_SPACE, KEY_RIGHT = 32, 262  # GLFW key codes
LABEL_HEIGHT = 0.6  # m above a robot's base where its label floats
NO_DISPLAY = ("no display: `teamsim view` opens a window; run it on a desktop, under `xvfb-run`, or headless with "
              "`teamsim run --video`")


@dataclass(frozen=True)
class ViewResult:
    status: str  # completed, failed (time limit), closed (window closed early) or unstable
    sim_time_s: float
    wall_time_s: float
    metrics: dict


class _Keys:
    """Pause state driven by the viewer's key callback (called on the viewer's thread)."""

    def __init__(self) -> None:
        self.paused = False
        self.steps = 0  # control periods asked for while paused

    def __call__(self, key: int) -> None:
        if key == KEY_SPACE:
            self.paused = not self.paused
        elif key == KEY_RIGHT and self.paused:
            self.steps += 1


def require_display() -> None:
    """Raise ConfigError (exit 2 from the CLI) unless a window can be opened."""
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise ConfigError(NO_DISPLAY)
    import glfw  # noqa: PLC0415  (MuJoCo's viewer opens its window through GLFW)

    with warnings.catch_warnings():  # GLFW warns, then returns False: the one-line error says it
        warnings.simplefilter("ignore")
        if not glfw.init():
            raise ConfigError(f"cannot open a window on display {os.environ.get('DISPLAY')!r}; run it on a "
                              "desktop, under `xvfb-run`, or headless with `teamsim run --video`")


def _frame_arena(camera, model: mujoco.MjModel, data: mujoco.MjData) -> None:
    """Point the free camera at the arena (the fixed geoms but the floor: walls, obstacles, zones) from above at
    an angle, far enough back to see all of it."""
    fixed = (model.geom_bodyid == 0) & (model.geom_type != mujoco.mjtGeom.mjGEOM_PLANE)
    if not fixed.any():
        fixed = model.geom_bodyid > 0
    corners = np.concatenate([data.geom_xpos[fixed] - model.geom_rbound[fixed, None],
                              data.geom_xpos[fixed] + model.geom_rbound[fixed, None]])
    low, high = corners.min(axis=0), corners.max(axis=0)
    camera.lookat[:] = (low + high) / 2
    camera.distance = 1.1 * float(np.max(high[:2] - low[:2]))
    camera.elevation, camera.azimuth = -60.0, 90.0


def _label(scene: mujoco.MjvScene, world: World) -> None:
    """One invisible marker per live robot, labelled ``name: behaviour``, above the robot."""
    scene.ngeom = 0
    for robot in world.robots.values():
        if robot.dormant or robot.health.removed or scene.ngeom >= scene.maxgeom:
            continue
        x, y, _ = world.pose(robot)
        geom = scene.geoms[scene.ngeom]
        mujoco.mjv_initGeom(geom, mujoco.mjtGeom.mjGEOM_SPHERE, np.array([0.01, 0, 0]),
                            np.array([x, y, LABEL_HEIGHT]), np.eye(3).ravel(), np.array([1, 1, 1, 0], np.float32))
        geom.label = f"{robot.name}: {robot.behaviour if robot.active else 'dead'}"
        scene.ngeom += 1


def _corner_text(world: World, keys: _Keys) -> tuple:
    names = [f"t = {world.time:.1f} s" + ("  (paused)" if keys.paused else "")]
    states = [""]
    for robot in world.robots.values():
        if not robot.dormant:
            names.append(robot.name)
            states.append(robot.behaviour if robot.active else "dead")
    return (mujoco.mjtFontScale.mjFONTSCALE_150, mujoco.mjtGridPos.mjGRID_TOPLEFT, "\n".join(names),
            "\n".join(states))


def view(config: TrialConfig, mission, speed: float = 1.0) -> ViewResult:
    """Run ``config``'s trial in the live viewer, ``speed`` simulated seconds per wall second."""
    if not (speed > 0):
        raise ConfigError("--speed: must be > 0 (simulated seconds per wall-clock second)")
    validate(config)
    config = resolve(config, mission)
    if getattr(mission, "without_physics", None) and mission.without_physics(config):
        raise ConfigError("a physics-free run has nothing to show; the viewer needs the physics backend")
    require_display()
    import mujoco.viewer  # noqa: PLC0415

    world = World(config, mission)
    duration = config.duration or mission.default_duration
    end_step = round(duration / world.physics_dt)
    keys = _Keys()
    status, started = "closed", time.perf_counter()
    before = set(threading.enumerate())
    with mujoco.viewer.launch_passive(world.model, world.data, key_callback=keys, show_left_ui=False,
                                      show_right_ui=False) as window:
        with window.lock():
            _frame_arena(window.cam, world.model, world.data)
        wall_base, sim_base = time.perf_counter(), world.time
        try:
            while window.is_running():
                if world.step >= end_step or mission.done(world):
                    status = "ended"
                    break
                if keys.paused and keys.steps == 0:
                    time.sleep(0.02)
                    wall_base, sim_base = time.perf_counter(), world.time
                    window.sync()
                    continue
                keys.steps = max(0, keys.steps - 1)
                with window.lock():
                    world.tick()
                    world.advance(min(world.steps_per_tick, end_step - world.step))
                    world.check_stable()
                    _label(window.user_scn, world)
                window.set_texts(_corner_text(world, keys))
                window.sync()
                ahead = (world.time - sim_base) / speed - (time.perf_counter() - wall_base)
                if ahead > 0:
                    time.sleep(ahead)
        except PhysicsUnstable:
            status = "unstable"
    # The viewer's (daemon) thread tears its window down after close(): wait for it, or the interpreter may exit
    # under it (a segfault or a hang at exit).
    for thread in set(threading.enumerate()) - before:
        thread.join(timeout=10)
    wall = time.perf_counter() - started
    metrics = {}
    if status == "ended":
        completed, metrics = mission.outcome(world)
        status = "completed" if completed else "failed"
    return ViewResult(status, round(world.time, 6), round(wall, 3), metrics)
