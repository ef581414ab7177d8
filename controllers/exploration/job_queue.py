"""The manager's job queue (Chand §6.4.1, eq. 6.11-6.14) and the explorers' estimated completion time (eq. 5.23,
§6.4.3, Fig 6.11).

An explorer asks for a new path, or for a new local environment plus a path:
  (6.11) JB_ej = {j, TT_j}          (6.12) M_TI = {TI, JB_ej}, TI a unique task ID          (6.13) UJL = {UJL; M_TI}
The unassigned job list UJL is sorted in task-ID order, then new-environment jobs before path jobs, then the
new-environment jobs by the explorer's TS_ej ascending, as printed (a stable sort, so equal scores keep task-ID
order). With more new-environment jobs than available environments the weakest explorers' (lowest TS_ej) jobs are
purged, and feedback removes those explorers. The free planners, ranked by TS_pj descending, take the jobs in order:
  (6.14) AJL = {AJL; M*}, the job leaving UJL; on completion it moves from AJL to the completed list CJL.
Faults (Fig 6.9): a planner's active jobs go back to UJL; an explorer's pending jobs are purged.
ECT (5.23), computed only when fewer environments are available than there are explorers:
  ECT_k = t_ek (A_ck + A_n'k) / A_o   if t_ek > T_m,   else (A_ck + A_n'k) / E_o
t_ek the exploration time so far, A_ck and A_n'k the unexplored areas of the current and proposed environments,
A_o the area explored so far and E_o the predicted exploration rate. Explorer j's ECT is acceptable if its rank,
ascending, is within the number of available environments.
[RECON] Purge ties (equal TS_ej) drop the later request first; dispatch ties (equal TS_pj) go by planner name; ECT
ties by explorer name; with A_o = 0 the observed rate is undefined, so the predicted-rate branch is used.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

ENVIRONMENT = "environment"  # TT: new local environment plus path
PATH = "path"  # TT: new path only


@dataclass(frozen=True)
class Job:
    task_id: int  # TI (6.12)
    explorer: str
    kind: str  # ENVIRONMENT or PATH (6.11)


class JobQueue:
    """UJL, AJL and CJL (§6.4.1). ``active`` maps a task ID to its job and the planner working on it."""

    def __init__(self):
        self.unassigned: list[Job] = []
        self.active: dict[int, tuple[Job, str]] = {}
        self.completed: list[Job] = []
        self._last_task_id = 0

    def request(self, explorer: str, kind: str) -> Job:
        """(6.12)-(6.13): a job with the next task ID, appended to UJL. Whether an environment is left to give
        (§6.4.1) is the caller's check."""
        if kind not in (ENVIRONMENT, PATH):
            raise ValueError(f"unknown job kind {kind!r}")
        self._last_task_id += 1
        job = Job(self._last_task_id, explorer, kind)
        self.unassigned.append(job)
        return job

    def sorted_jobs(self, task_scores: Mapping[str, float]) -> list[Job]:
        """Sort UJL in place (dispatch serves it in this order) and return a copy of it."""
        by_id = sorted(self.unassigned, key=lambda job: job.task_id)
        environment = sorted((job for job in by_id if job.kind == ENVIRONMENT),
                             key=lambda job: task_scores[job.explorer])  # ascending, as printed
        self.unassigned = environment + [job for job in by_id if job.kind == PATH]
        return list(self.unassigned)

    def purge(self, available: int, task_scores: Mapping[str, float]) -> list[str]:
        """Drop the lowest-TS explorers' environment jobs beyond ``available``; return those explorers."""
        environment = [job for job in self.unassigned if job.kind == ENVIRONMENT]
        excess = len(environment) - max(available, 0)
        if excess <= 0:
            return []
        # Weakest first; among equals the later request goes, so the queue stays first come, first served.
        doomed = sorted(environment, key=lambda job: (task_scores[job.explorer], -job.task_id))[:excess]
        self.unassigned = [job for job in self.unassigned if job not in doomed]
        return [job.explorer for job in doomed]

    def dispatch(self, free_planners: Mapping[str, float]) -> list[tuple[Job, str]]:
        """(6.14): the head of UJL to the highest-TS_pj free planner, the next job to the next planner, and so on."""
        planners = sorted(free_planners, key=lambda name: (-free_planners[name], name))
        handed = list(zip(self.unassigned, planners))
        for job, planner in handed:
            self.active[job.task_id] = (job, planner)
        self.unassigned = self.unassigned[len(handed):]
        return handed

    def complete(self, task_id: int) -> None:
        """AJL -> CJL."""
        job, _ = self.active.pop(task_id)
        self.completed.append(job)

    def requeue_planner(self, planner: str) -> list[Job]:
        """Planner fault (Fig 6.9b): its active jobs go back to UJL, in task-ID order."""
        returned = sorted((job for job, holder in self.active.values() if holder == planner),
                          key=lambda job: job.task_id)
        for job in returned:
            del self.active[job.task_id]
        self.unassigned.extend(returned)
        return returned

    def drop_explorer(self, explorer: str) -> list[Job]:
        """Explorer fault (Fig 6.9a): purge its pending jobs from UJL and AJL; return them in task-ID order."""
        dropped = [job for job in self.unassigned if job.explorer == explorer]
        dropped += [job for job, _ in self.active.values() if job.explorer == explorer]
        self.unassigned = [job for job in self.unassigned if job.explorer != explorer]
        for job in dropped:
            self.active.pop(job.task_id, None)
        return sorted(dropped, key=lambda job: job.task_id)

    def pending(self, explorer: str) -> bool:
        """Whether the explorer has a job waiting in UJL or being worked on in AJL."""
        return (any(job.explorer == explorer for job in self.unassigned)
                or any(job.explorer == explorer for job, _ in self.active.values()))


def estimated_completion_time(t_explored: float, unexplored_current: float, unexplored_new: float,
                              area_explored: float, predicted_rate: float, t_m: float) -> float:
    """(5.23) ECT_k: the observed rate once the explorer has run longer than T_m, the predicted rate before."""
    unexplored = unexplored_current + unexplored_new
    if t_explored > t_m and area_explored > 0:
        return t_explored * unexplored / area_explored
    return unexplored / predicted_rate


def ect_acceptable(ects: Mapping[str, float], explorer: str, available: int) -> bool:
    """§6.4.3: the explorer's rank by ECT, ascending (ties by name), is within the available environments."""
    ranking = sorted(ects, key=lambda name: (ects[name], name))
    return ranking.index(explorer) + 1 <= available
