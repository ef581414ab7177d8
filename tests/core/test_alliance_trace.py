"""ALLIANCE in a physics trial: the motivation trace each robot's command carries is recorded in events.jsonl and
trajectory.npz and plotted in timeline.png, and a teammate takes over the task of a robot that is killed."""
from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

from teamsim.config import RadioConfig
from teamsim.controllers.alliance.lalliance import LAllianceParams, LAllianceRobot
from teamsim.controllers.alliance.motivation import (AllianceController, AllianceParams, BehaviourSetDefinition,
                                                     MotivationRates)
from teamsim.controllers.base import Command
from teamsim.controllers.skills.wander import WanderController, WanderParams
from teamsim.faults import parse_fault
from teamsim.recording import MotivationRecorder, load_trajectory
from teamsim.runner import run_trial
from teamsim.scene import RobotSlot
from teamsim.tasks import MISSIONS
from teamsim.tasks.missions.custom import CustomMission, CustomParams, custom_config

RADIO = RadioConfig(rate_hz=2.0)  # tau = 1.5 s
# red is keen to patrol; green would patrol too but rests first, and gives rest up after lambda = 3 s.
RATES = {
    "red": {"patrol": MotivationRates(delta_fast=1.0, delta_slow=0.01, phi=100.0),
            "rest": MotivationRates(delta_fast=0.05, delta_slow=0.01)},
    "green": {"patrol": MotivationRates(delta_fast=0.5, delta_slow=0.01, phi=100.0),
              "rest": MotivationRates(delta_fast=0.4, delta_slow=0.01, lam=3.0)},
}
KILL = 3.0


def stop(observation) -> Command:
    return Command()


def alliance_mission(learning: bool = False) -> CustomMission:
    """Two diffdrive robots, each with the behaviour sets patrol (wander) and rest (stand still), always applicable;
    with ``learning``, L-ALLIANCE selects among them."""

    def controller_for(robot, rng):
        wander = WanderController(robot.ir_bearings, rng,
                                  WanderParams().for_robot(robot.limits.v_max, robot.limits.omega_max,
                                                           robot.ir.max_range))
        rates = RATES[robot.name]
        definitions = [BehaviourSetDefinition("patrol", lambda obs: True, wander, rates=rates["patrol"]),
                       BehaviourSetDefinition("rest", lambda obs: True, stop, rates=rates["rest"])]
        params = AllianceParams(tau=RADIO.timeout)
        selector = None
        if learning:
            selector = LAllianceRobot(robot.name, [d.behaviour_set for d in definitions],
                                      LAllianceParams(alliance=params, prior_task_time=4.0, min_delay=0.5,
                                                      max_delay=3.0))
        return AllianceController(robot.name, definitions, params, selector)

    return CustomMission(controller_for)


def trial(tmp_path, monkeypatch, run_id: str, duration: float, faults=(), learning: bool = False):
    monkeypatch.setitem(MISSIONS, "custom", alliance_mission(learning))
    params = CustomParams(room=(6.0, 6.0), robots=[RobotSlot("red", "diffdrive", -1.5, 0.0, 0.0),
                                                   RobotSlot("green", "diffdrive", 1.5, 0.0, np.pi)])
    config = custom_config(params, seed=1, out=str(tmp_path), run_id=run_id, duration=duration, radio=RADIO,
                           faults=[parse_fault(f) for f in faults])
    result = run_trial(config, progress=False)
    assert result.status == "completed", result.summary.get("error")
    lines = (result.run_dir / "events.jsonl").read_text().splitlines()
    return result, [json.loads(line) for line in lines]


def test_trace_events_timeline_and_takeover_after_a_kill(tmp_path, monkeypatch):
    result, events = trial(tmp_path, monkeypatch, "kill", 9.0, faults=[f"kill:red@{KILL:g}"])
    marks = [e for e in events if e["event"] == "motivation"]
    assert {e["kind"] for e in marks} >= {"activate", "deactivate", "impatience", "impatience_reset", "acquiescence"}
    activations = [(e["t"], e["robot"], e["behaviour_set"]) for e in marks if e["kind"] == "activate"]
    assert activations[0][1:] == ("red", "patrol")
    resets = [e for e in marks if e["kind"] == "impatience_reset"]
    assert ("green", "red", "patrol") in [(e["robot"], e["teammate"], e["behaviour_set"]) for e in resets]
    assert any(e["kind"] == "acquiescence" and e["detail"] == "lambda" and e["robot"] == "green" for e in marks)
    # The takeover: green activates patrol only after red died, within tau of red's last message plus the time
    # its motivation takes to reach theta at delta_fast (and a control period for the step that crosses it).
    takeover = [t for t, robot, s in activations if robot == "green" and s == "patrol"]
    bound = KILL + RADIO.timeout + 1.0 / RATES["green"]["patrol"].delta_fast + RATES["green"]["rest"].lam + 0.1
    assert len(takeover) == 1 and KILL < takeover[0] <= bound
    assert not [e for e in marks if e["robot"] == "red" and e["t"] > KILL]  # a dead robot's controller is silent

    samples = [e for e in events if e["event"] == "motivation_sample"]
    for robot in ("red", "green"):
        times = [e["t"] for e in samples if e["robot"] == robot]
        event_times = {e["t"] for e in marks if e["robot"] == robot}
        assert len(times) >= 3 and set(samples[0]["m"]) == {"patrol", "rest"}
        for before, after in zip(times, times[1:]):  # throttled: 1 Hz unless something happened
            assert after - before >= 1.0 - 1e-6 or after in event_times

    trajectory = load_trajectory(result.run_dir / "trajectory.npz")
    assert list(trajectory["motivation/green/sets"]) == ["patrol", "rest"]
    levels, active = trajectory["motivation/green/m"], trajectory["motivation/green/active"]
    assert levels.shape == (len(trajectory["motivation/green/time"]), 2)
    assert float(trajectory["motivation/green/threshold"]) == 1.0
    assert active[-1] == 0 and levels[:, 1].max() > 1.0  # patrolling at the end; rest crossed theta before
    assert trajectory["motivation/red/time"][-1] <= KILL

    # timeline.png and .svg: one row per behaviour set for both robots, each with its m(t) drawn.
    svg = (result.run_dir / "timeline.svg").read_text()
    assert all(f'id="motivation/{robot}/{name}"' in svg for robot in ("red", "green") for name in ("patrol", "rest"))
    assert 'id="acquiescence/green"' in svg and (result.run_dir / "timeline.png").stat().st_size > 0


def test_same_seed_same_trace_and_lalliance_is_traced_too(tmp_path, monkeypatch):
    runs = [trial(tmp_path, monkeypatch, run_id, 3.0, learning=True)[0] for run_id in ("a", "b")]
    logs = [(r.run_dir / "events.jsonl").read_bytes() for r in runs]
    assert logs[0] == logs[1]
    events = [json.loads(line) for line in logs[0].decode().splitlines()]
    assert any(e["event"] == "motivation" and e["kind"] == "activate" for e in events)
    assert {e["robot"] for e in events if e["event"] == "motivation_sample"} == {"red", "green"}


def _trace(time, m, events=()):
    return SimpleNamespace(time=time, threshold=1.0, active=None, motivation={"x": m},
                           events=[SimpleNamespace(kind=k, behaviour_set="x", teammate=None, detail="")
                                   for k in events])


def test_samples_only_on_change_at_most_once_a_period_unless_an_event():
    logged = []
    recorder = MotivationRecorder(logged.append, sample_period=1.0)
    for k in range(31):  # 3 s at 10 Hz; m grows until 1.5 s, then holds; an event at 0.4 s
        t = round(0.1 * k, 6)
        recorder("r", t, _trace(t, min(t, 1.5), events=("impatience",) if k == 4 else ()))
    samples = [(e["t"], e["m"]["x"]) for e in logged if e["event"] == "motivation_sample"]
    assert samples == [(0.0, 0.0), (0.4, 0.4), (1.4, 1.4), (2.4, 1.5)]
    assert [e["t"] for e in logged if e["event"] == "motivation"] == [0.4]
    assert len(recorder.series["r"].times) == 31
    with pytest.raises(ValueError, match="behaviour sets changed"):
        recorder("r", 3.1, SimpleNamespace(time=3.1, threshold=1.0, active=None, motivation={"y": 0.0}, events=[]))
