"""The planner (Chand §6.3, Fig 6.6): take a job from the manager, choose the explorer's next local environment by
(6.6)-(6.10), settle it with the other planners by distributed mutual exclusion, check its ECT acceptability when
environments run short (5.23, §6.4.3), and plan the explorer's path to the environment's centre with the
two-tiered A* (ch.4), round the environments assigned to others and, for a wheeled explorer, the boggy ones and
the bogs met (``bogs``).

Negotiation: a planner broadcasts its proposal to the other planners and waits ``negotiation`` s for theirs; of
the proposals for one environment the minimum trade-off wins, then the lowest job ID (§6.3); a planner that loses
proposes again without that environment. The winner broadcasts the assignment to planners and manager.

Map access: the two-tiered A* reads the manager's global map a local map at a time (§4.1). Its fetches are not
sent as packets; the plan goes out after they would have taken over the link (``TwoTierResult``'s
transmission time), the planning itself taking no simulated time (docs/decisions.md, "Exploration").
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from teamsim.controllers.exploration.assignment import (AVAILABLE, ExplorerState, Proposal,
                                                        candidate_environments, mutual_exclusion, propose)
from teamsim.controllers.exploration.bogs import keep_out
from teamsim.controllers.exploration.job_queue import ect_acceptable, estimated_completion_time
from teamsim.controllers.exploration.territory import SMALL_MESSAGE, Territory
from teamsim.controllers.navigation.two_tier_astar import TwoTierParams, two_tier_astar
from teamsim.network import Packet

PATH_NODE_BYTES = 16  # one (x, y) pair of doubles


@dataclass(frozen=True)
class PlannerParams:
    negotiation: float = 0.5  # s to wait for the other planners' proposals (not given; a few radio round trips)
    memories: int = 2  # Q, local-map memories of the two-tiered A* (§4.6 tests 1, 5 and 15)
    blocked: float = 0.95  # occupancy written over environments the path must avoid


@dataclass
class _Negotiation:
    job: dict
    proposal: Proposal
    until: float
    excluded: set = field(default_factory=set)


@dataclass
class PlannerAchievement:
    local_environment_assignments: int = 0
    global_path_plans: int = 0
    bytes: int = 0

    def by_category(self) -> dict[str, list[float]]:
        return {"plan": [self.local_environment_assignments, self.global_path_plans], "comm": [self.bytes]}


class Planner:
    def __init__(self, name: str, territory: Territory, *, manager: str, params: PlannerParams = PlannerParams()):
        self.name = name
        self.territory = territory
        self.manager = manager
        self.params = params
        self.jobs: list[dict] = []
        self.negotiation: _Negotiation | None = None
        self.heard: list[Proposal] = []  # other planners' proposals
        self.taken: dict[int, str] = {}  # environment -> explorer, confirmed by any planner
        self.delayed: list[tuple[float, Packet]] = []
        self.outbox: list[Packet] = []
        self.achievement = PlannerAchievement()

    def send(self, kind: str, payload: dict, size: int = SMALL_MESSAGE, to: str | None = None,
             at: float | None = None) -> None:
        packet = Packet(kind, payload, size, to)
        self.achievement.bytes += size
        if at is None:
            self.outbox.append(packet)
        else:
            self.delayed.append((at, packet))

    def receive(self, kind: str, payload: dict, size: int) -> None:
        self.achievement.bytes += size
        if kind == "job":
            self.jobs.append(payload)
        elif kind == "propose":
            self.heard.append(payload["proposal"])
        elif kind == "assigned":
            self.taken[payload["environment"]] = payload["explorer"]
        elif kind in ("released", "explored"):  # no longer anyone's
            self.taken.pop(payload["environment"], None)

    def report(self) -> dict[str, list[float]]:
        out = self.achievement.by_category()
        self.achievement = PlannerAchievement()
        return out

    # -- one control tick ---------------------------------------------------------------------------------------
    def step(self, now: float) -> None:
        due = [p for t, p in self.delayed if t <= now + 1e-9]
        self.delayed = [(t, p) for t, p in self.delayed if t > now + 1e-9]
        self.outbox.extend(due)
        if self.negotiation is not None:
            if now >= self.negotiation.until:
                self._settle(now)
            return
        if self.jobs:
            job = self.jobs.pop(0)
            if job["kind"] == "path":
                self._plan_path(job, job["environment"], now)
            else:
                self._propose(job, set(), now)

    def _propose(self, job: dict, excluded: set, now: float) -> None:
        explorer: ExplorerState = job["explorer"]
        status = [("assigned" if e in self.taken and self.taken[e] != explorer.name else s)
                  for e, s in enumerate(job["status"])]
        candidates = candidate_environments(status, job["boggy"], explorer.bog_capable,
                                            set(job["excluded"]) | excluded)
        proposal = None
        if candidates:
            proposal = propose(explorer, job["others"], self.territory.centres, self.territory.neighbour_lists,
                               candidates, status, job_id=job["job_id"])
        available = sum(state in AVAILABLE for state in status)  # the team's, not this explorer's candidates
        if proposal is None or not self._ect_acceptable(job, proposal, available):
            self.send("no-environment", {"job_id": job["job_id"], "explorer": explorer.name}, to=self.manager)
            return
        self.heard = [p for p in self.heard if p.environment != proposal.environment or p.job_id != job["job_id"]]
        self.send("propose", {"proposal": proposal})
        self.negotiation = _Negotiation(job, proposal, now + self.params.negotiation, excluded)

    def _ect_acceptable(self, job: dict, proposal: Proposal, available: int) -> bool:
        """§6.4.3: only when fewer environments remain than explorers; the manager's figures come with the job.
        ``available`` counts every available environment, as the manager's purge does, not only this explorer's
        candidates: a tracked explorer offered the one boggy environment left was otherwise refused, and retired,
        while dry ones remained (docs/decisions.md, "ECT when environments run short")."""
        figures = job["ect"]
        if available >= len(figures):
            return True
        new_area = job["unexplored"][proposal.environment]
        ects = {name: estimated_completion_time(f["time"], f["unexplored_current"], new_area, f["explored"],
                                                f["rate"], job["t_m"]) for name, f in figures.items()}
        return ect_acceptable(ects, proposal.explorer, available)

    def _settle(self, now: float) -> None:
        """Mutual exclusion over the proposals for our environment (§6.3)."""
        negotiation, self.negotiation = self.negotiation, None
        mine = negotiation.proposal
        rivals = [p for p in self.heard if p.environment == mine.environment]
        self.heard = [p for p in self.heard if p.environment != mine.environment]
        winner = mutual_exclusion([mine, *rivals])[mine.environment]
        if winner.job_id != mine.job_id or mine.environment in self.taken:
            self._propose(negotiation.job, negotiation.excluded | {mine.environment}, now)
            return
        self.taken[mine.environment] = mine.explorer
        self.achievement.local_environment_assignments += 1
        self.send("assigned", {"job_id": mine.job_id, "explorer": mine.explorer, "environment": mine.environment})
        self._plan_path(negotiation.job, mine.environment, now)

    def _plan_path(self, job: dict, environment: int, now: float) -> None:
        """The two-tiered A* to the environment's centre, round others' and (wheeled) boggy environments."""
        explorer: ExplorerState = job["explorer"]
        territory = self.territory
        global_map = np.array(job["global_map"], float)
        avoid = {e for e, who in self.taken.items() if who != explorer.name}
        if not explorer.bog_capable:
            avoid |= {e for e, boggy in enumerate(job["boggy"]) if boggy}
        start_environment = territory.environment_of(*explorer.position)
        for e in avoid - {environment, start_environment}:
            global_map[territory.slices(e)] = np.maximum(global_map[territory.slices(e)], self.params.blocked)
        if not explorer.bog_capable:  # and out of the bogs met in its own environment (``bogs``)
            bogs = keep_out(job["bog_points"], explorer.position, job["radius"], territory.origin,
                            territory.resolution, global_map.shape)
            global_map[bogs] = np.maximum(global_map[bogs], self.params.blocked)
        start, goal = territory.cell_of(*explorer.position), territory.cell_of(*territory.centre(environment))
        radius_cells = max(1, math.ceil(job["radius"] / territory.resolution))
        result = two_tier_astar(global_map, start, goal, territory.partition,
                                TwoTierParams(memories=self.params.memories, radius_cells=radius_cells))
        x0, y0 = territory.origin
        path = np.column_stack([x0 + (result.cells[:, 1] + 0.5) * territory.resolution,
                                y0 + (result.cells[:, 0] + 0.5) * territory.resolution]) \
            if len(result.cells) else np.zeros((0, 2))
        if not result.reached:  # on from the partial path's end reactively (§3.2.2)
            path = np.vstack([path, territory.centre(environment)])
        self.achievement.global_path_plans += 1
        self.send("plan", {"job_id": job["job_id"], "environment": environment, "path": path},
                  size=SMALL_MESSAGE + PATH_NODE_BYTES * len(path), to=explorer.name,
                  at=now + result.transmission_time)
        self.send("job-done", {"job_id": job["job_id"]}, to=self.manager, at=now + result.transmission_time)
