"""``teamsim bench physics`` and ``teamsim bench render``: figures measured in one run, printed with ratios.

physics: for teams of N wandering diffdrive robots, and for one robot of each kind alone, the steps/s and
real-time factor of
  (a) bare ``mujoco.mj_step`` on the same compiled model, sensors off, one C call for all steps;
  (b) the full stack: faults, IR sensing through the IR model, positioning, radio, controllers, locomotion,
      energy sampling and trajectory recording;
and the ratio b/a (the share of the physics rate that survives the Python layer). Then where (a)'s time goes,
from MuJoCo's own timers: collision detection, building the constraint rows, the constraint solver and the
rest (kinematics, inertia, integration), per step and per robot, with the contacts and rows per robot.

cleanup: the 3-robot hazardous-waste mission's real-time factor (the issue's target: >= 20x on one core, no video),
with resting objects asleep (as shipped, see :func:`teamsim.models.arenas.walled_room`) and with sleeping
switched off on the same world, and the ratio of the two.

box-pushing: two R-2s pushing the box, Genghis-II standing behind one, real-time factor (target >= 20x, no video).

render: frames/s at 640x480 for a 5-robot scene: the MuJoCo render alone, with the HUD, and with the HUD
and H.264 encoding (the whole live video path).
"""
from __future__ import annotations

import tempfile
import time
from pathlib import Path

import mujoco
import numpy as np

from teamsim.config import TrialConfig
from teamsim.faults import Fault
from teamsim.recording import TrajectoryRecorder
from teamsim.runner import simulate
from teamsim.scenario import resolve
from teamsim.tasks import MISSIONS
from teamsim.world import World

TEAM_SIZES = (1, 5, 20, 50)


def _wander_world(robots: int, seed: int = 0) -> World:
    mission = MISSIONS["wander"]
    return World(TrialConfig(mission="wander", params=mission.Params(robots=robots), seed=seed), mission)


def bare_steps_per_second(world: World, steps: int) -> float:
    """(a): the same compiled model stepped by one ``mj_step(nstep=...)`` call, robots driving forward."""
    model = mujoco.MjModel.from_xml_string(world.xml)
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_SENSOR)
    data = mujoco.MjData(model)
    data.ctrl[:] = np.clip(3.0, model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1])  # all drive
    start = time.perf_counter()
    mujoco.mj_step(model, data, nstep=steps)
    return steps / (time.perf_counter() - start)


def steps_from_state(world: World, steps: int) -> float:
    """Bare ``mj_step`` steps/s of a world's model from its current state, its controls held."""
    data = mujoco.MjData(world.model)
    data.qpos[:], data.qvel[:], data.ctrl[:] = world.data.qpos, world.data.qvel, world.data.ctrl
    start = time.perf_counter()
    mujoco.mj_step(world.model, data, nstep=steps)
    return steps / (time.perf_counter() - start)


# MuJoCo's timers, grouped into the parts a model change could cut
PHASES = {"collision": ("mjTIMER_POS_COLLISION",), "rows": ("mjTIMER_POS_MAKE", "mjTIMER_POS_PROJECT"),
          "solver": ("mjTIMER_CONSTRAINT",)}


def physics_time_split(world: World, steps: int) -> dict:
    """Microseconds per bare step in each of PHASES and the rest, and contacts and rows per robot."""
    model = mujoco.MjModel.from_xml_string(world.xml)
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_SENSOR)
    data = mujoco.MjData(model)
    data.ctrl[:] = np.clip(3.0, model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1])
    mujoco.mj_step(model, data, nstep=steps)

    def microseconds(timer: str) -> float:
        record = data.timer[int(mujoco.mjtTimer.__members__[timer])]
        return record.duration / max(record.number, 1) * 1e6

    split = {phase: sum(map(microseconds, timers)) for phase, timers in PHASES.items()}
    split["other"] = microseconds("mjTIMER_STEP") - sum(split.values())
    robots = len(world.robots)
    split |= {"contacts_per_robot": data.ncon / robots, "rows_per_robot": data.nefc / robots}
    return split


def stack_steps_per_second(world: World, seconds: float) -> float:
    """(b): the full control loop, as ``run_trial`` runs it without outputs."""
    recorder = TrajectoryRecorder(world.xml, list(world.robots), 30, world.physics_dt)
    start = time.perf_counter()
    simulate(world, world.mission, seconds, recorder,
             lambda: recorder.capture(world.time, world.data.qpos, [r.behaviour for r in world.robots.values()]))
    return world.step / (time.perf_counter() - start)


def best_of(repeats: int, measure) -> float:
    """The highest of ``repeats`` rates: other load on the machine only ever slows a run down."""
    return max(measure() for _ in range(repeats))


def physics(seconds: float = 10.0, sizes: tuple[int, ...] = TEAM_SIZES, repeats: int = 3) -> list[dict]:
    print(f"bench physics: wander, {seconds:g} s simulated per measurement, best of {repeats}, "
          f"physics dt 2 ms, control 100 ms")
    print(f"{'robots':>6} {'(a) bare steps/s':>17} {'RTF':>7} {'(b) stack steps/s':>18} {'RTF':>7} {'b/a':>6}")
    rows = []
    for n in sizes:
        world = _wander_world(n)
        steps = round(seconds / world.physics_dt)
        bare = best_of(repeats, lambda: bare_steps_per_second(world, steps))
        stack = best_of(repeats, lambda: stack_steps_per_second(_wander_world(n), seconds))
        row = {"robots": n, "bare_steps_per_s": bare, "stack_steps_per_s": stack, "ratio": stack / bare,
               "bare_rtf": bare * world.physics_dt, "stack_rtf": stack * world.physics_dt}
        rows.append(row)
        print(f"{n:>6} {bare:>17.0f} {row['bare_rtf']:>6.1f}x {stack:>18.0f} {row['stack_rtf']:>6.1f}x "
              f"{row['ratio']:>6.2f}", flush=True)
    print("where (a)'s time goes, microseconds per step (per robot in brackets), from MuJoCo's timers")
    print(f"{'robots':>6} " + " ".join(f"{phase:>14}" for phase in (*PHASES, "other"))
          + f" {'contacts/robot':>15} {'rows/robot':>11}")
    for row in rows:
        n = row["robots"]
        row["split"] = split = physics_time_split(_wander_world(n), round(seconds / 2 / _wander_world(1).physics_dt))
        print(f"{n:>6} " + " ".join(f"{split[p]:>7.0f} ({split[p] / n:>4.1f})" for p in (*PHASES, "other"))
              + f" {split['contacts_per_robot']:>15.1f} {split['rows_per_robot']:>11.1f}", flush=True)
    return rows


def robot_kinds(seconds: float = 10.0) -> list[dict]:
    """One scene per robot kind: the robot alone in a room driving a (0.2 m/s, 0.1 rad/s) circle."""
    from teamsim.controllers.base import Command
    from teamsim.models import ROBOT_BUILDERS
    from teamsim.scene import RobotSlot
    from teamsim.tasks.missions.custom import CustomMission, CustomParams, custom_config

    print(f"bench physics: one robot per scene, driving a circle, {seconds:g} s simulated")
    print(f"{'robot':>10} {'(a) bare steps/s':>17} {'(b) stack steps/s':>18} {'RTF':>7} {'b/a':>6}")
    rows = []
    for kind in ROBOT_BUILDERS:
        mission = CustomMission(lambda robot, rng: lambda obs: Command(v=0.2, omega=0.1, behaviour="circle"))
        params = CustomParams(room=(10.0, 10.0), robots=[RobotSlot("red", kind, 0.0, -2.0, 0.0)])
        world = World(custom_config(params), mission)
        bare = bare_steps_per_second(world, round(seconds / world.physics_dt))
        stack = stack_steps_per_second(world, seconds)
        rows.append({"robot": kind, "bare_steps_per_s": bare, "stack_steps_per_s": stack})
        print(f"{kind:>10} {bare:>17.0f} {stack:>18.0f} {stack * world.physics_dt:>6.1f}x {stack / bare:>6.2f}",
              flush=True)
    return rows


def cleanup(seconds: float = 300.0, seed: int = 9) -> dict:
    mission = MISSIONS["hazardous-waste"]

    def real_time_factor(sleep: bool) -> float:
        world = World(TrialConfig(mission="hazardous-waste", params=mission.Params(), seed=seed), mission)
        if not sleep:
            world.model.opt.enableflags &= ~int(mujoco.mjtEnableBit.mjENBL_SLEEP)
        return stack_steps_per_second(world, seconds) * world.physics_dt

    print(f"bench cleanup: hazardous-waste, 3 robots, seed {seed}, {seconds:g} s simulated, full control stack, "
          f"no video")
    result = {"sleep_rtf": real_time_factor(True), "awake_rtf": real_time_factor(False)}
    result["ratio"] = result["sleep_rtf"] / result["awake_rtf"]
    print(f"  resting objects asleep  {result['sleep_rtf']:6.1f}x real time   (target >= 20x)")
    print(f"  every body awake        {result['awake_rtf']:6.1f}x real time")
    print(f"  ratio                   {result['ratio']:6.2f}")
    return result


def box_pushing(seconds: float = 120.0, seed: int = 0, repeats: int = 3) -> dict:
    """Two R-2s pushing the box's ends and Genghis-II, joining at t = 0, standing behind green on its twelve leg
    servos (issue 23's target: >= 20x real time)."""
    mission = MISSIONS["box-pushing"]
    config = TrialConfig(mission="box-pushing", params=mission.Params(), seed=seed,
                         faults=[Fault("add-robot", "genghis", 0.0, {"kind": "genghis2"})])
    print(f"bench box-pushing: red and green (R-2s) pushing, genghis (Genghis-II) standing behind green, seed {seed}, "
          f"{seconds:g} s simulated, full control stack, no video, best of {repeats}")
    return mission_speed(config, seconds, repeats)


def janitorial(seconds: float = 300.0, seed: int = 0, repeats: int = 2) -> dict:
    """The janitorial service's default mission: three janitors, their tools and the ground truth measured every
    control period (issue 26's target: >= 20x real time)."""
    mission = MISSIONS["janitorial"]
    config = TrialConfig(mission="janitorial", params=mission.Params(), seed=seed)
    print(f"bench janitorial: r1, r2, r3 (janitors), seed {seed}, {seconds:g} s simulated, full control stack, "
          f"no video, best of {repeats}")
    return mission_speed(config, seconds, repeats)


def formation(seconds: float = 120.0, seed: int = 0, repeats: int = 2) -> dict:
    """Keeping formation: four robots in line under strategy IV, and a crossing team of two (held to issue 27's
    figure for eight robots, >= 15x real time)."""
    config = TrialConfig(mission="formation", params=MISSIONS["formation"].Params(crossing=2), seed=seed)
    print(f"bench formation: A-D in line (strategy IV) and X1, X2 crossing, seed {seed}, {seconds:g} s simulated, "
          f"full control stack, no video, best of {repeats}")
    return mission_speed(config, seconds, repeats, target=15.0)


def overwatch(seconds: float = 120.0, seed: int = 0, repeats: int = 2) -> dict:
    """Bounding overwatch's eight robots (issue 27's target: >= 15x real time)."""
    config = TrialConfig(mission="bounding-overwatch", params=MISSIONS["bounding-overwatch"].Params(), seed=seed)
    print(f"bench bounding-overwatch: 8 robots, seed {seed}, {seconds:g} s simulated, full control stack, no video, "
          f"best of {repeats}")
    return mission_speed(config, seconds, repeats, target=15.0)


def mission_speed(config: TrialConfig, seconds: float, repeats: int, target: float = 20.0) -> dict:
    """A mission's full control stack, no video, best of ``repeats``; and bare ``mj_step`` from the state a run
    ended in (its controls held), the most the stack could reach."""
    mission = MISSIONS[config.mission]
    worlds = []

    def stack() -> float:
        worlds.append(World(resolve(config, mission), mission))
        return stack_steps_per_second(worlds[-1], seconds)

    stack_rate = best_of(repeats, stack)
    bare_rate = best_of(repeats, lambda: steps_from_state(worlds[-1], 5000))
    dt = worlds[-1].physics_dt
    result = {"rtf": stack_rate * dt, "bare_rtf": bare_rate * dt}
    print(f"  full stack      {result['rtf']:6.1f}x real time   (target >= {target:g}x)")
    print(f"  bare mj_step    {result['bare_rtf']:6.1f}x real time   (b/a {stack_rate / bare_rate:.2f})")
    return result


def render(seconds: float = 4.0, robots: int = 5, width: int = 640, height: int = 480) -> dict:
    from teamsim.video import FrameRenderer, Mp4Writer

    world = _wander_world(robots)
    recorder = TrajectoryRecorder(world.xml, list(world.robots), 30, world.physics_dt)
    names = list(world.robots)
    simulate(world, world.mission, seconds, recorder,
             lambda: recorder.capture(world.time, world.data.qpos, [r.behaviour for r in world.robots.values()]))
    frames = list(zip(recorder.times, recorder.qpos, recorder.behaviours))
    renderer = FrameRenderer(world.xml, names, width, height)
    renderer.render(*frames[0])  # the first frame pays for GL context and texture upload

    def rate(draw) -> float:
        start = time.perf_counter()
        for frame in frames:
            draw(frame)
        return len(frames) / (time.perf_counter() - start)

    def scene_only(frame) -> np.ndarray:
        renderer.data.qpos[:] = frame[1]
        mujoco.mj_kinematics(renderer.model, renderer.data)
        mujoco.mj_camlight(renderer.model, renderer.data)
        renderer.renderer.update_scene(renderer.data, camera=renderer.camera)
        return renderer.renderer.render()

    result = {"frames": len(frames), "scene_fps": rate(scene_only), "hud_fps": rate(lambda f: renderer.render(*f))}
    with tempfile.TemporaryDirectory() as tmp:
        writer = Mp4Writer(Path(tmp) / "bench.mp4", width, height, 30)
        result["video_fps"] = rate(lambda f: writer.write(renderer.render(*f)))
        writer.close()
    renderer.close()
    print(f"bench render: {robots} robots, {width}x{height}, {len(frames)} frames, MUJOCO_GL backend "
          f"{__import__('os').environ.get('MUJOCO_GL')}")
    print(f"  render only           {result['scene_fps']:6.1f} frames/s")
    print(f"  render + HUD          {result['hud_fps']:6.1f} frames/s")
    print(f"  render + HUD + H.264  {result['video_fps']:6.1f} frames/s   (target >= 25)")
    return result
