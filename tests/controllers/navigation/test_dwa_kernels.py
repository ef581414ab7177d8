"""The dynamic window's compiled loops (dwa_kernels, through DynamicWindow's methods) against the plain Python
loops of reference_dwa, one candidate at a time, on random scenes: the same DC_cd and the same ST_v; the lazy
choice by the primary objective (best_primary) against scoring every candidate; and HRDU's compiled re-planning
test against the numpy form it replaced."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from teamsim.controllers.navigation import dwa_kernels as kernels
from teamsim.controllers.navigation.dynamic_window import (INVALID, DynamicWindow, DynamicWindowParams, Method,
                                                             can_stop_turning)
from teamsim.controllers.navigation.occupancy_grid import OccupancyGrid
from teamsim.controllers.navigation.reference_dwa import _braking_steps, _collision_distance, _stops_clear
from teamsim.models.robot import DriveLimits

LIMITS = DriveLimits(v_max=0.5, omega_max=math.pi / 7, accel_max=0.1, angular_accel_max=0.15)
WINDOWS = {"differential": DynamicWindow(LIMITS, "diffdrive", 0.35),
           "tricycle": DynamicWindow(LIMITS, "tricycle", 0.5, centre_offset=0.25)}


def scene(rng: np.random.Generator):
    v = rng.uniform(-0.3, 0.5, 56)
    omega = rng.uniform(-0.45, 0.45, 56)
    v[:5], omega[5:10] = 0.0, 0.0  # point turns, stops and straight lines too
    points = rng.uniform(-3.0, 3.0, (rng.integers(0, 150), 2))
    return v, omega, points, float(rng.uniform(0.0, 0.2))


@pytest.mark.parametrize("form", WINDOWS)
def test_collision_distances_match_the_reference(form):
    window, rng = WINDOWS[form], np.random.default_rng(11)
    for _ in range(100):
        v, omega, points, margin = scene(rng)
        r = window.radius + margin
        dist = np.hypot(points[:, 0], points[:, 1])
        kept = float(np.clip(dist.min() - r, 0.0, window.params.dc_max)) if len(points) else window.params.dc_max
        outside = [(x, y, d) for (x, y), d in zip(points, dist) if d >= window.radius]
        expected = [_collision_distance(a, w, outside, r, window.offset, kept, window.params.dc_max, window.radius)
                    for a, w in zip(v, omega)]
        np.testing.assert_allclose(window.collision_distances(v, omega, points, margin), expected, rtol=0,
                                   atol=1e-12)


@pytest.mark.parametrize("form", WINDOWS)
def test_stops_clear_matches_the_reference(form):
    window, rng = WINDOWS[form], np.random.default_rng(12)
    brake = min(window.params.a_a, window.limits.accel_max)
    checked = blocked = 0
    for _ in range(100):
        v, omega, points, margin = scene(rng)
        r = window.radius + margin
        dist = np.hypot(points[:, 0], points[:, 1])
        stop_points = [(x, y, r if d >= r else window.radius) for (x, y), d in zip(points, dist)
                       if d >= window.radius]
        steps = _braking_steps(float(np.abs(v).max()), brake, 2 * window.dt)
        expected = [_stops_clear(a, w, stop_points, window, steps) for a, w in zip(v, omega)]
        got = window.stops_clear(v, omega, points, margin)
        assert got.tolist() == expected
        checked += len(expected)
        blocked += expected.count(False)
    assert 0.1 * checked < blocked < 0.9 * checked  # the scenes test both outcomes


@pytest.mark.parametrize("form", WINDOWS)
@pytest.mark.parametrize("method", list(Method))
@pytest.mark.parametrize("beta1", [None, 0.1])
def test_best_primary_is_the_argmax_of_every_candidate_scored(form, method, beta1):
    """The lazy search (DC_cd and ST_v only for candidates that could still win) against scoring them all as
    (3.35), (3.38) and (3.39) print them, ties included (equal bases: the lowest index wins, as np.argmax). A
    clearance weight of 0.1 with DC_cdmax 3 is one where 0.1 * 3 / 3 rounds above 0.1: a bound taken as the
    weight itself fell an ulp short of a tying score."""
    kind, radius, offset = {"differential": ("diffdrive", 0.35, 0.0), "tricycle": ("tricycle", 0.5, 0.25)}[form]
    params = replace(DynamicWindowParams(), dcf=0.5)
    if beta1 is not None:
        params = replace(params, beta1_odw=beta1, beta1_odwds=beta1)
    window = DynamicWindow(LIMITS, kind, radius, method=method, centre_offset=offset, params=params)
    p, rng = window.params, np.random.default_rng(13)
    found = scaled = 0
    for _ in range(200):
        v, omega, points, margin = scene(rng)
        base = np.round(rng.uniform(0.0, 0.6, v.size), 1)  # few distinct values: many ties
        share = rng.choice([0.8, 0.05])  # at times only a few, none of them standing: maybe none stops clear
        admissible = rng.random(v.size) < share
        admissible[:5] &= share > 0.5
        steers = rng.random(v.size) < 0.3
        alpha_min = float(rng.choice([0.0, rng.uniform(0.01, 0.5)]))  # 0: omega at a window edge
        dc = window.collision_distances(v, omega, points, margin)
        if method is Method.FRC and window.tricycle:
            dc = np.where(steers, dc * p.dcf, dc)
        st_v = window.in_place(v, omega) | ((dc > 0) & window.stops_clear(v, omega, points, margin))
        if method.modified:
            value = np.where(dc > p.dc_min, base, p.alpha3 * base) if method is Method.FRC else base
        else:
            beta1 = p.beta1_odw if method is Method.ODW else p.beta1_odwds
            value = base + beta1 * dc / p.dc_max
            if not window.tricycle:
                with np.errstate(divide="ignore", invalid="ignore"):
                    st_v &= can_stop_turning(dc, omega, alpha_min)
        primary = np.where(admissible & st_v, value, INVALID)
        expected = int(np.argmax(primary)) if primary.max() > INVALID else -1
        best, score = window.best_primary(v, omega, base, admissible, steers, points, margin, alpha_min)
        assert best == expected
        if best >= 0:
            assert score == primary[best]
            found += 1
            scaled += bool(dc[best] <= p.dc_min)
    assert 20 < found < 200  # both outcomes
    assert method is not Method.FRC or scaled > 0  # and FRC's alpha_3 scaling chosen at times


def test_best_primary_keeps_a_tie_whose_clearance_term_rounds_above_its_weight():
    """(3.38) with beta_1 = 0.1 and DC_cdmax = 3: candidate 0 backs away free (DC_cd = DC_cdmax, so its score is
    base + 0.1 * 3 / 3, which rounds to 0.1 + 1 ulp) and candidate 1, with the higher base, drives at a point and
    scores exactly the same. np.argmax takes candidate 0; a bound of base + beta_1 fell an ulp short of its score
    and the search stopped before it."""
    b0, px = 0.0123, 1.025
    b1 = b0 + 0.1 * 3.0 / 3.0 - 0.1 * (px - 0.35) / 3.0
    assert b1 > b0 and b0 + 0.1 < b0 + 0.1 * 3.0 / 3.0  # the scene is the one the old bound got wrong
    best, score = kernels.best_primary(np.array([-0.2, 0.2]), np.zeros(2), np.array([b0, b1]), np.ones(2, bool),
                                       np.ones(2), np.array([px]), np.zeros(1), 0.35, 0.0, 10.0, 0.0, 0.1, 0.1,
                                       0.03, 3.0, 0.6, 1.0, 0.1, False, 0.0)
    assert (best, score) == (0, b0 + 0.1 * 3.0 / 3.0)


def test_memory_thinning_keeps_the_first_point_of_every_cell_as_np_unique_does():
    rng, kept, seen = np.random.default_rng(13), 0, 0
    for _ in range(50):
        spread, crowd = rng.integers(0, 200, 2)  # the crowd, 10 cm across, has many points in one 2 cm cell
        world = np.round(np.concatenate([rng.uniform(-3.0, 3.0, (spread, 2)), rng.uniform(-0.05, 0.05, (crowd, 2))]), 2)
        ox, oy, heading = rng.uniform(-2.0, 2.0, 3)
        c, s = math.cos(heading), math.sin(heading)
        cell = np.round(world / 0.02).astype(np.int64)
        cell -= cell.min(axis=0, initial=0)
        _, first = np.unique(cell[:, 0] * (cell[:, 1].max(initial=0) + 1) + cell[:, 1], return_index=True)
        dx, dy = world[first, 0] - ox, world[first, 1] - oy
        expected = np.column_stack([c * dx + s * dy - 0.25, -s * dx + c * dy]).reshape(-1, 2)
        got = kernels.thin_to_robot_frame(np.ascontiguousarray(world), 0.02, ox, oy, c, s, 0.25)
        np.testing.assert_array_equal(got, expected)
        kept, seen = kept + len(got), seen + len(world)
    assert kept < 0.9 * seen  # the scenes do have points to thin


def numpy_path_blocked(probabilities, ahead, origin, resolution, reach, threshold):
    """HRDU's re-planning test as numpy arrays, as it was before it was compiled: the oracle."""
    g = OccupancyGrid(origin, resolution, probabilities)
    g.probabilities = probabilities  # unclamped, as given
    rows, cols = g.world_to_cell(ahead[:, 0], ahead[:, 1])
    margin = int(math.ceil(reach / resolution))
    r0, c0 = max(int(rows.min()) - margin, 0), max(int(cols.min()) - margin, 0)
    window = probabilities[r0:int(rows.max()) + margin + 1, c0:int(cols.max()) + margin + 1]
    occupied_rows, occupied_cols = np.nonzero(window >= threshold)
    if occupied_rows.size == 0:
        return False
    x, y = g.cell_to_world(occupied_rows + r0, occupied_cols + c0)
    return bool((np.hypot(x[:, None] - ahead[:, 0], y[:, None] - ahead[:, 1]) <= reach).any())


def test_path_blocked_matches_the_numpy_form():
    # Paths on and off the grid (far beyond its edges too) and thresholds that some cells meet exactly.
    rng, blocked = np.random.default_rng(14), 0
    for _ in range(3000):
        shape = tuple(rng.integers(1, 30, 2))
        resolution = float(rng.choice([0.1, 0.3, rng.uniform(0.05, 0.5)]))
        origin = tuple(rng.uniform(-2.0, 2.0, 2))
        probabilities = np.round(rng.uniform(0.0, 1.0, shape), 1)
        centre = np.array(origin) + rng.uniform(-1.0, 2.0, 2) * np.array(shape[::-1]) * resolution
        ahead = centre + np.cumsum(rng.normal(0.0, resolution, (int(rng.integers(1, 21)), 2)), axis=0)
        reach, threshold = float(rng.uniform(0.0, 1.0)), float(rng.choice([0.7, 0.9, 1.0]))
        expected = numpy_path_blocked(probabilities, ahead, origin, resolution, reach, threshold)
        assert kernels.path_blocked(probabilities, ahead, *origin, resolution, reach, threshold) == expected
        blocked += expected
    assert 300 < blocked < 2700  # both answers are tested


def test_reading_points_by_hand():
    ranges = np.array([1.0, np.inf, 0.5, 0.25])
    bearings = np.array([0.0, math.pi / 2, math.pi / 2, math.pi])
    # sensors 0.3 m from a centre 0.1 m ahead of the reference point; the unseen reading marks nothing
    points = kernels.reading_points(ranges, bearings, np.array([0.3]), 0.1)
    np.testing.assert_allclose(points, [[1.4, 0.0], [0.1, 0.8], [-0.45, 0.0]], atol=1e-12)
    # one radius per sensor
    per_sensor = kernels.reading_points(ranges, bearings, np.array([0.3, 0.3, 0.5, 0.3]), 0.0)
    np.testing.assert_allclose(per_sensor, [[1.3, 0.0], [0.0, 1.0], [-0.55, 0.0]], atol=1e-12)
    with pytest.raises(ValueError):
        kernels.reading_points(ranges, bearings, np.array([0.3, 0.3]), 0.0)


def test_sector_nearest_by_hand():
    distance = np.array([2.0, 1.0, 3.0, 0.5])
    bearing = np.array([0.1, 0.5, 3.0, 2.0])  # |bearing|: ahead, ahead-left, behind, beside
    assert kernels.sector_nearest(distance, bearing, 0.6, 2.5, 3.1) == (1.0, 3.0, math.inf)
    assert kernels.sector_nearest(distance[:0], bearing[:0], 0.6, 2.5, 3.1) == (math.inf,) * 3


def test_primary_terms_by_hand():
    v, omega = np.array([0.25, 0.5]), np.array([0.0, 0.2])
    heading_term, base = kernels.primary_terms(v, omega, 0.5, 0.1, 0.15, 0.5, 2.0, 0.2)
    turned = 0.2 * 0.1 + 0.2 * 0.2 / (2 * 0.15)  # turned by the time the turn is stopped
    np.testing.assert_allclose(heading_term, [1 - 0.5 / math.pi, 1 - (0.5 - turned) / math.pi], rtol=1e-14)
    np.testing.assert_allclose(base, 2.0 * heading_term + 0.2 * np.array([0.5, 1.0]), rtol=1e-14)
    # a heading behind wraps: 3 rad off to the left minus a turn of -0.5 is 3.5, i.e. 2 pi - 3.5 to the right
    assert kernels.primary_terms(np.array([0.0]), np.array([-0.5]), 3.0, 1.0, 1e9, 0.5, 1.0, 0.0)[0][0] == \
        pytest.approx(1 - (2 * math.pi - 3.5) / math.pi)
