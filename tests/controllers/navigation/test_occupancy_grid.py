"""Unit tests for the occupancy grid (Chand §3.2.1, §6.2.2, eq. 6.3-6.5): frames, the sensor model, Bayes'
rule, clamping and the IR beam update."""
from __future__ import annotations

import math

import numpy as np
import pytest

from teamsim.controllers.navigation.occupancy_grid import (MappingParams, OccupancyGrid, bayes_update,
                                                           p_free_given_free, p_occupied_given_occupied, sensor_noise)

PARAMS = MappingParams()


def grid(resolution=0.1, shape=(60, 60), origin=(-3.05, -3.05)):
    """Cells centred on multiples of the resolution, so beams along the axes run through cell centres."""
    return OccupancyGrid.unexplored(origin, resolution, shape)


# ---------------------------------------------------------------- frames and initial values


def test_unexplored_cells_are_one_half_and_known_map_is_clamped():
    assert np.all(grid().probabilities == 0.5)
    known = OccupancyGrid.known((0, 0), 0.1, np.array([[True, False]]))
    np.testing.assert_array_equal(known.probabilities, [[0.95, 0.05]])


def test_world_to_cell_by_hand():
    g = grid()  # origin (-3.05, -3.05), 0.1 m cells: x = 0.22 is 3.27 m in, column 32; y = -3.0 is row 0
    row, col = g.world_to_cell(0.22, -3.0)
    assert (int(row), int(col)) == (0, 32)
    row, col = g.world_to_cell(-3.06, 0.0)
    assert int(col) == -1 and not g.contains(row, col)


def test_cell_to_world_returns_cell_centres_and_round_trips():
    g = grid()
    x, y = g.cell_to_world(0, 32)
    assert (float(x), float(y)) == pytest.approx((0.2, -3.0))
    rows, cols = np.meshgrid(np.arange(60), np.arange(60), indexing="ij")
    back_r, back_c = g.world_to_cell(*g.cell_to_world(rows, cols))
    np.testing.assert_array_equal(back_r, rows)
    np.testing.assert_array_equal(back_c, cols)


def test_probabilities_are_clamped_on_construction():
    g = OccupancyGrid((0, 0), 0.1, np.array([[0.0, 0.5, 1.0]]))
    np.testing.assert_array_equal(g.probabilities, [[0.05, 0.5, 0.95]])


# ---------------------------------------------------------------- (6.3) - (6.5) by hand


def test_eq_6_3_ratio_of_areas():
    # 0.1 m cells, 5 mm noise: 0.01 / (0.01 + 2 * 0.005 * 0.2) = 0.01 / 0.012
    assert p_occupied_given_occupied(0.005, 0.1, 0.1) == pytest.approx(0.01 / 0.012)
    # 0.3 m cells (Fig 3.2), 5 cm noise: 0.09 / (0.09 + 2 * 0.05 * 0.6) = 0.6
    assert p_occupied_given_occupied(0.05, 0.3, 0.3) == pytest.approx(0.6)


def test_eq_6_4_linear_from_point_two_to_one_half():
    assert p_free_given_free(PARAMS.range_min, PARAMS) == pytest.approx(0.2)
    assert p_free_given_free(PARAMS.range_max, PARAMS) == pytest.approx(0.5)
    assert p_free_given_free((PARAMS.range_min + PARAMS.range_max) / 2, PARAMS) == pytest.approx(0.35)


def test_sensor_noise_is_linear_in_range():
    assert sensor_noise(PARAMS.range_min, PARAMS) == pytest.approx(PARAMS.noise_min)
    assert sensor_noise(PARAMS.range_max, PARAMS) == pytest.approx(PARAMS.noise_max)
    assert sensor_noise(0.75, PARAMS) == pytest.approx((PARAMS.noise_min + PARAMS.noise_max) / 2)


def test_eq_6_5_bayes_by_hand():
    assert bayes_update(0.5, 0.8) == pytest.approx(0.8)
    assert bayes_update(0.8, 0.8) == pytest.approx(0.64 / (0.64 + 0.04))
    assert bayes_update(0.5, 0.2) == pytest.approx(0.2)
    assert bayes_update(0.3, 0.5) == pytest.approx(0.3)  # uninformative evidence keeps the prior


# ---------------------------------------------------------------- IR update


def straight_ahead(g, distance_m, offset_m=0.0):
    """Probability of the cell ``distance_m`` ahead of the origin along +x, ``offset_m`` to the side."""
    row, col = g.world_to_cell(distance_m, offset_m)
    return g.probabilities[int(row), int(col)]


def test_a_beam_frees_the_cells_it_crosses_and_marks_the_hit():
    g = grid()
    # Sensor on the rim 0.2 m ahead of the centre at the origin, looking along +x, obstacle 1.0 m away.
    g.update((0.0, 0.0, 0.0), np.array([1.0]), np.array([0.0]), sensor_radius=0.2)
    for distance in (0.3, 0.7, 1.1):
        assert straight_ahead(g, distance) < 0.5
    assert straight_ahead(g, 1.2) > 0.5  # the hit, 0.2 + 1.0 from the centre
    assert straight_ahead(g, 1.4) == 0.5  # beyond the hit: unseen
    assert straight_ahead(g, 0.75, offset_m=0.5) == 0.5  # off the beam
    assert straight_ahead(g, -0.75) == 0.5  # behind


def test_each_sensor_has_its_own_distance_from_the_centre():
    g = grid()
    # Two sensors looking along +x and +y, 0.2 m and 0.6 m from the centre, each seeing something 0.5 m away.
    g.update((0.0, 0.0, 0.0), np.array([0.5, 0.5]), np.array([0.0, math.pi / 2]), sensor_radius=np.array([0.2, 0.6]))
    assert straight_ahead(g, 0.7) > 0.5 and straight_ahead(g, 1.1) == 0.5
    row, col = g.world_to_cell(0.0, 1.1)
    assert g.probabilities[int(row), int(col)] > 0.5
    row, col = g.world_to_cell(0.0, 0.5)
    assert g.probabilities[int(row), int(col)] == 0.5  # inside the robot, before that sensor


def test_free_evidence_is_stronger_near_the_sensor():
    g = grid()
    g.update((0.0, 0.0, 0.0), np.array([np.inf]), np.array([0.0]), sensor_radius=0.0)
    assert straight_ahead(g, 0.2) < straight_ahead(g, 1.0) < 0.5
    assert straight_ahead(g, 0.2) == pytest.approx(bayes_update(0.5, p_free_given_free(0.2, PARAMS)))


def test_no_return_frees_the_beam_to_full_range_and_marks_nothing():
    g = grid()
    g.update((0.0, 0.0, 0.0), np.array([np.inf]), np.array([0.0]), sensor_radius=0.0)
    assert straight_ahead(g, 1.4) < 0.5
    assert not np.any(g.probabilities > 0.5)


def test_beam_follows_pose_heading_and_bearing():
    g = grid()
    # Robot facing +y, sensor bearing -90 degrees: the beam points along +x.
    g.update((0.0, 0.0, math.pi / 2), np.array([0.8]), np.array([-math.pi / 2]), sensor_radius=0.0)
    assert straight_ahead(g, 0.8) > 0.5
    row, col = g.world_to_cell(0.0, 0.8)
    assert g.probabilities[int(row), int(col)] == 0.5


def test_centre_offset_moves_the_sensors():
    g = grid()
    g.update((0.0, 0.0, 0.0), np.array([0.5]), np.array([0.0]), sensor_radius=0.0, centre_offset=0.3)
    assert straight_ahead(g, 0.8) > 0.5
    assert straight_ahead(g, 0.5) < 0.5


def test_beam_is_a_cone_of_about_five_degrees():
    g = grid(resolution=0.02, shape=(150, 150), origin=(-1.51, -1.51))
    g.update((-1.0, 0.0, 0.0), np.array([np.inf]), np.array([0.0]), sensor_radius=0.0)
    # 1.0 m out the cone is tan(2.5 deg) * 1.0 = 4.4 cm either side: the cell centred 4 cm off is in, 6 cm out.
    assert straight_ahead(g, 0.0, offset_m=0.04) < 0.5
    assert straight_ahead(g, 0.0, offset_m=0.06) == 0.5


def test_footprint_is_marked_free():
    g = grid()
    g.update((1.0, 1.0, 0.0), np.array([]), np.array([]), sensor_radius=0.3, footprint_radius=0.3)
    row, col = g.world_to_cell(1.0, 1.0)
    assert g.probabilities[int(row), int(col)] == pytest.approx(bayes_update(0.5, PARAMS.p_free_near))
    row, col = g.world_to_cell(1.5, 1.0)
    assert g.probabilities[int(row), int(col)] == 0.5


def test_two_beams_on_one_cell_apply_bayes_twice():
    g = grid()
    g.update((0.0, 0.0, 0.0), np.array([1.0, 1.0]), np.array([0.0, 0.0]), sensor_radius=0.0)
    q = p_occupied_given_occupied(sensor_noise(1.0, PARAMS), 0.1, 0.1)
    assert straight_ahead(g, 1.0) == pytest.approx(bayes_update(bayes_update(0.5, q), q))


def test_repeated_updates_saturate_at_the_clamps():
    g = grid()
    for _ in range(40):
        g.update((0.0, 0.0, 0.0), np.array([1.0]), np.array([0.0]), sensor_radius=0.0)
    assert straight_ahead(g, 1.0) == pytest.approx(0.95)
    assert straight_ahead(g, 0.3) == pytest.approx(0.05)
    assert g.probabilities.min() >= 0.05 and g.probabilities.max() <= 0.95


def test_robot_outside_the_grid_changes_nothing():
    g = grid()
    g.update((50.0, 50.0, 0.0), np.array([1.0]), np.array([0.0]), sensor_radius=0.2)
    assert np.all(g.probabilities == 0.5)
