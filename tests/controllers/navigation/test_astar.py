"""Unit tests for Chand's modified A* (§3.2.2, eq. 3.1-3.8): the cost terms by hand, the numpy helpers against
brute force, optimality against the textbook ``reference_astar`` on random grids, the corner rule and the partial
path to an unreachable goal; the compiled heap search against the plain Python loop it replaced."""
from __future__ import annotations

import heapq
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamsim.controllers.navigation.astar import (SQRT2, CostMaps, PlannerParams, WeightAdaptation, _heap_search,
                                                  _padded, adapt_weights, astar, cost_maps, cost_multiplier,
                                                  distance_transform, modified_astar, plan_on_grid, probability_cost,
                                                  reference_astar, window_mean)
from teamsim.controllers.navigation.occupancy_grid import OccupancyGrid

FREE, WALL = 0.05, 0.95


def path_cost(path, multiplier):
    """(3.3) summed along a path: each step's length times the cost multiplier of the cell it enters."""
    path = np.asarray(path)
    steps = np.hypot(*np.diff(path, axis=0).T)
    return float((steps * multiplier[path[1:, 0], path[1:, 1]]).sum())


def assert_valid_path(path, blocked, start):
    path = np.asarray(path)
    assert tuple(path[0]) == tuple(start)
    steps = np.abs(np.diff(path, axis=0))
    assert np.all(steps.max(axis=1) == 1), "every step goes to one of the eight neighbours"
    for (r0, c0), (r1, c1) in zip(path[:-1], path[1:]):
        assert not blocked[r1, c1]
        if r0 != r1 and c0 != c1:
            assert not blocked[r0, c1] and not blocked[r1, c0], "a diagonal step may not cut a corner"


# ---------------------------------------------------------------- (3.5) - (3.8) by hand


def test_probability_cost_cases_of_eq_3_5():
    params = PlannerParams(critical_min=0.2, critical_max=0.6, weight_critical=0.25, weight_unexplored=0.5)
    p = np.array([0.05, 0.3, 0.5, 0.6, 0.9])
    # outside the band: p; inside: (1 - 0.25) p; unexplored: (1 - 0.5) 0.5
    np.testing.assert_allclose(probability_cost(p, params), [0.05, 0.225, 0.25, 0.45, 0.9])


def test_known_environment_weights_leave_probabilities_unchanged():
    p = np.array([0.05, 0.3, 0.5, 0.95])
    np.testing.assert_allclose(probability_cost(p, PlannerParams()), p)


def test_eq_3_6_weights_grow_on_poor_progress_and_reset_on_good():
    adaptation = WeightAdaptation(initial_critical=0.3, initial_unexplored=0.5, factor=1.5, min_progress=0.5)
    params = PlannerParams(weight_critical=0.3, weight_unexplored=0.5)
    poor = adapt_weights(params, progress=0.1, adaptation=adaptation)
    assert (poor.weight_critical, poor.weight_unexplored) == pytest.approx((0.45, 0.75))
    poorer = adapt_weights(poor, progress=0.1, adaptation=adaptation)
    assert poorer.weight_unexplored == 1.0  # unit interval
    good = adapt_weights(poorer, progress=2.0, adaptation=adaptation)
    assert (good.weight_critical, good.weight_unexplored) == (0.3, 0.5)


def test_eq_3_7_on_a_uniform_map():
    # c_m = 1 + 0.5 * 0.05 + 0.5 * mean(0.05) = 1.05 everywhere
    np.testing.assert_allclose(cost_multiplier(np.full((5, 5), FREE), PlannerParams()), 1.05)


def test_eq_3_8_clearance_term_by_hand():
    p = np.full((5, 5), FREE)
    p[2, 2] = WALL
    params = PlannerParams(clearance_nodes=1)
    cm = cost_multiplier(p, params)
    # Next to the wall cell: c_prc is the mean of its 3x3 window, one 0.95 among nine cells.
    assert cm[2, 1] == pytest.approx(1 + 0.5 * FREE + 0.5 * (8 * FREE + WALL) / 9)
    # A corner cell sees only its four in-grid cells.
    assert cm[0, 0] == pytest.approx(1 + 0.5 * FREE + 0.5 * FREE)


def test_window_mean_matches_brute_force():
    rng = np.random.default_rng(3)
    values = rng.random((7, 9))
    for radius in (0, 1, 2, 5):
        expected = np.array([[values[max(r - radius, 0):r + radius + 1, max(c - radius, 0):c + radius + 1].mean()
                              for c in range(9)] for r in range(7)])
        np.testing.assert_allclose(window_mean(values, radius), expected)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 10_000), st.floats(0.5, 6.0))
def test_distance_transform_matches_brute_force(seed, cap):
    rng = np.random.default_rng(seed)
    mask = rng.random((12, 15)) < 0.08
    rows, cols = np.indices(mask.shape)
    marked = np.argwhere(mask)
    if len(marked):
        brute = np.min(np.hypot(rows[..., None] - marked[:, 0], cols[..., None] - marked[:, 1]), axis=-1)
    else:
        brute = np.full(mask.shape, np.inf)
    expected = np.where(brute <= cap, brute, np.inf)
    np.testing.assert_allclose(distance_transform(mask, cap), expected)


def test_inflation_blocks_cells_within_the_radius():
    p = np.full((9, 9), FREE)
    p[4, 4] = WALL
    blocked = cost_maps(p, PlannerParams(), inflation_cells=2.0).blocked
    assert blocked[4, 6] and blocked[6, 4] and not blocked[4, 7]
    assert not blocked[6, 6]  # 2.83 cells away


# ---------------------------------------------------------------- search by hand


def test_open_grid_diagonal_path_and_cost():
    costs = CostMaps(np.zeros((5, 5), bool), np.full((5, 5), 2.0))
    result = astar(costs, (0, 0), (4, 4), heuristic="octile")
    assert result.reached
    np.testing.assert_array_equal(result.cells, [(k, k) for k in range(5)])
    assert result.cost == pytest.approx(4 * SQRT2 * 2.0)
    assert result.length == pytest.approx(4 * SQRT2)


def test_path_goes_through_the_gap_in_a_wall():
    p = np.full((7, 7), FREE)
    p[3, :] = WALL
    p[3, 5] = FREE
    result = modified_astar(p, (0, 0), (6, 0))
    assert result.reached
    assert [3, 5] in result.cells.tolist()
    assert_valid_path(result.cells, p >= 0.7, (0, 0))


def test_no_squeezing_between_cells_that_touch_at_a_corner():
    p = np.full((2, 2), FREE)
    p[0, 1] = p[1, 0] = WALL
    assert not modified_astar(p, (0, 0), (1, 1)).reached
    assert reference_astar(p >= 0.7, np.ones((2, 2)), (0, 0), (1, 1)) is None


def test_start_on_an_impassable_cell_can_still_leave_it():
    p = np.full((3, 3), FREE)
    p[0, 0] = WALL
    result = modified_astar(p, (0, 0), (2, 2))
    assert result.reached and tuple(result.cells[-1]) == (2, 2)


def test_unreachable_goal_gives_the_partial_path_ending_closest_to_it():
    p = np.full((9, 9), FREE)
    p[2:7, 2] = p[2:7, 6] = p[2, 2:7] = p[6, 2:7] = WALL  # a closed room around the goal
    result = modified_astar(p, (0, 0), (4, 4))
    assert not result.reached
    assert_valid_path(result.cells, p >= 0.7, (0, 0))
    end = result.cells[-1]
    reachable = np.argwhere(p < 0.7)
    reachable = reachable[~((reachable >= 2) & (reachable <= 6)).all(axis=1)]  # outside the room
    nearest = np.min(np.hypot(*(reachable - (4, 4)).T))
    assert math.dist(end, (4, 4)) == pytest.approx(nearest)
    assert result.cost == pytest.approx(path_cost(result.cells, cost_multiplier(p, PlannerParams())))


def test_plan_on_grid_returns_world_waypoints():
    occupied = np.zeros((20, 20), bool)
    occupied[10, :15] = True
    grid = OccupancyGrid.known((-1.0, -1.0), 0.1, occupied)
    waypoints, result = plan_on_grid(grid, (-0.85, -0.85), (-0.85, 0.85), PlannerParams(), robot_radius=0.15)
    assert result.reached
    np.testing.assert_allclose(waypoints[0], (-0.85, -0.85))
    np.testing.assert_allclose(waypoints[-1], (-0.85, 0.85))
    rows, cols = grid.world_to_cell(waypoints[:, 0], waypoints[:, 1])
    assert np.all(cols[rows == 10] >= 16)  # round the wall's end (column 14), more than 1.5 cells clear


# ---------------------------------------------------------------- against the textbook A*


grids = st.builds(
    lambda seed, rows, cols, density: (np.random.default_rng(seed), rows, cols, density),
    st.integers(0, 2**32 - 1), st.integers(2, 12), st.integers(2, 12), st.floats(0.0, 0.45))


def random_problem(case):
    rng, rows, cols, density = case
    p = np.where(rng.random((rows, cols)) < density, WALL, rng.uniform(0.05, 0.6, (rows, cols)))
    start, goal = ((int(rng.integers(rows)), int(rng.integers(cols))) for _ in range(2))
    p[start] = p[goal] = FREE
    return p, start, goal


@settings(max_examples=300, deadline=None)
@given(grids)
def test_same_cost_as_the_reference_astar(case):
    p, start, goal = random_problem(case)
    params = PlannerParams(heuristic="octile", weight_unexplored=0.3, weight_critical=0.2)
    costs = cost_maps(p, params)
    result = astar(costs, start, goal, "octile")
    reference = reference_astar(costs.blocked, costs.multiplier, start, goal)
    assert result.reached == (reference is not None)
    if reference is not None:
        assert result.cost == pytest.approx(reference[1], rel=1e-9)
        assert result.cost == pytest.approx(path_cost(result.cells, costs.multiplier), rel=1e-9)
        assert_valid_path(result.cells, costs.blocked, start)
        assert tuple(result.cells[-1]) == goal


@settings(max_examples=150, deadline=None)
@given(grids)
def test_thesis_heuristic_finds_valid_paths_no_cheaper_than_optimal(case):
    p, start, goal = random_problem(case)
    params = PlannerParams(heuristic="manhattan")
    costs = cost_maps(p, params)
    result = astar(costs, start, goal, "manhattan")
    reference = reference_astar(costs.blocked, costs.multiplier, start, goal)
    assert result.reached == (reference is not None)
    if reference is not None:
        assert_valid_path(result.cells, costs.blocked, start)
        assert result.cost >= reference[1] - 1e-9


@pytest.mark.parametrize("seed", range(6))
def test_batched_search_matches_the_reference_on_larger_grids(seed):
    # Grids big enough that the octile search's batches hold many cells and re-open some; seeds 4 and 5 wall the
    # goal in, so both searches exhaust the reachable cells and end on the same closest one.
    rng = np.random.default_rng(seed)
    size = 70
    p = np.where(rng.random((size, size)) < 0.25, WALL, rng.uniform(0.05, 0.6, (size, size)))
    start, goal = (1, 2), (size - 3, size - 2)
    p[start] = p[goal] = FREE
    if seed >= 4:
        p[goal[0] - 2:goal[0] + 3, goal[1] - 2] = p[goal[0] - 2, goal[1] - 2:] = p[goal[0] + 2, goal[1] - 2:] = WALL
    costs = cost_maps(p, PlannerParams(heuristic="octile"))
    result = astar(costs, start, goal, "octile")
    reference = reference_astar(costs.blocked, costs.multiplier, start, goal)
    assert_valid_path(result.cells, costs.blocked, start)
    assert result.cost == pytest.approx(path_cost(result.cells, costs.multiplier), rel=1e-9)
    if reference is None:
        assert not result.reached
        heap = astar(costs, start, goal, "euclidean")  # the one-at-a-time search also ends on the nearest cell
        assert tuple(result.cells[-1]) == tuple(heap.cells[-1])
    else:
        assert result.reached and tuple(result.cells[-1]) == goal
        assert result.cost == pytest.approx(reference[1], rel=1e-9)


def test_unknown_heuristic_is_refused():
    with pytest.raises(ValueError, match="heuristic"):
        astar(CostMaps(np.zeros((2, 2), bool), np.ones((2, 2))), (0, 0), (1, 1), heuristic="chebyshev")


# ---------------------------------------------------------------- the compiled heap search against plain Python


def python_heap_search(grid):
    """The thesis heuristics' search as the plain Python loop it was before it was compiled: (g, parent, closed,
    expansions)."""
    done = grid.blocked.tolist()
    g = [math.inf] * len(done)
    parent = [-1] * len(done)
    g[grid.source] = 0.0
    heap = [(grid.h[grid.source], grid.source)]
    expanded = 0
    while heap:
        _, node = heapq.heappop(heap)
        if done[node]:
            continue
        done[node] = True
        expanded += 1
        if node == grid.target:
            break
        moves = [(move, grid.multiplier[node + move], True) for move in grid.straight]
        moves += [(move, SQRT2 * grid.multiplier[node + move], not (grid.blocked[node + a] or grid.blocked[node + b]))
                  for move, a, b in grid.diagonal]
        for move, step, allowed in moves:
            nb = node + move
            if allowed and not done[nb] and g[node] + step < g[nb]:
                g[nb], parent[nb] = g[node] + step, node
                heapq.heappush(heap, (g[nb] + grid.h[nb], nb))
    return np.array(g), np.array(parent), np.array(done), expanded


@pytest.mark.parametrize("heuristic", ["manhattan", "euclidean"])
def test_compiled_heap_search_expands_as_the_python_loop(heuristic):
    # Uniform grids among them, where many cells tie on f and the order of the heap's tuples decides.
    rng = np.random.default_rng(31)
    for case in range(200):
        rows, cols = rng.integers(2, 45, 2)
        density = rng.uniform(0.0, 0.4)
        p = np.where(rng.random((rows, cols)) < density, WALL, rng.uniform(0.05, 0.6, (rows, cols)))
        if case % 4 == 0:
            p = np.where(p == WALL, WALL, FREE)
        start, goal = ((int(rng.integers(rows)), int(rng.integers(cols))) for _ in range(2))
        params = PlannerParams(heuristic=heuristic, weight_unexplored=0.3, weight_critical=0.2)
        grid = _padded(cost_maps(p, params, inflation_cells=rng.choice([0.0, 1.5])), start, goal, heuristic)
        g, parent, closed, expanded = _heap_search(grid)
        ref_g, ref_parent, ref_closed, ref_expanded = python_heap_search(grid)
        np.testing.assert_array_equal(g, ref_g)
        np.testing.assert_array_equal(parent, ref_parent)
        np.testing.assert_array_equal(closed, ref_closed)
        assert expanded == ref_expanded
