"""Unit tests for the manager's global map update and environment status (Chand §6.4.2, eq. 6.15-6.19)."""
from __future__ import annotations

import numpy as np
import pytest

from teamsim.controllers.exploration.global_map import (EXPLORED_THRESHOLD, environment_status, explored_fraction,
                                                        merge)
from teamsim.controllers.navigation.occupancy_grid import bayes_update

CELL = {".": 0.05, "#": 0.95, "?": 0.5}  # explored free, occupied, unexplored


def drawn(*rows: str) -> np.ndarray:
    return np.array([[CELL[c] for c in row] for row in rows])


# ---------------------------------------------------------------- merge (6.15)


def test_merge_by_hand():
    # 0.8 * 0.7 / (0.56 + 0.2 * 0.3) = 0.56 / 0.62; 0.2 and 0.8 cancel to 0.5;
    # 0.95 * 0.95 / (0.9025 + 0.0025) = 0.9972, clamped to 0.95
    np.testing.assert_allclose(merge(np.array([0.8, 0.2, 0.95]), np.array([0.7, 0.8, 0.95])),
                               [0.56 / 0.62, 0.5, 0.95])
    assert merge(np.array([0.05]), np.array([0.05]))[0] == 0.05  # 0.0028 unclamped


def test_merge_of_certain_inputs_is_clamped_not_nan():
    np.testing.assert_allclose(merge(np.array([0.0]), np.array([1.0])), [0.5])  # 0.05 and 0.95 after the clamp


def test_a_new_map_of_one_half_leaves_the_old_one_unchanged():
    old = np.random.default_rng(0).uniform(0.05, 0.95, (8, 8))
    np.testing.assert_allclose(merge(old, np.full((8, 8), 0.5)), old)


def test_sending_only_new_evidence_reproduces_the_senders_map():
    first, second = 0.6, 0.65  # two pieces of occupied evidence, sent one at a time
    on_sender = bayes_update(bayes_update(0.5, first), second)
    on_manager = merge(merge(np.array([0.5]), np.array([first])), np.array([second]))
    assert on_manager[0] == pytest.approx(on_sender)
    resent_cumulative = merge(merge(np.array([0.5]), np.array([first])), np.array([on_sender]))
    # odds 1.5 * 1.857 = 2.786 (0.736) on the sender; resending it on top of 0.6: odds 4.18 (0.807)
    assert resent_cumulative[0] > on_sender + 0.05  # the first piece counted twice


# ---------------------------------------------------------------- explored area (6.16)-(6.17)

BOX = ("..........??",
       "..........??",
       "..########..",
       "..#??????#..",
       "..#??????#..",
       "..#??????#..",
       "..#??????#..",
       "..#??????#..",
       "..#??????#..",
       "..########..",
       "............",
       "............")


def test_the_inside_of_a_box_is_not_counted_but_open_unexplored_cells_are():
    # The four "?" at the top right are open (none touches the outline): 1 - 4/144. The 36 inside the box cannot
    # be reached (counting them would give 1 - 40/144 = 0.722).
    assert explored_fraction(drawn(*BOX)) == pytest.approx(1 - 4 / 144)


@pytest.mark.parametrize("gap", ["..###?####..", "..##??####.."])
def test_an_outline_with_a_one_or_two_cell_gap_still_encloses(gap):
    # The gap cells are unexplored but lie in the dilated wall, so neither they nor the inside are counted.
    assert explored_fraction(drawn(BOX[0], BOX[1], gap, *BOX[3:])) == pytest.approx(1 - 4 / 144)


def test_an_unexplored_room_behind_a_three_cell_opening_is_counted():
    room = drawn(".........",
                 ".........",
                 "###???###",
                 *["?????????"] * 6)
    # Dilation closes the opening's outer cells and the room's cells under the wall ends (row 3, columns 0-2 and
    # 6-8): reached are (2, 4), row 3's columns 3-5 and rows 4-8 whole, 1 + 3 + 45 = 49 of 81.
    assert explored_fraction(room) == pytest.approx(1 - 49 / 81)
    closed = room.copy()
    closed[2, 3], closed[2, 5] = 0.95, 0.95  # a one-cell opening: closed
    assert explored_fraction(closed) == 1.0


def test_an_open_map_counts_every_unexplored_cell():
    assert explored_fraction(drawn("..??", "..??", "..??", "..??")) == 0.5  # 1 - 8/16


def test_with_no_explored_free_cell_nothing_is_explored_unless_all_is_occupied():
    assert explored_fraction(drawn("????", "????")) == 0.0
    assert explored_fraction(drawn("##??", "##??")) == 0.0
    assert explored_fraction(drawn("####", "####")) == 1.0


def test_the_occupied_threshold_decides_what_is_a_wall():
    room = drawn("....", "....", "....", "....", "????", "????")
    room[3, :] = 0.68  # weak occupied evidence along one row: below the default P_T = 0.7 the flood passes it
    assert explored_fraction(room) == pytest.approx(1 - 8 / 24)
    assert explored_fraction(room, occupied=0.65) == 1.0  # a wall now: the unexplored rows beyond are shut off


# ---------------------------------------------------------------- status (6.18)-(6.19)


def test_status_is_explored_at_or_above_the_threshold():
    assert EXPLORED_THRESHOLD == 0.9
    assert environment_status(0.9) == "E" and environment_status(0.8999) == "PE"
    assert environment_status(0.5, ea_threshold=0.5) == "E" and environment_status(0.49, ea_threshold=0.5) == "PE"
