"""Where a bog met is taken to lie (``bogs.keep_out``): a 3 m disc centred 3 m ahead of the spot, short of the
robot. Hand-worked on a 0.1 m grid from (-5, -5)."""
from __future__ import annotations

import math

import numpy as np

from teamsim.controllers.exploration.bogs import keep_out

ORIGIN, RESOLUTION, SHAPE = (-5.0, -5.0), 0.1, (100, 150)  # x from -5 to 10, y from -5 to 5


def inside(mask: np.ndarray, x: float, y: float) -> bool:
    return bool(mask[math.floor((y - ORIGIN[1]) / RESOLUTION), math.floor((x - ORIGIN[0]) / RESOLUTION)])


def test_the_disc_lies_ahead_of_the_spot_the_way_the_robot_went():
    """Met at (0, 0) going east, the robot 2 m back west: the disc is centred at (3, 0), radius 3 (the robot is 5 m
    from its centre, less its 0.5 m radius: more than 3)."""
    mask = keep_out([(0.0, 0.0, 0.0)], (-2.0, 0.0), 0.5, ORIGIN, RESOLUTION, SHAPE)
    assert inside(mask, 0.05, 0.05) and inside(mask, 5.95, 0.05) and inside(mask, 3.05, 2.95)
    assert not inside(mask, -0.15, 0.05) and not inside(mask, 6.15, 0.05) and not inside(mask, 3.05, 3.15)
    going_north = keep_out([(0.0, 0.0, math.pi / 2)], (0.0, -2.0), 0.5, ORIGIN, RESOLUTION, SHAPE)
    assert inside(going_north, 0.05, 2.95) and not inside(going_north, 2.95, 0.05)


def test_the_disc_shrinks_to_leave_the_robot_out():
    """The robot at (2, 0), radius 0.5, 1 m from the centre (3, 0): the disc's radius is 0.5."""
    mask = keep_out([(0.0, 0.0, 0.0)], (2.0, 0.0), 0.5, ORIGIN, RESOLUTION, SHAPE)
    assert inside(mask, 3.05, 0.05) and inside(mask, 3.45, 0.05)
    assert not inside(mask, 2.45, 0.05) and not inside(mask, 3.65, 0.05)
    assert not keep_out([(0.0, 0.0, 0.0)], (3.0, 0.0), 0.5, ORIGIN, RESOLUTION, SHAPE).any()  # on it: none
