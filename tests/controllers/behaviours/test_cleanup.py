"""The hazardous-waste behaviours' logic, without physics: locations from extents (§3.8.1), beliefs merged
from broadcasts, the report trigger (ch.5), the pose estimate and the go-to and avoid layers."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from teamsim.controllers.base import Observation
from teamsim.controllers.base import Command
from teamsim.controllers.behaviours.cleanup import CleanupKnowledge, locations_from_extents
from teamsim.controllers.skills.goto import AvoidObstacles, DriveParams, Unstick, steer_to
from teamsim.controllers.skills.pose_estimate import PoseEstimate
from teamsim.models.robot import DifferentialSpec
from teamsim.positioning import PoseFix

EXTENTS = np.array([-3.7, 3.7, -1.6, 1.6])  # (xmin, xmax, ymin, ymax) of a robot's track


@pytest.mark.parametrize("home, spill, goal, entrance", [
    ((-3.2, 0.3), (-3.7 + 7.4 / 6, 0.0), (3.7 - 0.4, 0.0), (-3.7, 0.0)),  # entrance west
    ((3.3, -0.2), (3.7 - 7.4 / 6, 0.0), (-3.7 + 0.4, 0.0), (3.7, 0.0)),  # entrance east
    ((0.5, 1.4), (0.0, 1.6 - 3.2 / 6), (0.0, -1.6 + 0.4), (0.0, 1.6)),  # entrance north
])
def test_spill_is_the_centre_of_the_front_third_and_goal_the_back_centre(home, spill, goal, entrance):
    found = locations_from_extents(EXTENTS, np.array(home), clearance=0.4)
    assert found["spill"] == pytest.approx(spill)
    assert found["goal"] == pytest.approx(goal)
    assert found["entrance"] == pytest.approx(entrance)
    assert found["extents"] == tuple(EXTENTS)  # the room, as far as a robot's centre goes, for the search


def test_a_robot_learns_locations_and_reports_from_teammates_broadcasts():
    k = CleanupKnowledge(report_interval=240.0)
    k.hear({"task": "idle", "report": 0.0, "emptied_at": None})
    assert not k.located
    k.hear({"task": "find-locations", "spill": (1, 2), "goal": (3, 4), "entrance": (0, 0),
            "extents": (-1, 5, -2, 2), "report": 0.0})
    assert k.located and k.spill == (1, 2) and k.goal == (3, 4) and k.extents == (-1, 5, -2, 2)
    assert k.message()["extents"] == (-1, 5, -2, 2)  # passed on
    k.hear({"spill": (9, 9), "goal": (9, 9), "entrance": (9, 9), "extents": (9, 9, 9, 9)})  # first locations stick
    assert k.goal == (3, 4)
    k.delivered()
    assert k.report_due(250.0)
    k.hear({"report": 245.0})  # a teammate reported: this robot's delivery is covered
    assert not k.report_due(500.0) and k.last_report == 245.0

def test_a_spill_found_empty_by_a_teammate_is_believed_empty_until_the_rest_is_over():
    k = CleanupKnowledge(report_interval=240.0, empty_rest=120.0)
    assert not k.spill_empty(0.0)
    k.hear({"emptied_at": 500.0})
    assert k.spill_empty(500.0) and k.spill_empty(619.0)
    assert not k.spill_empty(620.0)  # the rest is over: look again
    k.hear({"emptied_at": 400.0})  # an older finding changes nothing
    assert k.message()["emptied_at"] == 500.0 and not k.spill_empty(620.0)
    k.found_empty(700.0)
    assert k.spill_empty(700.0) and k.message()["emptied_at"] == 700.0


def test_report_is_due_only_after_a_delivery_and_the_interval():
    k = CleanupKnowledge(report_interval=240.0)
    assert not k.report_due(1000.0)  # nothing delivered yet
    k.delivered()
    assert not k.report_due(239.0) and k.report_due(240.0)
    k.reported(240.0)
    assert k.reports == 1 and not k.report_due(1000.0)
    assert k.message()["report"] == 240.0


def _observation(t, fix, wheel_speed, touch=None, ir=None):
    ir = np.full(4, np.inf) if ir is None else np.asarray(ir, float)
    return Observation(time=t, robot="red", ir_raw=np.zeros(len(ir)), ir_range=ir,
                       ir_bearings=np.array([0.0, math.pi / 2, math.pi, -math.pi / 2]), pose=fix,
                       motor_speeds=np.array([wheel_speed, wheel_speed]), touch=touch or {})


def test_a_report_due_interrupts_a_fruitless_search_but_not_a_load():
    """Move-spill yields to a due report only while it sweeps the spill with no load after an empty line: on an
    exhausted spill the report would otherwise wait for lambda (radio-off seed 200: 1608 s instead of 814 s)."""
    from teamsim.controllers.behaviours.cleanup import MOVE, CleanupRobot
    from teamsim.models import build_robot

    brain = CleanupRobot(build_robot("r2", "red"), np.random.default_rng(0))
    k, move = brain.knowledge, brain.sets[MOVE]
    k.learn_locations(locations_from_extents(EXTENTS, np.array([-3.2, 0.0]), clearance=0.4))
    k.delivered()
    k.just_delivered = False
    applicable = brain.alliance.definitions[MOVE].applicable
    obs = Observation(time=100.0, robot="red", ir_raw=np.array([]), ir_range=np.array([]), ir_bearings=np.array([]),
                      pose=None)
    move.state, move.empty_lines = "sweep", 3
    assert applicable(obs)  # no report due yet: it searches on
    obs = replace(obs, time=300.0)  # the report interval has passed since the start
    assert not applicable(obs)
    move.empty_lines = 0  # its first line of this activation is still under way
    assert applicable(obs)
    move.state, move.empty_lines = "carry", 3  # a load in the jaw is delivered first
    assert applicable(obs)


def test_pose_estimate_is_steadier_than_the_raw_fixes():
    """Straight at 0.3 m/s with 0.15 m fix noise every 0.6 s: the blended estimate's error is well below it."""
    rng = np.random.default_rng(0)
    drive = DifferentialSpec(wheel_radius=0.05, track_width=0.3, left=("l",), right=("r",))
    estimate, dt, speed = PoseEstimate(drive), 0.1, 0.3
    errors, fix = [], None
    for k in range(600):
        t = k * dt
        if k % 6 == 0:
            fix = PoseFix(speed * t + 0.15 * rng.standard_normal(), 0.15 * rng.standard_normal(), 0.0, t)
        pose = estimate.update(_observation(t, fix, speed / drive.wheel_radius))
        errors.append(math.hypot(pose[0] - speed * t, pose[1]))
    assert np.sqrt(np.mean(np.square(errors[60:]))) < 0.5 * 0.15 * math.sqrt(2)


def test_steer_to_turns_on_the_spot_when_far_off_heading_and_stops_on_arrival():
    params = DriveParams()
    v, omega = steer_to(np.array([0.0, 0.0, 0.0]), (0.0, 2.0), params, arrive=0.2)
    assert v == 0.0 and omega > 0
    v, omega = steer_to(np.array([0.0, 0.0, 0.0]), (2.0, 0.1), params, arrive=0.2)
    assert v == pytest.approx(params.cruise, rel=0.01) and omega > 0
    assert steer_to(np.array([1.95, 0.0, 0.0]), (2.0, 0.0), params, arrive=0.2) is None


def test_avoid_backs_off_from_a_front_bump_then_turns_right_and_releases():
    avoid = AvoidObstacles(("a", "b", "c", "d"), np.array([0.0, math.pi / 2, math.pi, -math.pi / 2]),
                           ("bump_front", "bump_back"), np.random.default_rng(0))
    p = avoid.params
    assert avoid(_observation(0.0, None, 0.0)) is None
    v, omega = avoid(_observation(0.1, None, 0.0, touch={"bump_front": 5.0}))
    assert v < 0 and omega == 0.0
    v, omega = avoid(_observation(0.1 + p.back_time + 0.05, None, 0.0))
    assert v == 0.0 and omega < 0  # dead ahead: turn right, so two robots meeting pass left to left
    assert avoid(_observation(0.2 + p.back_time + p.turn_time, None, 0.0)) is None
    v, omega = avoid(_observation(10.0, None, 0.0, ir=[np.inf, 0.1, np.inf, np.inf]))  # close on the left
    assert v > 0 and omega == 0.0  # not ahead: it moves on, then turns away to the right
    assert avoid(_observation(10.0 + p.back_time + 0.05, None, 0.0))[1] < 0


def test_avoid_hemmed_in_front_and_behind_turns_on_the_spot_instead_of_rocking():
    """Delivered pucks ahead and the wall behind, both within avoid_range (break-gripper seed 119): backing off the
    one brought the other into range, and moving off that the first, for 1200 s. Now it turns on the spot."""
    avoid = AvoidObstacles(("a", "b", "c", "d"), np.array([0.0, math.pi / 2, math.pi, -math.pi / 2]), (),
                           np.random.default_rng(0))
    p = avoid.params
    hemmed = [0.1, np.inf, 0.12, np.inf]  # ahead and behind
    commands = [avoid(_observation(0.1 * k, None, 0.0, ir=hemmed)) for k in range(round(3 * p.turn_time / 0.1))]
    assert all(v == 0.0 for v, _ in commands)  # it never drives into either
    assert all(omega < 0 for _, omega in commands)  # dead ahead: it turns right, and keeps turning the same way
    v, omega = avoid(_observation(10.0, None, 0.0, ir=[0.1, np.inf, np.inf, np.inf]))  # ahead only: backs off
    assert v < 0 and omega == 0.0


def _fixes_while_asked(unstick, command, fix_at, seconds, rng, noise=0.0127, heading_noise=0.05):
    """Run ``unstick`` at the control rate with a positioning fix every 0.6 s; the commands it returns."""
    out = []
    for k in range(round(seconds / 0.1)):
        t = 0.1 * k
        x, y, heading = fix_at(0.6 * math.floor(t / 0.6))
        fix = PoseFix(x + rng.normal(0, noise), y + rng.normal(0, noise), heading + rng.normal(0, heading_noise),
                      0.6 * math.floor(t / 0.6))
        out.append(unstick(_observation(t, fix, 0.0), command))
    return out


def test_unstick_backs_off_with_the_lift_up_when_asked_to_move_but_the_fixes_stand_still():
    """The wheels lifted by the jaw on a puck (§3.8.4): asked to turn, the robot's fixes do not move."""
    p = DriveParams()
    unstick = Unstick(np.random.default_rng(1), p, escape_extras={"lift": 1.0})
    turn = Command(omega=p.turn_rate, behaviour="move-spill", extras={"grip": 0.0, "lift": 0.0})
    out = _fixes_while_asked(unstick, turn, lambda t: (3.1, 0.2, 0.5), p.stuck_window + 0.6 + 3.0,
                             np.random.default_rng(2))
    escaping = [k for k, c in enumerate(out) if c.v < 0]
    assert unstick.escapes == 1 and escaping
    assert p.stuck_window <= 0.1 * escaping[0] <= p.stuck_window + 0.7  # within a fix of the window
    first = out[escaping[0]]
    assert first.omega == 0.0 and first.extras == {"grip": 0.0, "lift": 1.0}  # lift up, the grip untouched
    assert first.behaviour == "move-spill"
    after = out[escaping[0] + round(p.unstick_back_time / 0.1) + 1]
    assert after.v == 0.0 and abs(after.omega) == p.turn_rate


@pytest.mark.parametrize("motion", ["drive", "turn"])
def test_unstick_leaves_a_robot_that_moves_alone(motion):
    """Driving at 0.3 m/s with 0.15 m fix noise, or turning on the spot at 1 rad/s: never stuck."""
    p = DriveParams()
    unstick = Unstick(np.random.default_rng(1), p)
    if motion == "drive":
        command, noise, fix_at = Command(v=0.3), 0.15, lambda t: (0.3 * t, 0.0, 0.0)
    else:
        command, noise, fix_at = Command(omega=1.0), 0.0127, lambda t: (0.0, 0.0, math.remainder(t, 2 * math.pi))
    out = _fixes_while_asked(unstick, command, fix_at, 60.0, np.random.default_rng(3), noise)
    assert unstick.escapes == 0 and all(c is command for c in out)


def test_unstick_ignores_standing_still_when_not_asked_to_move():
    """Grasping, lifting, creeping up on a puck at 6 cm/s: the robot stands (nearly) still on purpose."""
    p = DriveParams()
    for command in (Command(), Command(v=0.06, omega=0.3)):
        unstick = Unstick(np.random.default_rng(1), p)
        out = _fixes_while_asked(unstick, command, lambda t: (1.0, 1.0, 0.0), 30.0, np.random.default_rng(4))
        assert unstick.escapes == 0 and all(c is command for c in out)


class _Pose:
    """A perfect pose estimate, for driving a behaviour kinematically."""
    def __init__(self, x, y, heading):
        self.pose = np.array([x, y, heading], float)

    def drive(self, command, dt: float = 0.1) -> None:
        """Follow ``command`` for ``dt`` (unicycle, Euler step)."""
        x, y, heading = self.pose
        self.pose = np.array([x + command.v * dt * math.cos(heading), y + command.v * dt * math.sin(heading),
                              heading + command.omega * dt])


def _tip_range(pose, boxes, half_x=3.96, half_y=1.83, nose=0.2) -> float:
    """Distance from the jaw's front straight ahead to the first wall or box face (boxes: (x0, x1, y0, y1))."""
    x, y, heading = pose
    c, s = math.cos(heading), math.sin(heading)
    x, y = x + nose * c, y + nose * s
    hits = [((half_x if c > 0 else -half_x) - x) / c if abs(c) > 1e-9 else math.inf,
            ((half_y if s > 0 else -half_y) - y) / s if abs(s) > 1e-9 else math.inf]
    for x0, x1, y0, y1 in boxes:
        with np.errstate(divide="ignore", invalid="ignore"):
            tx = sorted(((x0 - x) / c, (x1 - x) / c)) if abs(c) > 1e-9 else ([-math.inf, math.inf] if x0 <= x <= x1
                                                                             else [math.inf, -math.inf])
            ty = sorted(((y0 - y) / s, (y1 - y) / s)) if abs(s) > 1e-9 else ([-math.inf, math.inf] if y0 <= y <= y1
                                                                             else [math.inf, -math.inf])
        near, far = max(tx[0], ty[0]), min(tx[1], ty[1])
        if near <= far and near >= 0:
            hits.append(near)
    return min(hits)


def _wander_east(boxes, seconds=90.0):
    """Run find-wander's east leg (leg 2) from where its north leg stops, by the west and north walls of the
    7.92 x 3.66 m room, already facing east, kinematically (0.1 s ticks, perfect pose), until the leg ends; the
    robot's track and the behaviour. ``boxes``: (x0, x1, y0, y1) each, or a function of the time and the pose
    estimate giving them (an obstacle that moves, and may push the robot)."""
    from teamsim.controllers.behaviours.cleanup import CleanupParams, FindWander
    from teamsim.models import build_robot

    robot = build_robot("r2", "blue")
    params = CleanupParams()
    estimate = _Pose(-3.5, 1.41, 0.0)
    knowledge = CleanupKnowledge(report_interval=240.0, home=np.array([-3.2, 0.0]))
    wander = FindWander(robot, knowledge, estimate, None, params)
    tips = [robot.ir_sensors.index(n) for n in ("ir_tip_left", "ir_tip_right")]

    def observe(time, ranges):
        return Observation(time=time, robot="blue", ir_raw=ranges, ir_range=ranges, ir_bearings=robot.ir_bearings,
                           pose=None)

    wander.leg = 2  # east
    track = []
    for tick in range(round(seconds / 0.1)):
        if wander.leg != 2:
            break
        ranges = np.full(len(robot.ir_sensors), np.inf)
        ranges[tips] = _tip_range(estimate.pose, boxes(tick * 0.1, estimate) if callable(boxes) else boxes)
        estimate.drive(wander(observe(tick * 0.1, ranges)))
        track.append(estimate.pose.copy())
    return np.array(track), wander


def test_find_wander_sidesteps_a_robot_in_its_way_but_stops_at_the_wall():
    """A switched-off teammate by the north wall (0.35 m across at x = 1) is passed with one sidestep to the
    right, so the east leg still reaches the far wall; without it the leg would end at x < 0.8."""
    teammate = (1.0, 1.35, 1.2, 1.83)
    track, wander = _wander_east([teammate])
    assert track[:, 0].max() > 3.4  # the far wall is at 3.96, the jaw 0.2 m ahead of the pose
    beside = track[(track[:, 0] > 0.9) & (track[:, 0] < 1.45), 1]
    assert beside.size and (beside < 1.2 - 0.1).all()  # it passed the teammate on its south side (right of east)
    assert (beside > 1.41 - 0.5 - 0.1).all()  # by one sidestep, not more
    # The leg ends at the wall (second sidestep spent, blocked again), not at the time limit.
    assert wander.leg == 3 and track[-1, 0] > 3.4 and len(track) < 600


def test_find_wander_does_not_take_a_teammate_that_pushes_it_back_for_the_wall():
    """A teammate that keeps in the robot's way, moving with its sidesteps and pushing it back west at 10 cm/s while
    they touch (red following blue's body as a wall in radio-off seed 217), blocks it further back each time: the
    leg goes on, and reaches the far wall once the teammate has gone (after 30 s), instead of ending at the third
    block and putting the room's east end at x < 0."""
    face = [0.3]

    def teammate(time, estimate):
        if time > 30.0:
            return []
        x, y, _ = estimate.pose
        if face[0] - (x + 0.2) < 0.22:  # touching the jaw: push
            face[0] -= 0.01
            estimate.pose[0] -= 0.01
        return [(face[0], face[0] + 0.35, y - 0.3, y + 0.3)]

    track, wander = _wander_east(teammate, seconds=150.0)
    assert face[0] < 0.3 - 1.0  # it did push the robot back, round several sidesteps
    assert wander.leg == 3 and track[-1, 0] > 3.4  # the leg ended at the far wall


def test_find_wander_boxed_in_by_a_teammate_beside_it_does_not_take_the_one_ahead_for_the_wall():
    """Dead red by the north wall ahead, and blue beside the robot on its right for 35 s (kill-red seed 191): every
    sidestep is blocked before it starts. Counted, two of them and one more block put the room's east end at red
    (x < 0.8, the goal 1.5 m short of the goal zone); now the first few do not count, and once blue has moved the
    robot passes red and reaches the far wall."""
    red = (1.0, 1.35, 1.2, 1.83)

    def world(time, estimate):
        return [red, (0.2, 0.9, 0.8, 1.15)] if time < 35.0 else [red]

    track, wander = _wander_east(world, seconds=150.0)
    assert wander.leg == 3 and track[-1, 0] > 3.4


def test_find_wander_held_back_by_a_teammate_still_reaches_the_wall():
    """A teammate pressing against the robot's side (red following blue's body as its wall, radio-off seed 121)
    holds it to a tenth of its speed for 70 s while it drives unblocked: the leg is measured in progress along
    its heading, not in time driving, so it reaches the far wall instead of ending near x = -2.6 after 30 s."""
    def teammate(time, estimate):
        if time < 70.0 and abs(estimate.pose[2]) < 0.1:  # driving east: held back to 3 cm/s
            estimate.pose[0] -= 0.027
        return []

    track, wander = _wander_east(teammate, seconds=150.0)
    assert track[(np.arange(len(track)) * 0.1) < 70.0, 0].max() < -1.0  # it was held back
    assert wander.leg == 3 and track[-1, 0] > 3.4  # the leg ended at the far wall


def test_find_wander_without_obstacles_drives_the_leg_straight_to_the_wall():
    track, _ = _wander_east([])
    assert track[:, 0].max() > 3.4
    on_the_way = track[track[:, 0] < 3.3]
    assert np.abs(on_the_way[:, 1] - 1.41).max() < 1e-6  # no sidestep before the wall: nothing was in the way


def test_sweep_lines_aim_inside_the_room_and_away_from_the_goal():
    """Widened past the room's width (24 empty lines: 4.2 m), the search area is mostly beyond the walls; every
    line's point is still drawn inside the extents the finder reached and out of the delivered pucks' way."""
    from teamsim.controllers.behaviours.cleanup import CleanupParams, MoveSpill
    from teamsim.models import build_robot

    params = CleanupParams()
    found = locations_from_extents(np.array([-3.7, 3.7, -1.6, 1.6]), np.array([-3.2, 0.0]), params.goal_clearance)
    knowledge = CleanupKnowledge(report_interval=240.0, home=np.array([-3.2, 0.0]))
    knowledge.learn_locations(found)
    estimate = _Pose(*found["spill"], 0.0)
    spill = MoveSpill(build_robot("r2", "blue"), np.random.default_rng(5), knowledge, estimate, None, params)
    spill.empty_lines = 24
    points = []
    for _ in range(300):
        heading, length, _ = spill._new_line()
        reach = length - params.sweep_overshoot
        points.append(estimate.pose[:2] + reach * np.array([math.cos(heading), math.sin(heading)]))
    points = np.array(points)
    assert (np.abs(points[:, 0]) <= 3.7 + 1e-9).all() and (np.abs(points[:, 1]) <= 1.6 + 1e-9).all()
    assert (np.hypot(*(points - np.array(found["goal"])).T) > params.goal_keepout).all()
    assert np.hypot(*(points - np.array(found["spill"])).T).max() > 3.0  # and the search does reach down the room


def test_find_methodical_pushed_off_the_wall_seeks_it_again_to_its_right():
    """Red following the north wall westwards (wall on its right) is pushed 0.45 m off it: its side IR (0.3 m)
    loses the wall. It curves right for ``wall_lost_time``, then drives north (right of west, where the wall was),
    follows the wall round the corner and concludes back home; with only the curve it circled on the spot
    (radio-off seed 3, 1800 s)."""
    from teamsim.controllers.behaviours.cleanup import CleanupParams, FindMethodical
    from teamsim.models import build_robot
    from teamsim.models.r2 import R2Dims

    robot = build_robot("r2", "red")
    params = CleanupParams()
    estimate = _Pose(0.0, 1.83 - 0.15 - 0.45, math.pi)
    knowledge = CleanupKnowledge(report_interval=240.0, home=np.array([-3.2, -0.6]))
    methodical = FindMethodical(robot, knowledge, estimate, None, params)
    methodical.found_wall, methodical.far_from_home = True, True
    tips = [robot.ir_sensors.index(n) for n in ("ir_tip_left", "ir_tip_right")]
    side = [robot.ir_sensors.index(n) for n in ("ir_right_front", "ir_right_rear")]
    track = []
    for tick in range(round(40.0 / 0.1)):
        ranges = np.full(len(robot.ir_sensors), np.inf)
        ranges[tips] = _tip_range(estimate.pose, [])
        x, y, heading = estimate.pose
        to_side = _tip_range((x, y, heading - math.pi / 2), [], nose=R2Dims().width / 2)
        ranges[side] = to_side if to_side <= R2Dims().ir_range else np.inf
        command = methodical(Observation(time=tick * 0.1, robot="red", ir_raw=ranges, ir_range=ranges,
                                         ir_bearings=robot.ir_bearings, pose=None))
        estimate.drive(command)
        track.append(estimate.pose.copy())
    track = np.array(track)
    circling = track[: round(params.wall_lost_time / 0.1)]
    assert np.ptp(circling[:, 1]) < 0.4  # the lost-wall curve alone stays put
    back = track[round(params.wall_lost_time / 0.1):]
    assert back[:, 1].max() > 1.83 - 0.127 - 0.3  # back within side-IR range of the north wall
    assert back[:, 0].min() < -3.4  # followed it west to the corner and on round it
    assert knowledge.located  # and closed the loop at home
