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
from teamsim.sweep import JournalError, run_trials
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


# -- the journal (issue 29): a killed sweep resumes without re-running its finished trials --------------------------
def _echo(config) -> dict:
    """A trial stand-in: its result is made of its configuration (a tuple here: any picklable object)."""
    name, k = config
    return {"status": "failed" if k % 3 == 0 else "completed", "value": k / 7, "pair": (k, name), "nan": float("nan")}


class _Stop:
    """A trial stand-in that is interrupted (as by Ctrl-C) at call ``at``, counting its calls."""

    def __init__(self, at: int | None = None):
        self.at, self.calls = at, []

    def __call__(self, config) -> dict:
        if len(self.calls) == self.at:
            raise KeyboardInterrupt
        self.calls.append(config)
        return _echo(config)


def _configs(n: int = 6, name: str = "a") -> list:
    return [(name, k) for k in range(n)]


def _same(a, b) -> bool:  # equal, NaN included
    import json

    return json.dumps(a) == json.dumps(b)


def test_a_resumed_sweep_runs_only_the_missing_trials_and_returns_the_same(tmp_path):
    journal = tmp_path / "trials.jsonl"
    whole = run_trials(_configs(), workers=1, run=_echo, journal=tmp_path / "whole.jsonl")
    killed = _Stop(at=4)
    with pytest.raises(KeyboardInterrupt):
        run_trials(_configs(), workers=1, run=killed, journal=journal)
    assert len(journal.read_text().splitlines()) == 4
    rest = _Stop()
    resumed = run_trials(_configs(), workers=1, run=rest, journal=journal, resume=True)
    assert rest.calls == [("a", 4), ("a", 5)]
    assert _same(resumed, whole)
    assert resumed[0]["pair"] == [0, "a"]  # every result has been through JSON, fresh or read back
    again = _Stop()
    assert _same(run_trials(_configs(), workers=1, run=again, journal=journal, resume=True), whole)
    assert again.calls == []


def test_a_resumed_sweep_on_the_process_pool(tmp_path):
    journal = tmp_path / "trials.jsonl"
    first = run_trials(_configs(4), workers=2, run=_echo, journal=journal)
    lines = journal.read_text().splitlines(keepends=True)
    journal.write_text("".join(lines[:2]))
    assert _same(run_trials(_configs(4), workers=2, run=_echo, journal=journal, resume=True), first)
    assert len(journal.read_text().splitlines()) == 4


def test_a_journal_cut_in_the_middle_of_a_line(tmp_path):
    journal = tmp_path / "trials.jsonl"
    whole = run_trials(_configs(3), workers=1, run=_echo, journal=journal)
    text = journal.read_text()
    journal.write_text(text[: len(text) - 25])  # the kill came while the last line was written
    rest = _Stop()
    assert _same(run_trials(_configs(3), workers=1, run=rest, journal=journal, resume=True), whole)
    assert rest.calls == [("a", 2)]
    assert len(journal.read_text().splitlines()) == 3


def test_crashed_interrupted_and_error_trials_run_again_on_resume(tmp_path):
    journal = tmp_path / "trials.jsonl"
    statuses = {0: "crashed", 1: "interrupted", 2: "error", 3: "failed"}
    run_trials(_configs(4), workers=2, run=_status_of, journal=journal)  # (interrupted would end a serial sweep)
    rest = _Stop()
    run_trials(_configs(4), workers=1, run=rest, journal=journal, resume=True)
    assert sorted(rest.calls) == [("a", k) for k, s in statuses.items() if s != "failed"]


def _status_of(config) -> dict:
    return {"status": {0: "crashed", 1: "interrupted", 2: "error", 3: "failed"}[config[1]]}


def test_a_resume_with_other_settings_is_refused_naming_them(tmp_path):
    journal = tmp_path / "trials.jsonl"
    configs = [wander_config(tmp_path, params={"robots": 2}, seed=s, duration=2.0, run_id=f"s{s}") for s in (1, 2)]
    run_trials(configs, workers=1, run=lambda c: {"status": "completed"}, journal=journal)
    moved = [wander_config(tmp_path / "elsewhere", params={"robots": 2}, seed=s, duration=2.0, run_id=f"s{s}")
             for s in (1, 2)]  # another output folder is the same trial
    run_trials(moved, workers=1, run=lambda c: {"status": "completed"}, journal=journal, resume=True)
    other = [wander_config(tmp_path, params={"robots": 3}, seed=s, duration=2.0, run_id=f"s{s}") for s in (1, 2)]
    with pytest.raises(JournalError, match=r"trial 0 \(wander seed 1 s1\) was run with params.robots=2 there, 3 now"):
        run_trials(other, workers=1, run=lambda c: {"status": "completed"}, journal=journal, resume=True)
    with pytest.raises(JournalError, match="not in this study, which has 1 trials"):
        run_trials(configs[:1], workers=1, run=lambda c: {"status": "completed"}, journal=journal, resume=True)


def test_an_existing_journal_is_not_overwritten_without_resume(tmp_path):
    journal = tmp_path / "trials.jsonl"
    run_trials(_configs(2), workers=1, run=_echo, journal=journal)
    before = journal.read_bytes()
    with pytest.raises(JournalError, match=f"--resume {tmp_path} to continue it, or another --out"):
        run_trials(_configs(2), workers=1, run=_echo, journal=journal)
    assert journal.read_bytes() == before
    with pytest.raises(JournalError, match="nothing to resume"):
        run_trials(_configs(2), workers=1, run=_echo, journal=tmp_path / "none" / "trials.jsonl", resume=True)
