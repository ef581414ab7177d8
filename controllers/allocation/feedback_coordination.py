"""Feedback coordination (Chand 2011 §5.6, Fig 5.12, (5.7)-(5.22), Tables 5.29-5.34; spec §3.7): the manager's
monitor, failure detection and task reallocation, called by a mission every T_m with the workers' measurements.

Monitoring, per worker task i and robot j executing it, from the achievement sub-categories of the task's
feedback weights (Table 5.29):

- a sub-category's success is achievement over expected achievement RA' (the expert's best-case calibration,
  per robot and task), capped at 1 (§5.6.1: every monitoring variable is normalised to the unit interval);
- a category's success is the KA-weighted sum of its sub-categories, or their maximum where KA is "max";
- (5.12) TES_ind = WS-weighted sum over categories, of this interval's RA / RA';
- (5.13) TES_tm: the same with RA' summed over the n robots executing task i;
- (5.14)-(5.15) OTES_ind, OTES_tm: the same with ORA = sum of RA over the N intervals so far (5.8), ORA' (5.9).
  The ratio is capped after summing, so early over-achievement carries over: Table 5.33's planner Robot4 keeps
  OTES 1 after doing all its plans in the first interval;
- (5.16) RLS = WL-weighted sum over categories: for a rate category (sensing, actuation: RU [on] entries > 0 Hz)
  the KU-weighted sum of sum(RU) / sum(RU') over the N intervals, RU' being the task's RU [on] rates; for an
  event-driven category (planning, communication) its overall achievement success, as §5.6.1 allows.

Failure detection: complete failure CF when a robot sends neither measurements nor a pulse; partial failure PF
(5.19) when TES_ind < TES_T; poor performance PP (5.20) when OTES_ind < OTES_T. A threshold of -1 disables its
check. Task scores (5.21)-(5.22): TS_ij = OTES_ijtm / max over the robots executing task i.

Reallocation, when a failure is detected (or the mission asks, rules 5 and 6): every RTCM value of a robot that
has executed the task becomes its OTES_ind; the columns are re-ranked; then the rules RL in priority order:
(1) CF robots leave every column for good; (2) a PF robot's current task leaves its row for good; (3) PF robots
go to the bottom of every other column; (4) PP robots go to the bottom of their current task's column; (5)
robots the mission names go to the top of a column (task-specific capability, e.g. bog-capable drives); (6) the
mission may change a task's quantity. Then secondary devolution steps 6-9 assign again and reset RU. No
hysteresis (§5.6.2, §8.5.1).

Choices where the thesis is silent or inconsistent (also in docs/decisions.md):

- RLS: (5.16) prints RU' summed over the team; the worked example (8.86 Hz over a 10 Hz target -> 0.8866, and
  the later intervals) is the robot's own cumulative ratio, which is what is computed.
- A robot that has never executed a task keeps its VOTS-derived value V in that column; both are unit interval.
- A robot that sends a pulse but no measurements for a task it holds has achieved nothing on it this interval.
- A robot (re)assigned a task starts its sums afresh; its task score is (5.6) among the task's new robots
  until it has reported.
- Table 5.33 is reproduced closely for Robot2 and Robot4's planner task, not for Robot4's explorer task (its
  TES_ind 0.9 needs an actuation ratio of 1 where 14.58 m / 15.26 m is 0.955); Robot2's OTES_ind matches the
  running mean of its TES_ind (0.7847, 0.7877) rather than (5.14) (0.802, 0.800), which the planner example
  contradicts (the mean would drop Robot4's OTES to 0.5). The tests pin what is reproduced.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Iterable, Mapping, Sequence

import numpy as np

from teamsim.config import ConfigError
from teamsim.controllers.allocation.devolution import Allocation, assign_workers, normalised, resource_utilisation
from teamsim.controllers.allocation.spec import CATEGORIES, FeedbackSpec, TaskSpec

COMPLETE_FAILURE, PARTIAL_FAILURE, POOR_PERFORMANCE = "CF", "PF", "PP"


@dataclass(frozen=True)
class Report:
    """What one worker measured on one task over the last T_m (Tables 5.30 and 5.32)."""
    achievement: Mapping[str, Sequence[float]]  # category -> one value per achievement sub-category
    utilisation: Mapping[str, Sequence[float]] = field(default_factory=dict)  # rate category -> Hz per RU entry


@dataclass(frozen=True)
class Success:
    """Table 5.33's values for one robot on one task at one interval."""
    tes_ind: float
    tes_tm: float
    otes_ind: float
    otes_tm: float
    rls: float


@dataclass
class FeedbackStep:
    """The outcome of one call of :meth:`FeedbackCoordinator.update`."""
    interval: int  # N
    success: dict[tuple[str, str], Success]  # (robot, task) -> values
    flags: dict[tuple[str, str], str]  # (robot, task) -> CF, PF or PP
    task_scores: dict[str, dict[str, float]]  # task -> robot -> TS
    reallocated: bool
    workers: dict[str, list[str]]  # task -> robots, after any reallocation
    ru: dict[str, dict[str, dict[str, tuple]]]  # robot -> task -> category -> RU to apply now ({}: no change)
    shortfall: dict[str, int]


@dataclass
class _Sums:
    """Running sums of one robot on one task since it was assigned it."""
    achieved: dict = field(default_factory=dict)  # category -> array over sub-categories
    expected: dict = field(default_factory=dict)
    used: dict = field(default_factory=dict)  # rate category -> array over RU entries
    target: dict = field(default_factory=dict)


class FeedbackCoordinator:
    """The manager's feedback loop over an :class:`~teamsim.controllers.allocation.devolution.Allocation`.

    ``expected[robot][task][category]`` is RA' per T_m (Table 5.31), one value per achievement sub-category, for
    every robot that may execute the task (every RTCM candidate). Call :meth:`update` every T_m. ``feedback``:
    weights and thresholds to use instead of a task's own (an experiment's level, as Chand's Table 8.1 varies
    them); ``detect_failures`` False: task scores only, no flag and no reallocation (Table 8.1 level 2).
    """

    def __init__(self, allocation: Allocation, expected: Mapping[str, Mapping[str, Mapping[str, Sequence[float]]]],
                 feedback: Mapping[str, FeedbackSpec] | None = None, detect_failures: bool = True):
        self.allocation = allocation
        feedback = feedback or {}
        self.tasks: dict[str, TaskSpec] = {t: replace(allocation.tasks[t], feedback=feedback[t]) if t in feedback
                                           else allocation.tasks[t] for t in allocation.rtcm}
        self.detect_failures = detect_failures
        self.expected = {}
        for task_id, task in self.tasks.items():
            if task.feedback is None:
                raise ConfigError(f"tasks.{task_id}.feedback: missing; feedback coordination needs its weights")
            for candidate in allocation.rtcm[task_id]:
                self.expected[candidate.robot, task_id] = self._expected(expected, candidate.robot, task)
        self.columns = {task: [c.robot for c in column] for task, column in allocation.rtcm.items()}
        self.value = {(c.robot, task): c.value for task, column in allocation.rtcm.items() for c in column}
        self.counts = {task: self.tasks[task].quantity[0] for task in self.tasks}
        self.workers = {task: list(robots) for task, robots in allocation.workers.items()}
        self.ru = allocation.ru
        self.task_scores = allocation.task_scores
        self.shortfall = allocation.shortfall
        self.sums = {(r, task): _Sums() for task, robots in self.workers.items() for r in robots}
        self.interval = 0

    def _expected(self, expected, robot: str, task: TaskSpec) -> dict:
        where = f"expected achievement of {robot} on {task.id}"
        given = expected.get(robot, {}).get(task.id)
        if given is None:
            raise ConfigError(f"{where}: missing; every RTCM candidate needs its best-case RA' per T_m")
        out = {}
        for cat, weight in zip(CATEGORIES, task.feedback.ws):
            if weight == 0:
                continue
            names = task.feedback.achievement[cat]
            values = np.asarray(given.get(cat, ()), dtype=float)
            if values.shape != (len(names),) or not (values > 0).all():
                raise ConfigError(f"{where}.{cat}: expected {len(names)} values > 0 ({', '.join(names)})")
            out[cat] = values
        return out

    # -- monitoring ---------------------------------------------------------------------------------------------

    @staticmethod
    def _category(task: TaskSpec, cat: str, achieved, expected) -> float:
        ratio = np.minimum(np.asarray(achieved, dtype=float) / expected, 1.0)
        weights = task.feedback.ka[cat]
        return float(ratio.max()) if weights == "max" else float(np.dot(weights, ratio))

    def _success(self, task: TaskSpec, achieved: dict, expected: dict) -> tuple[float, dict]:
        """WS-weighted success over categories, and each category's success."""
        per = {cat: self._category(task, cat, achieved[cat], expected[cat]) for cat in expected}
        return sum(w * per[cat] for cat, w in zip(CATEGORIES, task.feedback.ws) if cat in per), per

    def _monitor(self, task_id: str, reports: dict) -> dict[str, Success]:
        task = self.tasks[task_id]
        robots = self.workers[task_id]
        if not robots:
            return {}
        now = {}
        for robot in robots:
            report = reports.get(robot)
            cats = self.expected[robot, task_id]
            achieved = {cat: self._values(report.achievement if report else {}, cat, len(cats[cat]), robot, task_id)
                        for cat in cats}
            now[robot] = achieved
            sums = self.sums[robot, task_id]
            for cat, values in achieved.items():
                sums.achieved[cat] = sums.achieved.get(cat, 0) + values
                sums.expected[cat] = sums.expected.get(cat, 0) + cats[cat]
            for cat, rates in task.ru_on.items():
                if cat in task.feedback.ku and all(rate > 0 for rate in rates):
                    used = self._values(report.utilisation if report else {}, cat, len(rates), robot, task_id)
                    sums.used[cat] = sums.used.get(cat, 0) + used
                    sums.target[cat] = sums.target.get(cat, 0) + np.asarray(rates, dtype=float)
        team_now = {cat: sum(self.expected[r, task_id][cat] for r in robots) for cat in now[robots[0]]}
        team_all = {cat: sum(self.sums[r, task_id].expected[cat] for r in robots) for cat in team_now}
        out = {}
        for robot in robots:
            sums = self.sums[robot, task_id]
            tes_ind, _ = self._success(task, now[robot], self.expected[robot, task_id])
            otes_ind, overall = self._success(task, sums.achieved, sums.expected)
            load = dict(overall)
            for cat, weights in task.feedback.ku.items():
                if cat in sums.used:
                    load[cat] = float(np.dot(weights, np.minimum(sums.used[cat] / sums.target[cat], 1.0)))
            rls = sum(w * load.get(cat, 0.0) for cat, w in zip(CATEGORIES, task.feedback.wl))
            out[robot] = Success(tes_ind, self._success(task, now[robot], team_now)[0], otes_ind,
                                 self._success(task, sums.achieved, team_all)[0], rls)
        return out

    @staticmethod
    def _values(measured: Mapping, cat: str, count: int, robot: str, task: str) -> np.ndarray:
        values = np.asarray(measured.get(cat, np.zeros(count)), dtype=float)
        if values.shape != (count,) or (values < 0).any():
            raise ConfigError(f"report of {robot} on {task}: {cat} needs {count} values >= 0")
        return values

    # -- the loop -----------------------------------------------------------------------------------------------

    def update(self, reports: Mapping[str, Mapping[str, Report]], pulse: Iterable[str] = (),
               promote: Mapping[str, Sequence[str]] | None = None,
               quantities: Mapping[str, int] | None = None) -> FeedbackStep:
        """One feedback pass (call every T_m). ``reports``: robot -> task -> :class:`Report`; ``pulse``: robots
        whose heartbeat arrived (a robot that reports is alive too). ``promote`` (rule 5): task -> robots to put
        at the top of its column; ``quantities`` (rule 6): task -> new robot count."""
        self.interval += 1
        alive = set(reports) | set(pulse)
        success, flags = {}, {}
        for task_id, robots in self.workers.items():
            feedback = self.tasks[task_id].feedback
            for robot in robots:
                if robot not in alive and self.detect_failures:
                    flags[robot, task_id] = COMPLETE_FAILURE
            monitored = self._monitor(task_id, {r: reports.get(r, {}).get(task_id) for r in robots if r in alive})
            for robot, values in monitored.items():
                if robot not in alive:
                    continue
                success[robot, task_id] = values
                self.value[robot, task_id] = values.otes_ind
                if not self.detect_failures:
                    continue
                if values.tes_ind < feedback.tes_threshold:
                    flags[robot, task_id] = PARTIAL_FAILURE
                elif values.otes_ind < feedback.otes_threshold:
                    flags[robot, task_id] = POOR_PERFORMANCE
        self.task_scores = {task: normalised({r: success[r, task].otes_tm for r in robots if (r, task) in success})
                            for task, robots in self.workers.items()}
        reallocate = bool(flags or promote or quantities)
        ru = {}
        if reallocate:
            ru = self._reallocate(flags, promote or {}, quantities or {})
        return FeedbackStep(self.interval, success, flags, self.task_scores, reallocate,
                            {t: list(r) for t, r in self.workers.items()}, ru, self.shortfall if reallocate else {})

    def _reallocate(self, flags: dict, promote: Mapping, quantities: Mapping) -> dict:
        """Task reallocation (§5.6.2): re-rank by OTES, apply RL, reassign (secondary steps 6-9)."""
        for task, column in self.columns.items():
            column.sort(key=lambda robot: -self.value[robot, task])  # stable: earlier rank on ties
        failed = {robot for (robot, _), flag in flags.items() if flag == COMPLETE_FAILURE}
        partial = {(robot, task) for (robot, task), flag in flags.items() if flag == PARTIAL_FAILURE}
        for task, column in self.columns.items():  # rules 1 and 2
            column[:] = [r for r in column if r not in failed and (r, task) not in partial]
        partial_robots = {robot for robot, _ in partial}
        poor = {(robot, task) for (robot, task), flag in flags.items() if flag == POOR_PERFORMANCE}
        for task, column in self.columns.items():  # rules 3 and 4
            column.sort(key=lambda robot: robot in partial_robots or (robot, task) in poor)
        for task, robots in promote.items():  # rule 5
            if task not in self.columns:
                raise ConfigError(f"promote: {task}: not a worker task; tasks: {', '.join(self.columns)}")
            column = self.columns[task]
            column[:] = [r for r in robots if r in column] + [r for r in column if r not in robots]
        for task, count in quantities.items():  # rule 6
            if task not in self.counts or count < 0:
                raise ConfigError(f"quantities: {task}={count}: expected a worker task and a count >= 0")
            self.counts[task] = count
        order = sorted(self.columns, key=lambda task: len(self.columns[task]))
        before = {task: set(robots) for task, robots in self.workers.items()}
        self.workers, self.shortfall = assign_workers(self.allocation.suitability,
                                                      {t: self.columns[t] for t in order}, self.counts)
        previous = sorted({robot for robots in before.values() for robot in robots})
        self.ru = resource_utilisation(self.allocation.suitability, self.workers, previous)
        for task, robots in self.workers.items():
            for robot in set(robots) - before[task]:
                self.sums[robot, task] = _Sums()
            votsws = {c.robot: c.votsws for c in self.allocation.rtcm[task]}
            fresh = normalised({r: votsws[r] for r in robots})
            kept = self.task_scores.get(task, {})
            self.task_scores[task] = {r: kept.get(r, fresh[r]) for r in robots}
        return self.ru
