"""Sweeps: trials in spawned worker processes give the same results as trials run one by one."""
from __future__ import annotations

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
