"""The territorial division (teamsim.controllers.exploration.territory, Chand §6.1): hand-worked values for the
thesis's 38.4 m area at 0.3 m cells in 4 x 4 local environments (128 cells a side, 32 an environment), numbered 0
to 15 row-major from the lower-left corner:

    12 13 14 15     y 9.6 to 19.2
     8  9 10 11
     4  5  6  7
     0  1  2  3     y -19.2 to -9.6
"""
from __future__ import annotations

import numpy as np
import pytest

from teamsim.controllers.exploration.territory import Territory

TERRITORY = Territory(38.4, 0.3, 4)


def middle(cell: int) -> float:
    """The world coordinate of the middle of map cell ``cell`` along either axis."""
    return -19.2 + (cell + 0.5) * 0.3


def test_sizes():
    assert TERRITORY.origin == (-19.2, -19.2)
    assert TERRITORY.cells == 128
    assert TERRITORY.environment_cells == 32
    assert TERRITORY.environments == 16


def test_neighbours_share_an_edge_in_ascending_order():
    assert TERRITORY.neighbours(0) == (1, 4)
    assert TERRITORY.neighbours(5) == (1, 4, 6, 9)
    assert TERRITORY.neighbours(15) == (11, 14)
    assert TERRITORY.neighbour_lists == tuple(TERRITORY.neighbours(e) for e in range(16))


def test_bounds_and_centres():
    np.testing.assert_allclose(TERRITORY.bounds(0), ((-19.2, -19.2), (-9.6, -9.6)))
    np.testing.assert_allclose(TERRITORY.bounds(6), ((0.0, -9.6), (9.6, 0.0)), atol=1e-12)  # row 1, column 2
    assert TERRITORY.centre(0) == pytest.approx((-14.4, -14.4))
    assert TERRITORY.centre(15) == pytest.approx((14.4, 14.4))
    assert TERRITORY.centres[15] == TERRITORY.centre(15) and len(TERRITORY.centres) == 16


def test_slices_are_each_environments_rows_then_columns():
    assert TERRITORY.slices(0) == (slice(0, 32), slice(0, 32))
    assert TERRITORY.slices(6) == (slice(32, 64), slice(64, 96))
    assert TERRITORY.slices(15) == (slice(96, 128), slice(96, 128))


def test_cell_of_is_row_along_y_then_column_along_x_clamped_to_the_area():
    assert TERRITORY.cell_of(middle(0), middle(0)) == (0, 0)
    assert TERRITORY.cell_of(middle(0), middle(1)) == (1, 0)  # y picks the row
    assert TERRITORY.cell_of(middle(70), middle(5)) == (5, 70)
    assert TERRITORY.cell_of(19.2, 19.2) == (127, 127)  # the far walls belong to the cells inside them
    assert TERRITORY.cell_of(-100.0, 100.0) == (127, 0)


def test_environment_of_a_point_and_of_points_outside_clamped():
    assert TERRITORY.environment_of(0.1, 0.1) == 10
    assert TERRITORY.environment_of(-0.1, 0.1) == 9
    assert TERRITORY.environment_of(-0.1, -0.1) == 5
    assert TERRITORY.environment_of(-19.2, -19.2) == 0
    assert TERRITORY.environment_of(19.2, 19.2) == 15
    assert TERRITORY.environment_of(100.0, -100.0) == 3
    assert TERRITORY.environment_of(-100.0, 100.0) == 12
    assert TERRITORY.environment_of(19.3, 0.1) == TERRITORY.environment_of(19.1, 0.1) == 11


def test_environment_grid_agrees_with_slices():
    grid = TERRITORY.environment_grid()
    assert grid.shape == (128, 128)
    for environment in range(16):
        assert (grid[TERRITORY.slices(environment)] == environment).all()
    assert np.bincount(grid.ravel()).tolist() == [32 * 32] * 16


def test_a_local_map_is_8_kb_of_doubles():
    assert TERRITORY.local_map_bytes() == 8192
    assert TERRITORY.local_map_bytes(4) == 4096


def test_unexplored_map_covers_the_area():
    grid = TERRITORY.unexplored_map()
    assert grid.shape == (128, 128) and grid.origin == (-19.2, -19.2) and grid.resolution == 0.3
    assert np.unique(grid.probabilities).size == 1


@pytest.mark.parametrize("lo, hi, expected", [
    ((-14.0, -14.0), (-13.0, -13.0), {0}),  # inside one
    ((-9.6, -9.6), (0.0, 0.0), {5}),  # exactly environment 5: its neighbours only touch it
    ((-1.0, -1.0), (1.0, 1.0), {5, 6, 9, 10}),  # across the centre
    ((-12.0, 0.0), (-9.6, 2.4), {8}),  # ends on the edge between 8 and 9
    ((-12.0, -0.1), (-9.6, 2.4), {4, 8}),  # reaches into 4 across a border
    ((0.0, 0.0), (0.0, 5.0), set()),  # no area
    ((-30.0, -30.0), (-19.2, -19.2), set()),  # outside, touching the corner
    ((-30.0, -30.0), (30.0, 30.0), set(range(16))),  # the whole area and beyond
])
def test_overlapping_counts_shared_area_not_touching_edges(lo, hi, expected):
    assert TERRITORY.overlapping(lo, hi) == expected
