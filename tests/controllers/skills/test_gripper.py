"""The R-2 gripper behaviours' state machines (teamsim.controllers.skills.gripper), fed synthetic observations: no
physics. Sensor layout: fingertip IR left = 0, right = 1; beams front = 0, rear = 1."""
from __future__ import annotations

import math

import numpy as np
import pytest

from teamsim.controllers.base import Observation
from teamsim.controllers.skills import gripper as G
from teamsim.models.r2 import build

LAYOUT = G.GripperSensors(tip_left=0, tip_right=1, front_beam=0, rear_beam=1)
P = G.GripperParams()
NOTHING = (math.inf, math.inf)


def obs(t=0.0, tips=NOTHING, beams=(False, False), grip=1.0, lift=0.0, force=0.0) -> Observation:
    ranges = np.array(tips, dtype=float)
    return Observation(time=t, robot="red", ir_raw=np.where(np.isfinite(ranges), 100.0, 0.0), ir_range=ranges,
                       ir_bearings=np.array([-0.17, 0.17]), pose=None, touch={"fingers": force},
                       break_beams=np.array(beams), effectors={"grip": grip, "lift": lift})


def test_sensor_layout_of_the_r2():
    robot = build("red")
    layout = G.GripperSensors.of(robot)
    assert robot.ir_sensors[layout.tip_left] == "ir_tip_left" and robot.ir_sensors[layout.tip_right] == "ir_tip_right"
    assert robot.beams[layout.front_beam] == "beam_front" and robot.beams[layout.rear_beam] == "beam_rear"
    assert layout.grip_touch in robot.touch


def test_approach_waits_for_an_open_lowered_jaw():
    approach = G.Approach(LAYOUT)
    command = approach(obs(tips=(0.2, 0.2), grip=0.3))
    assert (command.v, command.extras) == (0.0, {"grip": G.OPEN, "lift": G.DOWN})
    assert approach(obs(t=0.1, tips=(0.2, 0.2), lift=0.5)).v == 0.0
    assert approach.status == G.RUNNING


@pytest.mark.parametrize("tips, turn", [((0.20, 0.20), 0), ((0.15, 0.20), 1), ((0.20, 0.15), -1),
                                        ((0.2, math.inf), 1), ((math.inf, 0.2), -1)])
def test_approach_steers_towards_the_nearer_fingertip(tips, turn):
    command = G.Approach(LAYOUT)(obs(tips=tips))
    assert command.v == P.approach_speed and command.behaviour == "approach"
    assert np.sign(command.omega) == turn and abs(command.omega) <= P.turn_rate


def test_approach_centres_with_the_beams():
    approach = G.Approach(LAYOUT)
    assert approach(obs(tips=(0.2, 0.2))).v > 0
    assert approach(obs(t=1.0)).v == P.approach_speed, "blind close in: keeps going"
    assert approach(obs(t=2.0, beams=(True, False))).v == P.creep_speed, "front beam only: not in yet"
    assert approach(obs(t=2.1, beams=(False, True))).v == -P.creep_speed, "rear beam only: too far"
    command = approach(obs(t=2.2, beams=(True, True)))
    assert approach.status == G.SUCCEEDED and (command.v, command.omega) == (0.0, 0.0)


def test_approach_fails_with_nothing_ahead_or_after_losing_it():
    nothing = G.Approach(LAYOUT)
    nothing(obs())
    assert (nothing.status, nothing.reason) == (G.FAILED, "nothing ahead")
    lost = G.Approach(LAYOUT)
    lost(obs(tips=(0.2, 0.2)))
    lost(obs(t=P.blind_time - 0.1))
    assert lost.status == G.RUNNING
    lost(obs(t=P.blind_time + 0.1))
    assert (lost.status, lost.reason) == (G.FAILED, "lost it")


def test_approach_times_out():
    approach = G.Approach(LAYOUT)
    approach(obs(beams=(True, False)))
    approach(obs(t=P.approach_timeout + 0.1, beams=(True, False)))
    assert (approach.status, approach.reason) == (G.FAILED, "timed out")


def test_grasp_succeeds_when_the_jaw_stops_on_something():
    grasp = G.Grasp(LAYOUT)
    assert grasp(obs(beams=(True, True), grip=0.9)).extras["grip"] == G.CLOSED
    grasp(obs(t=0.1, beams=(True, True), grip=0.67, force=30.0))
    assert grasp.status == G.RUNNING, "still closing"
    grasp(obs(t=0.2, beams=(True, False), grip=0.67, force=30.0))
    assert grasp.status == G.SUCCEEDED


def test_grasp_fails_on_nothing_or_without_force():
    empty = G.Grasp(LAYOUT)
    empty(obs(grip=0.05))
    assert (empty.status, empty.reason) == (G.FAILED, "closed on nothing")
    weak = G.Grasp(LAYOUT)
    for k in range(5):
        weak(obs(t=k, beams=(True, True), grip=0.67, force=1.0))
    assert (weak.status, weak.reason) == (G.FAILED, "no grip")


def holding(t, lift, **kw):
    return obs(t=t, beams=(True, True), grip=0.67, lift=lift, force=30.0, **kw)


def test_lift_succeeds_at_the_top():
    lift = G.Lift(LAYOUT)
    assert lift(holding(0.0, 0.0)).extras == {"grip": G.CLOSED, "lift": G.UP}
    lift(holding(0.5, 0.5))
    assert lift.status == G.RUNNING
    lift(holding(1.0, P.lift_done))
    assert lift.status == G.SUCCEEDED


def test_lift_stalls_under_too_heavy_a_load():
    lift = G.Lift(LAYOUT)
    t = 0.0
    while lift.status == G.RUNNING and t < 5.0:
        lift(holding(t, 0.005 * t))  # creeping up far slower than stall_progress per stall_time
        t += 0.1
    assert (lift.status, lift.reason) == (G.FAILED, "too heavy")
    assert t == pytest.approx(P.stall_time + 0.1, abs=0.15)


def test_lift_and_carry_fail_when_the_object_is_lost_for_lost_time():
    lost_time = G.GripperParams().lost_time
    lift = G.Lift(LAYOUT)
    lift(obs(grip=0.67, lift=0.3, force=30.0))
    assert lift.status == G.RUNNING, "one tick with the beams clear is not yet a loss"
    lift(obs(t=lost_time, grip=0.67, lift=0.3, force=30.0))
    assert (lift.status, lift.reason) == (G.FAILED, "lost it"), "beams clear"
    carry = G.Carry(LAYOUT, lambda o: (0.2, 0.0))
    carry(holding(0.0, 1.0))
    carry(obs(t=0.1, beams=(True, True), grip=0.67, lift=1.0, force=0.5))
    carry(holding(0.2, 1.0))  # the force back a tick later: a dip, not a loss
    carry(obs(t=0.3, beams=(True, True), grip=0.67, lift=1.0, force=0.5))
    assert carry.status == G.RUNNING
    carry(obs(t=0.3 + lost_time, beams=(True, True), grip=0.67, lift=1.0, force=0.5))
    assert (carry.status, carry.reason) == (G.FAILED, "lost it"), "no grip force"


def test_carry_follows_its_route_until_it_ends():
    route = G.TimedRoute([(0.2, 0.0, 1.0), (0.0, 1.0, 0.5)])
    carry = G.Carry(LAYOUT, route)
    assert (carry(holding(10.0, 1.0)).v, carry(holding(10.9, 1.0)).v) == (0.2, 0.2)
    assert carry(holding(11.2, 1.0)).omega == 1.0
    carry(holding(11.5, 1.0))
    assert carry.status == G.SUCCEEDED


def test_lower_and_release():
    lower = G.Lower(LAYOUT)
    assert lower(holding(0.0, 0.5)).extras == {"grip": G.CLOSED, "lift": G.DOWN}
    lower(holding(0.5, 0.01))
    assert lower.status == G.SUCCEEDED
    release = G.Release(LAYOUT)
    assert release(obs(beams=(True, True), grip=0.7)).v == 0.0, "opens first"
    assert release(obs(t=0.5, beams=(True, False), grip=1.0)).v == -P.back_off_speed, "then backs off"
    release(obs(t=1.0, grip=1.0))
    assert release.status == G.SUCCEEDED


def test_sequence_moves_on_in_the_same_tick_and_stops_at_a_failure():
    sequence = G.Sequence([G.Approach(LAYOUT), G.Grasp(LAYOUT), G.Lift(LAYOUT)])
    command = sequence(obs(beams=(True, True)))
    assert command.behaviour == "grasp" and command.extras["grip"] == G.CLOSED
    sequence(obs(t=0.1, grip=0.05))
    assert sequence.status == G.FAILED and sequence.current.name == "grasp"
    still = sequence(obs(t=0.2, tips=(0.2, 0.2)))
    assert (still.v, still.behaviour) == (0.0, "grasp")


def test_sequence_succeeds_when_all_have():
    sequence = G.Sequence([G.Lower(LAYOUT)])
    command = sequence(holding(0.0, 0.0))
    assert sequence.status == G.SUCCEEDED and command.behaviour == "lower" and command.v == 0.0
