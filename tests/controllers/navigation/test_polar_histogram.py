"""Unit tests for the direction sensor (Chand §3.4, eq. 3.9-3.10, Table 3.2)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from teamsim.controllers.navigation.polar_histogram import (DirectionSensorParams, candidate_directions,
                                                            direction_objective, modified_target_heading,
                                                            obstacle_distances, smooth, target_heading, wrap)

PARAMS = DirectionSensorParams()
STEP = 2 * math.pi / 41


def test_table_3_2():
    assert (PARAMS.alpha1, PARAMS.beta, PARAMS.max_distance, PARAMS.directions) == (0.5, 1.0, 1.5, 41)


def test_eq_3_9_target_heading_from_the_x_axis():
    assert target_heading(0, 0, 1, 1) == pytest.approx(math.pi / 4)
    assert target_heading(1, 1, 1, 3) == pytest.approx(math.pi / 2)
    assert target_heading(0, 0, -1, 0) == pytest.approx(-math.pi)  # normalised to [-pi, pi)
    assert target_heading(0, 0, 0, -2) == pytest.approx(-math.pi / 2)


def test_wrap_into_minus_pi_to_pi():
    np.testing.assert_allclose(wrap([math.pi, 3 * math.pi / 2, -3 * math.pi / 2, 0.1]),
                               [-math.pi, -math.pi / 2, math.pi / 2, 0.1])


def test_candidate_directions_are_even_from_straight_ahead():
    directions = candidate_directions(41)
    assert len(directions) == 41 and directions[0] == 0.0
    assert np.all((directions >= -math.pi) & (directions < math.pi))
    np.testing.assert_allclose(np.diff(np.sort(directions)), STEP)


def test_obstacle_distances_by_hand():
    directions = np.array([0.0, math.pi / 2, math.pi])
    # A point 1.0 m ahead, robot radius 0.5: the point robot enters its enlarged disc after 0.5 m.
    d = obstacle_distances(np.array([[1.0, 0.0]]), directions, robot_radius=0.5, max_distance=1.5)
    np.testing.assert_allclose(d, [0.5 + 0.5, 1.5, 1.5])
    # Off the ray by 0.3: enters the disc at 1.0 - sqrt(0.25 - 0.09) = 0.6.
    d = obstacle_distances(np.array([[1.0, 0.3]]), np.array([0.0]), robot_radius=0.5, max_distance=1.5)
    assert d[0] == pytest.approx(0.5 + 0.6)


def test_obstacle_distances_are_limited_to_r_m_and_d_obmax():
    directions = candidate_directions(41)
    touching = obstacle_distances(np.array([[0.4, 0.0]]), directions, robot_radius=0.5, max_distance=1.5)
    assert touching[0] == 0.5
    far = obstacle_distances(np.array([[5.0, 0.0]]), directions, robot_radius=0.5, max_distance=1.5)
    assert np.all(far == 1.5)
    assert np.all(obstacle_distances(np.zeros((0, 2)), directions, 0.5, 1.5) == 1.5)


def test_smooth_is_a_circular_weighted_average():
    d = np.array([1.0, 0.0, 0.0, 0.0, 2.0])
    np.testing.assert_allclose(smooth(d, (0.25, 0.5, 0.25)), [1.0, 0.25, 0.0, 0.5, 1.25])
    np.testing.assert_allclose(smooth(d, (1.0,)), d)


def test_eq_3_10_by_hand():
    directions = np.array([0.0, math.pi / 2, -math.pi])
    smoothed = np.array([1.5, 0.75, 0.5])
    scores = direction_objective(directions, target=0.0, smoothed=smoothed, params=PARAMS)
    np.testing.assert_allclose(scores, [0.5 * 1 + 1.0, 0.5 * 0.5 + 0.5, 0.5 * 0 + 1 / 3])


def test_open_space_heads_for_the_nearest_direction_to_the_target():
    assert modified_target_heading(np.zeros((0, 2)), 0.3, 0.5) == pytest.approx(2 * STEP)
    assert modified_target_heading(np.zeros((0, 2)), -2.0, 0.5) == pytest.approx(-13 * STEP)


def test_an_obstacle_ahead_turns_the_heading_away_from_it():
    wall = np.column_stack([np.full(9, 1.0), np.linspace(-0.4, 0.4, 9)])  # across the way, 1 m ahead
    heading = modified_target_heading(wall, 0.0, robot_radius=0.35)
    assert abs(heading) > 0.3
    distances = obstacle_distances(wall, np.array([heading]), 0.35, 1.5)
    assert distances[0] == 1.5  # the chosen direction is clear to the sensing range


def test_near_ties_keep_the_previous_side():
    wall = np.column_stack([np.full(9, 1.0), np.linspace(-0.4, 0.4, 9) + 0.01])  # a shade to the left
    free_choice = modified_target_heading(wall, 0.0, robot_radius=0.35)
    kept = modified_target_heading(wall, 0.0, robot_radius=0.35, previous=-free_choice)
    assert kept == pytest.approx(-free_choice)
    # A clearly better direction still wins over the previous one.
    assert modified_target_heading(np.zeros((0, 2)), 0.0, 0.35, previous=1.0) == 0.0


def test_the_compiled_choice_is_the_equations_composed_to_the_bit():
    rng = np.random.default_rng(5)
    for _ in range(600):
        count = int(rng.choice([8, 41, 72]))
        params = DirectionSensorParams(directions=count, alpha1=rng.uniform(0.1, 1.0), beta=rng.uniform(0.1, 2.0),
                                       tie_tolerance=float(rng.choice([0.02, 0.5])))
        points = rng.uniform(-2.0, 2.0, (int(rng.integers(0, 40)), 2))
        halfway = math.pi * (2 * int(rng.integers(count)) + 1) / count  # equally far from two directions
        target, previous = rng.uniform(-math.pi, math.pi), rng.choice([None, rng.uniform(-math.pi, math.pi), halfway])
        directions = candidate_directions(params.directions)
        distances = obstacle_distances(points, directions, 0.35, params.max_distance)
        scores = direction_objective(directions, target, smooth(distances, params.smoothing), params)
        if previous is None:
            expected = directions[np.argmax(scores)]
        else:
            ties = np.flatnonzero(scores >= scores.max() - params.tie_tolerance)
            expected = directions[ties[np.argmin(np.abs(wrap(directions[ties] - previous)))]]
        assert modified_target_heading(points, target, 0.35, params, previous) == expected


def test_wrap_of_one_angle_is_the_array_form_to_the_bit():
    angles = np.concatenate([np.random.default_rng(2).uniform(-20, 20, 2000),
                             [math.pi, -math.pi, 3 * math.pi, 0.0, -0.0, 2 * math.pi, 1e-300]])
    one_by_one = np.array([wrap(float(a)) for a in angles])
    assert np.array_equal(one_by_one, wrap(angles)) and np.array_equal(np.signbit(one_by_one), np.signbit(wrap(angles)))
