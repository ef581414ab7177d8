"""Unit tests for the explorer's coverage waypoints (Chand §6.2, Fig 6.4, eq. 6.1-6.2)."""
from __future__ import annotations

import numpy as np
import pytest

from teamsim.controllers.exploration.waypoints import (WaypointParams, coverage_waypoints, line_count,
                                                       threshold_noise, threshold_range)
from teamsim.controllers.navigation.occupancy_grid import MappingParams, p_occupied_given_occupied

MAPPING = MappingParams()  # SR 0..1.5 m, NS 0.005..0.02 m


def test_threshold_noise_by_hand():
    # 0.5 * 0.3 * 0.3 * (1 - 0.68) / (2 * 0.68 * (0.3 + 0.3)) = 0.0144 / 0.816 = 0.0176470...
    assert threshold_noise(0.68, 0.3, 0.3) == pytest.approx(0.0144 / 0.816)
    # 0.5 * 0.1 * 0.2 * 0.5 / (2 * 0.5 * 0.3) = 0.005 / 0.3
    assert threshold_noise(0.5, 0.1, 0.2) == pytest.approx(0.005 / 0.3)


def test_threshold_noise_keeps_the_printed_half_so_it_is_not_the_exact_inverse_of_6_3():
    noise = threshold_noise(0.68, 0.3, 0.3)
    # (6.3) at twice the printed NS_t gives back P_s; at NS_t itself it gives more.
    assert p_occupied_given_occupied(2 * noise, 0.3, 0.3) == pytest.approx(0.68)
    assert p_occupied_given_occupied(noise, 0.3, 0.3) > 0.68 + 0.05


def test_threshold_range_by_hand_and_clipped():
    # 0 + (1.5 - 0) * (0.017 - 0.005) / (0.02 - 0.005) = 1.5 * 0.8 = 1.2
    assert threshold_range(0.017, MAPPING) == pytest.approx(1.2)
    assert threshold_range(0.0375, MAPPING) == 1.5  # unclipped 3.25 m: the sensor reads no further than SR_max
    assert threshold_range(0.001, MAPPING) == 0.0  # unclipped -0.4 m


def test_default_p_s_gives_fig_6_5s_eight_waypoints_in_a_ch8_local_environment():
    sensing_range = WaypointParams().sensing_range(0.3)
    # NS_t = 0.0176470 (above); SR_t = 1.5 * (0.0176470 - 0.005) / 0.015 = 1.26471;
    # n = ceil(9.6 / 2.52941) = ceil(3.795) = 4
    assert sensing_range == pytest.approx(1.5 * (0.0144 / 0.816 - 0.005) / 0.015)
    assert line_count(9.6, sensing_range) == 4
    assert coverage_waypoints((0, 0), (9.6, 9.6), sensing_range, (4.8, 4.8)).shape == (8, 2)


def test_line_count_is_exact_at_the_fit():
    assert line_count(9.6, 1.2) == 4  # 9.6 / 2.4 = 4 exactly: no fifth line to rounding
    assert line_count(9.6, 1.19) == 5
    assert line_count(1.0, 5.0) == 1
    # the third row of ch.8's 4 x 4 local environments: 28.8 - 19.2 = 9.600000000000001 m in floats, still 4 lines
    assert coverage_waypoints((0, 19.2), (9.6, 28.8), 1.2, (0, 0)).shape == (8, 2)


def test_square_from_the_lower_left_corner_by_hand():
    # n = 4, spacing 2.4: lines at y = 1.2, 3.6, 6.0, 8.4; ends inset 1.2 from x = 0 and 9.6
    expected = [(1.2, 1.2), (8.4, 1.2), (8.4, 3.6), (1.2, 3.6), (1.2, 6.0), (8.4, 6.0), (8.4, 8.4), (1.2, 8.4)]
    np.testing.assert_allclose(coverage_waypoints((0, 0), (9.6, 9.6), 1.2, (-1, -1)), expected)


@pytest.mark.parametrize("start, first_three", [
    ((10, 10), [(8.4, 8.4), (1.2, 8.4), (1.2, 6.0)]),
    ((9, 0.5), [(8.4, 1.2), (1.2, 1.2), (1.2, 3.6)]),
    ((0, 9), [(1.2, 8.4), (8.4, 8.4), (8.4, 6.0)]),
])
def test_the_sweep_starts_at_the_corner_nearest_the_start(start, first_three):
    np.testing.assert_allclose(coverage_waypoints((0, 0), (9.6, 9.6), 1.2, start)[:3], first_three)


def test_offset_rectangle_by_hand():
    # y-width 3, SR_t 1: n = ceil(1.5) = 2, spacing 1.5, lines at y = -2 + 0.75 = -1.25 and 0.25, ends at
    # x = 10.75 and 13.25. Nearest corner to the origin: (10, 1) at sqrt(101), before (10, -2) at sqrt(104).
    expected = [(10.75, 0.25), (13.25, 0.25), (13.25, -1.25), (10.75, -1.25)]
    np.testing.assert_allclose(coverage_waypoints((10, -2), (14, 1), 1.0, (0, 0)), expected)


@pytest.mark.parametrize("width, sensing_range", [(9.6, 1.265), (9.6, 0.7), (5.0, 1.3), (3.1, 0.4), (1.0, 1.5)])
def test_lines_cover_the_rectangle_with_the_fewest_lines(width, sensing_range):
    points = coverage_waypoints((0, 0), (width, width), sensing_range, (0, 0))
    lines = np.unique(points[:, 1])
    ys = np.linspace(0, width, 1001)
    gaps = np.min(np.abs(ys[:, None] - lines[None, :]), axis=1)
    assert gaps.max() <= sensing_range + 1e-9
    assert len(lines) == 1 or width / (len(lines) - 1) > 2 * sensing_range  # one line fewer would leave a gap


def test_bad_rectangle_or_range_is_refused():
    with pytest.raises(ValueError):
        coverage_waypoints((0, 0), (0, 5), 1.0, (0, 0))
    with pytest.raises(ValueError):
        coverage_waypoints((0, 0), (5, 5), 0.0, (0, 0))
