"""Offscreen video: H.264 mp4 streamed live, and ``teamsim render`` reproducing the live frames."""
from __future__ import annotations

import imageio_ffmpeg
import numpy as np
from tests.helpers import wander_config

from teamsim.cli import main
from teamsim.runner import run_trial


def decode(path):
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    width, height = meta["size"]
    frames = [np.frombuffer(f, np.uint8).reshape(height, width, 3) for f in reader]
    return meta, frames


def test_live_video_and_rerender_match(tmp_path, capsys):
    cfg = wander_config(tmp_path, params={"robots": 3}, seed=2, duration=2.0, run_id="v")
    cfg.video.enabled = True
    cfg.video.width, cfg.video.height = 320, 240
    result = run_trial(cfg)
    assert result.status == "completed" and "video.mp4" in result.summary["outputs"]
    meta, live = decode(result.run_dir / "video.mp4")
    assert meta["codec"].startswith("h264") and meta["pix_fmt"].startswith("yuv420p")
    assert meta["fps"] == 30 and len(live) == 61
    # Robots move: the first and last frames differ by more than the HUD's clock.
    assert np.mean(np.any(live[0] != live[-1], axis=2)) > 0.005

    assert main(["render", str(result.run_dir), "--width", "320", "--height", "240",
                 "--out", str(tmp_path / "again.mp4")]) == 0
    _, again = decode(tmp_path / "again.mp4")
    assert len(again) == len(live)
    for a, b in zip(live, again):
        np.testing.assert_array_equal(a, b)
    assert (result.run_dir / "video.mp4").read_bytes() == (tmp_path / "again.mp4").read_bytes()


def test_tracking_camera_rerender(tmp_path):
    cfg = wander_config(tmp_path, params={"robots": 2}, seed=2, duration=1.0, run_id="t")
    run_trial(cfg)  # no video while running: the trajectory alone is enough to render later
    assert main(["render", str(tmp_path / "wander" / "t"), "--camera", "green", "--width", "160",
                 "--height", "120"]) == 0
    meta, frames = decode(tmp_path / "wander" / "t" / "video-green-track.mp4")
    assert meta["size"] == (160, 120) and len(frames) == 31
