"""The tricycle locomotion's steering (teamsim.controllers.skills.locomotion.TricycleDrive): besides the turn-rate and
angular-acceleration limits of Table 3.4 that every drive applies to (v, omega), the front wheel turns no faster
than the steering rate (the tricycle's dynamic constraint, §3.5) and within its range, and holds its angle while
the robot stands still (no point turns), unless a turn-only command turns it."""
from __future__ import annotations

import math

import numpy as np
import pytest

from teamsim.controllers.skills.locomotion import TricycleDrive
from teamsim.models.robot import DriveLimits, TricycleSpec

SPEC = TricycleSpec(wheel_radius=0.1, wheelbase=0.5, steer="steer", drive="drive", steer_max=math.radians(60),
                    steer_rate_max=1.0)
DT = 0.1


def drive(limits=DriveLimits(v_max=0.5, omega_max=math.pi / 7, accel_max=0.1, angular_accel_max=0.15)):
    return TricycleDrive(SPEC, limits, DT)


def test_steering_angle_moves_at_most_the_steering_rate_per_tick():
    # Generous speed limits so that only the steering rate can hold the wheel back.
    tricycle = drive(DriveLimits(v_max=1.0, omega_max=10.0, accel_max=100.0, angular_accel_max=100.0))
    angles = []
    for _ in range(12):
        tricycle.command(0.5, 1.5)  # wants atan(1.5 * 0.5 / 0.5) = 56.3 degrees
        angles.append(tricycle.steer)
    steps = np.diff([0.0] + angles)
    assert np.all(np.abs(steps) <= SPEC.steer_rate_max * DT + 1e-12)
    assert steps[0] == pytest.approx(SPEC.steer_rate_max * DT)  # the rate, not the target, limits the first ticks
    assert angles[-1] == pytest.approx(math.atan(1.5))


def test_steering_angle_stays_in_range():
    tricycle = drive(DriveLimits(v_max=1.0, omega_max=10.0, accel_max=100.0, angular_accel_max=100.0))
    for _ in range(30):
        tricycle.command(0.2, 5.0)  # would need atan(12.5): 85 degrees
    assert tricycle.steer == pytest.approx(SPEC.steer_max)


def test_table_3_4_limits_the_turn_rate_that_the_steering_follows():
    tricycle = drive()
    for _ in range(5):
        tricycle.command(0.5, 1.0)
    # omega rises by 0.15 rad/s^2 x 0.1 s a tick; v by 0.1 m/s^2 x 0.1 s: after 5 ticks 0.075 rad/s at 0.05 m/s.
    assert tricycle.slew.omega == pytest.approx(0.075) and tricycle.slew.v == pytest.approx(0.05)
    assert abs(tricycle.steer) <= 5 * SPEC.steer_rate_max * DT + 1e-12


def test_standing_still_holds_the_wheel_and_cannot_turn():
    tricycle = drive(DriveLimits(v_max=1.0, omega_max=10.0, accel_max=100.0, angular_accel_max=100.0))
    tricycle.command(0.5, 0.5)
    held = tricycle.steer
    for _ in range(5):
        tricycle.command(0.0, 0.0)
    assert tricycle.steer == held
    assert tricycle.targets(0.0)[1] == 0.0  # the drive wheel does not turn: no point turn


def test_a_turn_only_command_turns_the_standing_wheel_towards_that_side_at_the_steering_rate():
    tricycle = drive(DriveLimits(v_max=1.0, omega_max=10.0, accel_max=100.0, angular_accel_max=100.0))
    tricycle.command(0.5, -0.5)  # wheel turned right
    tricycle.command(0.0, 0.0)  # and stopped there
    start = tricycle.steer
    assert start < 0
    angles = []
    for _ in range(15):
        tricycle.command(0.0, 0.01)  # stand, asking to turn left
        angles.append(tricycle.steer)
        assert tricycle.targets(0.0)[1] == 0.0  # the robot stays put
    steps = np.diff([start] + angles)
    assert np.all(steps >= 0) and np.all(steps <= SPEC.steer_rate_max * DT + 1e-12)
    assert steps[0] == pytest.approx(SPEC.steer_rate_max * DT)
    assert angles[-1] == pytest.approx(SPEC.steer_max)  # to the left lock, and no further
