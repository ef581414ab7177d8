"""Faults applied by the world at their time, each recorded as an event (issue 2, scope 7)."""
from __future__ import annotations

import numpy as np
import pytest
from tests.helpers import ScriptedMission, advance_seconds, wander_config

from teamsim.config import ConfigError
from teamsim.faults import parse_fault
from teamsim.world import World


def make_world(tmp_path, faults=(), v=0.2, omega=0.0, robots=3, **config):
    events = []
    mission = ScriptedMission(v, omega)
    cfg = wander_config(tmp_path, params={"robots": robots, "obstacles": 0, "room_size": 30.0},
                        faults=[parse_fault(f) for f in faults], seed=7, **config)
    world = World(cfg, mission)
    world.record = events.append
    return world, mission, events


def fault_events(events):
    return [e for e in events if e["event"] == "fault"]


def test_kill_stops_robot_and_its_radio(tmp_path):
    # Killed at 4 s: by then every robot has had its first radio slot (phases lie within one 3 s period).
    world, mission, events = make_world(tmp_path, ["kill:red@4"])
    advance_seconds(world, 4.0)
    red = world.robots["red"]
    assert world.speed(red) > 0.1
    advance_seconds(world, 3.0)
    assert world.speed(red) < 0.01, "a killed robot stops"
    assert fault_events(events) == [{"t": 4.0, "event": "fault", "kind": "kill", "robot": "red", "time": 4.0}]
    observed_times = [o.time for o in mission.controllers["red"].observations]
    assert max(observed_times) < 4.0, "a killed robot's controller no longer runs"
    sent_after = [e for e in events if e["event"] == "radio" and e["robot"] == "red" and e["t"] >= 4.0]
    assert sent_after == []
    # Teammates stop counting red as present once tau (9 s at the default 1/3 Hz) has passed in silence.
    assert "red" in world.radio.robots_present("green", world.time)
    advance_seconds(world, world.config.radio.timeout)
    assert "red" not in world.radio.robots_present("green", world.time)


def test_blind_ir_reads_nothing(tmp_path):
    world, mission, _ = make_world(tmp_path, ["blind-ir:green@1"], v=0.0, robots=2)
    # Put a wall-like neighbour in range: move red next to green so green's IR sees it before blinding.
    red, green = world.robots["red"], world.robots["green"]
    gx, gy, _ = world.pose(green)
    world.data.qpos[red.qpos_adr:red.qpos_adr + 2] = [gx + 1.0, gy]
    advance_seconds(world, 2.0)
    observations = mission.controllers["green"].observations
    before = [o for o in observations if o.time < 1.0]
    after = [o for o in observations if o.time >= 1.0]
    assert any((o.ir_raw > 0).any() for o in before), "green sees red before it is blinded"
    assert all((o.ir_raw == 0).all() and np.isinf(o.ir_range).all() for o in after)


def test_radio_off_silences_sender(tmp_path):
    world, _, events = make_world(tmp_path, ["radio-off:blue@0"])
    advance_seconds(world, 10.0)
    senders = {e["robot"] for e in events if e["event"] == "radio"}
    assert senders == {"red", "green"}
    assert "blue" not in world.radio.robots_present("red", world.time)


def mean_speed(world, robot, seconds: float) -> float:
    """Average ground speed over the next ``seconds`` (instantaneous speed rocks with the chassis)."""
    start = world.pose(robot)[:2]
    advance_seconds(world, seconds)
    return float(np.hypot(*(world.pose(robot)[:2] - start))) / seconds


def test_slow_halves_speed(tmp_path):
    world, _, _ = make_world(tmp_path, ["slow:red@6,factor=0.5"], robots=1)
    red = world.robots["red"]
    advance_seconds(world, 4.0)
    before = mean_speed(world, red, 2.0)
    advance_seconds(world, 2.0)
    after = mean_speed(world, red, 2.0)
    assert before == pytest.approx(0.2, rel=0.05)
    assert after == pytest.approx(0.5 * before, rel=0.05)


def test_break_motor_unpowers_one_wheel(tmp_path):
    world, _, _ = make_world(tmp_path, ["break-motor:red@1,motor=left"], robots=1)
    advance_seconds(world, 3.0)
    red = world.robots["red"]
    left, right = red.actuators
    assert world.data.actuator_force[left] == 0.0
    assert abs(world.data.actuator_force[right]) > 0.0
    # One wheel driving, one freewheeling: the robot veers to the left instead of going straight.
    _, _, yaw0 = world.pose(red)
    advance_seconds(world, 2.0)
    assert abs(world.pose(red)[2] - yaw0) > 0.05


def test_add_robot_joins_at_its_time(tmp_path):
    world, mission, events = make_world(tmp_path, ["add-robot:purple@3,kind=diffdrive"], robots=2)
    purple = world.robots["purple"]
    assert purple.dormant
    advance_seconds(world, 3.0)
    assert "purple" not in mission.controllers or not mission.controllers["purple"].observations
    x, y, _ = world.pose(purple)
    assert x > 500, "a dormant robot waits outside the arena"
    advance_seconds(world, 3.0)
    x, y, _ = world.pose(purple)
    assert abs(x) < 15 and abs(y) < 15
    assert mean_speed(world, purple, 1.0) > 0.05
    assert fault_events(events) == [{"t": 3.0, "event": "fault", "kind": "add-robot", "robot": "purple",
                                     "time": 3.0, "options": {"kind": "diffdrive"}}]


@pytest.mark.parametrize("spec, message", [
    ("kill:nobody@1", "no robot 'nobody'"),
    ("break-gripper:red@1", "has no gripper"),
    ("break-motor:red@1,motor=middle", "motor must be one of left, right"),
    ("add-robot:red@1", "already in the team"),
])
def test_faults_checked_against_team(tmp_path, spec, message):
    with pytest.raises(ConfigError, match=message):
        make_world(tmp_path, [spec])


def test_a_newcomers_faults_come_after_it_joins(tmp_path):
    with pytest.raises(ConfigError, match="purple joins at 5 s"):
        make_world(tmp_path, ["add-robot:purple@5,kind=diffdrive", "remove:purple@2"], robots=2)


def test_remove_parks_a_robot_and_revive_brings_it_back_with_a_fresh_controller(tmp_path):
    world, mission, events = make_world(tmp_path, ["remove:red@1", "revive:red@3"], robots=2)
    red = world.robots["red"]
    first = red.controller
    advance_seconds(world, 2.0)
    assert world.pose(red)[0] > 500 and not red.active, "removed: parked outside the arena, switched off"
    advance_seconds(world, 1.1)  # revived at 3 s, then 0.1 s of driving at 0.2 m/s
    x, y, _ = world.pose(red)
    assert (x, y) == pytest.approx(red.spawn[:2], abs=0.05), "no entry_pose: back at its start"
    assert red.active and red.controller is not first
    assert [e["kind"] for e in fault_events(events)] == ["remove", "revive"]


class RoleMission(ScriptedMission):
    """The scripted team with one run-time role, ``boss``, held by whoever the test says (None: vacant)."""
    fault_roles = {"boss": "the robot the test names"}

    def __init__(self):
        super().__init__(0.0, 0.0)
        self.holder = None

    def role_holder(self, world, role):
        assert role == "boss"
        return self.holder


def role_world(tmp_path, *faults):
    mission = RoleMission()
    world = World(wander_config(tmp_path, params={"robots": 3, "obstacles": 0, "room_size": 30.0}, seed=7,
                                faults=[parse_fault(f) for f in faults]), mission)
    events = []
    world.record = events.append
    return world, mission, events


def test_a_role_is_resolved_when_the_fault_is_due_not_before(tmp_path):
    world, mission, events = role_world(tmp_path, "kill:@boss@2")
    mission.holder = "red"
    advance_seconds(world, 1.0)
    mission.holder = "green"  # the role changes hands before the fault is due
    advance_seconds(world, 2.0)
    assert not world.robots["green"].health.alive and world.robots["red"].health.alive
    assert fault_events(events) == [{"t": 2.0, "event": "fault", "kind": "kill", "robot": "green", "time": 2.0,
                                     "target": "@boss"}]
    assert world.fault_report() == [{"kind": "kill", "robot": "@boss", "time": 2.0, "hit": "green", "hit_at": 2.0}]


def test_a_vacant_role_keeps_its_fault_waiting_until_someone_holds_it(tmp_path):
    world, mission, events = role_world(tmp_path, "kill:@boss@1", "slow:blue@2,factor=0.5")
    advance_seconds(world, 3.0)
    assert all(r.health.alive for r in world.robots.values())
    assert [e["event"] for e in events if e["event"].startswith("fault")] == ["fault-waiting", "fault"]  # logged once
    assert world.fault_report()[0]["hit"] is None  # (the run would end with the role vacant: hit null)
    assert world.robots["blue"].health.speed_factor == 0.5, "a waiting fault holds up none after it"
    mission.holder = "red"
    advance_seconds(world, 0.5)
    assert not world.robots["red"].health.alive
    hit = fault_events(events)[-1]
    assert (hit["robot"], hit["target"], hit["time"], hit["t"]) == ("red", "@boss", 1.0, 3.0)


def test_a_role_held_by_a_dead_robot_is_vacant(tmp_path):
    world, mission, events = role_world(tmp_path, "kill:red@1", "blind-ir:@boss@2")
    mission.holder = "red"
    advance_seconds(world, 3.0)
    assert world.fault_report()[1]["hit"] is None
    assert [e["event"] for e in events if e["event"].startswith("fault")] == ["fault", "fault-waiting"]


@pytest.mark.parametrize("spec, message", [
    ("kill:@chief@1", "has no role 'chief'; allowed roles: @boss"),
    ("break-motor:@boss@1,motor=middle", "(the role may fall to red): motor must be one of left, right"),
])
def test_bad_role_faults_are_refused_before_the_run(tmp_path, spec, message):
    with pytest.raises(ConfigError) as info:
        role_world(tmp_path, spec)
    assert message in str(info.value) and "\n" not in str(info.value)


def test_a_mission_without_roles_refuses_a_role(tmp_path):
    with pytest.raises(ConfigError, match=r"wander has no roles a fault may name \(@ROLE"):
        make_world(tmp_path, ["kill:@leader@1"])
