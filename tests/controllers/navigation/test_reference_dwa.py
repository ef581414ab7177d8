"""The plain reference dynamic window (``teamsim.controllers.navigation.reference_dwa``), the yardstick of ``bench
nav``: on decisions recorded from FRC driving Robots A and B through random 10 % worlds it chooses the same command as
``DynamicWindow.decide``, on every branch of the selection logic."""
from __future__ import annotations

import math

import numpy as np
import pytest

from teamsim.controllers.navigation.dynamic_window import FRC, DriveState, DynamicWindow, Method
from teamsim.controllers.navigation.reference_dwa import reference_decide
from teamsim.models.robot import DriveLimits
from teamsim.tasks.worlds.navigation import KinematicRobot, kinematic_run, random_world

LIMITS = DriveLimits(v_max=0.5, omega_max=math.pi / 7, accel_max=0.1, angular_accel_max=0.15)  # Tables 3.1, 3.4
ROBOTS = {
    "tricycle": KinematicRobot("tricycle", LIMITS, radius=0.5, ir_count=11, centre_offset=0.25),
    "differential": KinematicRobot("diffdrive", LIMITS, radius=0.35, ir_count=10),
}


def window_of(robot: KinematicRobot) -> DynamicWindow:
    return DynamicWindow(robot.limits, robot.kind, robot.radius, centre_offset=robot.centre_offset)


def recorded_decisions(robot: KinematicRobot, seeds=(0, 1), duration: float = 40.0) -> list:
    """The arguments of every dynamic-window decision FRC made driving ``robot`` through random 10 % worlds."""
    record = []
    for seed in seeds:
        world = random_world(0.1, np.random.default_rng(seed))
        controller = FRC(robot.limits, robot.kind, robot.radius, world.goal, centre_offset=robot.centre_offset)
        decide = controller.window.decide

        def recorded(*args, decide=decide, **kwargs):
            record.append((args, kwargs))
            return decide(*args, **kwargs)

        controller.window.decide = recorded
        kinematic_run(world, controller, robot, duration)
    return record


@pytest.fixture(scope="module", params=sorted(ROBOTS))
def recorded(request):
    robot = ROBOTS[request.param]
    return robot, recorded_decisions(robot)


def test_reference_chooses_frcs_command_on_recorded_observations(recorded):
    robot, decisions = recorded
    window = window_of(robot)
    branches, differ = {}, []
    for args, kwargs in decisions:
        frc = window.decide(*args, **kwargs)
        v, omega, branch, v_min = reference_decide(window, *args, **kwargs)
        branches[frc.branch] = branches.get(frc.branch, 0) + 1
        if not (abs(v - frc.v) <= 1e-9 and abs(omega - frc.omega) <= 1e-9 and branch == frc.branch
                and v_min == frc.v_min):
            differ.append((frc, (v, omega, branch, v_min)))
    # The recordings are not trivial: obstacles were seen, and FRC moved and took more than its primary branch.
    assert len(decisions) > 200
    assert sum(args[1].shape[0] > 0 for args, _ in decisions) > 100
    assert {"primary", "secondary"} <= set(branches), branches
    assert not differ, f"{len(differ)} of {len(decisions)} decisions differ, e.g. {differ[:3]}"


def random_scene(rng: np.random.Generator):
    """decide's arguments, drawn at random: a drive state (standing still one time in five), up to 60 obstacle
    points within 2.5 m, a target heading, a goal distance, the previous v_min."""
    state = DriveState(float(rng.uniform(-0.5, 0.5)) * (rng.random() < 0.8), float(rng.uniform(-0.3, 0.3)),
                       float(rng.uniform(-0.8, 0.8)))
    points = rng.uniform(-2.5, 2.5, size=(int(rng.integers(0, 60)), 2))
    return state, points, float(rng.uniform(-math.pi, math.pi)), float(rng.uniform(0.2, 10.0)), \
        float(rng.choice([0.0, -0.5]))


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_reference_matches_frc_on_every_branch_in_random_scenes(name):
    """Random scenes reach the fallbacks (secondary objective, average curvature, steer, brake) far more often than
    driving does, for both drives."""
    window = window_of(ROBOTS[name])
    rng = np.random.default_rng(7)
    branches = set()
    for _ in range(400):
        args = random_scene(rng)
        frc = window.decide(*args)
        v, omega, branch, v_min = reference_decide(window, *args)
        branches.add(frc.branch)
        assert (v, omega, branch, v_min) == pytest.approx((frc.v, frc.omega, frc.branch, frc.v_min), abs=1e-9), args
    # A differential drive never reaches the average-curvature fallback: whenever its window holds v = 0 a stop
    # or a point turn about its centre is admissible (it sweeps nothing), and otherwise the fallback's velocity,
    # the same as the secondary search's, moves its centre straight towards what made that search fail.
    # A standing tricycle that can neither move on nor back away turns its wheel ("steer").
    expected = {"primary", "secondary", "brake"} | ({"curvature", "steer"} if name == "tricycle" else set())
    assert branches == expected


def test_reference_is_not_blind():
    """A wall just ahead changes the reference's choice, as it changes FRC's: the comparison above can fail."""
    window = window_of(ROBOTS["differential"])
    state = DriveState(0.3, 0.0)
    free = reference_decide(window, state, np.zeros((0, 2)), 0.0, 8.0)
    wall = np.column_stack([np.full(21, 0.8), np.linspace(-1.0, 1.0, 21)])
    blocked = reference_decide(window, state, wall, 0.0, 8.0)
    assert free[:2] == pytest.approx((0.31, 0.0))
    assert blocked[0] < free[0] - 0.01


def test_reference_covers_frc_only():
    window = DynamicWindow(LIMITS, "differential", 0.35, method=Method.ODW)
    with pytest.raises(ValueError):
        reference_decide(window, DriveState(), np.zeros((0, 2)), 0.0, 8.0)
