"""``teamsim render RUN_DIR...``: a video from ``trajectory.npz`` alone, through the live render's own path;
several runs at once in parallel worker processes, one core each."""
from __future__ import annotations

import concurrent.futures as futures
import json
import os
from pathlib import Path

from teamsim.config import ConfigError
from teamsim.progress import Progress
from teamsim.recording import load_trajectory
from teamsim.sweep import worker_pool


def trajectory_of(run_dir: Path) -> Path:
    path = Path(run_dir) / "trajectory.npz"
    try:
        found = path.is_file()
    except OSError as exc:  # (a name too long: is_file lets that through)
        raise ConfigError(f"RUN_DIR {run_dir}: cannot read ({exc.strerror or exc})") from None
    if not found:
        raise ConfigError(f"RUN_DIR {run_dir}: no trajectory.npz there{_why_missing(Path(run_dir))}")
    return path


def _why_missing(run_dir: Path) -> str:
    """What the run's summary says about a missing trajectory: a run cut off (killed), or one still running."""
    from teamsim.runner import cut_off  # (the runner imports every mission; only needed on this error path)

    try:
        summary = json.loads((run_dir / "summary.json").read_text())
    except (OSError, ValueError):
        return ""
    if cut_off(summary):
        return (f" (the run was cut off: its process {summary['pid']} is gone and its summary still says "
                "'running'; nothing after its start was saved)")
    if summary.get("status") == "running":
        return " (the run is still going)"
    return ""


def rerender(run_dir: Path, camera: str = "top", out: Path | None = None, width: int = 640,
             height: int = 480, progress: bool | None = None) -> Path:
    trajectory_path = trajectory_of(run_dir)
    from teamsim.video import FrameRenderer, Mp4Writer, camera_name

    t = load_trajectory(trajectory_path)
    names = [str(n) for n in t["robot_names"]]
    try:
        renderer = FrameRenderer(str(t["model_xml"]), names, width, height, camera)
    except ValueError as exc:
        raise ConfigError(f"--camera: {exc}") from None
    out = Path(out) if out else Path(run_dir) / f"video-{camera_name(camera).replace('/', '-')}.mp4"
    writer = Mp4Writer(out, width, height, int(t["fps"]))
    bar = Progress(float(t["time"][-1]) if len(t["time"]) else 0.0, f"render {camera}", enabled=progress)
    try:
        for time, qpos, behaviours in zip(t["time"], t["qpos"], t["behaviour"]):
            writer.write(renderer.render(float(time), qpos, [str(b) for b in behaviours]))
            bar.update(float(time))
    finally:
        bar.finish()
        writer.close()
        renderer.close()
    return out


def rerender_all(run_dirs: list[Path], camera: str = "top", width: int = 640, height: int = 480,
                 workers: int | None = None) -> list[Path]:
    """Each run's video (as ``rerender``), ``workers`` at a time (default: one per core), in order."""
    for run_dir in run_dirs:
        trajectory_of(run_dir)  # every bad RUN_DIR is named before any work starts
    workers = min(len(run_dirs), workers or os.cpu_count() or 1)
    if workers == 1:
        return [rerender(run_dir, camera, None, width, height) for run_dir in run_dirs]
    bar = Progress(len(run_dirs), f"render {len(run_dirs)} runs on {workers} workers", unit="runs done")
    with worker_pool(workers) as pool:  # spawned: a GL context does not survive a fork
        jobs = [pool.submit(rerender, run_dir, camera, None, width, height, False) for run_dir in run_dirs]
        for done, _ in enumerate(futures.as_completed(jobs), start=1):
            bar.update(done)
        outs = [job.result() for job in jobs]
    bar.finish()
    return outs
