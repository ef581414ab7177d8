"""The trial runner: outputs, atomic writes, endings (error, unstable, killed) and determinism."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from tests.helpers import wander_config

from teamsim import recording
from teamsim.faults import parse_fault
from teamsim.files import write_json
from teamsim.recording import load_trajectory
from teamsim.runner import run_trial
from teamsim.world import World


def quick_config(tmp_path, run_id="run", seed=3, **extra):
    cfg = wander_config(tmp_path, params={"robots": 4}, seed=seed, duration=6.0, run_id=run_id, **extra)
    cfg.radio.loss = 0.3  # exercise the radio's random stream too
    cfg.faults = [parse_fault("kill:red@2"), parse_fault("blind-ir:green@1"), parse_fault("slow:blue@3,factor=0.5")]
    return cfg


def test_outputs_written(tmp_path):
    result = run_trial(quick_config(tmp_path))
    run_dir = tmp_path / "wander" / "run"
    assert result.run_dir == run_dir and result.status == "completed"
    assert sorted(p.name for p in run_dir.iterdir()) == ["events.jsonl", "summary.json", "timeline.png",
                                                             "timeline.svg", "trajectory.npz"]
    summary = json.loads((run_dir / "summary.json").read_text())
    assert summary["completed"] is True and summary["sim_time_s"] == pytest.approx(6.0)
    assert set(summary["robots"]) == {"red", "green", "blue", "yellow"}
    assert summary["robots"]["red"]["alive"] is False
    assert summary["robots"]["green"]["energy_j"] > 0
    assert summary["robots"]["green"]["parker_energy_units"] == pytest.approx(6.0)
    events = [json.loads(line) for line in (run_dir / "events.jsonl").read_text().splitlines()]
    assert events[0]["event"] == "trial_start" and events[-1] == {"t": 6.0, "event": "trial_end",
                                                                   "status": "completed"}
    assert [e["kind"] for e in events if e["event"] == "fault"] == ["blind-ir", "kill", "slow"]
    trajectory = load_trajectory(run_dir / "trajectory.npz")
    assert len(trajectory["time"]) == 6 * 30 + 1  # 30 fps, both ends included
    assert trajectory["qpos"].shape[0] == len(trajectory["time"])


def test_same_seed_same_results(tmp_path):
    first = run_trial(quick_config(tmp_path, run_id="a"))
    second = run_trial(quick_config(tmp_path, run_id="b"))
    other = run_trial(quick_config(tmp_path, run_id="c", seed=4))
    events = [(r.run_dir / "events.jsonl").read_bytes() for r in (first, second, other)]
    assert events[0] == events[1]
    assert events[0] != events[2]
    assert first.summary["final_state_sha256"] == second.summary["final_state_sha256"]
    assert first.summary["final_state_sha256"] != other.summary["final_state_sha256"]
    qpos = [load_trajectory(r.run_dir / "trajectory.npz")["qpos"] for r in (first, second)]
    np.testing.assert_array_equal(qpos[0], qpos[1])


def test_python_exception_ends_in_error_with_outputs(tmp_path, monkeypatch):
    original = World.act

    def failing(self, robot, observation, command):
        if observation.time >= 1.0:
            raise RuntimeError("controller exploded")
        original(self, robot, observation, command)

    monkeypatch.setattr(World, "act", failing)
    result = run_trial(quick_config(tmp_path))
    assert result.status == "error"
    summary = json.loads((result.run_dir / "summary.json").read_text())
    assert summary["status"] == "error" and "controller exploded" in summary["error"]
    assert summary["sim_time_s"] == pytest.approx(1.0)
    events = (result.run_dir / "events.jsonl").read_text().splitlines()
    assert '"exception"' in events[-2] and json.loads(events[-1])["status"] == "error"
    assert len(load_trajectory(result.run_dir / "trajectory.npz")["time"]) == 31  # frames up to 1 s are kept


def test_nan_state_ends_unstable(tmp_path, monkeypatch):
    original = World.advance

    def corrupting(self, steps):
        original(self, steps)
        if self.time >= 2.0:
            self.data.qvel[0] = np.nan

    monkeypatch.setattr(World, "advance", corrupting)
    result = run_trial(quick_config(tmp_path))
    assert result.status == "unstable"
    assert "non-finite" in result.summary["error"]
    summary = json.loads((result.run_dir / "summary.json").read_text())
    assert summary["status"] == "unstable"
    assert {"events.jsonl", "trajectory.npz", "timeline.png"} <= set(summary["outputs"])  # every output written
    assert all((result.run_dir / name).exists() for name in summary["outputs"])


def test_mujoco_warning_ends_unstable(tmp_path, monkeypatch):
    import mujoco

    original = World.advance

    def warn(self, steps):
        original(self, steps)
        if self.time >= 1.0:
            self.data.warning[int(mujoco.mjtWarning.mjWARN_BADQACC)].number = 1

    monkeypatch.setattr(World, "advance", warn)
    result = run_trial(quick_config(tmp_path))
    assert result.status == "unstable" and "mjWARN_BADQACC" in result.summary["error"]


def test_atomic_write_keeps_old_file_when_writing_fails(tmp_path, monkeypatch):
    path = tmp_path / "summary.json"
    write_json(path, {"status": "running"})

    def broken_fsync(fd):
        raise OSError("disk gone")

    monkeypatch.setattr(recording.os, "fsync", broken_fsync)
    with pytest.raises(OSError):
        write_json(path, {"status": "completed", "padding": "x" * 100000})
    assert json.loads(path.read_text()) == {"status": "running"}
    assert list(tmp_path.iterdir()) == [path]  # and no temporary file left beside it


def test_killed_process_leaves_summary_and_events(tmp_path):
    """SIGKILL mid-run: the summary says 'running' and the events so far survive in events.jsonl.part."""
    run_dir = tmp_path / "wander" / "killed"
    proc = subprocess.Popen([sys.executable, "-m", "teamsim.cli", "run", "wander", "--duration", "3600",
                             "--out", str(tmp_path), "--run-id", "killed", "--set", "robots=10"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        part = run_dir / "events.jsonl.part"
        while time.monotonic() < deadline and not (part.exists() and part.stat().st_size > 2000):
            time.sleep(0.1)
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
    summary = json.loads((run_dir / "summary.json").read_text())
    assert summary["status"] == "running" and summary["seed"] == 0
    lines = (run_dir / "events.jsonl.part").read_text().splitlines()
    assert json.loads(lines[0])["event"] == "trial_start"
    assert all(json.loads(line) for line in lines[:-1])  # every complete line parses
    assert not list(Path(run_dir).glob("*.tmp"))
