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

    assert main(["render", str(result.run_dir), "--video-size", "320x240",
                 "--out", str(tmp_path / "again.mp4")]) == 0
    _, again = decode(tmp_path / "again.mp4")
    assert len(again) == len(live)
    for a, b in zip(live, again):
        np.testing.assert_array_equal(a, b)
    assert (result.run_dir / "video.mp4").read_bytes() == (tmp_path / "again.mp4").read_bytes()


def test_tracking_camera_rerender(tmp_path):
    cfg = wander_config(tmp_path, params={"robots": 2}, seed=2, duration=1.0, run_id="t")
    run_trial(cfg)  # no video while running: the trajectory alone is enough to render later
    assert main(["render", str(tmp_path / "wander" / "t"), "--camera", "green", "--video-size",
                 "160x120"]) == 0
    meta, frames = decode(tmp_path / "wander" / "t" / "video-green-track.mp4")
    assert meta["size"] == (160, 120) and len(frames) == 31


def test_a_failing_video_process_is_reported_and_the_run_goes_on(tmp_path):
    """The video process dies at once (no such camera): writing never blocks for good, and ``close`` says why."""
    from teamsim.video import FRAME_QUEUE, VideoProcess

    video = VideoProcess(tmp_path / "v.mp4", "<mujoco/>", [], 64, 48, "nowhere", 30)
    for k in range(FRAME_QUEUE + 10):
        video.write(k / 30, np.zeros(0), [])
    assert "camera 'nowhere' not in the scene" in video.close()
    assert not (tmp_path / "v.mp4").exists()


def test_several_runs_render_in_parallel_as_each_alone(tmp_path, capsys):
    runs = []
    for seed in (3, 4):
        run_trial(wander_config(tmp_path, params={"robots": 2}, seed=seed, duration=1.0, run_id=f"r{seed}"))
        runs.append(tmp_path / "wander" / f"r{seed}")
    assert main(["render", *map(str, runs), "--video-size", "160x120", "--workers", "2"]) == 0
    assert main(["render", str(runs[1]), "--video-size", "160x120", "--out", str(tmp_path / "alone.mp4")]) == 0
    _, parallel = decode(runs[1] / "video-top.mp4")
    _, alone = decode(tmp_path / "alone.mp4")
    assert len(parallel) == len(alone) == 31
    for a, b in zip(parallel, alone):
        np.testing.assert_array_equal(a, b)
    assert (runs[0] / "video-top.mp4").is_file()


def test_render_names_a_bad_run_dir_and_a_misused_out(tmp_path, capsys):
    run_trial(wander_config(tmp_path, params={"robots": 2}, seed=3, duration=0.5, run_id="ok"))
    good, bad = tmp_path / "wander" / "ok", tmp_path / "nothing"
    assert main(["render", str(good), str(bad)]) == 2
    assert f"RUN_DIR {bad}: no trajectory.npz there" in capsys.readouterr().err
    assert not (good / "video-top.mp4").exists()  # nothing rendered before every RUN_DIR was checked
    assert main(["render", str(good), str(good), "--out", str(tmp_path / "x.mp4")]) == 2
    assert "--out names one video" in capsys.readouterr().err
