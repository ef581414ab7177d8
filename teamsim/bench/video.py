"""``teamsim bench render``, second part: what ``--video`` costs a run, measured in one run.

The README's job, shortened: the hazardous-waste cleanup, seed 9, ``seconds`` simulated, its 4x time-lapse video
at 640x480. Three runs of the same trial, wall time each:
  (a) no video;
  (b) ``--video`` as shipped: frames rendered and encoded in their own process (``teamsim.video.VideoProcess``);
  (c) the path before, kept here as the reference: every frame rendered and encoded on the physics' own core,
      between physics steps.
Target: b/a <= 1.3 on 2 cores.
"""
from __future__ import annotations

import tempfile
import time
from pathlib import Path

from teamsim.config import TrialConfig
from teamsim.recording import TrajectoryRecorder
from teamsim.runner import run_trial, simulate
from teamsim.tasks import MISSIONS
from teamsim.world import World

COST_TARGET = 1.3


def _config(out: Path, seconds: float, seed: int, video: bool) -> TrialConfig:
    config = TrialConfig(mission="hazardous-waste", params=MISSIONS["hazardous-waste"].Params(), seed=seed,
                         duration=seconds, out=str(out), run_id=f"video-{video}")
    config.video.enabled = video
    return config


def _run_seconds(config: TrialConfig) -> float:
    began = time.perf_counter()
    run_trial(config, progress=False)
    return time.perf_counter() - began


def _on_the_physics_core(config: TrialConfig, out: Path) -> float:
    """The reference: the same trial with each frame rendered and encoded in the physics' own loop."""
    from teamsim.video import FrameRenderer, Mp4Writer

    began = time.perf_counter()
    mission = MISSIONS[config.mission]
    world = World(config, mission)
    v = config.video
    renderer = FrameRenderer(world.xml, list(world.robots), v.width, v.height, v.camera)
    writer = Mp4Writer(out / "reference.mp4", v.width, v.height, v.fps)
    speedup = v.speedup or getattr(mission, "video_speedup", 1.0)
    recorder = TrajectoryRecorder(world.xml, list(world.robots), v.fps, world.physics_dt, speedup)

    def capture() -> None:
        behaviours = [r.behaviour for r in world.robots.values()]
        recorder.capture(world.time, world.data.qpos, behaviours)
        writer.write(renderer.render(world.time, world.data.qpos, behaviours))

    simulate(world, mission, config.duration, recorder, capture)
    writer.close()
    renderer.close()
    return time.perf_counter() - began


def video_cost(seconds: float = 120.0, seed: int = 9) -> dict:
    print(f"bench render: what --video costs the README's job (hazardous-waste seed {seed}, {seconds:g} s "
          f"simulated, 4x time-lapse, 640x480), target <= {COST_TARGET:g}x a run without", flush=True)
    with tempfile.TemporaryDirectory(prefix="teamsim-bench-video-") as folder:
        out = Path(folder)
        result = {"none_s": _run_seconds(_config(out, seconds, seed, False)),
                  "process_s": _run_seconds(_config(out, seconds, seed, True)),
                  "inline_s": _on_the_physics_core(_config(out, seconds, seed, True), out)}
    result["process_ratio"] = result["process_s"] / result["none_s"]
    result["inline_ratio"] = result["inline_s"] / result["none_s"]
    verdict = "ok" if result["process_ratio"] <= COST_TARGET else "OVER TARGET"
    print(f"  no video                              {result['none_s']:6.1f} s")
    print(f"  video in its own process (shipped)    {result['process_s']:6.1f} s   "
          f"{result['process_ratio']:4.2f}x  {verdict}")
    print(f"  video on the physics core (before)    {result['inline_s']:6.1f} s   {result['inline_ratio']:4.2f}x")
    return result
