"""Contact: why box pushing needs both ends (Parker §6.1): pushed at one end only, the long box turns about its
other end rather than advancing; pushed at both ends in turn, it advances square.

The scenes are those of the box tests at the end of tests/contact/test_r2.py (the long box across y at the origin,
R-2s facing it 2 cm away, 0.15 m in from an end, seed 0), through the full World. The end points are the box's
ends on its centre line, from its pose, so a rigid turn about the unpushed end shows as that end standing still.
"""
from __future__ import annotations

import math

import numpy as np

from tests.contact.harness import run_for
from tests.contact.test_r2 import BOX, END_Y, box_pose, pushing, unstable_warnings

PUSH = 0.2  # m/s asked of a pushing R-2 (it moves slower against the box)


def ends(pose: np.ndarray) -> dict[str, np.ndarray]:
    """Where the left (+y) and right (-y) ends of the box's centre line are, for a box pose (x, y, yaw)."""
    x, y, yaw = pose
    along = np.array([-math.sin(yaw), math.cos(yaw)]) * BOX.length / 2
    return {"left": np.array([x, y]) + along, "right": np.array([x, y]) - along}


def moved(start: np.ndarray, end: np.ndarray) -> tuple[float, dict[str, float], float]:
    """(yaw change in degrees, each end's advance along +x, the centre's advance along +x)."""
    a, b = ends(start), ends(end)
    return (math.degrees(end[2] - start[2]), {k: float(b[k][0] - a[k][0]) for k in a},
            float(end[0] - start[0]))


def test_pushed_at_one_end_only_the_box_turns_about_the_other():
    """red pushes the left end for 10 s, nobody the right (Parker's box with pushing disabled at one end)."""
    world = pushing({"red": (END_Y, lambda o: (PUSH, 0.0))})
    start = box_pose(world)
    run_for(world, 10.0)
    yaw, advance, centre = moved(start, box_pose(world))
    assert unstable_warnings(world) == []
    assert advance["left"] > 0.1  # the pushed end went a good way (measured 0.20 m)
    assert yaw < -5.0  # pushing the left (+y) end along +x turns the box clockwise (measured -7.7 degrees)
    # It pivots about the unpushed end: that end hardly moves (measured 1.4 mm), and the centre goes half as far
    # as the pushed end, as a rigid turn about the far end gives (not the full distance of a translation).
    assert abs(advance["right"]) < 0.1 * advance["left"]
    assert 0.35 * advance["left"] < centre < 0.65 * advance["left"]
    # The turn accounts for the pushed end's travel: length x sin(yaw), within 20 %.
    assert abs(advance["left"] - BOX.length * math.sin(-math.radians(yaw))) < 0.2 * advance["left"]


def test_pushed_at_both_ends_in_turn_the_box_advances_square():
    """The same pushes shared: red and green push their ends 4 s each in turn, twice each (16 s, 8 s of pushing
    per end where the lone pusher had 10 s)."""
    period = 4.0

    def turn_of(k):
        return lambda o: (PUSH if int(o.time // period) % 2 == k else 0.0, 0.0)

    world = pushing({"red": (END_Y, turn_of(0)), "green": (-END_Y, turn_of(1))})
    start = box_pose(world)
    run_for(world, 4 * period)
    yaw, advance, centre = moved(start, box_pose(world))
    assert unstable_warnings(world) == []
    assert min(advance.values()) > 0.1  # both ends went forward (measured 0.19 and 0.17 m)
    assert abs(yaw) < 2.0  # and the box stayed square (measured -0.6 degrees): far less than the lone push's turn
    assert centre > 0.1 and abs(advance["left"] - advance["right"]) < 0.3 * centre
