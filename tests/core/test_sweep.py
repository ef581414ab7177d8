"""Sweeps: trials in spawned worker processes give the same results as trials run one by one, and the workers die
with their parent."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from teamsim.runner import run_trial
from teamsim.sweep import run_trials
from tests.helpers import wander_config


def test_process_pool_matches_serial_runs(tmp_path):
    configs = [wander_config(tmp_path / "pool", params={"robots": 2}, seed=s, duration=2.0, run_id=f"s{s}")
               for s in (1, 2, 3)]
    pooled = run_trials(configs, workers=2)
    serial = [run_trial(wander_config(tmp_path / "serial", params={"robots": 2}, seed=s, duration=2.0,
                                      run_id=f"s{s}")).summary for s in (1, 2, 3)]
    assert [p["seed"] for p in pooled] == [1, 2, 3]
    assert all(p["status"] == "completed" for p in pooled)
    assert [p["final_state_sha256"] for p in pooled] == [s["final_state_sha256"] for s in serial]
    for seed in (1, 2, 3):
        pool_events = (tmp_path / "pool" / "wander" / f"s{seed}" / "events.jsonl").read_bytes()
        serial_events = (tmp_path / "serial" / "wander" / f"s{seed}" / "events.jsonl").read_bytes()
        assert pool_events == serial_events


def test_unknown_backend(tmp_path):
    with pytest.raises(ValueError, match="allowed: process, ray"):
        run_trials([wander_config(tmp_path)], backend="dask")


def _without_timing(summary: dict) -> dict:
    """A summary less what depends on the machine and the output folder."""
    return {k: v for k, v in summary.items() if k not in ("wall_time_s", "real_time_factor", "config", "pid")}


def test_ray_backend_matches_the_process_pool(tmp_path):
    """The same two-trial sweep on a local Ray instance and on the process pool: the same summaries and events."""
    ray = pytest.importorskip("ray")
    configs = {where: [wander_config(tmp_path / where, params={"robots": 2}, seed=s, duration=2.0, run_id=f"s{s}")
                       for s in (4, 5)] for where in ("ray", "pool")}
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        on_ray = run_trials(configs["ray"], backend="ray")
    finally:
        ray.shutdown()
    pooled = run_trials(configs["pool"], workers=2)
    assert [s["status"] for s in on_ray] == ["completed", "completed"]
    assert [_without_timing(s) for s in on_ray] == [_without_timing(s) for s in pooled]
    for seed in (4, 5):
        assert ((tmp_path / "ray" / "wander" / f"s{seed}" / "events.jsonl").read_bytes()
                == (tmp_path / "pool" / "wander" / f"s{seed}" / "events.jsonl").read_bytes())


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


def test_workers_die_with_a_killed_parent(tmp_path):
    """SIGKILL on a sweep's parent leaves no worker running its trial on (they used to run on, re-parented)."""
    repo = Path(__file__).resolve().parents[2]
    parent = subprocess.Popen([sys.executable, "-m", "tests.core.sweep_sleeper", str(tmp_path)], cwd=repo,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        for _ in range(300):  # the workers start within a few seconds (spawn imports teamsim)
            if len(list(tmp_path.glob("worker-*"))) == 2:
                break
            time.sleep(0.1)
        workers = [int(p.read_text()) for p in tmp_path.glob("worker-*")]
        assert len(workers) == 2
        parent.kill()
        parent.wait()
        for _ in range(50):  # a worker looks for its parent every PARENT_CHECK_S (0.5 s)
            if not any(_alive(pid) for pid in workers):
                break
            time.sleep(0.1)
        assert not any(_alive(pid) for pid in workers)
    finally:
        parent.kill()
        for p in tmp_path.glob("worker-*"):
            pid = int(p.read_text())
            if _alive(pid):
                os.kill(pid, signal.SIGKILL)
