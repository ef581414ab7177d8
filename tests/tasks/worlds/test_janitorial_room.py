"""The janitorial room's ground truth (teamsim.tasks.worlds.janitorial): sound, cans, dust and floor."""
from __future__ import annotations

import math

import numpy as np
import pytest

from teamsim.tasks.worlds.janitorial import Can, Cans, Floor, Furniture, detector_levels, rasterise


def levels(sources, ears=((0.0, 0.1), (0.0, -0.1)), heading=0.0, noise=0.0, seed=0):
    angles = np.array([heading + math.pi / 4, heading - math.pi / 4])
    axes = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    return detector_levels(np.array(ears), axes, np.array(sources, float).reshape(-1, 2), 1.0, 1.0, noise,
                           np.random.default_rng(seed))


def test_sound_falls_off_and_tells_left_from_right_and_front_from_back():
    near, far = levels([(1.0, 0.0)]).sum(), levels([(3.0, 0.0)]).sum()
    assert near > 2 * far > 0
    left, right = levels([(1.0, 1.0)])
    assert left > right  # a can ahead on the left is louder on the left detector
    ahead, behind = levels([(2.0, 0.0)]).sum(), levels([(-2.0, 0.0)]).sum()
    assert ahead > 3 * behind  # cardioid detectors facing forward
    assert levels([]).tolist() == [0.0, 0.0]  # every can silent


def test_sound_noise_is_relative_and_seeded():
    quiet = levels([(1.0, 0.0)])
    noisy = np.array([levels([(1.0, 0.0)], noise=0.2, seed=s) for s in range(400)])
    assert np.allclose(noisy.mean(axis=0), quiet, rtol=0.05)
    assert np.allclose(noisy.std(axis=0), 0.2 * quiet, rtol=0.2)
    assert np.array_equal(levels([(1.0, 0.0)], noise=0.2, seed=3), levels([(1.0, 0.0)], noise=0.2, seed=3))


def test_a_can_empties_after_the_emptier_is_held_at_it_and_falls_silent():
    cans = Cans([Can(1.0, 0.0, 0.15, "f1"), Can(-1.0, 0.0, 0.15, "f1", appears=50.0)], empty_time=5.0, reach=0.05)
    assert len(cans.sources("f1", 0.0)) == 1 and len(cans.sources("f1", 50.0)) == 2  # the second appears at 50 s
    tip = np.array([0.82, 0.0])  # 3 cm from the can's side
    for k in range(45):
        cans.hold("r2", tip, 0.1, 10.0 + 0.1 * k)
    assert cans.cans[0].emptied_at is None
    cans.hold("r2", tip, 1.0, 15.0)
    assert cans.cans[0].emptied_by == "r2" and len(cans.sources("f1", 15.0)) == 0
    cans.hold("r1", np.array([0.6, 0.0]), 10.0, 60.0)  # 25 cm off the second can: nothing
    assert cans.cans[1].emptied_at is None and not cans.all_emptied()


def test_an_object_is_dusted_when_the_arm_has_passed_its_accessible_sides():
    size = (4.0, 4.0)
    floor = Floor(size, 0.05, rasterise(size, 0.05, [(0.0, 0.0, 0.3, 0.3, 0.0)], []))
    furniture = Furniture([(0.0, 0.0, 0.3, 0.3, 0.0)], floor, spacing=0.1, reach=0.06, share=0.9, clearance=0.55)
    assert furniture.accessible[0].all()  # free on every side
    sweeps = {"south": lambda u: ((u, -0.5), (u, -0.2)), "north": lambda u: ((u, 0.5), (u, 0.2)),
              "east": lambda u: ((0.5, u), (0.2, u)), "west": lambda u: ((-0.5, u), (-0.2, u))}
    shares = []
    for k, side in enumerate(sweeps.values()):  # the arm across each edge in turn, swept along it
        for u in np.linspace(-0.3, 0.3, 13):
            hinge, tip = side(u)
            furniture.sweep(np.array(hinge), np.array(tip), float(k))
        shares.append(furniture.fraction(0))
    assert shares[0] == pytest.approx(10 / 24)  # a side's 6 points and the 2 nearest of each neighbouring side
    assert shares[1] < 0.9 and furniture.done_at == [2.0] and shares[3] == 1.0


def test_a_side_against_a_wall_is_not_accessible():
    size = (2.0, 2.0)
    box = (0.0, -0.7, 0.3, 0.3, 0.0)  # its south side 0 m from the south wall
    floor = Floor(size, 0.05, rasterise(size, 0.05, [box], []))
    furniture = Furniture([box], floor, spacing=0.1, reach=0.06, share=0.75, clearance=0.55)
    south = furniture.points[0][:, 1] < -0.99
    assert south.any() and not furniture.accessible[0][south].any()


def test_reachable_floor_excludes_walls_obstacles_and_closed_off_space_and_the_deck_cleans_a_rectangle():
    size = (3.0, 2.0)
    occupied = rasterise(size, 0.05, [(1.0, 0.0, 0.05, 1.0, 0.0)], [])  # a wall across: x > 1.05 is closed off
    floor = Floor(size, 0.05, occupied)
    floor.settle_reachable(0.27, np.array([[-1.0, 0.0]]), 0.08)
    xs, ys = floor.centres()
    assert not floor.reachable[xs > 1.05].any()
    assert floor.reachable[(np.abs(xs) < 0.2) & (np.abs(ys) < 0.2)].all()
    assert not floor.reachable[(xs < 0) & (np.abs(ys) > 1.0 - 0.15)].any()  # too near the walls for the deck
    floor.clean(np.array([0.0, 0.0]), math.pi / 2, 0.08, 0.2)  # facing north: 0.4 m across x, 0.16 m along y
    cleaned = floor.cleaned
    assert cleaned[(np.abs(xs) < 0.18) & (np.abs(ys) < 0.06)].all() and not cleaned[np.abs(ys) > 0.1].any()
    assert 0.0 < floor.share_cleaned() < 0.1
