"""Unit tests for the memory-constrained two-tiered A* (Chand ch.4): the partition worked example of Figs 4.3-4.4
exactly, the memory equations (4.2)-(4.5), exit points (Fig 4.7, eq. 4.15), safe boundaries, the search itself,
eviction, backtracking (Fig 4.8), map data fetched and the transmission time (§4.6.3)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from teamsim.controllers.navigation.astar import PlannerParams, modified_astar
from teamsim.controllers.navigation.two_tier_astar import (EFFECTIVE_LINK_RATE, TwoTierParams, boundary_is_safe,
                                                           cluster_exit_points, exit_points, free_clusters,
                                                           local_map_memory, local_map_node_budget,
                                                           partition_global_map, rank_exit_points, transmission_time,
                                                           two_tier_astar)

FREE, WALL = 0.05, 0.95
THRESHOLD = PlannerParams().occupied_threshold


def assert_valid_path(cells, global_map, start, goal=None):
    cells = np.asarray(cells)
    assert tuple(cells[0]) == tuple(start)
    if goal is not None:
        assert tuple(cells[-1]) == tuple(goal)
    assert np.all(np.abs(np.diff(cells, axis=0)).max(axis=1) == 1), "8-connected, no repeated nodes at joins"
    assert np.all(global_map[cells[1:, 0], cells[1:, 1]] < THRESHOLD)


# ---------------------------------------------------------------- partition (Figs 4.2-4.4)


def test_partition_of_the_worked_example_exactly():
    partition = partition_global_map(40, 40, 200)
    assert partition.row_col == 14
    assert (partition.rows_p, partition.cols_p) == (3, 3)
    assert partition.dims == {
        1: (1, 14, 1, 14), 2: (1, 14, 15, 28), 3: (1, 14, 29, 40),
        4: (15, 28, 1, 14), 5: (15, 28, 15, 28), 6: (15, 28, 29, 40),
        7: (29, 40, 1, 14), 8: (29, 40, 15, 28), 9: (29, 40, 29, 40),
    }
    assert partition.neighbours == {
        1: (2, 4), 2: (1, 3, 5), 3: (2, 6),
        4: (1, 5, 7), 5: (2, 4, 6, 8), 6: (3, 5, 9),
        7: (4, 8), 8: (5, 7, 9), 9: (6, 8),
    }


def test_partition_lookups():
    partition = partition_global_map(40, 40, 200)
    assert partition.index_of(0, 0) == 1
    assert partition.index_of(13, 14) == 2
    assert partition.index_of(39, 39) == 9
    assert partition.nodes(5) == 14 * 14 and partition.nodes(9) == 12 * 12
    rows, cols = partition.slices(6)
    assert (rows.start, rows.stop, cols.start, cols.stop) == (14, 28, 28, 40)


def test_partition_of_a_rectangular_map():
    partition = partition_global_map(10, 25, 30)  # 5 x 5 local maps: 2 rows, 5 columns
    assert (partition.row_col, partition.rows_p, partition.cols_p) == (5, 2, 5)
    assert partition.dims[10] == (6, 10, 21, 25)
    assert partition.neighbours[1] == (2, 6) and partition.neighbours[7] == (2, 6, 8)  # bottom row: none below


# ---------------------------------------------------------------- memory and communication (4.2)-(4.5), §4.6.3


def test_memory_equations_of_section_4_6():
    # 64 KB local maps of doubles: 8192 nodes -> RowCol 90 -> 8100 nodes -> 64 800 bytes.
    assert local_map_node_budget(64 * 1024, 8) == 8192
    partition = partition_global_map(1000, 1000, 8192)
    assert partition.row_col == 90
    assert partition.nodes(1) * 8 == 64_800
    # (4.2): Q = 1 plus the two merged-map memories share the total three ways.
    assert local_map_memory(3 * 64 * 1024, memories=1) == 64 * 1024
    assert local_map_memory(17 * 1024, memories=15) == 1024


def test_transmission_time_at_the_effective_rate():
    assert EFFECTIVE_LINK_RATE == 5.5e6
    assert transmission_time(64_800) == pytest.approx(64_800 * 8 / 5.5e6)
    assert transmission_time(5.5e6 / 8) == pytest.approx(1.0)


# ---------------------------------------------------------------- exit points (Fig 4.7, eq. 4.15)


def test_free_clusters():
    free = np.array([1, 1, 0, 1, 0, 0, 1, 1, 1], bool)
    assert free_clusters(free) == [(0, 1), (3, 3), (6, 8)]
    assert free_clusters(np.zeros(4, bool)) == []


def test_cluster_exit_points_as_in_fig_4_7():
    # One cell is the robot's radius: a cluster needs three free cells.
    assert cluster_exit_points(0, 1, 1) == ()
    assert cluster_exit_points(4, 6, 1) == (5,)  # three cells: all three points coincide
    assert cluster_exit_points(4, 7, 1) == (5, 6)  # four cells: two unique points
    assert cluster_exit_points(0, 6, 1) == (1, 3, 5)  # seven cells: ends one radius in, and the centre
    assert cluster_exit_points(0, 4, 2) == (2,)


def test_exit_points_lie_on_sides_towards_other_local_maps():
    partition = partition_global_map(20, 20, 100)  # 2 x 2 local maps of 10
    global_map = np.full((20, 20), FREE)
    global_map[9, 0:4] = WALL  # map 1's bottom side: free from column 4 to 9
    local = global_map[partition.slices(1)]
    points = exit_points(partition, 1, local, THRESHOLD, radius_cells=1)
    # Map 1 borders map 2 (right side, column 9) and map 3 (bottom side, row 9); its top and left are the edge.
    assert sorted(points) == sorted([(1, 9), (4, 9), (8, 9), (9, 5), (9, 6), (9, 8)])
    assert all(col == 9 for _, col in exit_points(partition, 1, local, THRESHOLD, 1, exclude_towards=3))


def test_rank_exit_points_by_eq_4_15():
    goal, parent_end = (10, 10), (0, 0)
    points = [(0, 9), (9, 0), (5, 5)]
    ranked = rank_exit_points(points, goal, parent_end, k3=0.5, k4=0.5)
    utilities = [0.5 * math.dist(p, goal) + 0.5 * math.dist(p, parent_end) for p in ranked]
    assert utilities == sorted(utilities)
    assert ranked[0] == (5, 5)  # on the straight line: 0.5 * (7.07 + 7.07)
    assert rank_exit_points(points, goal, parent_end, k3=1.0, k4=0.0)[0] == (5, 5)


def test_boundary_is_safe_needs_a_passage_wider_than_the_robot():
    partition = partition_global_map(20, 20, 100)
    global_map = np.full((20, 20), FREE)
    global_map[:, 9] = WALL
    global_map[4:6, 9] = FREE  # a two-cell gap in map 1's right column
    left, right = global_map[partition.slices(1)], global_map[partition.slices(2)]
    assert not boundary_is_safe(partition, 1, left, 2, right, THRESHOLD, radius_cells=1)
    global_map[4:7, 9] = FREE
    left = global_map[partition.slices(1)]
    assert boundary_is_safe(partition, 1, left, 2, right, THRESHOLD, radius_cells=1)
    global_map[5, 10] = WALL  # blocked on map 2's side of the same gap
    right = global_map[partition.slices(2)]
    assert not boundary_is_safe(partition, 1, left, 2, right, THRESHOLD, radius_cells=1)


# ---------------------------------------------------------------- the two-tiered search


def open_world(size=40, seed=0, density=0.1):
    rng = np.random.default_rng(seed)
    global_map = np.where(rng.random((size, size)) < density, WALL, FREE)
    global_map[:3, :3] = global_map[-3:, -3:] = FREE
    return global_map


def test_finds_a_valid_path_through_the_worked_example_partition():
    global_map = open_world()
    partition = partition_global_map(40, 40, 200)
    result = two_tier_astar(global_map, (0, 0), (39, 39), partition, TwoTierParams(radius_cells=1))
    assert result.reached
    assert_valid_path(result.cells, global_map, (0, 0), (39, 39))
    assert result.local_maps[0] == 1 and result.local_maps[-1] == 9
    for before, after in zip(result.local_maps[:-1], result.local_maps[1:]):
        assert after in partition.neighbours[before]


def test_path_is_no_shorter_than_the_unconstrained_optimum():
    global_map = open_world(seed=2)
    partition = partition_global_map(40, 40, 200)
    result = two_tier_astar(global_map, (0, 0), (39, 39), partition, TwoTierParams(radius_cells=1))
    optimum = modified_astar(global_map, (0, 0), (39, 39), PlannerParams(weight_probability=0, weight_clearance=0,
                                                                          heuristic="octile"))
    assert result.reached and optimum.reached
    assert result.length >= optimum.length - 1e-9


def test_bytes_fetched_count_every_local_map_received():
    global_map = open_world(seed=1)
    partition = partition_global_map(40, 40, 200)
    results = {q: two_tier_astar(global_map, (0, 0), (39, 39), partition, TwoTierParams(memories=q, radius_cells=1))
               for q in (1, 5, 15)}
    for result in results.values():
        assert result.reached
        assert result.transmission_time == pytest.approx(result.bytes_fetched * 8 / 5.5e6)
        assert result.overall_time == pytest.approx(result.planning_time + result.transmission_time)
    # With a memory for every local map, none is ever evicted: each is fetched once at most, and the data
    # received is at most the whole global map.
    assert results[15].fetches <= 9
    assert results[15].bytes_fetched <= 40 * 40 * 8
    assert results[1].fetches >= results[5].fetches >= results[15].fetches
    assert results[1].bytes_fetched >= results[5].bytes_fetched >= results[15].bytes_fetched


def test_a_single_memory_evicts_and_refetches():
    global_map = open_world(seed=1)
    partition = partition_global_map(40, 40, 200)
    single = two_tier_astar(global_map, (0, 0), (39, 39), partition, TwoTierParams(memories=1, radius_cells=1))
    assert single.fetches > 9  # more fetches than there are local maps: some came back after eviction
    sizes = {partition.nodes(k) * 8 for k in range(1, 10)}
    assert single.bytes_fetched >= single.fetches * min(sizes)


def test_cost_method_2_also_reaches_the_goal():
    global_map = open_world(seed=3)
    partition = partition_global_map(40, 40, 200)
    result = two_tier_astar(global_map, (0, 0), (39, 39), partition, TwoTierParams(cost_method=2, radius_cells=1))
    assert result.reached
    assert_valid_path(result.cells, global_map, (0, 0), (39, 39))


def test_start_and_goal_in_one_local_map():
    global_map = np.full((40, 40), FREE)
    partition = partition_global_map(40, 40, 200)
    result = two_tier_astar(global_map, (15, 15), (25, 20), partition)
    assert result.reached and result.local_maps == (5,)
    assert result.fetches == 1 and result.bytes_fetched == 14 * 14 * 8
    assert_valid_path(result.cells, global_map, (15, 15), (25, 20))


def walled_world(seed):
    """Long random walls on a 30 x 30 map: the kind of map on which closed local maps block the search."""
    rng = np.random.default_rng(seed)
    global_map = np.full((30, 30), FREE)
    for _ in range(6):
        if rng.random() < 0.5:
            row, first = rng.integers(3, 27), rng.integers(0, 20)
            global_map[row, first:first + rng.integers(8, 20)] = WALL
        else:
            col, first = rng.integers(3, 27), rng.integers(0, 20)
            global_map[first:first + rng.integers(8, 20), col] = WALL
    global_map[:2, :2] = global_map[-2:, -2:] = FREE
    return global_map


def test_backtracking_finds_a_route_round_a_blocked_local_map():
    global_map = walled_world(seed=36)  # found by search: the first pass closes a map it must revisit
    partition = partition_global_map(30, 30, 100)
    result = two_tier_astar(global_map, (0, 0), (29, 29), partition, TwoTierParams(radius_cells=1))
    assert result.backtracks >= 1
    assert result.reached
    assert_valid_path(result.cells, global_map, (0, 0), (29, 29))


def test_no_path_ends_with_the_partial_path_closest_to_the_goal():
    global_map = np.full((40, 40), FREE)
    global_map[30:, 30] = global_map[30, 30:] = WALL  # the goal's corner is walled off
    partition = partition_global_map(40, 40, 200)
    result = two_tier_astar(global_map, (0, 0), (39, 39), partition, TwoTierParams(radius_cells=1))
    assert not result.reached
    assert result.local_maps == ()
    assert_valid_path(result.cells, global_map, (0, 0))
    assert result.backtracks >= 1
    end = tuple(result.cells[-1])
    assert math.dist(end, (39, 39)) < math.dist((0, 0), (39, 39)) / 2  # it got well on its way
