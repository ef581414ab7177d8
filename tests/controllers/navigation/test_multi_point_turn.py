"""A trapped tricycle's multi-point turn (teamsim.controllers.navigation.multi_point_turn), and FRC's wheel sweep
when the window wedges a standing tricycle (``DynamicWindowController._wedged``), driven through the kinematic
body (bicycle model, the locomotion's steering) between boxes."""
from __future__ import annotations

import math

import numpy as np

from teamsim.controllers.base import Command, Observation
from teamsim.controllers.navigation.dynamic_window import DriveState, DynamicWindow
from teamsim.controllers.navigation.multi_point_turn import MultiPointTurn
from teamsim.controllers.skills.locomotion import next_steer
from teamsim.models import build_robot
from teamsim.models.arenas import Box
from teamsim.positioning import PoseFix
from teamsim.tasks.missions.navigate import kinematic_robot, navigation_controller
from teamsim.tasks.worlds.navigation import KinematicBody, NavWorld

ROBOT = kinematic_robot(build_robot("tricycle", "red"))  # Robot A: radius 0.5, centre 0.25 m ahead of the axle


def world(*boxes: Box) -> NavWorld:
    return NavWorld(tuple(boxes), np.zeros((1, 1), bool), (-7.5, -7.5), 0.1, 15.0, (0.0, 0.0, 0.0), (6.0, 0.0))


def window() -> DynamicWindow:
    return DynamicWindow(ROBOT.limits, "tricycle", ROBOT.radius, centre_offset=ROBOT.centre_offset, steering=ROBOT)


def seen_points(body: KinematicBody, nav_world: NavWorld) -> np.ndarray:
    """The IR hits relative to the centre, robot frame, as the controller hands them to the turn."""
    origins, directions = body.rays()
    ranges = body.ranges(nav_world)
    hit = np.isfinite(ranges)
    points = origins[hit] + ranges[hit, None] * directions[hit] - np.array(body.centre(body.x, body.y, body.heading))
    c, s = math.cos(body.heading), math.sin(body.heading)
    return points @ np.array([[c, -s], [s, c]])


def drive_turn(nav_world: NavWorld, target: tuple[float, float], seconds: float = 90.0):
    """Drive the turn until the target lies within 30 degrees of the heading; the directions of the legs that
    moved, the least gap to a box, and whether it faced the target."""
    body = KinematicBody(ROBOT, (0.0, 0.0, 0.0))
    turn = MultiPointTurn(window())
    state, legs, least_gap = DriveState(), [], math.inf
    for _ in range(round(seconds / body.control_dt)):
        cx, cy = body.centre(body.x, body.y, body.heading)
        bearing = math.remainder(math.atan2(target[1] - cy, target[0] - cx) - body.heading, 2 * math.pi)
        if abs(bearing) <= math.radians(30):
            return legs, least_gap, True
        command = turn.command(state, seen_points(body, nav_world), bearing)
        assert command is not None
        if command[0] != 0.0 and (not legs or legs[-1] != math.copysign(1, command[0])):
            legs.append(math.copysign(1, command[0]))  # a leg that moved, forwards (+1) or backwards (-1)
        steer = next_steer(state.steer, command[0], command[1], command, ROBOT, body.control_dt)
        x, y, heading, velocity = body.motion(Command(v=command[0], omega=command[1]))
        least_gap = min(least_gap, body.gap(nav_world, x, y, heading))
        body.move(x, y, heading, velocity)
        state = DriveState(command[0], command[1] if command[0] else 0.0, steer)
    return legs, least_gap, False


def test_in_a_pocket_it_turns_round_in_legs_without_touching():
    # Boxes 0.2 m ahead of the circle, 0.3 m behind it and 0.6 m to its left (the centre is at x = 0.25); the way
    # out lies behind.
    pocket = world(Box(1.45, 0.0, 0.5, 1.5), Box(-0.85, 0.0, 0.3, 1.5), Box(0.25, 1.35, 1.5, 0.25))
    for target in ((-6.0, 1.0), (-6.0, -1.0)):
        legs, least_gap, faced = drive_turn(pocket, target)
        assert faced
        assert len(legs) >= 2 and set(legs) == {1.0, -1.0}  # it moved both ways
        assert least_gap > 0.0  # never touched a box


def test_in_the_open_one_leg_does_it():
    legs, _, faced = drive_turn(world(), target=(-6.0, 1.0))
    assert faced and len(legs) == 1


def test_the_first_leg_goes_where_there_is_more_room():
    blocked_ahead = world(Box(1.2, 0.0, 0.3, 1.0))
    body = KinematicBody(ROBOT, (0.0, 0.0, 0.0))
    turn = MultiPointTurn(window())
    turn.command(DriveState(), seen_points(body, blocked_ahead), bearing=math.radians(150))
    assert turn.direction == -1
    blocked_behind = world(Box(-0.95, 0.0, 0.3, 1.0))
    turn.restart()
    turn.command(DriveState(), seen_points(body, blocked_behind), bearing=math.radians(150))
    assert turn.direction == 1


def test_with_no_room_either_way_it_gives_up_after_two_idle_legs():
    wedged = world(Box(1.05, 0.0, 0.3, 1.0), Box(-0.6, 0.0, 0.3, 1.0))  # 0.05 m ahead, 0.05 m behind
    body = KinematicBody(ROBOT, (0.0, 0.0, 0.0))
    turn = MultiPointTurn(window())
    points = seen_points(body, wedged)
    assert turn.command(DriveState(), points, bearing=math.pi / 2) == (0.0, 0.0)
    assert turn.command(DriveState(), points, bearing=math.pi / 2) is None


def drive_frc_from_the_lock(nav_world: NavWorld, sweep: bool, seconds: float = 40.0) -> tuple[float, float]:
    """FRC drives Robot A from rest at (0, 0, 0) with its wheel at the left lock; how far along x it got and the
    least gap to a box."""
    controller = navigation_controller("FRC", build_robot("tricycle", "red"), nav_world)
    if not sweep:
        controller._wedged = lambda decision: False
    body = KinematicBody(ROBOT, (0.0, 0.0, 0.0))
    body.steer = ROBOT.steer_max
    controller.state = DriveState(0.0, 0.0, ROBOT.steer_max)
    least_gap = math.inf
    for tick in range(round(seconds / body.control_dt)):
        time = tick * body.control_dt
        ranges = body.ranges(nav_world)
        command = controller(Observation(time=time, robot="red", ir_raw=ranges, ir_range=ranges,
                                         ir_bearings=body.bearings, pose=PoseFix(body.x, body.y, body.heading, time),
                                         velocity=body.velocity))
        x, y, heading, velocity = body.motion(command)
        least_gap = min(least_gap, body.gap(nav_world, x, y, heading))
        body.move(x, y, heading, velocity)
    return body.x, least_gap


def test_a_tricycle_wedged_with_its_wheel_at_the_lock_sweeps_it_and_drives_on():
    # A channel 5 cm wider than the circle on each side, the goal straight along it: at the left lock every
    # forward arc runs into the left wall, and the window stands (measured: it never moves); a straighter wheel
    # leads out.
    channel = world(Box(0.25, 1.05, 2.5, 0.5), Box(0.25, -1.05, 2.5, 0.5))
    stood, _ = drive_frc_from_the_lock(channel, sweep=False)
    assert abs(stood) < 0.05
    moved, least_gap = drive_frc_from_the_lock(channel, sweep=True)
    assert moved > 0.5  # measured: 0.75 m in 40 s
    assert least_gap > 0.0


def test_a_turn_begun_on_the_move_first_brakes_to_a_stop_then_sets_the_wheel():
    turn = MultiPointTurn(window())
    body = KinematicBody(ROBOT, (0.0, 0.0, 0.0))
    points = seen_points(body, world(Box(1.2, 0.0, 0.3, 1.0)))  # a box ahead: the first leg goes backwards
    state = DriveState(0.3, 0.0, 0.0)  # driving straight on at 0.3 m/s
    speeds = []
    while state.v != 0.0:
        v, omega = turn.command(state, points, bearing=math.radians(150))
        assert turn.direction == -1 and 0.0 <= v < state.v and omega == 0.0  # slowing, straight on, not reversing
        speeds.append(v)
        state = DriveState(v, omega, 0.0)
    assert len(speeds) > 5  # within the drive's deceleration, not at once
    v, omega = turn.command(state, points, bearing=math.radians(150))
    assert v == 0.0 and omega < 0.0  # standing: the wheel goes to the right lock for the backward leg


def test_with_no_room_for_a_leg_frc_ends_the_turn_and_the_window_drives(monkeypatch):
    nav_world = world()
    controller = navigation_controller("FRC", build_robot("tricycle", "red"), nav_world)
    monkeypatch.setattr(controller.escape, "turn_first", lambda heading, time: True)
    monkeypatch.setattr(controller.turn, "command", lambda state, points, bearing: None)
    controller.escape.turning = True
    body = KinematicBody(ROBOT, (0.0, 0.0, 0.0))
    ranges = body.ranges(nav_world)
    command = controller(Observation(time=0.0, robot="red", ir_raw=ranges, ir_range=ranges, ir_bearings=body.bearings,
                                     pose=PoseFix(0.0, 0.0, 0.0, 0.0), velocity=(0.0, 0.0)))
    assert not controller.escape.turning
    assert command.behaviour == "frc" and command.v > 0.0  # the window's own choice: off towards the goal
