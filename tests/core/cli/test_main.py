"""The CLI: bad input gets one line naming the problem and exit status 2; good input runs."""
from __future__ import annotations

import json
import os
import subprocess
import sys

import mujoco
import pytest

from teamsim.cli import main
from teamsim.models import ROBOT_BUILDERS, build_robot


def run_cli(capsys, *argv):
    code = main(list(argv))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.mark.parametrize("argv, fragment", [
    (["run", "nosuch"], "unknown mission 'nosuch'; known: wander"),
    (["run", "wander", "--set", "speed=3"], "--set speed: unknown key for mission 'wander'; allowed: robots"),
    (["run", "wander", "--set", "robots=three"], "--set robots=three: expected an integer"),
    (["run", "wander", "--set", "radio.loss=yes"], "--set radio.loss=yes: expected a number"),
    (["run", "wander", "--set", "robots=0"], "robots=0: must be in [1, 200]"),
    (["run", "wander", "--set", "robots"], "expected key=value"),
    (["run", "wander", "--fault", "kill-red-60"], "--fault 'kill-red-60': expected KIND:ROBOT@SECONDS"),
    (["run", "wander", "--fault", "explode:red@3"], "unknown kind 'explode'"),
    (["run", "wander", "--fault", "slow:red@3,factor=2"], "factor must be in (0, 1]"),
    (["run", "wander", "--fault", "kill:mauve@3"], "no robot 'mauve'; team: red, green, blue"),
    (["run", "wander", "--fault", "kill:@leader@3"], "faults[0] kill:@leader@3: wander has no roles a fault may name"),
    (["run", "wander", "--seed", "x"], "argument --seed: invalid int value: 'x'"),
    (["run", "wander", "--video", "--camera", "nobody"],
     "camera 'nobody' not in the scene; cameras: top, perspective, or a robot's name for its tracking camera: red"),
    (["frobnicate"], "invalid choice: 'frobnicate'"),
    (["render", "/nonexistent/run"], "no trajectory.npz"),
    (["export", "hovercraft", "--out", "x.xml"], "unknown robot 'hovercraft'"),
])
def test_bad_input_is_one_line_and_exit_2(capsys, tmp_path, argv, fragment):
    if argv[0] == "run":
        argv = [*argv, "--out", str(tmp_path)]
    code, out, err = run_cli(capsys, *argv)
    assert code == 2
    assert err.startswith("teamsim: error: ") and err.count("\n") == 1, err
    assert fragment in err
    assert not list(tmp_path.glob("wander/*")), "nothing is written for a rejected run"


def test_unwritable_out(capsys, tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    code, _, err = run_cli(capsys, "run", "wander", "--out", str(blocker / "renders"))
    assert code == 2 and err.count("\n") == 1
    assert f"--out {blocker / 'renders'}: not writable" in err


def test_console_script_errors_without_traceback(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "teamsim.cli", "run", "wander", "--set", "robots=abc"],
                          capture_output=True, text=True, cwd=tmp_path)
    assert proc.returncode == 2
    assert proc.stderr == "teamsim: error: --set robots=abc: expected an integer\n"


def test_output_into_a_closed_pipe_is_no_traceback(tmp_path):
    """`teamsim list | head -1`: the reader has gone; teamsim stops quietly (its stdout is a pipe whose read end
    is closed, and unbuffered, so the first print meets the broken pipe)."""
    script = ("import os, sys; r, w = os.pipe(); os.close(r); os.dup2(w, 1); "
              "from teamsim.cli import main; sys.exit(main(['list']))")
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, cwd=tmp_path,
                          env={**os.environ, "PYTHONUNBUFFERED": "1"})
    assert proc.returncode == 1
    assert proc.stderr == b""


def test_run_writes_summary_and_is_quiet_off_a_terminal(capsys, tmp_path):
    code, out, err = run_cli(capsys, "run", "wander", "--duration", "3", "--seed", "5", "--out", str(tmp_path),
                             "--run-id", "r", "--set", "robots=2", "--set", "radio.latency=0.5",
                             "--fault", "kill:green@1")
    assert code == 0
    assert out.startswith(f"completed: {tmp_path / 'wander' / 'r'}") and err == ""
    summary = json.loads((tmp_path / "wander" / "r" / "summary.json").read_text())
    assert summary["config"]["params"]["robots"] == 2
    assert summary["config"]["radio"]["latency"] == 0.5
    assert summary["faults"] == [{"kind": "kill", "robot": "green", "time": 1.0}]


def test_list_names_robots_and_missions(capsys):
    code, out, _ = run_cli(capsys, "list")
    assert code == 0
    for word in ("diffdrive", "10 IR", "r2", "genghis2", "tricycle", "tracked", "wander", "hazardous-waste"):
        assert word in out
    # each robot with its sensors and actuators
    assert "8 IR (0.3 m)" in out and "2 break-beams" in out and "grip: grip; lift: lift" in out
    assert "inclinometer" in out and "swing_lf, lift_lf" in out and "11 IR (1.5 m)" in out and "steer, drive" in out


@pytest.mark.parametrize("kind", sorted(ROBOT_BUILDERS))
def test_export_loads_in_plain_mujoco(capsys, tmp_path, kind):
    out = tmp_path / f"{kind}.xml"
    code, _, _ = run_cli(capsys, "export", kind, "--out", str(out))
    assert code == 0
    model = mujoco.MjModel.from_xml_path(str(out))
    robot = build_robot(kind, kind)
    assert model.nu == len(robot.motors) + sum(len(e.actuators) for e in robot.effectors.values())
    assert model.nsensor == len(robot.ir_sensors) + len(robot.beams)
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data, nstep=500)  # 1 s on the floor with its actuators at rest: stays upright
    assert data.qpos[3] > 0.99 and not data.warning.number.any()
