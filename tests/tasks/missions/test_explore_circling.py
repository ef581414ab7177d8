"""A lone explorer that circled for good (docs/results/exploration-10, [1 1], 10 % world 5): the tracked Robot4, in
a 1.7 m gap between a box and the world's north wall with its path 1 m ahead, turned round and round in a 0.15 m
circle from 780 s to the end, which explored 45.9 % of the world. HRDU's turn to the path after poor progress
(``Replanning.turn_to_path``) gets it out. Kinematic, as the study runs it."""
from __future__ import annotations

import math

from teamsim.config import TrialConfig
from teamsim.tasks.missions.explore import ExploreParams, kinematic_trial

WORLD_5 = ExploreParams(team="1 1", density=0.1, bog_share=0.0, world_seed=1759083768, backend="kinematic")
WHERE_IT_CIRCLED = (0.2, 18.3)


def test_the_lone_explorer_leaves_the_gap_it_circled_in():
    run = kinematic_trial(TrialConfig(mission="explore", params=WORLD_5, seed=0), 1100.0)
    late = [(x, y) for t, x, y in run["team"].members["Robot4"].trail if t >= 800.0]
    farthest = max(math.dist(p, WHERE_IT_CIRCLED) for p in late)
    assert farthest > 3.0  # measured: 0.21 m circling, 21.5 m with the turn
    assert run["metrics"]["explored_share"] > 0.25  # measured: 0.165 circling, 0.323 with the turn
