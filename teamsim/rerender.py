"""``teamsim render RUN_DIR``: a video from ``trajectory.npz`` alone, through the live render's own path."""
from __future__ import annotations

from pathlib import Path

from teamsim.config import ConfigError
from teamsim.progress import Progress
from teamsim.recording import load_trajectory


def rerender(run_dir: Path, camera: str = "top", out: Path | None = None, width: int = 640,
             height: int = 480) -> Path:
    trajectory_path = Path(run_dir) / "trajectory.npz"
    if not trajectory_path.is_file():
        raise ConfigError(f"RUN_DIR {run_dir}: no trajectory.npz there")
    from teamsim.video import FrameRenderer, Mp4Writer, camera_name

    t = load_trajectory(trajectory_path)
    names = [str(n) for n in t["robot_names"]]
    try:
        renderer = FrameRenderer(str(t["model_xml"]), names, width, height, camera)
    except ValueError as exc:
        raise ConfigError(f"--camera: {exc}") from None
    out = Path(out) if out else Path(run_dir) / f"video-{camera_name(camera).replace('/', '-')}.mp4"
    writer = Mp4Writer(out, width, height, int(t["fps"]))
    bar = Progress(float(t["time"][-1]) if len(t["time"]) else 0.0, f"render {camera}")
    try:
        for time, qpos, behaviours in zip(t["time"], t["qpos"], t["behaviour"]):
            writer.write(renderer.render(float(time), qpos, [str(b) for b in behaviours]))
            bar.update(float(time))
    finally:
        bar.finish()
        writer.close()
        renderer.close()
    return out
