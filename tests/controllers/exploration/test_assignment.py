"""Unit tests for local-environment assignment and mutual exclusion (Chand §6.3, §6.3.1, eq. 6.6-6.10,
Table 6.1)."""
from __future__ import annotations

import random

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamsim.controllers.exploration.assignment import (ExplorerState, Proposal, candidate_environments, cost,
                                                        mutual_exclusion, propose, utility, utility_factor)

# A strip of four environments, 10 m apart: 0 - 1 - 2 - 3.
STRIP_CENTRES = [(0.0, 0.0), (10.0, 0.0), (20.0, 0.0), (30.0, 0.0)]
STRIP_NEIGHBOURS = [[1], [0, 2], [1, 3], [2]]


def explorer(name="A", position=(0.0, 0.0), task_score=0.8, environment=0, bog_capable=False):
    return ExplorerState(name, position, task_score, bog_capable, environment)


# ---------------------------------------------------------------- candidates (Fig 6.7)

STATUS = ["UE", "assigned", "PE", "E", "UE", "PE"]
BOGGY = [False, False, True, False, True, False]


def test_bog_capable_explorers_get_the_available_boggy_environments():
    assert candidate_environments(STATUS, BOGGY, bog_capable=True) == [2, 4]


def test_bog_capable_explorers_fall_back_to_non_boggy_when_no_boggy_one_is_available():
    assert candidate_environments(STATUS, BOGGY, bog_capable=True, excluded={2, 4}) == [0, 5]


def test_other_explorers_get_available_non_boggy_environments_less_the_excluded():
    assert candidate_environments(STATUS, BOGGY, bog_capable=False) == [0, 5]  # 1 assigned and 3 explored: not offered
    assert candidate_environments(STATUS, BOGGY, bog_capable=False, excluded=(5,)) == [0]


# ---------------------------------------------------------------- utility (6.6)-(6.8)


def test_utility_factor_cases_by_hand():
    me = explorer(task_score=0.8, environment=0)
    weaker = explorer("B", (30, 0), task_score=0.6, environment=3)
    assert utility_factor(1, me, [weaker], STRIP_NEIGHBOURS) == pytest.approx(1 / 0.8)  # own neighbour: 1.25
    assert utility_factor(2, me, [weaker], STRIP_NEIGHBOURS) == pytest.approx(0.8)  # B's neighbour, 0.8 >= 0.6
    assert utility_factor(3, me, [weaker], STRIP_NEIGHBOURS) == 1.0  # B's own environment is not its neighbour
    assert utility_factor(0, me, [weaker], STRIP_NEIGHBOURS) == 1.0  # nor is mine


def test_a_stronger_neighbour_leaves_the_factor_at_one_and_equal_scores_count_as_stronger():
    me = explorer(task_score=0.8, environment=0)
    assert utility_factor(2, me, [explorer("B", (30, 0), 0.9, 3)], STRIP_NEIGHBOURS) == 1.0
    assert utility_factor(2, me, [explorer("B", (30, 0), 0.8, 3)], STRIP_NEIGHBOURS) == pytest.approx(0.8)


def test_own_neighbour_wins_when_both_cases_hold():
    me = explorer(task_score=0.8, environment=0)
    weaker = explorer("B", (20, 0), task_score=0.5, environment=2)  # environment 1 neighbours both 0 and 2
    assert utility_factor(1, me, [weaker], STRIP_NEIGHBOURS) == pytest.approx(1.25)


def test_an_explorer_with_no_environment_has_no_own_neighbours():
    me = explorer(task_score=0.8, environment=None)
    assert utility_factor(1, me, [], STRIP_NEIGHBOURS) == 1.0


def test_utility_is_limited_to_two_and_zero_when_explored():
    status = ["assigned", "UE", "E", "UE"]
    weak = explorer(task_score=0.4, environment=1)  # 1 / 0.4 = 2.5, limited to 2
    assert utility(0, weak, [], STRIP_NEIGHBOURS, ["UE"] * 4) == 2.0
    assert utility(1, explorer(task_score=0.8), [], STRIP_NEIGHBOURS, status) == pytest.approx(1.25)
    assert utility(2, weak, [], STRIP_NEIGHBOURS, status) == 0.0  # an own neighbour, but explored


# ---------------------------------------------------------------- cost (6.9)


def test_cost_by_hand_with_one_other_explorer():
    me, other = explorer(position=(0, 0)), explorer("B", (30, 0), 0.6, 3)
    candidates = [1, 2, 3]
    # dist = 10, 20, 30 (max 30); dbar to B = 20, 10, 0 (max 20)
    assert cost(1, me, [other], STRIP_CENTRES, candidates) == pytest.approx(0.9 * 10 / 30 + 0.1 * 0 / 20)  # 0.3
    assert cost(2, me, [other], STRIP_CENTRES, candidates) == pytest.approx(0.9 * 20 / 30 + 0.1 * 10 / 20)  # 0.65
    assert cost(3, me, [other], STRIP_CENTRES, candidates) == pytest.approx(0.9 * 30 / 30 + 0.1 * 20 / 20)  # 1.0


def test_cost_averages_the_distance_to_every_other_explorer():
    others = [explorer("B", (30, 0), 0.6, 3), explorer("C", (10, 10), 0.6, None)]
    # dbar(1) = (20 + 10) / 2 = 15 (the max); dbar(3) = (0 + sqrt(500)) / 2 = 11.180
    expected = 0.9 * 30 / 30 + 0.1 * (15 - 500 ** 0.5 / 2) / 15  # 0.92546
    assert cost(3, explorer(position=(0, 0)), others, STRIP_CENTRES, [1, 2, 3]) == pytest.approx(expected)


def test_cost_without_other_explorers_or_distance_is_the_remaining_term():
    assert cost(2, explorer(position=(0, 0)), [], STRIP_CENTRES, [1, 2, 3]) == pytest.approx(0.9 * 20 / 30)
    assert cost(1, explorer(position=(10, 0)), [], STRIP_CENTRES, [1]) == 0.0  # standing on the only centre
    assert cost(2, explorer(position=(0, 0)), [], STRIP_CENTRES, [1, 2, 3], w1=0.5, w2=0.5) == pytest.approx(1 / 3)


# ---------------------------------------------------------------- proposal (6.10)


def test_proposal_maximises_the_tradeoff_by_hand():
    me, other = explorer(position=(0, 0), task_score=0.8), explorer("B", (30, 0), 0.6, 3)
    status = ["assigned", "UE", "UE", "assigned"]
    # env 1: U = 1/0.8 = 1.25, C = 0.9 * 10/20 + 0.1 * (20 - 20)/20 = 0.45, T = 0.8
    # env 2: U = 0.8 (B's neighbour), C = 0.9 * 20/20 + 0.1 * (20 - 10)/20 = 0.95, T = -0.15
    proposal = propose(me, [other], STRIP_CENTRES, STRIP_NEIGHBOURS, [2, 1], status, job_id=7)
    assert proposal.environment == 1 and proposal.job_id == 7 and proposal.explorer == "A"
    assert proposal.tradeoff == pytest.approx(0.8)


def test_equal_tradeoffs_go_to_the_lowest_environment_index():
    me = explorer(position=(10, 0), task_score=1.0, environment=1)  # both ends: U = 1, C = 0.9
    proposal = propose(me, [], STRIP_CENTRES, STRIP_NEIGHBOURS, [2, 0], ["UE", "assigned", "UE", "UE"], job_id=1)
    assert proposal.environment == 0 and proposal.tradeoff == pytest.approx(0.1)


def test_no_candidates_no_proposal():
    assert propose(explorer(), [], STRIP_CENTRES, STRIP_NEIGHBOURS, [], ["UE"] * 4, job_id=1) is None


# ---------------------------------------------------------------- mutual exclusion (§6.3)


def test_mutual_exclusion_keeps_the_minimum_tradeoff_and_the_lowest_job_id_on_ties():
    proposals = [Proposal(3, "A", 1, 0.5), Proposal(1, "B", 1, 0.5), Proposal(2, "C", 1, 0.7),
                 Proposal(4, "D", 2, 0.9), Proposal(6, "E", 3, 1.1), Proposal(5, "F", 3, 0.2)]
    for seed in range(5):  # the result must not depend on the order the proposals arrive in
        shuffled = random.Random(seed).sample(proposals, len(proposals))
        kept = mutual_exclusion(shuffled)
        assert {env: p.job_id for env, p in kept.items()} == {1: 1, 2: 4, 3: 5}


# ---------------------------------------------------------------- Table 6.1

# A 4 x 4 grid of 9.6 m environments, row-major. The explorer is in environment 5 (neighbours 1, 4, 6, 9) and one
# other explorer in 15 (neighbours 11, 14); the rest neighbour neither.
SIDE = 9.6
GRID_CENTRES = [((i % 4 + 0.5) * SIDE, (i // 4 + 0.5) * SIDE) for i in range(16)]
GRID_NEIGHBOURS = [[j for j in range(16) if abs(j // 4 - i // 4) + abs(j % 4 - i % 4) == 1] for i in range(16)]
OWN, OTHERS, NEITHER = [1, 4, 6, 9], [11, 14], [0, 2, 3, 7, 8, 10, 12, 13]
CANDIDATES = [i for i in range(16) if i not in (5, 15)]

fraction = st.floats(0.01, 0.99)
# U class -> (environments, explorer TS range, T range, U check); TS ranges pick the class out of (6.8)
TABLE_6_1 = {
    "U=2": (OWN, (0.01, 0.5), (1, 2), lambda u: u == 2),
    "1<U<2": (OWN, (0.51, 0.99), (0, 2), lambda u: 1 < u < 2),
    "U=1": (NEITHER, (0.01, 1.0), (0, 1), lambda u: u == 1),
    "0<U<1": (OTHERS, (0.01, 0.99), (-1, 1), lambda u: 0 < u < 1),
    "U=0": (OWN + OTHERS + NEITHER, (0.01, 1.0), (-1, 0), lambda u: u == 0),
}


def in_range(row: str, t: float) -> bool:
    low, high = TABLE_6_1[row][2]
    closed_low = row in ("U=2", "U=1", "U=0")  # [1, 2), [0, 1), [-1, 0); the others are open
    return (low <= t if closed_low else low < t) and t < high


@pytest.mark.parametrize("row", list(TABLE_6_1))
@settings(max_examples=60, deadline=None)
@given(data=st.data(), w1=st.floats(0.01, 1.0))
def test_table_6_1_tradeoff_ranges(row, data, w1):
    envs, ts_range, _, u_check = TABLE_6_1[row]
    env = data.draw(st.sampled_from(envs))
    task_score = data.draw(st.floats(*ts_range))
    me = ExplorerState("A", (SIDE * (1 + data.draw(fraction)), SIDE * (1 + data.draw(fraction))), task_score,
                       False, 5)
    weaker = ExplorerState("B", (SIDE * (3 + data.draw(fraction)), SIDE * (3 + data.draw(fraction))),
                           task_score * data.draw(st.floats(0.01, 1.0)), False, 15)
    status = ["UE"] * 16
    status[5] = status[15] = "assigned"
    if row == "U=0":
        status[env] = "E"
    u = utility(env, me, [weaker], GRID_NEIGHBOURS, status)
    c = cost(env, me, [weaker], GRID_CENTRES, CANDIDATES, w1=w1, w2=1 - w1)
    assert u_check(u)
    assert 0 < c <= 1 + 1e-12
    assert in_range(row, u - c)
