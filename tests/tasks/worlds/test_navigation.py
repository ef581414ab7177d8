"""Unit tests for Chand's random navigation worlds (§3.6.2): reproducibility, density, clear start and goal,
even spread, the occupancy raster, ideal IR ranges and the kinematic runner."""
from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from teamsim.controllers.base import Command
from teamsim.models.arenas import Box
from teamsim.models.robot import DriveLimits
from teamsim.scenario import Obstacle
from teamsim.tasks.worlds.navigation import (DENSITIES, KinematicRobot, NavWorldParams, cell_centres, clearance,
                                             covered_cells, has_passage, kinematic_run, random_world, ray_ranges)

PARAMS = NavWorldParams()


def world(density=0.10, seed=0):
    return random_world(density, np.random.default_rng(seed))


def test_same_seed_same_world_and_different_seed_different_world():
    a, b, c = world(seed=7), world(seed=7), world(seed=8)
    assert a.boxes == b.boxes
    np.testing.assert_array_equal(a.occupancy, b.occupancy)
    assert a.boxes != c.boxes


@pytest.mark.parametrize("density", DENSITIES)
def test_density_within_one_percent(density):
    for seed in range(10):
        assert world(density, seed).density == pytest.approx(density, abs=0.01)


def test_boxes_are_arena_boxes_inside_the_world():
    w = world(0.20, 3)
    half = w.size / 2
    for box in w.boxes:
        assert isinstance(box, Box)
        assert PARAMS.half_size_range[0] <= box.half_x <= PARAMS.half_size_range[1]
        assert abs(box.x) + box.half_x <= half and abs(box.y) + box.half_y <= half


@pytest.mark.parametrize("density", [0.05, 0.20])
def test_obstacles_overlap_or_keep_the_minimum_gap_and_keep_it_from_the_walls(density):
    gaps = []
    for seed in range(5):
        w = world(density, seed)
        for k, a in enumerate(w.boxes):
            assert w.size / 2 - max(abs(a.x) + a.half_x, abs(a.y) + a.half_y) >= PARAMS.min_gap - 1e-9
            gaps += [math.hypot(max(abs(a.x - b.x) - a.half_x - b.half_x, 0.0),
                                max(abs(a.y - b.y) - a.half_y - b.half_y, 0.0)) for b in w.boxes[k + 1:]]
    gaps = np.array(gaps)
    assert np.all((gaps == 0.0) | (gaps >= PARAMS.min_gap - 1e-9))
    assert np.any(gaps >= PARAMS.min_gap)


def test_every_world_has_a_passage_for_robot_c():
    """Checked apart from ``has_passage``'s raster: exact clearance on a 5 cm lattice, flood-filled."""
    for density in (0.15, 0.20):
        for seed in range(3):
            w = world(density, seed)
            ticks = np.arange(-w.size / 2, w.size / 2, 0.05) + 0.025
            x, y = np.meshgrid(ticks, ticks)
            free = w.size / 2 - np.maximum(np.abs(x), np.abs(y)) >= 0.67
            for b in w.boxes:
                gap = np.hypot(np.maximum(np.abs(x - b.x) - b.half_x, 0), np.maximum(np.abs(y - b.y) - b.half_y, 0))
                free &= gap >= 0.67
            _, label = cv2.connectedComponents(free.astype(np.uint8), connectivity=8)
            at = lambda p: label[np.argmin(np.abs(ticks - p[1])), np.argmin(np.abs(ticks - p[0]))]
            assert at(w.start) != 0 and at(w.start) == at(w.goal)


def test_has_passage_by_hand():
    """A wall of two boxes across the world, leaving a 1.2 m gap in the middle: wide enough for a 0.4 m circle
    (the check keeps up to two cells in hand), not for a 0.67 m one."""
    wall = empty_world(Box(0.0, 4.05, 0.5, 3.45), Box(0.0, -4.05, 0.5, 3.45))
    centres = cell_centres(wall.size, wall.resolution)
    occupancy = np.zeros_like(wall.occupancy)
    for box in wall.boxes:
        occupancy |= covered_cells(Obstacle("box", box.x, box.y, box.half_x, box.half_y), centres)
    wall = type(wall)(wall.boxes, occupancy, wall.origin, wall.resolution, wall.size, wall.start, wall.goal)
    assert has_passage(wall, 0.4)
    assert not has_passage(wall, 0.67)
    closed = type(wall)(wall.boxes, occupancy | (np.abs(centres)[None, :] <= 0.5), wall.origin, wall.resolution,
                        wall.size, wall.start, wall.goal)
    assert not has_passage(closed, 0.1)


def test_start_and_goal_are_clear_corners():
    for seed in range(10):
        w = world(0.20, seed)
        x, y, heading = w.start
        assert (x, y) == (-7.5 + PARAMS.corner_margin, 7.5 - PARAMS.corner_margin)  # top left
        assert w.goal == (7.5 - PARAMS.corner_margin, -7.5 + PARAMS.corner_margin)  # bottom right
        assert heading == pytest.approx(-math.pi / 4)
        assert clearance(w, x, y) >= min(PARAMS.clear_radius, PARAMS.corner_margin)
        assert clearance(w, *w.goal) >= min(PARAMS.clear_radius, PARAMS.corner_margin)
        rows, cols = w.known_map().world_to_cell(np.array([x, w.goal[0]]), np.array([y, w.goal[1]]))
        assert not w.occupancy[rows, cols].any()


def test_occupancy_is_the_raster_of_the_boxes():
    w = world(0.15, 4)
    grid = w.known_map()
    rows, cols = np.indices(w.occupancy.shape)
    x, y = grid.cell_to_world(rows, cols)
    inside = np.zeros(w.occupancy.shape, int)
    for box in w.boxes:
        inside += (np.abs(x - box.x) <= box.half_x) & (np.abs(y - box.y) <= box.half_y)
    np.testing.assert_array_equal(w.occupancy, inside >= 1)


def test_obstacles_are_spread_over_the_whole_world():
    for seed in range(10):
        blocks = world(0.20, seed).occupancy.reshape(3, 50, 3, 50).mean(axis=(1, 3))  # 5 m x 5 m blocks
        assert blocks.min() > 0.0 and blocks.max() < 0.5


def test_known_and_unexplored_maps():
    w = world()
    known, unexplored = w.known_map(), w.unexplored_map()
    assert known.shape == unexplored.shape == (150, 150)
    assert set(np.unique(known.probabilities)) == {0.05, 0.95}
    assert np.all(unexplored.probabilities == 0.5)


# ---------------------------------------------------------------- ray casting and the kinematic runner


def empty_world(*boxes):
    w = world(0.05, 0)
    return type(w)(tuple(boxes), w.occupancy, w.origin, w.resolution, w.size, w.start, w.goal)


def test_ray_ranges_by_hand():
    w = empty_world(Box(2.0, 0.0, 0.5, 0.5))
    origins = np.zeros((4, 2))
    directions = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [math.sqrt(0.5), math.sqrt(0.5)]])
    ranges = ray_ranges(w, origins, directions, max_range=12.0)
    np.testing.assert_allclose(ranges, [1.5, 7.5, 7.5, 7.5 * math.sqrt(2)])
    np.testing.assert_array_equal(ray_ranges(w, origins, directions, max_range=10.0)[[0, 3]], [1.5, np.inf])


def test_clearance_by_hand():
    w = empty_world(Box(2.0, 0.0, 0.5, 0.5))
    assert clearance(w, 0.0, 0.0) == pytest.approx(1.5)
    assert clearance(w, 3.0, 1.0) == pytest.approx(math.hypot(0.5, 0.5))
    assert clearance(w, 7.0, 5.0) == pytest.approx(0.5)  # the east wall


class Constant:
    def __init__(self, v, omega):
        self.v, self.omega = v, omega

    def __call__(self, observation):
        return Command(v=self.v, omega=self.omega)


LIMITS = DriveLimits(0.5, math.pi / 7, 0.1, 0.15)


def test_kinematic_run_drives_straight_into_a_wall():
    w = empty_world()
    robot = KinematicRobot("diffdrive", LIMITS, radius=0.35, ir_count=10)
    run = kinematic_run(w, Constant(0.5, 0.0), robot, duration=60.0)
    assert run.collided and not run.reached
    # From the start, a margin below the north wall, heading -45 degrees, the circle meets the south and east
    # walls after 15 m - margin - 0.35 m of descent; the 5 s climb to 0.5 m/s costs 2.5 s.
    descent = 15.0 - PARAMS.corner_margin - 0.35
    assert run.time == pytest.approx(descent * math.sqrt(2) / 0.5 + 2.5, abs=0.2)


def test_kinematic_tricycle_turns_on_its_steering_circle():
    w = empty_world()
    robot = KinematicRobot("tricycle", LIMITS, radius=0.5, ir_count=11, centre_offset=0.25)
    # 0.5 m turning radius: the centre, 0.25 m ahead of the rear axle, circles at 0.56 m, so the robot sweeps
    # 1.06 m round a centre of rotation 1.15 m from the north wall.
    run = kinematic_run(w, Constant(0.1, 0.2), robot, duration=60.0)
    assert not run.collided and not run.reached
    assert run.time == pytest.approx(60.0)
    assert 0.0 < run.min_clearance < 0.2


def test_kinematic_run_that_stops_on_contact_halts_at_the_wall_and_counts_the_touches():
    w = empty_world()
    robot = KinematicRobot("diffdrive", LIMITS, radius=0.35, ir_count=10)
    run = kinematic_run(w, Constant(0.5, 0.0), robot, duration=60.0, on_contact="stop")
    assert not run.collided and not run.reached
    assert run.time == pytest.approx(60.0)
    assert run.min_clearance >= 0.0
    # It stopped where the next tick's motion would have touched: within one tick's travel of the walls, and the
    # path it travelled is the straight descent from the start to there.
    assert run.min_clearance < 0.5 * 0.1
    assert run.touches > 100
    assert run.travelled == pytest.approx(math.dist(w.start[:2], run.pose[:2]), rel=1e-6)
    x, y, _ = run.pose
    assert clearance(w, x, y) - 0.35 == pytest.approx(run.min_clearance)


class Recording(Constant):
    """Drives at a constant command and keeps the odometry each observation carries."""
    def __init__(self, v, omega):
        super().__init__(v, omega)
        self.velocities = []

    def __call__(self, observation):
        self.velocities.append(observation.velocity)
        return super().__call__(observation)


def test_kinematic_odometry_reads_the_motion_of_the_last_tick_and_zero_once_halted():
    robot = KinematicRobot("diffdrive", LIMITS, radius=0.35, ir_count=10)
    driver = Recording(0.5, 0.1)
    run = kinematic_run(empty_world(), driver, robot, duration=60.0, on_contact="stop")
    assert driver.velocities[0] == (0.0, 0.0)
    # Slewed at 0.1 m/s^2 and 0.15 rad/s^2 over 0.1 s ticks: the first tick moved at (0.01, 0.015).
    assert driver.velocities[1] == pytest.approx((0.01, 0.015))
    assert driver.velocities[20] == pytest.approx((0.2, 0.1))
    assert run.touches > 0 and driver.velocities[-1] == (0.0, 0.0)  # halted at a wall: the robot reads stopped


def test_kinematic_run_rejects_an_unknown_contact_rule():
    with pytest.raises(ValueError, match="on_contact='bounce': allowed: end, stop"):
        kinematic_run(empty_world(), Constant(0.0, 0.0), KinematicRobot("diffdrive", LIMITS, 0.35, 10), 1.0,
                      on_contact="bounce")
