"""Unit tests for the occupancy grid (Chand §3.2.1, §6.2.2, eq. 6.3-6.5): frames, the sensor model, Bayes'
rule, clamping and the IR beam update; the compiled update against the numpy form it replaced, bit for bit, and a
reading's evidence shared between grids."""
from __future__ import annotations

import math

import numpy as np
import pytest

from teamsim.controllers.navigation.occupancy_grid import (MappingParams, OccupancyGrid, _numpy_sum, bayes_update,
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


# ---------------------------------------------------------------- evidence, apply, and the compiled loop


def _libm(function):
    """``function`` (from :mod:`math`: the C library's) elementwise over an array. numpy's own float64 log, exp,
    sin and cos, which it uses on CPUs with AVX-512, may differ from the C library's in the last bit; the compiled
    update uses the C library's everywhere, so the oracle does too."""
    ufunc = np.frompyfunc(function, 1, 1)
    return lambda a: np.asarray(ufunc(np.asarray(a, float)), dtype=float)


log, exp, cos, sin, tan = (_libm(f) for f in (math.log, math.exp, math.cos, math.sin, math.tan))


def numpy_update(g, pose, ranges, bearings, *, sensor_radius, centre_offset=0.0, footprint_radius=0.0):
    """The update as numpy arrays over (beams, rows, cols), as it was before it was compiled: the oracle."""
    def logit(q):
        return log(q / (1.0 - q))

    p = g.params
    x, y, heading = (float(v) for v in pose)
    ranges, bearings = np.asarray(ranges, float), np.asarray(bearings, float)
    cx, cy = x + centre_offset * cos(heading), y + centre_offset * sin(heading)
    ux, uy = cos(heading + bearings), sin(heading + bearings)
    sx, sy = cx + sensor_radius * ux, cy + sensor_radius * uy
    rows, cols = g.window(cx, cy, float(np.max(sensor_radius)) + p.range_max + g.resolution)
    if rows.size == 0 or cols.size == 0:
        return
    wx, wy = g.cell_to_world(rows[:, None], cols[None, :])
    dx, dy = wx[None] - sx[:, None, None], wy[None] - sy[:, None, None]
    along = dx * ux[:, None, None] + dy * uy[:, None, None]
    across = np.abs(dx * uy[:, None, None] - dy * ux[:, None, None])
    half_width = np.maximum(along * tan(p.beam_angle / 2), g.resolution / 2)
    in_beam = (along > 0) & (across <= half_width) & (along <= p.range_max)
    hit = np.isfinite(ranges) & (ranges < p.range_max)
    measured = np.where(hit, ranges, p.range_max)[:, None, None]
    if p.hit_cell == "beyond":
        free = in_beam & (along < measured)
        occupied = in_beam & hit[:, None, None] & (along >= measured) & (along < measured + g.resolution)
    else:
        free = in_beam & (along < measured - g.resolution / 2)
        occupied = in_beam & hit[:, None, None] & (np.abs(along - measured) <= g.resolution / 2)
    q_free = p_free_given_free(along, p)
    q_occ = p_occupied_given_occupied(sensor_noise(measured, p), g.resolution, g.resolution)
    evidence = (np.where(free & (q_free < 0.5), logit(q_free), 0.0).sum(axis=0)
                + np.where(occupied & (q_occ > 0.5), logit(q_occ), 0.0).sum(axis=0))
    if footprint_radius > 0:
        evidence += np.where(np.hypot(wx - cx, wy - cy) <= footprint_radius, logit(np.asarray(p.p_free_near)), 0.0)
    block = np.ix_(rows, cols)
    posterior = 1.0 / (1.0 + exp(-(logit(g.probabilities[block]) + evidence)))
    g.probabilities[block] = np.clip(posterior, p.p_min, p.p_max)


def random_reading(rng):
    """A grid (random frame, parameters and probabilities), and a reading on it: (grid, pose, ranges, bearings,
    keyword arguments). Some robots stand off the grid, some grids are a single cell (numpy then sums a cell's
    beams pairwise), and some readings have many beams."""
    params = MappingParams(beam_angle=np.radians(rng.uniform(2.0, 12.0)), range_min=rng.choice([0.0, 0.05]),
                           range_max=rng.uniform(0.8, 2.0), p_free_near=rng.uniform(0.1, 0.3),
                           p_free_far=rng.uniform(0.4, 0.6), noise_min=rng.uniform(0.0, 0.01),
                           noise_max=rng.uniform(0.01, 0.05), hit_cell=rng.choice(["around", "beyond"]))
    resolution = rng.choice([0.1, 0.3, rng.uniform(0.05, 0.5)])
    shape = (1, 1) if rng.random() < 0.1 else tuple(rng.integers(1, 40, 2))
    origin = tuple(rng.uniform(-3.0, 3.0, 2))
    g = OccupancyGrid(origin, resolution, rng.uniform(0.05, 0.95, shape), params)
    size = np.array(shape[::-1]) * resolution
    x, y = np.array(origin) + rng.uniform(-0.5, 1.5, 2) * size
    beams = int(rng.choice([0, 1, 5, 8, 11, 14, 20, 150]))
    ranges = rng.uniform(0.0, 1.2 * params.range_max, beams)
    ranges[rng.random(beams) < 0.3] = np.inf
    ranges[rng.random(beams) < 0.05] = params.range_max
    radius = rng.uniform(0.0, 0.6, beams) if rng.random() < 0.5 and beams else rng.uniform(0.0, 0.6)
    kwargs = dict(sensor_radius=radius, centre_offset=rng.choice([0.0, rng.uniform(-0.3, 0.3)]),
                  footprint_radius=rng.choice([0.0, rng.uniform(0.1, 0.6)]))
    return g, (x, y, rng.uniform(-np.pi, np.pi)), ranges, rng.uniform(-np.pi, np.pi, beams), kwargs


def test_compiled_update_is_the_numpy_update_bit_for_bit():
    rng, changed, single = np.random.default_rng(21), 0, 0
    for _ in range(1500):
        g, pose, ranges, bearings, kwargs = random_reading(rng)
        expected = OccupancyGrid(g.origin, g.resolution, g.probabilities.copy(), g.params)
        numpy_update(expected, pose, ranges, bearings, **kwargs)
        before = g.probabilities.copy()
        g.update(pose, ranges, bearings, **kwargs)
        np.testing.assert_array_equal(g.probabilities, expected.probabilities)
        changed += not np.array_equal(before, g.probabilities)
        single += g.shape == (1, 1) and len(ranges) >= 8 and not np.array_equal(before, g.probabilities)
    assert changed > 900 and single > 10  # the readings do map something, single cells with many beams among them


def test_numpy_sum_is_numpys_pairwise_summation():
    rng = np.random.default_rng(22)
    for n in list(range(40)) + [127, 128, 129, 130, 200, 255, 256, 257, 300, 1000]:
        values = rng.normal(0.0, 1.0, n) * 10.0 ** rng.uniform(-3, 3, n)
        assert _numpy_sum(values) == values.reshape(-1, 1, 1).sum(axis=0)[0, 0]


def test_evidence_leaves_the_grid_and_applies_to_any_grid_of_its_frame():
    a, b = grid(), grid()
    b.probabilities[:] = np.random.default_rng(23).uniform(0.05, 0.95, b.shape)
    expected = OccupancyGrid(b.origin, b.resolution, b.probabilities.copy())
    reading = ((0.3, -0.2, 0.4), np.array([1.0, np.inf, 0.6]), np.array([0.0, 1.0, -1.0]))
    kwargs = dict(sensor_radius=np.array([0.2, 0.25, 0.3]), centre_offset=0.1, footprint_radius=0.3)
    evidence = a.evidence(*reading, **kwargs)
    assert np.all(a.probabilities == 0.5)
    assert evidence.pose == (0.3, -0.2, 0.4) and evidence.frame == a.frame
    assert a.probabilities[evidence.rows, evidence.cols].shape == evidence.log_odds.shape
    b.apply(evidence)
    expected.update(*reading, **kwargs)
    np.testing.assert_array_equal(b.probabilities, expected.probabilities)


def test_evidence_of_another_frame_is_refused():
    evidence = grid().evidence((0.0, 0.0, 0.0), np.array([1.0]), np.array([0.0]), sensor_radius=0.2)
    for other in (grid(resolution=0.2), grid(origin=(-3.0, -3.05)), grid(shape=(60, 61)),
                  OccupancyGrid.unexplored((-3.05, -3.05), 0.1, (60, 60), MappingParams(hit_cell="beyond"))):
        with pytest.raises(ValueError, match="evidence"):
            other.apply(evidence)
