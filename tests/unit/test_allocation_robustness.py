"""Robustness of the allocation to the VOTS summation weights: Chand ch.7 (§7.3-7.4), the five random robot sets of
Table 7.3 under the weight sets of Tables 7.1 (managers, planner) and 7.2 (explorers)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from teamsim.controllers.allocation_spec import RobotSpec, load_tasks
from teamsim.controllers.devolution import Suitability, allocate, task_value

SETS = "abcde"
# Table 7.3, per robot and set: processing, IR count (1.5 m, 360 deg), actuation. R1-R2: 802.11g [54, 100];
# R3-R8: 802.11b [11, 100].
TABLE_7_3 = {
    "R1": [((3.1, 1, "pc"), 12, (2.00, .60, .5, .3)), ((2.1, 1, "pc"), 13, (2.00, .60, .5, .3)),
           ((2.1, .5, "pc"), 13, (2.00, .60, .5, .1)), ((2.1, .5, "pc"), 11, (2.00, .60, .5, .3)),
           ((3.1, 1, "pc"), 14, (2.00, .60, .4, 1))],
    "R2": [((2.1, 1, "pc"), 13, (2.00, .60, .5, .1)), ((3.1, .5, "pc"), 13, (2.00, .60, .5, .1)),
           ((3.1, 1, "pc"), 13, (2.00, .60, .5, .1)), ((3.1, 1, "pc"), 13, (2.00, .60, .4, 1)),
           ((2.1, 1, "pc"), 12, (2.00, .60, .4, 1))],
    "R3": [((6, 4, "mc"), 12, (1.06, .25, .4, 1)), ((10, 16, "mc"), 12, (1.50, .40, .5, .1)),
           ((10, 16, "mc"), 12, (1.19, .25, .5, .3)), ((10, 16, "mc"), 13, (1.19, .25, .5, .3)),
           ((10, 16, "mc"), 13, (1.19, .25, .5, .3))],
    "R4": [((10, 16, "mc"), 14, (1.50, .40, .5, .1)), ((6, 4, "mc"), 13, (0.95, .15, .5, .3)),
           ((6, 4, "mc"), 12, (0.95, .15, .5, .3)), ((10, 16, "mc"), 12, (1.19, .25, .5, .3)),
           ((6, 2, "mc"), 13, (0.85, .15, .4, 1))],
    "R5": [((10, 16, "mc"), 13, (1.50, .40, .5, .1)), ((10, 16, "mc"), 13, (1.43, .40, .5, .3)),
           ((10, 16, "mc"), 12, (1.25, .25, .5, .1)), ((10, 16, "mc"), 11, (1.25, .25, .5, .1)),
           ((10, 16, "mc"), 14, (1.50, .40, .5, .1))],
    "R6": [((6, 4, "mc"), 12, (1.06, .25, .4, 1)), ((10, 16, "mc"), 11, (1.43, .40, .5, .3)),
           ((10, 16, "mc"), 14, (1.19, .25, .5, .3)), ((6, 2, "mc"), 11, (1.19, .25, .5, .3)),
           ((6, 4, "mc"), 13, (1.19, .25, .5, .3))],
    "R7": [((6, 2, "mc"), 13, (1.43, .40, .5, .3)), ((6, 2, "mc"), 11, (1.43, .40, .5, .3)),
           ((6, 4, "mc"), 12, (1.06, .25, .4, 1)), ((6, 4, "mc"), 13, (1.25, .25, .5, .1)),
           ((10, 16, "mc"), 11, (1.25, .25, .5, .1))],
    "R8": [((6, 4, "mc"), 13, (1.25, .25, .5, .1)), ((6, 4, "mc"), 12, (1.19, .25, .5, .3)),
           ((10, 16, "mc"), 10, (1.19, .25, .5, .3)), ((6, 4, "mc"), 11, (0.95, .15, .5, .3)),
           ((10, 16, "mc"), 10, (1.06, .25, .4, 1))],
}
TABLE_7_1 = {"W1": (.25, .25, .25, .25), "W2": (.3, .3, .2, .2), "W3": (.4, .4, .1, .1), "W4": (.45, .45, .05, .05),
             "W5": (.5, .5, 0, 0), "W6": (.75, .25, 0, 0), "W7": (1, 0, 0, 0), "W8": (.25, .75, 0, 0),
             "W9": (0, 1, 0, 0)}
TABLE_7_2 = {"W1": (.25, .25, .25, .25), "W2": (.2, .2, .3, .3), "W3": (.1, .1, .4, .4), "W4": (.05, .05, .45, .45),
             "W5": (0, 0, .5, .5), "W6": (0, 0, .25, .75), "W7": (0, 0, 0, 1), "W8": (0, 0, .75, .25),
             "W9": (0, 0, 1, 0)}
SELECTED = {"manager": "W5", "planner": "W3", "explorer": "W4"}  # §7.3-7.4
FIG_7_14 = {"a": {"R3", "R4", "R5", "R6", "R8"}, "b": {"R3", "R5", "R6", "R7", "R8"},
            "c": {"R3", "R5", "R6", "R7", "R8"}, "d": {"R3", "R4", "R5", "R6", "R7"},
            "e": {"R3", "R5", "R6", "R7", "R8"}}


def robots(robot_set: str) -> list[RobotSpec]:
    k = SETS.index(robot_set)
    out = []
    for name, rows in TABLE_7_3.items():
        (benchmark, memory, kind), ir, act = rows[k]
        comm = (54, 100) if name in ("R1", "R2") else (11, 100)
        out.append(RobotSpec(name, "", kind, benchmark, memory, *comm, ir, 1.5, 360, *act))
    return out


def tasks(manager=SELECTED["manager"], planner=SELECTED["planner"], explorer=SELECTED["explorer"], explorers=5):
    thesis = {t.id: t for t in load_tasks()}
    return [replace(thesis["M1"], vsw=TABLE_7_1[manager]), replace(thesis["M2"], vsw=TABLE_7_1[manager]),
            replace(thesis["W1"], vsw=TABLE_7_1[planner], quantity=(1, 1, 5)),
            replace(thesis["W2"], vsw=TABLE_7_2[explorer], quantity=(explorers, 1, 5))]


@pytest.mark.parametrize("robot_set", SETS)
def test_the_same_five_explorers_for_every_weight_set_fig_7_14(robot_set):
    team = robots(robot_set)
    chosen = {w: set(allocate(tasks(explorer=w), team).workers["W2"]) for w in TABLE_7_2}
    assert all(explorers == FIG_7_14[robot_set] for explorers in chosen.values()), chosen


@pytest.mark.parametrize("robot_set", SETS)
def test_the_same_planner_across_w1_w4_and_across_w5_w8(robot_set):
    team = robots(robot_set)
    planner = {w: allocate(tasks(planner=w), team).workers["W1"] for w in TABLE_7_1}
    assert len({tuple(planner[w]) for w in ("W1", "W2", "W3", "W4")}) == 1
    assert len({tuple(planner[w]) for w in ("W5", "W6", "W7", "W8")}) == 1
    assert planner["W9"] == ["R3"]  # communication only: every candidate ties and the lowest ID wins (§7.4.1)


def test_the_same_managers_for_every_weight_set_but_three_ties():
    """§7.3: the same managers under every weight set of Table 7.1, MT2 to the best robot and MT1 to the second.
    Here that holds in 42 of the 45 (robot set, weight set) cases. The 3 others are ties: under W9 (communication
    only) R1 and R2 have equal VOTSWS and file order decides (R1 first), which differs from W1-W8 in sets (c) and
    (d); under W1 in set (a) their summed VOTSWS differ by less than 0.001 (our scores: R1 better processing, R2
    better sensing; the thesis's Table 7.4 has the same pattern and its FIS tipped the other way)."""
    differs = {}
    for robot_set in SETS:
        team = robots(robot_set)
        selected = allocate(tasks(), team).managers
        for w in TABLE_7_1:
            allocation = allocate(tasks(manager=w), team)
            if allocation.managers != selected:
                differs[robot_set, w] = [v for _, v in allocation.manager_ranking]
    assert set(differs) == {("a", "W1"), ("c", "W9"), ("d", "W9")}
    assert differs["c", "W9"][0] == differs["c", "W9"][1] and differs["d", "W9"][0] == differs["d", "W9"][1]
    assert abs(differs["a", "W1"][0] - differs["a", "W1"][1]) < 1e-3


def test_mt2_is_harder_and_goes_to_the_best_robot():
    """§7.3: MT2 asks more, so its VOTSWS is the lower (the thesis: MT1 > 0.4, MT2 < 0.3; our absolute values
    differ, as for Table 5.28) and it goes to the best-ranked robot, MT1 to the second."""
    for robot_set in SETS:
        allocation = allocate(tasks(), robots(robot_set))
        suitability = Suitability(tasks(), robots(robot_set))
        best = allocation.manager_ranking[0][0]
        assert allocation.managers["M2"] == best
        j = suitability.ids.index(best)
        values = []
        for task_id in ("M1", "M2"):
            vots, capable = suitability.vots([task_id])
            values.append(task_value(vots[j:j + 1], 0.0, np.array([TABLE_7_1["W5"]]))[0][0])
        assert values[1] < values[0]


def test_one_explorer_in_set_d_follows_the_weights_as_fig_7_16():
    # R3 has the better processing (W1-W4), R7 the better sensing and actuation (W5-W8), and under W9 (sensing
    # only) they tie and the lower ID, R3, wins.
    team = robots("d")
    chosen = {w: allocate(tasks(explorer=w, explorers=1), team).workers["W2"] for w in TABLE_7_2}
    assert chosen == {w: ["R3"] if w in ("W1", "W2", "W3", "W4", "W9") else ["R7"] for w in TABLE_7_2}
