"""Chand's exploration worlds (teamsim.tasks.worlds.exploration, §6.1, §8.2): density and bog share, bogs clear of
the base, the 16 local environments and their geometry, start poses, determinism and the parameter checks."""
from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np
import pytest

from teamsim.config import ConfigError
from teamsim.models.arenas import Bog
from teamsim.scenario import Obstacle
from teamsim.tasks.worlds.exploration import THESIS_DENSITIES, ExploreWorldParams, explore_world, thesis_world
from teamsim.tasks.worlds.navigation import clearance

PARAMS = ExploreWorldParams()
TEAM_RADII = (0.6, 0.5, 0.4, 0.4, 0.4, 0.67)  # Robots 4, 2, 5, 7, 6 (Ch.8) and Robot C


@functools.cache
def world(density=0.10, bog_share=0.05, seed=0):
    return explore_world(ExploreWorldParams(density=density, bog_share=bog_share), np.random.default_rng(seed))


@pytest.mark.parametrize("density", THESIS_DENSITIES)
def test_obstacle_density_is_reached(density):
    for seed in range(3):
        assert world(density, seed=seed).nav.density == pytest.approx(density, abs=0.005)


@pytest.mark.parametrize("density", THESIS_DENSITIES)
def test_bogs_cover_their_share_inside_the_world_clear_of_the_base_on_free_ground(density):
    for seed in range(3):
        w = world(density, seed=seed)
        assert w.bogs and w.bog_raster().mean() == pytest.approx(0.05, abs=0.015)
        half = w.nav.size / 2
        for bog in w.bogs:
            assert abs(bog.x) + bog.half_x <= half + 1e-9 and abs(bog.y) + bog.half_y <= half + 1e-9
            assert Obstacle("box", bog.x, bog.y, bog.half_x, bog.half_y).distance(*w.base) >= PARAMS.base_radius
            assert clearance(w.nav, bog.x, bog.y) >= PARAMS.robot_radius
            assert PARAMS.bog_side_range[0] - 1e-9 <= 2 * bog.half_x <= PARAMS.bog_side_range[1] + 1e-9
            edges = (np.array([bog.x - bog.half_x, bog.y - bog.half_y, bog.x + bog.half_x, bog.y + bog.half_y])
                     + half) / PARAMS.resolution
            np.testing.assert_allclose(edges, np.round(edges), atol=1e-9)  # on cell edges


def test_a_world_without_bog_share_has_no_bogs():
    w = world(bog_share=0.0)
    assert w.bogs == () and not w.bog_raster().any() and w.boggy_environments() == frozenset()


def test_the_base_is_a_clear_corner_facing_the_world():
    w = world(0.15)
    half = w.nav.size / 2
    assert w.base == pytest.approx((-half + PARAMS.base_radius, half - PARAMS.base_radius))
    assert clearance(w.nav, *w.base) >= PARAMS.base_radius - 1e-9
    assert w.nav.start[2] == pytest.approx(math.atan2(-w.base[1], -w.base[0]))  # towards the world's centre


def test_sixteen_local_environments_of_32_by_32_cells():
    w = world()
    assert w.nav.occupancy.shape == (128, 128) == (w.territory.cells, w.territory.cells)
    assert w.territory.environments == 16
    covered = np.zeros(w.nav.occupancy.shape, int)
    for index in range(w.territory.environments):
        assert w.nav.occupancy[w.territory.slices(index)].shape == (32, 32)
        covered[w.territory.slices(index)] += 1
    assert (covered == 1).all()  # the environments tile the raster


def test_bounds_centres_and_environment_of_agree():
    w = world()
    area = 0.0
    territory = w.territory
    for index in range(territory.environments):
        (x_lo, y_lo), (x_hi, y_hi) = territory.bounds(index)
        assert x_hi - x_lo == pytest.approx(9.6) and y_hi - y_lo == pytest.approx(9.6)
        area += (x_hi - x_lo) * (y_hi - y_lo)
        assert territory.centre(index) == pytest.approx(((x_lo + x_hi) / 2, (y_lo + y_hi) / 2))
        assert territory.environment_of(*territory.centre(index)) == index
        for x, y in ((x_lo + 1e-6, y_lo + 1e-6), (x_hi - 1e-6, y_hi - 1e-6)):
            assert territory.environment_of(x, y) == index
    assert area == pytest.approx(38.4 ** 2)
    assert territory.bounds(0)[0] == pytest.approx((-19.2, -19.2))  # row-major from the lowest y
    assert territory.bounds(1)[0] == pytest.approx((-9.6, -19.2))
    assert territory.environment_of(19.2, 19.2) == 15  # the far walls belong to the cells inside them
    assert territory.environment_of(*w.base) == 12  # the top-left corner
    assert territory.environment_of(19.3, 0.0) == territory.environment_of(19.1, 0.0) == 11  # outside: clamped
    assert territory.environment_of(-25.0, -25.0) == 0


def test_boggy_environments_are_those_with_a_boggy_cell_and_in_bog_agrees_with_the_raster():
    for seed in range(3):
        w = world(seed=seed)
        raster = w.bog_raster()
        from_raster = {i for i in range(w.territory.environments) if raster[w.territory.slices(i)].any()}
        assert from_raster and w.boggy_environments() == from_raster
        grid = w.nav.known_map()
        rows, cols = np.indices(raster.shape)
        xs, ys = grid.cell_to_world(rows.ravel(), cols.ravel())
        assert [w.in_bog(x, y) for x, y in zip(xs, ys)] == raster.ravel().tolist()


def test_a_bog_marks_the_environments_it_covers_not_those_it_touches():
    w = world(bog_share=0.0)
    bog = Bog(-9.6 - 1.2, 0.0, 1.2, 1.2)  # ends on the border between environments 8 and 9; straddles 4 and 8
    touching = dataclasses.replace(w, bogs=(bog,))
    assert touching.boggy_environments() == {4, 8}
    assert touching.in_bog(-9.6, 0.0) and not touching.in_bog(-9.5, 0.0)


def test_start_poses_fit_the_clear_zone_without_overlap_and_face_the_world():
    w = world(0.15)
    poses = w.start_poses(TEAM_RADII)
    assert poses == w.start_poses(TEAM_RADII)
    for k, ((x, y, heading), radius) in enumerate(zip(poses, TEAM_RADII)):
        assert clearance(w.nav, x, y) >= radius
        assert math.dist((x, y), w.base) + radius <= PARAMS.base_radius
        assert heading == pytest.approx(w.nav.start[2])
        for (ox, oy, _), other in zip(poses[k + 1:], TEAM_RADII[k + 1:]):
            assert math.dist((x, y), (ox, oy)) >= radius + other


def test_a_team_too_big_for_the_base_is_refused():
    with pytest.raises(ConfigError, match="base_radius"):
        world().start_poses([0.67] * 12)


def test_same_seed_same_world_and_different_seed_different_world():
    a = world(seed=5)
    b = explore_world(ExploreWorldParams(density=0.10, bog_share=0.05), np.random.default_rng(5))
    c = world(seed=6)
    assert a.nav.boxes == b.nav.boxes and a.bogs == b.bogs
    np.testing.assert_array_equal(a.nav.occupancy, b.nav.occupancy)
    assert a.nav.boxes != c.nav.boxes and a.bogs != c.bogs


def test_obstacles_are_spread_over_every_environment():
    for seed in range(3):
        w = world(0.10, seed=seed)
        shares = [w.nav.occupancy[w.territory.slices(i)].mean() for i in range(w.territory.environments)]
        assert min(shares) > 0.0 and max(shares) < 0.25


def test_thesis_worlds_are_fixed_and_distinct():
    a, b = thesis_world(0.10, True, 3), thesis_world(0.10, True, 3)
    assert a.nav.boxes == b.nav.boxes and a.bogs == b.bogs and a.bogs
    assert thesis_world(0.10, True, 4).nav.boxes != a.nav.boxes
    plain = thesis_world(0.10, False, 3)
    assert plain.bogs == () and plain.nav.boxes != a.nav.boxes
    assert thesis_world(0.15, False, 0).nav.density == pytest.approx(0.15, abs=0.005)


@pytest.mark.parametrize("density, index, field", [(0.2, 0, "density"), (0.05, 10, "index"), (0.05, -1, "index")])
def test_thesis_world_refuses_what_the_thesis_did_not_run(density, index, field):
    with pytest.raises(ConfigError, match=field):
        thesis_world(density, False, index)


@pytest.mark.parametrize("change, field", [
    ({"size": 0.0}, "size"),
    ({"size": 4.8}, "size 4.8 m is too small for divisions 4"),
    ({"divisions": 0}, "divisions"),
    ({"resolution": 0.0}, "resolution"),
    ({"resolution": 0.7}, "resolution"),  # not a whole number of cells
    ({"divisions": 5}, "divisions"),  # 128 cells do not split into 5
    ({"size": 9.6, "resolution": 4.8, "divisions": 2, "bog_side_range": (4.8, 4.8)}, "resolution"),  # 1 cell
    ({"density": -0.01}, "density"),
    ({"density": 0.16}, "density"),
    ({"bog_share": 0.31}, "bog_share"),
    ({"bog_side_range": (6.0, 3.6)}, "bog_side_range"),
    ({"bog_side_range": (3.6, 12.0)}, "bog_side_range"),
    ({"base_radius": 0.5}, "base_radius"),  # smaller than a robot
    ({"base_radius": 9.7}, "base_radius"),  # more than a quarter of the world
])
def test_check_names_the_bad_field(change, field):
    params = ExploreWorldParams(**change)
    with pytest.raises(ConfigError, match=field):
        params.check()
    with pytest.raises(ConfigError, match=field):
        explore_world(params, np.random.default_rng(0))


def test_the_defaults_and_the_edges_of_what_is_allowed_pass_check():
    for params in (PARAMS, ExploreWorldParams(density=0.0, bog_share=0.3), ExploreWorldParams(density=0.15),
                   ExploreWorldParams(divisions=1),
                   ExploreWorldParams(base_radius=9.6),
                   ExploreWorldParams(size=9.6, divisions=2, base_radius=2.4, bog_side_range=(3.6, 4.8))):
        params.check()


def test_density_above_the_thesis_densest_is_refused_saying_why():
    with pytest.raises(ConfigError, match=r"density=0\.2: allowed: 0 to 0\.15 \(.*no passage\)"):
        ExploreWorldParams(density=0.2).check()
