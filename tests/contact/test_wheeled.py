"""Contact regression: the wheeled robots drive, turn, stop, sense and idle as the theses' numbers say.

Each robot runs through the full World (locomotion with its acceleration limits, physics contacts, IR model)
with a scripted (v, omega). Tolerances are the issue's: heading drift < 3 % over 2 m, circle radius error
< 5 %, stopping within v^2 / 2a.
"""
from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from teamsim.faults import parse_fault
from teamsim.models.arenas import Bog, Box
from tests.contact.harness import CustomParams, RobotSlot, make_world, run_for

WHEELED = ("diffdrive", "tricycle", "tracked")


def solo(kind: str, policy, room=(16.0, 16.0), x=-5.0, y=0.0, yaw=0.0, **params):
    world = make_world(CustomParams(room=room, robots=[RobotSlot("red", kind, x, y, yaw)], **params),
                       {"red": policy})
    return world, world.robots["red"]


def unstable_warnings(world) -> list[str]:
    return [mujoco.mjtWarning(k).name for k, n in enumerate(world.data.warning.number) if n]


@pytest.mark.parametrize("kind", WHEELED)
def test_drives_two_metres_straight(kind):
    world, red = solo(kind, lambda o: (0.25, 0.0))
    start = world.pose(red)
    run_for(world, 30.0, until=lambda w: w.pose(red)[0] - start[0] >= 2.0)
    end = world.pose(red)
    travelled = end[0] - start[0]
    assert travelled >= 2.0
    assert abs(end[1] - start[1]) / travelled < 0.03, "lateral drift"
    assert abs(end[2] - start[2]) < 0.03, "heading drift (rad)"


@pytest.mark.parametrize("kind", WHEELED)
def test_follows_a_circle(kind):
    v, omega = 0.3, 0.15
    world, red = solo(kind, lambda o: (v, omega), x=0.0, y=-2.0)
    run_for(world, 8.0)  # past the acceleration ramp
    points = []
    for _ in range(40):  # about one full circle (2 pi / 0.15 = 42 s)
        run_for(world, 1.0)
        points.append(world.pose(red)[:2])
    points = np.array(points)
    a = np.c_[2 * points, np.ones(len(points))]
    cx, cy, k = np.linalg.lstsq(a, (points ** 2).sum(axis=1), rcond=None)[0]
    radius = math.sqrt(k + cx ** 2 + cy ** 2)
    assert radius == pytest.approx(v / omega, rel=0.05)


@pytest.mark.parametrize("kind", WHEELED)
def test_stops_within_its_deceleration_distance(kind):
    cruise = 0.3
    commands = {"v": cruise}
    world, red = solo(kind, lambda o: (commands["v"], 0.0))
    run_for(world, 8.0)
    speed = world.speed(red)
    assert speed == pytest.approx(cruise, rel=0.05)
    start = world.pose(red)[:2]
    commands["v"] = 0.0
    run_for(world, 6.0)
    stopped = float(np.hypot(*(world.pose(red)[:2] - start)))
    limit = speed ** 2 / (2 * red.model.limits.accel_max)
    assert world.speed(red) < 0.01
    # One control period of reaction at cruise speed on top of the braking distance. The drives brake a little
    # harder than accel_max (motor and rolling losses): measured 0.74, 0.87 and 0.63 of v^2 / 2a for diffdrive,
    # tricycle and tracked (2026-11-26); a stop in under half of it would be a velocity jump, not braking.
    assert 0.5 * limit <= stopped <= limit + speed * world.control_dt + 0.02


@pytest.mark.parametrize("kind", WHEELED)
def test_odometry_reads_the_motion_and_zero_against_a_wall(kind):
    """Observation.velocity: (forward speed, turn rate) over the last control period. Driving freely it reads
    the commanded motion; pushed against a wall, the wheels still driven, it reads (about) zero: what the
    navigation controllers' stall detection relies on."""
    v, omega = 0.3, 0.15
    world, red = solo(kind, lambda o: (v, omega), x=0.0, y=-2.0)
    run_for(world, 8.0)  # past the acceleration ramp
    speed, turn = np.mean([o.velocity for o in world.controllers["red"].observations[-20:]], axis=0)
    assert speed == pytest.approx(v, rel=0.05)
    assert turn == pytest.approx(omega, rel=0.05)
    world, red = solo(kind, lambda o: (0.3, 0.0), room=(4.0, 4.0), x=0.0)
    run_for(world, 15.0)  # the wall, 2 m ahead, is reached in about 8 s
    assert world.pose(red)[0] > 1.0
    speed, turn = np.mean([o.velocity for o in world.controllers["red"].observations[-20:]], axis=0)
    assert abs(speed) < 0.02 and abs(turn) < 0.05


@pytest.mark.parametrize("kind", WHEELED)
def test_idle_is_stable(kind):
    world, red = solo(kind, lambda o: (0.0, 0.0))
    run_for(world, 0.5)  # settle onto the floor
    start = world.data.qpos[red.qpos_adr:red.qpos_adr + 3].copy()
    run_for(world, 10.0)
    assert unstable_warnings(world) == []
    assert np.abs(world.data.qpos[red.qpos_adr:red.qpos_adr + 3] - start).max() < 1e-3


@pytest.mark.parametrize("kind", WHEELED)
def test_ir_reads_a_wall_within_the_noise_model(kind):
    """Facing a wall at several distances, the front sensor's raw readings stay within 4 sigma of the
    calibration's response (sigma = noise fraction x response, plus quantisation)."""
    for gap in (0.3, 0.6, 1.0, 1.3):
        room = 8.0
        world, red = solo(kind, lambda o: (0.0, 0.0), room=(room, room), x=0.0)
        ir = red.model.ir
        front = int(np.argmin(np.abs(red.model.ir_bearings)))
        mujoco.mj_kinematics(world.model, world.data)
        site = mujoco.mj_name2id(world.model, mujoco.mjtObj.mjOBJ_SITE, f"red/{red.model.ir_sensors[front]}")
        reach = world.data.site_xpos[site][0]  # sensor's distance ahead of the robot's frame
        world.data.qpos[red.qpos_adr] = room / 2 - gap - reach
        run_for(world, 3.0)
        raws = np.array([o.ir_raw[front] for o in world.controllers["red"].observations[5:]])
        clean = float(ir.response(gap))
        sigma = float(np.interp(gap, ir.distances, ir.noise_fractions)) * clean + ir.resolution
        assert np.all(np.abs(raws - clean) <= 4 * sigma), (kind, gap, raws.min(), raws.max(), clean)
        ranges = [o.ir_range[front] for o in world.controllers["red"].observations[5:]]
        # The median of 25 noisy readings: measured within 0.018 m of the gap for every kind (2026-11-26).
        assert np.median(ranges) == pytest.approx(gap, abs=0.03)


def test_blinded_sensors_read_nothing():
    world = make_world(CustomParams(room=(4.0, 4.0), robots=[RobotSlot("red", "diffdrive", 1.0, 0.0, 0.0)]),
                       {"red": lambda o: (0.0, 0.0)}, faults=[parse_fault("blind-ir:red@1")])
    run_for(world, 2.0)
    observations = world.controllers["red"].observations
    assert (observations[5].ir_raw > 0).any(), "the wall 0.65 m ahead is seen before the fault"
    assert all((o.ir_raw == 0).all() and np.isinf(o.ir_range).all() for o in observations if o.time >= 1.0)


def test_tricycle_cannot_turn_in_place():
    world, red = solo("tricycle", lambda o: (0.0, 0.4))
    start = world.pose(red)
    run_for(world, 6.0)
    end = world.pose(red)
    assert abs(end[2] - start[2]) < 0.02
    assert np.hypot(*(end[:2] - start[:2])) < 0.01


def test_tricycle_reverses_out_of_a_dead_end():
    """A corridor 1.7 m wide between its walls, closed ahead. The tricycle's tightest U-turn sweeps a circle about
    1.76 m across (rear axle on a wheelbase / tan 60 deg = 0.29 m radius, the 0.5 m pentagon centred 0.25 m ahead
    of it), so it cannot turn round in it: it sees the end wall and backs out straight."""
    walls = (Box(0.0, 0.95, 2.0, 0.1), Box(0.0, -0.95, 2.0, 0.1), Box(2.1, 0.0, 0.1, 1.05))
    commands = {"v": 0.2}
    world, red = solo("tricycle", lambda o: (commands["v"], 0.0), x=-1.0, obstacles=walls)
    run_for(world, 20.0, until=lambda w: w.pose(red)[0] > 1.0)  # drive in until the end wall is near
    ahead = world.controllers["red"].observations[-1]
    assert np.min(ahead.ir_range[np.abs(ahead.ir_bearings) < 0.3]) < 1.0, "it sees the dead end"
    commands["v"] = -0.2
    run_for(world, 30.0, until=lambda w: w.pose(red)[0] < -2.5)
    x, y, yaw = world.pose(red)
    assert x < -2.5, "out of the corridor, whose mouth is at x = -2"
    assert abs(y) < 0.2 and abs(yaw) < 0.1


def test_bog_stops_wheels_but_not_tracks():
    """A bog from x = -4 to 4: a differential robot of traversability 0.1 advances less than 30 % of its
    commanded distance in it; a tracked robot (traversability 1.0) crosses it."""
    bog = Bog(0.0, 0.0, 4.0, 3.0)
    cruise, seconds = 0.3, 12.0
    world, red = solo("diffdrive", lambda o: (cruise, 0.0), x=-3.0, bogs=[bog])
    run_for(world, seconds)
    commanded = cruise * (seconds - cruise / red.model.limits.accel_max / 2)  # minus the ramp's shortfall
    assert world.pose(red)[0] + 3.0 < 0.3 * commanded

    world, red = solo("tracked", lambda o: (cruise, 0.0), x=-5.0, bogs=[bog])
    run_for(world, 40.0, until=lambda w: w.pose(red)[0] > 4.0 + red.model.footprint_radius)
    assert world.pose(red)[0] > 4.0 + red.model.footprint_radius, "the tracked robot is through the bog"
    assert world.time < 1.25 * (9.0 + red.model.footprint_radius) / cruise


def test_diffdrive_radius_is_a_parameter():
    """Chand's circular robot is 0.35 m in ch.3 and 0.40 m in ch.5: the body and its IR ring follow."""
    world = make_world(CustomParams(room=(6.0, 6.0), robots=[
        RobotSlot("red", "diffdrive", -1.0, 0.0, 0.0),
        RobotSlot("green", "diffdrive", 1.0, 0.0, 0.0, options={"radius": 0.40})]),
        {"red": lambda o: (0.0, 0.0), "green": lambda o: (0.0, 0.0)})
    model = world.model
    for name, radius in (("red", 0.35), ("green", 0.40)):
        shell = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"{name}/shell")
        assert model.geom_size[shell][0] == pytest.approx(radius)
        site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, f"{name}/ir0")
        assert np.hypot(*model.site_pos[site][:2]) == pytest.approx(radius, abs=0.01)


@pytest.mark.parametrize("kind, cruise", [("diffdrive", 0.5), ("tricycle", 0.5), ("tracked", 0.4)])
def test_drive_effort_is_high_in_a_bog_and_only_there(kind, cruise):
    """The explorers' bog sign (Chand §6.2: high motor effort): ``Observation.drive_effort`` at or above 0.25 for
    1.5 s (15 ticks) running, which is where the explore mission's explorers call it a bog (decisions.md,
    "Exploration"), never happens driving and speeding up on firm ground (the effort peaks there at about 0.2
    for a moment as the robot accelerates) and does happen once the robot is wholly in a bog, whatever its drive."""
    bog = Bog(0.0, 0.0, 4.0, 3.0)
    world, red = solo(kind, lambda o: (cruise, 0.0), x=-5.5, bogs=[bog])
    firm, boggy = [], []
    for _ in range(150):
        run_for(world, 0.1)
        x = world.pose(red)[0]
        effort = world.controllers["red"].observations[-1].drive_effort
        if x + red.model.footprint_radius < -4.0:
            firm.append(effort)
        elif x - red.model.footprint_radius > -4.0:
            boggy.append(effort)

    def longest_high_run(efforts):
        run = best = 0
        for effort in efforts:
            run = run + 1 if effort >= 0.25 else 0
            best = max(best, run)
        return best

    assert len(firm) >= 20 and longest_high_run(firm) < 15 and max(firm) < 0.25
    assert longest_high_run(boggy) >= 15


@pytest.mark.parametrize("v, omega", [(0.0, 0.45), (0.2, 0.45), (0.4, 0.2)])
def test_a_tracked_skid_turn_is_hard_work_but_not_a_bog(v, omega):
    """A tracked robot turning on firm ground scrubs its tracks: its effort passes 0.25 (the bog sign), but only
    while it turns faster than 0.1 rad/s, which the explorers' bog test excludes (decisions.md, "Exploration")."""
    world, red = solo("tracked", lambda o: (v, omega), x=-2.0)
    readings = []
    for _ in range(60):
        run_for(world, 0.1)
        observation = world.controllers["red"].observations[-1]
        readings.append((observation.drive_effort, abs(observation.velocity[1])))
    assert max(effort for effort, _ in readings) >= 0.25, "turning is hard work"
    run = longest = 0
    for effort, turn in readings:  # the bog test: 15 ticks (1.5 s) running of high effort while hardly turning
        run = run + 1 if effort >= 0.25 and turn <= 0.1 else 0
        longest = max(longest, run)
    assert longest < 15
