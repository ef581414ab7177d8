"""The manager (Chand §6.4, Figs 6.8-6.11): the global information (management task M1) and the feedback system
(M2), each on the robot the primary devolution gave it.

M1, ``GlobalInfo``:
- the job queue (6.11)-(6.14): explorers' requests become jobs, sorted, purged when environments run short and
  dispatched to the free planners by task score; each job carries the figures the planner needs (statuses,
  terrain, the explorers' positions and scores, ECT figures, the global map to fetch local maps from);
- the global map: explorers' local maps merged by (6.15); an explored environment's status from its explored
  fraction by (6.16)-(6.19); a bog report marks its environment boggy (the terrain map, §6.1) and is kept as a
  point for the planners; a non-bog-capable explorer's bog cells are reset to 0.5;
- faults (Fig 6.9): an explorer removed by feedback loses its jobs and its environment is reset by how well it was
  explored (E, PE or UE) and released to the planners; a removed planner's active jobs go back to the queue;
- an environment open again (released, or explored only in part) wakes the explorers that had finished for want of
  one and could take it: they ask again (docs/decisions.md, "Finished explorers wake up").
M2, ``FeedbackSystem``: every T_m, the workers' reports go through the ch.5 monitor and reallocation
(``FeedbackCoordinator``); the new task scores (5.21)-(5.22) and any new roles are broadcast.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from teamsim.controllers.allocation.feedback_coordination import FeedbackCoordinator, FeedbackStep, Report
from teamsim.controllers.exploration.assignment import ExplorerState
from teamsim.controllers.exploration.global_map import EXPLORED_THRESHOLD, environment_status, explored_fraction, merge
from teamsim.controllers.exploration.job_queue import JobQueue
from teamsim.controllers.exploration.territory import SMALL_MESSAGE, Territory
from teamsim.network import Packet

EXPLORER, PLANNER = "W2", "W1"  # the worker tasks of Table 5.20
BOG_TURNS = 2  # a wheeled explorer turned back by bogs this often on its way to an environment gives it up
WAKE_WAIT = 10.0  # s a woken explorer has to ask again before it counts as finished (it may be dead or deaf)


@dataclass
class ExplorerRecord:
    position: tuple[float, float]
    bog_capable: bool
    radius: float
    environment: int | None = None
    excluded: set = field(default_factory=set)  # PE environments it explored (§6.4.2), ones it gave up
    bog_turns: dict = field(default_factory=dict)  # environment -> times a bog turned it back on the way there
    started: float | None = None  # s, first assignment
    explored_cells: float = 0.0  # from its reports, for ECT's A_o


class GlobalInfo:
    """M1 on its robot. ``radii``: each robot's enclosing radius (the planner plans with it); ``rates``: each
    explorer's predicted exploration rate E_o, cells/s (its RA' per T_m over T_m)."""

    def __init__(self, name: str, territory: Territory, *, explorers: list[str], planners: list[str],
                 task_scores: dict[str, dict[str, float]], bog_capable: dict[str, bool], radii: dict[str, float],
                 rates: dict[str, float], t_m: float, explored_threshold: float = EXPLORED_THRESHOLD):
        self.name = name
        self.territory = territory
        self.global_map = np.full((territory.cells, territory.cells), 0.5)
        self.status = ["UE"] * territory.environments
        self.boggy = [False] * territory.environments
        self.bog_points: list[tuple[float, float, float]] = []  # where explorers met bogs, the way they went
        self.explored = np.zeros(territory.environments)  # EA (6.17) at the last integration
        self.explorers = list(explorers)
        self.planners = list(planners)
        self.task_scores = task_scores
        self.bog_capable, self.radii, self.rates = bog_capable, radii, rates
        self.t_m = t_m
        self.threshold = explored_threshold
        self.records: dict[str, ExplorerRecord] = {}
        self.queue = JobQueue()
        self.busy: set[str] = set()
        self.finished: set[str] = set()
        self.woken: dict[str, float] = {}  # explorer -> when it was woken, until it asks again
        self.outbox: list[Packet] = []
        self.log: list[dict] = []  # what the mission measures and draws: (time, event, ...)

    def send(self, kind: str, payload: dict, to: str | None = None, size: int = SMALL_MESSAGE) -> None:
        self.outbox.append(Packet(kind, payload, size, to))

    # -- messages -----------------------------------------------------------------------------------------------
    def receive(self, sender: str, kind: str, payload: dict, now: float) -> None:
        handler = getattr(self, "_on_" + kind.replace("-", "_"), None)
        if handler is not None:
            handler(sender, payload, now)

    def _on_request(self, sender: str, payload: dict, now: float) -> None:
        if sender not in self.explorers or sender in self.finished:
            return
        self.woken.pop(sender, None)
        record = self.records.setdefault(sender, ExplorerRecord(tuple(payload["position"]), self.bog_capable[sender],
                                                                self.radii[sender]))
        record.position = tuple(payload["position"])
        given_up = payload.get("give_up")
        if payload["kind"] == "environment" and given_up is not None:
            self._release(given_up, sender, now)
            # Not this robot again: it could not get there, or a bog turned it back twice on the way.
            record.bog_turns[given_up] = record.bog_turns.get(given_up, 0) + bool(payload.get("bog"))
            if not payload.get("bog") or record.bog_turns[given_up] >= BOG_TURNS:
                record.excluded.add(given_up)
            record.environment = None
        elif payload["kind"] == "environment" and record.environment is not None:
            # It asks anew without giving up what it was given: it never took that up (its plan came while it
            # backed out of a bog and was dropped: kill seed 206), so it goes back, not excluded.
            self._release(record.environment, sender, now)
            record.environment = None
        self.queue.request(sender, payload["kind"])

    def _on_map(self, sender: str, payload: dict, now: float) -> None:
        for environment, local in payload["maps"].items():
            rows, cols = self.territory.slices(environment)
            self.global_map[rows, cols] = merge(self.global_map[rows, cols], local)

    def _on_reset(self, sender: str, payload: dict, now: float) -> None:
        self.global_map[payload["rows"], payload["cols"]] = 0.5

    def _on_bog(self, sender: str, payload: dict, now: float) -> None:
        environment = payload["environment"]
        self.bog_points.append((*payload["position"], payload["heading"]))
        if not self.boggy[environment]:
            self.boggy[environment] = True
            self.log.append({"t": now, "event": "bog", "robot": sender, "environment": environment})

    def _on_done(self, sender: str, payload: dict, now: float) -> None:
        environment = payload["environment"]
        status = self._integrate(environment)
        self.log.append({"t": now, "event": "explored", "robot": sender, "environment": environment,
                         "status": status, "explored": round(float(self.explored[environment]), 4)})
        self.records[sender].environment = None
        # The planners forget whose it was: a PE environment is on offer to the others again (§6.4.2)
        self.send("explored", {"environment": environment, "status": status})
        if status == "PE":
            self.records[sender].excluded.add(environment)
            self._wake(environment, now)

    def _on_assigned(self, sender: str, payload: dict, now: float) -> None:
        environment, explorer = payload["environment"], payload["explorer"]
        if explorer not in self.explorers:
            # Removed while a planner settled its request: the environment was never its, and nothing would ever
            # release it (the run went on to MET with it "assigned": kill seeds 130 and 146, docs/decisions.md).
            self.send("released", {"environment": environment, "status": self.status[environment]})
            self.log.append({"t": now, "event": "released", "robot": explorer, "environment": environment,
                             "status": self.status[environment]})
            return
        self.status[environment] = "assigned"
        record = self.records.get(explorer)
        if record is not None:
            record.environment = environment
            record.started = now if record.started is None else record.started
        self.log.append({"t": now, "event": "assigned", "robot": explorer, "environment": environment,
                         "planner": sender})

    def _on_no_environment(self, sender: str, payload: dict, now: float) -> None:
        self._job_done(sender, payload["job_id"])
        self._finish(payload["explorer"], now, "no environment for it")

    def _on_job_done(self, sender: str, payload: dict, now: float) -> None:
        self._job_done(sender, payload["job_id"])

    def _on_report(self, sender: str, payload: dict, now: float) -> None:
        if sender in self.records and EXPLORER in payload["tasks"]:
            self.records[sender].explored_cells += payload["tasks"][EXPLORER]["sense"][0]
            self.records[sender].position = tuple(payload["position"])

    def _on_scores(self, sender: str, payload: dict, now: float) -> None:
        self.task_scores = payload["task_scores"]

    def _on_roles(self, sender: str, payload: dict, now: float) -> None:
        """Feedback reallocated the workers: explorers and planners that left are faults (Fig 6.9)."""
        workers = payload["workers"]
        for explorer in sorted(set(self.explorers) - set(workers.get(EXPLORER, []))):  # not a set's hash order
            self._explorer_fault(explorer, now)
        for planner in sorted(set(self.planners) - set(workers.get(PLANNER, []))):
            requeued = self.queue.requeue_planner(planner)
            self.busy.discard(planner)
            self.log.append({"t": now, "event": "planner removed", "robot": planner, "requeued": len(requeued)})
        newcomers = set(workers.get(EXPLORER, [])) - set(self.explorers)
        self.explorers = list(workers.get(EXPLORER, []))
        self.planners = list(workers.get(PLANNER, []))
        self.finished -= newcomers  # an explorer that kept its role and had finished stays finished

    # -- the environments ---------------------------------------------------------------------------------------
    def _integrate(self, environment: int) -> str:
        """(6.16)-(6.19) on the merged map of one environment."""
        self.explored[environment] = explored_fraction(self.global_map[self.territory.slices(environment)])
        self.status[environment] = environment_status(self.explored[environment], self.threshold)
        return self.status[environment]

    def _release(self, environment: int, explorer: str, now: float) -> None:
        """An environment given up or whose explorer failed goes back by how well it was explored (Fig 6.9a)."""
        if self.status[environment] != "assigned":
            return
        status = self._integrate(environment)
        if self.explored[environment] < 1e-3:
            self.status[environment] = "UE"
        self.send("released", {"environment": environment, "status": self.status[environment]})
        self.log.append({"t": now, "event": "released", "robot": explorer, "environment": environment,
                         "status": status})
        if self.status[environment] in ("UE", "PE"):
            self._wake(environment, now)

    def _wake(self, environment: int, now: float) -> None:
        """The finished explorers that could take ``environment`` (not one they gave up or explored in part; a
        boggy one only if they cross bogs) ask again; the planners and the purge decide who gets it."""
        for explorer in sorted(self.finished):
            record = self.records.get(explorer)
            if explorer not in self.explorers or record is None or environment in record.excluded \
                    or (self.boggy[environment] and not record.bog_capable):
                continue
            self.finished.discard(explorer)
            self.woken[explorer] = now
            self.send("wake", {"environment": environment}, to=explorer)
            self.log.append({"t": now, "event": "woken", "robot": explorer, "environment": environment})

    def _explorer_fault(self, explorer: str, now: float) -> None:
        self.queue.drop_explorer(explorer)
        record = self.records.get(explorer)
        if record is not None and record.environment is not None:
            self._release(record.environment, explorer, now)
            record.environment = None
        self.log.append({"t": now, "event": "explorer removed", "robot": explorer})

    def _finish(self, explorer: str, now: float, why: str) -> None:
        self.finished.add(explorer)
        self.woken.pop(explorer, None)
        self.send("finished", {"why": why}, to=explorer)
        self.log.append({"t": now, "event": "finished", "robot": explorer, "why": why})

    def _job_done(self, planner: str, job_id: int) -> None:
        if job_id in self.queue.active:
            self.queue.complete(job_id)
        self.busy.discard(planner)

    def available(self) -> int:
        return sum(s in ("UE", "PE") for s in self.status)

    # -- one control tick ---------------------------------------------------------------------------------------
    def step(self, now: float) -> None:
        """Sort, purge and dispatch the queue (§6.4.1); integrate finished environments."""
        for explorer in sorted(e for e, woken in self.woken.items() if now - woken >= WAKE_WAIT):
            self._finish(explorer, now, "no answer when woken")
        scores = {e: self.task_scores.get(EXPLORER, {}).get(e, 0.0) for e in self.records}
        for explorer in self.queue.purge(self.available(), scores):
            self._finish(explorer, now, "purged: fewer environments than explorers")
        free = {p: self.task_scores.get(PLANNER, {}).get(p, 0.0) for p in self.planners if p not in self.busy}
        if not free or not self.queue.unassigned:
            return
        self.queue.sorted_jobs(scores)
        for job, planner in self.queue.dispatch(free):
            self.busy.add(planner)
            self.send("job", self._job_payload(job, now), to=planner)

    def _job_payload(self, job, now: float) -> dict:
        record = self.records[job.explorer]
        scores = self.task_scores.get(EXPLORER, {})

        def state(name: str) -> ExplorerState:
            r = self.records[name]
            return ExplorerState(name, r.position, max(scores.get(name, 1.0), 1e-3), r.bog_capable, r.environment)

        cells = self.territory.environment_cells ** 2
        unexplored = [cells * (1.0 - a) for a in self.explored]
        return {
            "job_id": job.task_id, "kind": job.kind, "explorer": state(job.explorer),
            "others": [state(n) for n in self.records if n != job.explorer and n in self.explorers],
            "environment": record.environment, "radius": record.radius,
            "status": list(self.status), "boggy": list(self.boggy), "bog_points": list(self.bog_points),
            "excluded": set(record.excluded),
            "global_map": self.global_map, "unexplored": unexplored, "t_m": self.t_m,
            "ect": {n: {"time": now - (r.started if r.started is not None else now),
                        "unexplored_current": unexplored[r.environment] if r.environment is not None else 0.0,
                        "explored": r.explored_cells, "rate": self.rates[n]}
                    for n, r in self.records.items() if n in self.explorers and n not in self.finished},
        }

    def explored_share(self) -> float:
        """PAE: the mean explored fraction (6.17) over every environment, on the global map as it is now."""
        return float(np.mean([explored_fraction(self.global_map[self.territory.slices(e)])
                              for e in range(self.territory.environments)]))


class FeedbackSystem:
    """M2 on its robot: the ch.5 feedback coordination every ``t_m`` s over the workers' reports. Not ``enabled``
    (Table 8.1's level 1, "no feedback"), it takes the reports and does nothing with them: the task scores stay
    the allocation's, and no failure is detected or reallocated."""

    def __init__(self, name: str, coordinator: FeedbackCoordinator, t_m: float, enabled: bool = True):
        self.name = name
        self.coordinator = coordinator
        self.t_m = t_m
        self.enabled = enabled
        self.next_check = t_m
        self.reports: dict[str, dict[str, Report]] = {}
        self.outbox: list[Packet] = []
        self.steps: list[tuple[float, FeedbackStep]] = []

    def receive(self, sender: str, kind: str, payload: dict, now: float) -> None:
        if kind == "report":
            self.reports[sender] = {task: Report(achievement) for task, achievement in payload["tasks"].items()}

    def step(self, now: float) -> None:
        if now + 1e-9 < self.next_check:
            return
        self.next_check += self.t_m
        reports, self.reports = self.reports, {}
        if not self.enabled:
            return
        result = self.coordinator.update(reports)
        self.steps.append((now, result))
        self.outbox.append(Packet("scores", {"task_scores": result.task_scores}, SMALL_MESSAGE, None))
        if result.reallocated:
            self.outbox.append(Packet("roles", {"workers": result.workers}, SMALL_MESSAGE, None))
