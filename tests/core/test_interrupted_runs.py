"""A run stopped from outside: Ctrl-C (SIGINT) and SIGTERM end it as ``interrupted`` with every output written;
after SIGKILL its summary still says ``running``, names the process, and the next command that reads the folder
says the run was cut off. Each case runs ``teamsim run`` in a child process and signals it mid-run."""
from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from teamsim.cli.main import main
from teamsim.runner import cut_off

REPO = Path(__file__).resolve().parents[2]


def start_run(out: Path) -> tuple[subprocess.Popen, Path]:
    """A wander run far longer than the test, once it is simulating (its events log, written as
    ``events.jsonl.part`` until the run ends, has grown)."""
    with (out / "stderr.txt").open("wb") as stderr:  # what it said, should the test fail
        # (SIGINT's default action restored in the child: a shell without job control starts background jobs with
        # SIGINT ignored, and Python then never raises KeyboardInterrupt; the test must not depend on how it ran)
        child = subprocess.Popen([sys.executable, "-m", "teamsim.cli", "run", "wander", "--duration", "3600",
                                  "--out", str(out), "--run-id", "signalled"], cwd=REPO, stdout=subprocess.DEVNULL,
                                 stderr=stderr, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    run_dir = out / "wander" / "signalled"
    events = run_dir / "events.jsonl.part"
    for _ in range(600):
        if events.is_file() and events.stat().st_size > 2000:
            break
        time.sleep(0.05)
    else:
        child.kill()
        pytest.fail("the run did not start")
    return child, run_dir


@pytest.mark.parametrize("sent, code, error", [(signal.SIGINT, 130, "interrupted by the user"),
                                               (signal.SIGTERM, 130, "terminated (SIGTERM)")])
def test_a_signalled_run_ends_interrupted_with_its_outputs(tmp_path, sent, code, error):
    child, run_dir = start_run(tmp_path)
    child.send_signal(sent)
    assert child.wait(timeout=60) == code, (tmp_path / "stderr.txt").read_text()[-2000:]
    summary = json.loads((run_dir / "summary.json").read_text())
    assert (summary["status"], summary["error"]) == ("interrupted", error)
    assert 0 < summary["sim_time_s"] < 3600
    assert {"events.jsonl", "trajectory.npz", "timeline.png"} <= set(summary["outputs"])
    assert json.loads((run_dir / "events.jsonl").read_text().splitlines()[-1])["status"] == "interrupted"
    assert not cut_off(summary)


def test_after_sigkill_the_folder_says_the_run_was_cut_off(tmp_path, capsys):
    child, run_dir = start_run(tmp_path)
    child.kill()
    child.wait(timeout=60)
    summary = json.loads((run_dir / "summary.json").read_text())  # whole: it is only ever replaced atomically
    assert summary["status"] == "running" and summary["pid"] == child.pid
    assert cut_off(summary)
    assert main(["render", str(run_dir)]) == 2
    err = capsys.readouterr().err.strip()
    assert "cut off" in err and "\n" not in err


def test_a_write_that_fails_mid_run_is_one_line_exit_2_and_keeps_what_was_written(tmp_path, monkeypatch, capsys):
    """The disk fills up while the events log grows: the run stops with one line and exit 2; the summary written at
    the start, and the trajectory and timeline written at the end, are kept (written whole, or not at all)."""
    from teamsim import recording

    write = recording.EventLog.__call__
    written = {"n": 0}

    def full_disk(self, event):
        written["n"] += 1
        if written["n"] > 40:
            raise OSError(28, "No space left on device")
        write(self, event)

    monkeypatch.setattr(recording.EventLog, "__call__", full_disk)
    code = main(["run", "wander", "--duration", "30", "--out", str(tmp_path), "--run-id", "full"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "\n" not in err
    assert "could not write events.jsonl (No space left on device)" in err
    run_dir = tmp_path / "wander" / "full"
    summary = json.loads((run_dir / "summary.json").read_text())
    assert summary["status"] == "error" and "No space left on device" in summary["error"]
    assert {"trajectory.npz", "timeline.png"} <= set(summary["outputs"])
    assert (run_dir / "events.jsonl").read_text().count("\n") == 40  # the events before the disk filled


def test_a_capture_torn_by_ctrl_c_still_saves_the_whole_frames_and_ticks(tmp_path):
    """A SIGINT between the appends of a frame (or of a motivation tick) left one list a record longer, and saving
    the interrupted run's trajectory raised ("cannot reshape array of size 1200 into shape (401,3)", seen in CI):
    the run lost its trajectory. The torn record is dropped."""
    import numpy as np

    from teamsim.recording import MotivationSeries, TrajectoryRecorder, load_trajectory

    recorder = TrajectoryRecorder("<mujoco/>", ["a", "b"], fps=10, physics_dt=0.01)
    for k in range(3):
        recorder.capture(0.1 * k, np.zeros(4), ["idle", "idle"])
    recorder.times.append(0.3)  # interrupted here: no qpos, no behaviours for this frame
    series = MotivationSeries(("s1", "s2"), 1.0)
    for k in range(3):
        series.times.append(0.1 * k)
        series.levels.extend((0.0, 0.5))
        series.active.append(-1)
    series.times.append(0.3)
    series.levels.extend((0.0,))  # interrupted half-way through a tick's levels
    recorder.save(tmp_path / "trajectory.npz", series.arrays("motivation/a/"))
    saved = load_trajectory(tmp_path / "trajectory.npz")
    assert saved["time"].shape == (3,) and saved["qpos"].shape == (3, 4) and saved["behaviour"].shape == (3, 2)
    assert saved["motivation/a/time"].shape == (3,) and saved["motivation/a/m"].shape == (3, 2)
    assert saved["motivation/a/active"].shape == (3,)
