"""Robustness of the allocation to the VOTS summation weights: Chand ch.7 (§7.3-7.4), the five random robot sets of
Table 7.3 under the weight sets of Tables 7.1 (managers, planner) and 7.2 (explorers)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from teamsim.controllers.allocation.devolution import TIE_TOLERANCE, Suitability, allocate, task_value
from teamsim.controllers.allocation.spec import RobotSpec, load_tasks

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
    # §7.4.1: in sets (b), (c) and (e) W1-W4 choose a different robot from W5-W9, one with identical processing;
    # in (a) and (d) W1-W8 agree
    first, second = planner["W1"][0], planner["W5"][0]
    if robot_set in "bce":
        scores = Suitability(tasks(), team)
        proc = {r: scores.scores["any"][scores.ids.index(r)][0] for r in (first, second)}
        assert first != second and proc[first] == proc[second]
        assert planner["W5"] == planner["W9"]
    else:
        assert first == second


def manager_cases() -> dict:
    """(robot set, Table 7.1 weight set) -> the allocation with that manager VSW."""
    return {(robot_set, w): allocate(tasks(manager=w), robots(robot_set)) for robot_set in SETS for w in TABLE_7_1}


def test_the_same_managers_for_every_weight_set_but_three_cases():
    """§7.3: the same managers under every weight set of Table 7.1, MT2 to the best robot and MT1 to the second.
    Here that holds in 42 of the 45 (robot set, weight set) cases. Of the 3 others, two are exact ties and one is
    a real, if tiny, rank change (docs/decisions.md, allocation):

    - (c, W9) and (d, W9): under W9 (communication only) R1 and R2 score the same to the last bit (their
      communication is identical); the tie goes to the lowest ID, R1, which takes MT2, while R2 is the best robot
      under W1-W8 in these two sets;
    - (a, W1): no tie: R2's summed VOTSWS is 0.91206 and R1's 0.91177, a gap of 2.9e-4, five orders above the
      tie tolerance; R1 has the better processing and R2 the better sensing (as in Table 7.4), and under equal
      weights our VOTSWS FIS favours R2."""
    cases = manager_cases()
    selected = {robot_set: cases[robot_set, SELECTED["manager"]].managers for robot_set in SETS}
    differs = {case: allocation for case, allocation in cases.items() if allocation.managers != selected[case[0]]}
    assert set(differs) == {("a", "W1"), ("c", "W9"), ("d", "W9")}
    for robot_set in SETS:  # W9: an exact tie in every set, broken by file order: R1 ranks first and takes MT2
        ranking = cases[robot_set, "W9"].manager_ranking
        assert [r for r, _ in ranking] == ["R1", "R2"] and ranking[0][1] == ranking[1][1]
        assert cases[robot_set, "W9"].managers == {"M1": "R2", "M2": "R1"}
    for robot_set in "cd":  # ... which is not the W1-W8 choice in (c) and (d)
        assert {cases[robot_set, w].managers["M2"] for w in TABLE_7_1 if w != "W9"} == {"R2"}
    (first, v1), (second, v2) = cases["a", "W1"].manager_ranking
    assert (first, second) == ("R2", "R1") and 1e-4 < v1 - v2 < 1e-3 and v1 - v2 > 1e4 * TIE_TOLERANCE
    assert cases["a", "W1"].managers == {"M1": "R1", "M2": "R2"}


def test_no_id_order_could_keep_the_managers_under_w9():
    """Why the W9 ties are left to the lowest ID rather than broken to match §7.3: under W1-W8 the best manager
    is R1 in sets (b) and (e) and R2 in (c) and (d), so whichever of R1, R2 a W9 tie-break by ID prefers, two
    sets change. The same holds with Table 7.4's published scores fed to our VOTSWS FIS, which also puts R2
    first under W1 in set (a)."""
    cases = manager_cases()
    best = {robot_set: {cases[robot_set, w].manager_ranking[0][0] for w in TABLE_7_1 if w != "W9"}
            for robot_set in SETS}
    assert best == {"a": {"R1", "R2"}, "b": {"R1"}, "c": {"R2"}, "d": {"R2"}, "e": {"R1"}}
    assert {w for w in TABLE_7_1 if cases["a", w].manager_ranking[0][0] == "R2"} == {"W1"}
    # Table 7.4 [proc, comm, sense, act] of R1 and R2 in each set, with the thesis's requirements of M1 and M2
    table_7_4 = {"R1": ([.54, .53, .46, .46, .54], [.52, .54, .54, .51, .55]),
                 "R2": ([.53, .47, .54, .54, .53], [.54, .54, .54, .54, .52])}
    thesis = {t.id: t for t in tasks()}

    def summed(robot, k, w):
        proc, sense = table_7_4[robot]
        vots = np.array([[proc[k], .87, sense[k], .58]]) - [thesis[m].requirement for m in ("M1", "M2")]
        return float(task_value(vots, 0.0, np.array([TABLE_7_1[w]] * 2))[0].sum())

    published = {robot_set: {w: summed("R1", k, w) - summed("R2", k, w) for w in TABLE_7_1}
                 for k, robot_set in enumerate(SETS)}
    for robot_set in "be":
        assert all(published[robot_set][w] > 1e-3 for w in TABLE_7_1 if w != "W9")
    for robot_set in "cd":
        assert all(published[robot_set][w] < -1e-3 for w in TABLE_7_1 if w != "W9")
    assert published["a"]["W1"] < 0 < published["a"]["W5"]
    assert all(abs(published[robot_set]["W9"]) < TIE_TOLERANCE for robot_set in SETS)


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


# Fig 7.16 (one explorer) as §7.4 describes it. SAME: the robot the set keeps for every other weight set, which
# the spec does not name; (b) and (c) "differ only at W7".
SAME = "same"
FIG_7_16 = {
    "a": dict.fromkeys(TABLE_7_2, SAME),
    "b": {**dict.fromkeys(TABLE_7_2, SAME), "W7": "R3"},  # R3, R5 and R6 tie at W7: the lowest ID
    "c": {**dict.fromkeys(TABLE_7_2, SAME), "W7": "R5"},
    "d": {**dict.fromkeys(("W1", "W2", "W3", "W4", "W9"), "R3"), **dict.fromkeys(("W5", "W6", "W7", "W8"), "R7")},
    "e": dict.fromkeys(TABLE_7_2, SAME),
}
OUR_SAME = {"a": "R4", "b": "R5", "c": "R6", "e": "R5"}  # what SAME resolves to here
# Where teamsim differs from Fig 7.16 (docs/decisions.md, allocation): (robot set, weight set) -> our explorer.
# In set (d) R5 and R7 have the same actuation specification in Table 7.3 ([1.25, .25, .5, .1]) and both can
# plan (TD 0.5), so under W7 (actuation only) their V is equal and the thesis's own tie-break, the lowest ID,
# gives R5; the thesis reports R7.
FIG_7_16_DIFFERS = {("d", "W7"): "R5"}


def one_explorer(robot_set: str) -> dict:
    team = robots(robot_set)
    return {w: allocate(tasks(explorer=w, explorers=1), team) for w in TABLE_7_2}


@pytest.mark.parametrize("robot_set", SETS)
def test_one_explorer_follows_fig_7_16(robot_set):
    chosen = {w: allocation.workers["W2"] for w, allocation in one_explorer(robot_set).items()}
    assert all(len(robots_on) == 1 for robots_on in chosen.values()), chosen
    expected = {w: [FIG_7_16_DIFFERS.get((robot_set, w), OUR_SAME.get(robot_set) if r == SAME else r)]
                for w, r in FIG_7_16[robot_set].items()}
    assert chosen == expected
    if robot_set in "bc":  # the W7 robot is not the one kept elsewhere
        assert chosen["W7"] != chosen["W1"]


def test_one_explorer_ties_under_w7_go_to_the_lowest_id():
    """The W7 (actuation only) choices of Fig 7.16 are ties: the top robots have the same actuation surplus (to
    1e-15: different specifications can score 0.5 a few ulp apart) and TD, so the same V, and file order decides;
    only in set (d) does that differ from the thesis. Set (c) has no tie: R5 leads by 1.3e-3."""
    tied = {"a": ["R4", "R5", "R8"], "b": ["R3", "R5", "R6"], "d": ["R5", "R7"], "e": ["R5", "R7"]}
    for robot_set, names in tied.items():
        column = one_explorer(robot_set)["W7"].rtcm["W2"]
        top = [c for c in column if column[0].value - c.value <= TIE_TOLERANCE]
        assert [c.robot for c in top] == names, robot_set
        assert column[len(top)].value < column[0].value - 1e-3  # the next one is well below
        assert max(c.vots[3] for c in top) - min(c.vots[3] for c in top) < 1e-12
        assert {c.diversity for c in top} == {0.5}
    column = one_explorer("c")["W7"].rtcm["W2"]
    assert column[0].robot == "R5" and column[0].value - column[1].value > 1e-3
    actuation = {r.id: (r.operation_h, r.radius, r.speed, r.traversability) for r in robots("d")}
    assert actuation["R5"] == actuation["R7"]
    assert (("d", "W7") in FIG_7_16_DIFFERS) and FIG_7_16["d"]["W7"] == "R7"


# §7.4, three explorers: "W4 shares >= 2 robots with every other set. Sets (a) and (c) are identical for all
# weights; (b) 6 of 8 identical; (d) 4 of 8; (e) 5 of 8". Counted over W1-W8 (W4 included), ours gives those
# numbers; counted over the eight sets other than W4, ours is one lower in (b), (d) and (e).
THREE_EXPLORERS = {  # ours, per robot set: weight sets -> the three explorers
    "a": {"W1 W2 W3 W4 W5 W6 W7 W8 W9": {"R4", "R5", "R8"}},
    "b": {"W1 W2 W3 W4 W6 W7": {"R3", "R5", "R6"}, "W5 W8 W9": {"R3", "R5", "R8"}},
    "c": {"W1 W2 W3 W4 W5 W6 W7 W8 W9": {"R3", "R5", "R6"}},
    "d": {"W1 W2 W3 W4": {"R3", "R4", "R5"}, "W5 W8 W9": {"R3", "R4", "R7"}, "W6 W7": {"R3", "R5", "R7"}},
    "e": {"W1 W2 W3 W4 W7": {"R3", "R5", "R7"}, "W5 W6 W8 W9": {"R3", "R5", "R6"}},
}


@pytest.mark.parametrize("robot_set", SETS)
def test_three_explorers_as_section_7_4(robot_set):
    team = robots(robot_set)
    chosen = {w: set(allocate(tasks(explorer=w, explorers=3), team).workers["W2"]) for w in TABLE_7_2}
    assert chosen == {w: robots_on for names, robots_on in THREE_EXPLORERS[robot_set].items()
                      for w in names.split()}
    assert all(len(chosen[w] & chosen["W4"]) >= 2 for w in TABLE_7_2)
    same_as_w4 = sum(chosen[w] == chosen["W4"] for w in ("W1", "W2", "W3", "W4", "W5", "W6", "W7", "W8"))
    assert same_as_w4 == {"a": 8, "b": 6, "c": 8, "d": 4, "e": 5}[robot_set]
