"""The explorer (Chand §6.2): persistent poor progress on the way (a new path, then a new environment), an
inaccessible waypoint skipped, and the bog rules: a wheeled explorer reports, backs out, resets what it mapped
inside the bog and asks for a dry environment; a tracked one reports and drives on. Driven tick by tick with
hand-made observations: the pose is whatever the test says, so the robot is stuck or bogged exactly when wanted."""
from __future__ import annotations

import math

import numpy as np

from teamsim.controllers.base import Observation
from teamsim.controllers.exploration.explorer import Explorer
from teamsim.controllers.exploration.territory import Territory
from teamsim.controllers.navigation.dynamic_window import HRDU
from teamsim.models.robot import DriveLimits
from teamsim.positioning import PoseFix

LIMITS = DriveLimits(v_max=0.4, omega_max=math.pi / 7, accel_max=0.2, angular_accel_max=0.3)
BEARINGS = np.linspace(-math.pi, math.pi, 12, endpoint=False)
TICK = 0.1


def explorer(bog_capable: bool) -> Explorer:
    territory = Territory(19.2, 0.3, 2)  # four environments of 9.6 m; 0 is south-west, 1 south-east
    navigator = HRDU(LIMITS, "diffdrive", 0.35, (0.0, 0.0), grid=territory.unexplored_map())
    return Explorer("Robot2", territory, navigator, manager="Robot3", bog_capable=bog_capable, radius=0.35)


def observe(time: float, pose, velocity=(0.0, 0.0), effort=0.0) -> Observation:
    ranges = np.full(len(BEARINGS), np.inf)  # nothing in sight: the ring maps free space round the robot
    return Observation(time=time, robot="Robot2", ir_raw=ranges, ir_range=ranges, ir_bearings=BEARINGS,
                       pose=PoseFix(*pose, time), velocity=velocity, drive_effort=effort)


def sent(robot: Explorer, kind: str) -> list[dict]:
    return [p.payload for p in robot.outbox if p.kind == kind]


def assigned(robot: Explorer, environment: int, start=(-7.0, -4.8, 0.0)) -> float:
    """The robot asks at ``start``, then gets the planner's straight path to ``environment``'s centre; returns the
    time."""
    robot.step(observe(0.0, start))
    assert sent(robot, "request")[0]["kind"] == "environment" and robot.state == "wait"
    robot.receive("plan", {"environment": environment, "path": np.array([start[:2], robot.territory.centre(
        environment)])}, 100)
    assert robot.state == "travel"
    return TICK


def test_persistent_poor_progress_on_the_way_asks_for_a_new_path_then_a_new_environment():
    robot = explorer(bog_capable=False)
    give_up = robot.params.give_up
    t = assigned(robot, 1)
    stand = (-7.0, -4.8, 0.0)
    while t < give_up - 1.0:  # standing still, not yet persistent
        robot.step(observe(t, stand))
        t += TICK
    assert robot.state == "travel" and len(sent(robot, "request")) == 1
    while robot.state == "travel":
        robot.step(observe(t, stand))
        t += TICK
    first = sent(robot, "request")[-1]
    assert first["kind"] == "path" and first["give_up"] == 1 and t < give_up + 1.0
    robot.receive("plan", {"environment": 1, "path": np.array([stand[:2], robot.territory.centre(1)])}, 100)
    start = t
    while robot.state == "travel":
        robot.step(observe(t, stand))
        t += TICK
    second = sent(robot, "request")[-1]
    assert second["kind"] == "environment" and second["give_up"] == 1
    assert t - start >= give_up - TICK  # the second request waited its own give-up time


def test_an_inaccessible_or_occupied_waypoint_is_skipped():
    robot = explorer(bog_capable=False)
    centre = robot.territory.centre(0)
    robot.step(observe(0.0, (*centre, 0.0)))  # a request
    robot.receive("plan", {"environment": 0, "path": np.zeros((0, 2))}, 0)
    robot.step(observe(TICK, (*centre, 0.0)))  # at the centre: arrived, the coverage waypoints are made
    assert robot.state == "explore" and robot.waypoints
    goal, rest = robot.nav.goal, list(robot.waypoints)
    t = 2 * TICK
    while robot.nav.goal == goal:  # no progress towards it: after ``give_up`` s it is given up
        robot.step(observe(t, (*centre, 0.0)))
        t += TICK
    assert robot.params.give_up - TICK <= t <= robot.params.give_up + 1.0
    assert robot.nav.goal == rest[0] and robot.waypoints == rest[1:]
    row, col = robot.territory.cell_of(*rest[1])  # the next one turns out to lie in an obstacle
    robot.nav.grid.probabilities[row, col] = 0.95
    robot._next_waypoint(t)
    assert robot.nav.goal == rest[2] and robot.waypoints == rest[3:]


def drive_into_bog(robot: Explorer, t: float, x_bog: float = -5.0) -> tuple[float, float]:
    """East along y = -4.8 at 0.3 m/s to ``x_bog``, then creeping at 0.01 m/s with high effort (a bog) until the
    explorer reacts; returns (time, x)."""
    x = -7.0
    while robot.state == "travel":
        boggy = x >= x_bog
        speed = 0.01 if boggy else 0.3
        robot.step(observe(t, (x, -4.8, 0.0), velocity=(speed, 0.0), effort=0.6 if boggy else 0.05))
        x += speed * TICK
        t += TICK
        if t > 30.0 or sent(robot, "bog"):
            break
    return t, x


def test_a_wheeled_explorer_backs_out_of_a_bog_resets_what_it_mapped_in_it_and_asks_for_a_dry_environment():
    robot = explorer(bog_capable=False)
    t, x = drive_into_bog(robot, assigned(robot, 1))
    report = sent(robot, "bog")
    assert report and report[0]["environment"] == 0 and robot.state == "back-out"
    target = robot.bog.first_node
    assert math.dist(target, (x - robot.params.back_out_distance, -4.8)) < 0.3  # its own trail, 2 m back
    v, omega, behaviour = robot.step(observe(t, (x, -4.8, 0.0), velocity=(0.01, 0.0), effort=0.6))
    assert v < 0 and behaviour == "explorer: back out of bog"
    mapped_in_bog = list(robot.bog.mapped_from)
    robot.step(observe(t + TICK, (*target, 0.0), velocity=(-0.2, 0.0)))  # out, at the point before the bog
    reset = sent(robot, "reset")[0]
    assert len(reset["rows"]) > 0
    assert np.all(robot.nav.grid.probabilities[reset["rows"], reset["cols"]] == 0.5)
    for bx, by in mapped_in_bog:  # every cell round where it stood in the bog is unexplored again
        assert robot.territory.cell_of(bx, by) in set(zip(reset["rows"].tolist(), reset["cols"].tolist()))
    request = sent(robot, "request")[-1]
    assert request == {"kind": "environment", "position": mapped_in_bog[-1], "bog_capable": False, "give_up": 1,
                       "bog": True}
    assert robot.state == "wait" and robot.assignment is None


def test_the_bog_sign_takes_bog_time_of_slow_hard_driving():
    robot = explorer(bog_capable=False)
    t = assigned(robot, 1)
    start = None
    x = -7.0
    while not sent(robot, "bog"):
        robot.step(observe(t, (x, -4.8, 0.0), velocity=(0.01, 0.0), effort=0.6))
        start = t if start is None else start
        x += 0.001
        t += TICK
    assert abs((t - TICK) - start - robot.params.bog_time) < TICK + 1e-9
    # hard driving while turning (a skid turn) or while stalled (v = 0, against a box) is no bog
    for velocity in ((0.01, 0.3), (0.0, 0.0)):
        other = explorer(bog_capable=False)
        t = assigned(other, 1)
        for _ in range(40):
            other.step(observe(t, (-7.0, -4.8, 0.0), velocity=velocity, effort=0.6))
            t += TICK
        assert not sent(other, "bog") and other.state == "travel"


def test_a_tracked_explorer_reports_a_bog_and_drives_on():
    robot = explorer(bog_capable=True)
    t, x = drive_into_bog(robot, assigned(robot, 1))
    assert sent(robot, "bog")[0]["environment"] == 0
    v, omega, behaviour = robot.step(observe(t, (x, -4.8, 0.0), velocity=(0.01, 0.0), effort=0.6))
    assert robot.state == "travel" and behaviour == "explorer: travel E1" and v >= 0.0
    assert not sent(robot, "reset") and len(sent(robot, "request")) == 1


def test_inside_its_environment_an_explorer_whose_centre_is_out_of_reach_starts_covering_from_where_it_is():
    """The centre mapped occupied (a box on it, a robot standing there): coverage starts at once inside the
    environment, not outside it. Stuck inside for ``give_up`` s (the centre cannot be reached): coverage starts
    then, with no request; stuck outside, a new path is asked for (the first test)."""
    for blocked in (True, False):
        robot = explorer(bog_capable=False)
        centre = robot.territory.centre(0)
        if blocked:
            row, col = robot.territory.cell_of(*centre)
            robot.nav.grid.probabilities[row, col] = 0.95
        outside = (centre[0] + 5.5, centre[1], math.pi)  # in environment 1, east of 0
        t = assigned(robot, 0, start=outside)
        robot.step(observe(t, outside))
        assert robot.state == "travel"
        inside = (centre[0] + 3.0, centre[1], math.pi)
        t += TICK
        while robot.state == "travel" and t < 2 * robot.params.give_up:
            robot.step(observe(t, inside))
            t += TICK
        assert robot.state == "explore" and robot.waypoints is not None
        assert len(sent(robot, "request")) == 1  # only the first, for an environment
        if blocked:
            assert t < 4 * TICK  # the first tick inside
        else:
            assert robot.params.give_up - TICK <= t <= robot.params.give_up + 1.0


def test_a_wheeled_explorer_that_crept_into_the_bog_backs_out_until_the_ground_is_firm():
    """The point 2 m from where the bog slowed it is still in the bog (it crept along inside before the sign held):
    there, reversing slowly at high effort, it goes on straight back; it stops at the first reading of firm ground,
    wherever that is. Firm: 0.05 effort at 0.2 m/s (v_max 0.4: 0.1 per unit of speed); boggy: 0.3 at 0.08 m/s."""
    robot = explorer(bog_capable=False)
    t, x = drive_into_bog(robot, assigned(robot, 1))
    target = robot.bog.first_node
    v, omega, behaviour = robot.step(observe(t, (*target, 0.3), velocity=(-0.08, 0.0), effort=0.3))  # still boggy
    assert robot.state == "back-out" and not sent(robot, "reset")
    assert v < 0 and omega == 0.0 and behaviour == "explorer: back out of bog"  # straight back
    further = (target[0] - 1.0, target[1], 0.3)  # beyond reach of the target
    v, omega, _ = robot.step(observe(t + TICK, further, velocity=(-0.08, 0.0), effort=0.3))
    assert v < 0 and omega == 0.0 and robot.state == "back-out"
    robot.step(observe(t + 2 * TICK, further, velocity=(-0.2, 0.0), effort=0.05))  # firm: out, here
    assert robot.state == "wait" and sent(robot, "reset") and sent(robot, "request")[-1]["bog"]


def test_a_wheeled_explorer_backs_out_to_the_point_of_its_trail_2_m_from_where_the_bog_slowed_it():
    """A trail that wiggled just before the bog: 2 m of it reach back only 1 m from where the bog slowed it; the
    target is the latest trail point 2 m away as the crow flies."""
    robot = explorer(bog_capable=False)
    legs = [((-10.0, -4.8), (-8.0, -4.8)), ((-8.0, -4.8), (-8.0, -4.3)), ((-8.0, -4.3), (-7.5, -4.3)),
            ((-7.5, -4.3), (-7.5, -4.8)), ((-7.5, -4.8), (-7.2, -4.8))]
    t = 0.0
    for (x0, y0), (x1, y1) in legs:
        for k in range(round(math.dist((x0, y0), (x1, y1)) / 0.05)):
            share = k * 0.05 / math.dist((x0, y0), (x1, y1))
            robot.trail.append((t, x0 + share * (x1 - x0), y0 + share * (y1 - y0)))
            t += TICK
    robot.trail.append((t, -7.2, -4.8))  # slowed here
    target = robot._before_bog(t, (-7.19, -4.8, 0.0))
    assert math.dist(target, (-9.2, -4.8)) < 0.06


def test_a_wheeled_explorer_s_own_plans_keep_out_of_the_bog_it_met():
    """Backed out of a bog met going east at x, its next travel's own re-plans (HRDU on its own map) keep out of
    the disc 3 m ahead of that spot, not of the cells round where it stands; a tracked explorer keeps out of
    nothing."""
    for bog_capable in (False, True):
        robot = explorer(bog_capable=bog_capable)
        t, x = drive_into_bog(robot, assigned(robot, 1))
        if not bog_capable:
            target = robot.bog.first_node
            robot.step(observe(t, (*target, 0.0), velocity=(-0.2, 0.0)))  # out, on firm ground
            assert robot.state == "wait"
        robot.receive("plan", {"environment": 1, "path": np.array([robot.trail[-1][1:], robot.territory.centre(1)])},
                      100)
        keep_out = robot.nav.keep_out
        if bog_capable:
            assert keep_out is None
            continue
        here = robot.nav.grid.world_to_cell(*robot.trail[-1][1:])
        ahead = robot.nav.grid.world_to_cell(x + 3.0, -4.8)
        assert keep_out[ahead] and not keep_out[here]


def test_a_finished_explorer_woken_by_the_manager_asks_again():
    robot = explorer(bog_capable=False)
    robot.step(observe(0.0, (-7.0, -4.8, 0.0)))
    robot.receive("finished", {"why": "no environment for it"}, 20)
    robot.outbox.clear()
    robot.step(observe(TICK, (-7.0, -4.8, 0.0)))
    assert robot.state == "finished" and not sent(robot, "request")
    robot.receive("wake", {"environment": 3}, 20)
    robot.step(observe(2 * TICK, (-7.0, -4.8, 0.0)))
    assert robot.state == "wait" and sent(robot, "request")[0]["kind"] == "environment"
