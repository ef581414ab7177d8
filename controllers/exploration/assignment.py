"""A planner's local-environment assignment and the planners' mutual exclusion (Chand §6.3, §6.3.1, Fig 6.7,
eq. 6.6-6.10, Table 6.1).

Greedy, after Burgard et al.: an explorer is offered the available environment with the best utility-cost trade-off.
Candidates: a bog-capable explorer gets the available (UE or PE) boggy environments, or the non-boggy ones if there
are none; any other explorer gets the available non-boggy ones. A PE environment the explorer explored before is
never offered again (the manager's record, §6.4.2).
  (6.6) U_init = 1
  (6.7) U = limit(UF U_init), limit = clip to [0, 2]; U = 0 for an explored (E) environment
  (6.8) UF = 1/TS_ej  for the explorer's own neighbouring environments
        UF = TS_ej    for another explorer j''s neighbouring environments, if TS_ej >= TS_ej'
        UF = 1        otherwise
  (6.9) C = w1 dist / max(dist) + w2 (max(dbar) - dbar) / max(dbar), w1 = 0.9, w2 = 0.1,
        dist the explorer-to-environment distance, dbar the mean distance from the environment to the OTHER
        explorers, both maxima over the candidates
  (6.10) T = U - C, the proposal maximises T
Weak (low-TS) explorers so keep the environments next to them, and strong ones are pushed to distant ones. With
w1 + w2 = 1 and C in (0, 1], Table 6.1's ranges follow: U = 2 gives T in [1, 2), U = 1 gives [0, 1), U = 0 [-1, 0).
[RECON] Where (6.8)'s first two cases both hold the own-neighbour case wins (see ``utility_factor``). "Neighbouring"
means 4-connected neighbours of the environment the explorer is in or assigned, not that environment itself.
Mutual exclusion (§6.3): of the proposals for one environment the one with the MINIMUM trade-off is kept, ties to
the lowest job ID, exactly as printed, although each proposal maximises T; the losing planners propose again.
"""
from __future__ import annotations

from collections.abc import Collection, Iterable, Sequence
from dataclasses import dataclass

import numpy as np

AVAILABLE = ("UE", "PE")  # unexplored, partially explored; "assigned" and "E" are not on offer
EXPLORED = "E"


@dataclass(frozen=True)
class ExplorerState:
    name: str
    position: tuple[float, float]  # world (x, y), m
    task_score: float  # TS_ej in (0, 1] (5.21)
    bog_capable: bool
    environment: int | None  # the local environment it is in or assigned, whose neighbours are "its own"


@dataclass(frozen=True)
class Proposal:
    job_id: int
    explorer: str
    environment: int
    tradeoff: float  # T (6.10)


def candidate_environments(status: Sequence[str], boggy: Sequence[bool], bog_capable: bool,
                           excluded: Collection[int] = ()) -> list[int]:
    """Fig 6.7's candidate set: boggy environments first for bog-capable explorers, else non-boggy ones."""
    available = [env for env, state in enumerate(status) if state in AVAILABLE and env not in excluded]
    non_boggy = [env for env in available if not boggy[env]]
    if bog_capable:
        return [env for env in available if boggy[env]] or non_boggy
    return non_boggy


def _neighbours_of(explorer: ExplorerState, neighbours: Sequence[Sequence[int]]) -> Sequence[int]:
    return () if explorer.environment is None else neighbours[explorer.environment]


def utility_factor(env: int, explorer: ExplorerState, others: Sequence[ExplorerState],
                   neighbours: Sequence[Sequence[int]]) -> float:
    """(6.8) UF. An environment next to both this explorer and a weaker one gets 1/TS_ej: the own-neighbour case is
    listed first, and it is what keeps an explorer's near environments for it, so another explorer's nearness does
    not push this one away from its own surroundings (mutual exclusion settles a clash)."""
    if env in _neighbours_of(explorer, neighbours):
        return 1.0 / explorer.task_score
    if any(env in _neighbours_of(other, neighbours) and explorer.task_score >= other.task_score for other in others):
        return explorer.task_score
    return 1.0


def utility(env: int, explorer: ExplorerState, others: Sequence[ExplorerState],
            neighbours: Sequence[Sequence[int]], status: Sequence[str]) -> float:
    """(6.6)-(6.7) U = clip(UF U_init, 0, 2) with U_init = 1; 0 for an explored environment."""
    if status[env] == EXPLORED:
        return 0.0
    initial = 1.0  # (6.6)
    return float(np.clip(utility_factor(env, explorer, others, neighbours) * initial, 0.0, 2.0))


def _distance(a, b) -> float:
    return float(np.hypot(a[0] - b[0], a[1] - b[1]))


def _mean_distance_to(centre, others: Sequence[ExplorerState]) -> float:
    return float(np.mean([_distance(centre, other.position) for other in others]))


def cost(env: int, explorer: ExplorerState, others: Sequence[ExplorerState], centres: Sequence[Sequence[float]],
         candidates: Sequence[int], w1: float = 0.9, w2: float = 0.1) -> float:
    """(6.9) C: near environments are cheap (w1 term), and so are ones far from the other explorers (w2 term).
    A term whose maximum is 0 (or, for the w2 term, with no other explorers) is 0."""
    distances = [_distance(centres[c], explorer.position) for c in candidates]
    travel = _distance(centres[env], explorer.position) / max(distances) if max(distances) > 0 else 0.0
    crowding = 0.0
    if others:
        mean_distances = [_mean_distance_to(centres[c], others) for c in candidates]
        farthest = max(mean_distances)
        if farthest > 0:
            crowding = (farthest - _mean_distance_to(centres[env], others)) / farthest
    return w1 * travel + w2 * crowding


def tradeoff(env: int, explorer: ExplorerState, others: Sequence[ExplorerState], centres: Sequence[Sequence[float]],
             neighbours: Sequence[Sequence[int]], candidates: Sequence[int], status: Sequence[str],
             w1: float = 0.9, w2: float = 0.1) -> float:
    """(6.10) T = U - C."""
    return (utility(env, explorer, others, neighbours, status)
            - cost(env, explorer, others, centres, candidates, w1, w2))


def propose(explorer: ExplorerState, others: Sequence[ExplorerState], centres: Sequence[Sequence[float]],
            neighbours: Sequence[Sequence[int]], candidates: Sequence[int], status: Sequence[str], job_id: int,
            w1: float = 0.9, w2: float = 0.1) -> Proposal | None:
    """The candidate with the largest T (6.10), ties to the lowest environment index; None with no candidates."""
    scored = [(tradeoff(env, explorer, others, centres, neighbours, candidates, status, w1, w2), env)
              for env in sorted(candidates)]
    if not scored:
        return None
    best, env = max(scored, key=lambda pair: (pair[0], -pair[1]))
    return Proposal(job_id, explorer.name, env, best)


def mutual_exclusion(proposals: Iterable[Proposal]) -> dict[int, Proposal]:
    """§6.3: per environment, the proposal with the MINIMUM trade-off (as printed), ties to the lowest job ID."""
    kept: dict[int, Proposal] = {}
    for proposal in proposals:
        current = kept.get(proposal.environment)
        if current is None or (proposal.tradeoff, proposal.job_id) < (current.tradeoff, current.job_id):
            kept[proposal.environment] = proposal
    return kept
