"""The tripod gait alone (no physics): phasing, strides, mirror symmetry, standing, limits."""
from __future__ import annotations

import math

import numpy as np
import pytest

from teamsim.controllers.skills.gait import TripodGait
from teamsim.controllers.skills.locomotion import make_locomotion
from teamsim.models.genghis2 import LEGS, Genghis2Dims, gait_spec
from teamsim.models.robot import DriveLimits

DIMS = Genghis2Dims()
SPEC = gait_spec(DIMS)
LIMITS = DriveLimits(DIMS.v_max, DIMS.omega_max, DIMS.accel_max, DIMS.angular_accel_max)
DT = 0.1
PERIOD = 1 / SPEC.frequency
MIRROR = [LEGS.index(("r" if leg[0] == "l" else "l") + leg[1]) for leg in LEGS]  # lf <-> rf, ...
# Sample times strictly inside stance or swing, over several cycles (the phase boundaries are exactly 0 and 0.5).
TIMES = (np.arange(200) + 0.5) / 200 * 4 * PERIOD


def gait_at(v, omega, ticks=50) -> TripodGait:
    """A gait after ``ticks`` control periods of one command: past the acceleration ramp."""
    gait = TripodGait(SPEC, LIMITS, DT)
    for _ in range(ticks):
        gait.command(v, omega)
    return gait


def legs(targets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(swing, lift) per leg."""
    pairs = targets.reshape(len(LEGS), 2)
    return pairs[:, 0], pairs[:, 1]


def test_actuator_order_matches_targets():
    assert SPEC.actuators[:4] == ("swing_lf", "lift_lf", "swing_lm", "lift_lm")
    assert len(SPEC.actuators) == 12 == len(gait_at(0.05, 0.0).targets(0.3))


def test_the_world_finds_the_gait_by_its_spec():
    assert isinstance(make_locomotion(SPEC, LIMITS, DT), TripodGait)
    assert TripodGait.continuous


@pytest.mark.parametrize("v, omega", [(0.08, 0.0), (0.03, 0.2), (0.0, -0.4), (-0.05, 0.1)])
def test_exactly_one_tripod_in_stance(v, omega):
    gait = gait_at(v, omega)
    tripod_a = {LEGS.index(leg) for leg in ("lf", "lr", "rm")}  # legs 1, 3, 5
    for t in TIMES:
        _, lift = legs(gait.targets(t))
        down = set(np.flatnonzero(lift == SPEC.lift_stance))
        assert len(down) == 3 and down in (tripod_a, set(range(6)) - tripod_a)
        assert (np.delete(lift, sorted(down)) > SPEC.lift_stance).all(), "the other three are raised"


def test_stance_feet_sweep_back_one_stride_per_half_cycle():
    v = 0.06
    gait = gait_at(v, 0.0)
    stride = v / (2 * SPEC.frequency)
    assert gait.stride == pytest.approx(np.full(6, stride))
    # Leg lf (phase offset 0): front of its stroke at the start of stance, back at the end.
    start, _ = legs(gait.targets(1e-9))
    end, _ = legs(gait.targets(PERIOD / 2 - 1e-9))
    foot = SPEC.reach * np.sin(np.array([start[0], end[0]]))
    assert foot == pytest.approx([stride / 2, -stride / 2], abs=1e-6)
    mid_swing, lift = legs(gait.targets(0.75 * PERIOD))
    assert mid_swing[0] == pytest.approx(0.0, abs=1e-9) and lift[0] == pytest.approx(SPEC.lift_swing)


def test_turning_is_a_difference_of_strides():
    left = [LEGS.index(leg) for leg in ("lf", "lm", "lr")]
    right = [LEGS.index(leg) for leg in ("rf", "rm", "rr")]
    spinning = gait_at(0.0, 0.3).stride
    assert (spinning[right] > 0).all() and spinning[left] == pytest.approx(-spinning[right])
    curving = gait_at(0.05, 0.2).stride
    assert (curving[right] > curving[left]).all() and (curving[left] > 0).all()
    assert gait_at(0.05, -0.2).stride[left] == pytest.approx(curving[right])


def test_mirror_symmetry():
    """Turning right is turning left seen in a mirror: each leg does what its mirror leg did half a cycle
    earlier (the mirror leg belongs to the other tripod)."""
    a, b = gait_at(0.04, 0.25), gait_at(0.04, -0.25)
    for t in TIMES:
        assert b.targets(t + PERIOD / 2).reshape(6, 2) == pytest.approx(a.targets(t).reshape(6, 2)[MIRROR])


def test_zero_command_stands_with_every_foot_down():
    standing = np.tile([0.0, SPEC.lift_stance], 6)
    gait = gait_at(0.0, 0.0)
    assert all((gait.targets(t) == standing).all() for t in TIMES)
    walking = gait_at(0.08, 0.3)
    assert not (walking.targets(0.3) == standing).all()
    for _ in range(10):  # decelerate (0.08 m/s at 0.2 m/s^2 takes 0.4 s; 0.3 rad/s at 1 rad/s^2 0.3 s)
        walking.command(0.0, 0.0)
    assert all((walking.targets(t) == standing).all() for t in TIMES)
    moving = gait_at(0.08, 0.0)
    moving.stop()
    assert (moving.targets(0.3) == standing).all()


def test_commands_are_slewed_and_strides_stay_within_the_swing_range():
    gait = TripodGait(SPEC, LIMITS, DT)
    gait.command(1.0, 0.0)
    assert gait.stride[0] == pytest.approx(DIMS.accel_max * DT / (2 * SPEC.frequency)), "one tick of accel"
    fastest = gait_at(10.0, 10.0)
    foot_speed = 2 * SPEC.frequency * fastest.stride
    assert np.abs(foot_speed).max() == pytest.approx(SPEC.foot_speed_max)
    ideal = DIMS.v_max - SPEC.turn_gain * DIMS.omega_max * np.asarray(SPEC.foot_y)
    assert foot_speed / foot_speed[0] == pytest.approx(ideal / ideal[0]), "scaled together: same curvature"
    swing = np.array([legs(fastest.targets(t))[0] for t in TIMES])
    assert np.abs(swing).max() <= SPEC.swing_max + 1e-12


def test_phase_depends_on_time_only():
    a, b = gait_at(0.05, 0.1), gait_at(0.05, 0.1, ticks=80)
    assert all((a.targets(t) == b.targets(t)).all() for t in TIMES)
    assert a.targets(0.2) == pytest.approx(a.targets(0.2 + 3 * PERIOD))


def test_limits_are_within_what_the_gait_can_step():
    assert DIMS.v_max <= SPEC.foot_speed_max
    with pytest.raises(ValueError, match="exceeds"):
        gait_spec(Genghis2Dims(v_max=1.0))
    assert math.isclose(SPEC.foot_speed_max, 4 * SPEC.frequency * SPEC.reach * math.sin(SPEC.swing_max))
