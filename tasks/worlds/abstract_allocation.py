"""The abstract task-allocation world of Parker's L-ALLIANCE study (§4.5.1 "Data Collection Methods"): no space,
no physics, only robots, independent tasks and time.

A problem is a matrix of task times: ``times[r, j]`` is how long robot r needs for task j, infinite where r cannot
do it. :func:`draw_problem` draws one as §4.5.1 does: every task has the same ``coverage`` (capable robots), the
capabilities spread evenly over the robots; a task length l ~ U[0, 500] per task and, for each capable robot,
time = l x (1 + x/100 x y), y ~ U[0, 1] per robot per task, x the heterogeneity in percent.

:func:`run_team` plays one mission with the real :class:`~teamsim.controllers.alliance.lalliance.LAllianceRobot`
motivational behaviours, stepped from event to event (a task finishing, or a robot's
:meth:`~teamsim.controllers.alliance.lalliance.LAllianceRobot.next_event_time`: a motivation crossing theta, a slow rate
lapsing, psi or lambda running out, boredom unblinding): the motivations are piecewise linear in between, so
this integrates them exactly. The robots know the task times already (learned, sd 0: one trial each, the
adaptive phase of §4.4.2 after learning), awareness is perfect and instantaneous (every robot hears every
teammate's current activity at every step, tau infinite, a newer message ends an older claim), and robots that
activate at the same instant are served in a fixed robot order, the lowest index first: "the fixed
tie-breaking mechanism determines which robot wins" (§4.5.1, region 1). Robots never fail: failures are folded
into heterogeneity (§4.5.1).

Work: a robot working on a task advances its own copy of the work at 1/time per unit time and the task is done
when any worker's copy is. With Progress When Working, a robot starting a task begins from the most progress any
robot has made on it (the remainder only); without, from zero (§4.5.1). Workers on the same task do not
interfere (both continue until one finishes, the strategy I case of §4.5.1). Mission time is when the last task
is done; energy is the total robot time spent working (§4.5.1).

:func:`optimal_time` and :func:`optimal_energy` are the brute-force optima of §4.5.4 (over every assignment of
tasks to capable robots; time is the makespan, energy the total work).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from teamsim.config import setting, validate
from teamsim.controllers.alliance.lalliance import LAllianceParams, LAllianceRobot, TaskStatistics
from teamsim.controllers.alliance.motivation import AllianceParams, BehaviourSet, activity_message
from teamsim.radio import Message

TASK_LENGTH_MAX = 500.0  # §4.5.1: l uniform in [0, 500]


@dataclass(frozen=True)
class AllocationProblem:
    times: np.ndarray  # (robots, tasks); inf where the robot cannot do the task

    @property
    def robots(self) -> int:
        return self.times.shape[0]

    @property
    def tasks(self) -> int:
        return self.times.shape[1]

    def capable(self, task: int) -> np.ndarray:
        return np.flatnonzero(np.isfinite(self.times[:, task]))


def draw_problem(robots: int, tasks: int, coverage: int, heterogeneity: float,
                 rng: np.random.Generator) -> AllocationProblem:
    """One random mission of §4.5.1. Each task in turn goes to ``coverage`` of the robots that have the fewest
    capabilities so far (ties at random), so every robot gets floor or ceil of tasks x coverage / robots."""
    if not 1 <= coverage <= robots:
        raise ValueError(f"coverage {coverage}: must be between 1 and the number of robots ({robots})")
    capable = np.zeros((robots, tasks), bool)
    load = np.zeros(robots)
    for task in range(tasks):
        chosen = np.argsort(load + 0.5 * rng.random(robots), kind="stable")[:coverage]
        capable[chosen, task] = True
        load[chosen] += 1
    length = rng.uniform(0.0, TASK_LENGTH_MAX, tasks)
    spread = rng.uniform(0.0, 1.0, (robots, tasks))
    times = np.where(capable, length * (1.0 + heterogeneity / 100.0 * spread), np.inf)
    return AllocationProblem(times)


@dataclass(frozen=True)
class TeamSettings:
    """The L-ALLIANCE values the thesis leaves open (§3.10 item 7), in the study's time units (task lengths
    0-500). Idle delays are kept small beside task times, as "the maximum delay before task activation"
    (§4.6) should be."""

    theta: float = setting(1.0, lo=0.0, open_lo=True, meaning="activation threshold (any value: rates scale with it)")
    min_delay: float = setting(1.0, lo=0.0, open_lo=True, meaning="shortest idle delay before an activation")
    max_delay: float = setting(10.0, lo=0.0, open_lo=True, meaning="longest idle delay before an activation")
    boredom_delay: float = setting(10.0, lo=0.0,
                                   meaning="idle time before a robot considers category-2 tasks (boredom rate 1, "
                                           "threshold this)")
    lambda_factor: float = setting(2.0, lo=1.0, meaning="lambda = this x own time (never reached: robots succeed)")
    delay_calibration: str = setting("robot", choices=("robot", "mission"),
                                     meaning="idle delays scaled between the extreme times each robot knows "
                                             "(§4.6), or between the mission's expected extremes, 0 and "
                                             "500 x (1 + x/100), given in advance (§4.6 footnote 6)")

    def __post_init__(self):
        validate(self)

    def robot_params(self, strategy: str, ordering: str, heterogeneity: float,
                     boredom_delay: float | None = None) -> LAllianceParams:
        """A robot's parameters in a scenario of this heterogeneity (``boredom_delay`` overrides the setting)."""
        given = (0.0, TASK_LENGTH_MAX * (1.0 + heterogeneity / 100.0)) if self.delay_calibration == "mission" else ()
        boredom = self.boredom_delay if boredom_delay is None else boredom_delay
        return LAllianceParams(strategy=strategy, task_ordering=ordering, min_delay=self.min_delay,
                               max_delay=self.max_delay, boredom_rate=1.0, boredom_threshold=boredom,
                               lambda_factor=self.lambda_factor, monitor_performance=False,
                               expected_time_range=given,
                               alliance=AllianceParams(threshold=self.theta, tau=math.inf))


@dataclass(frozen=True)
class TeamOutcome:
    time: float  # mission completion
    energy: float  # total robot time spent working
    performer: tuple  # robot index that completed each task


def task_name(task: int) -> str:
    return f"t{task}"


def robot_name(robot: int) -> str:
    return f"r{robot}"


def taught_robot(problem: AllocationProblem, robot: int, tasks: list[int], capable: list[list[int]],
                 params: LAllianceParams, rng: np.random.Generator) -> LAllianceRobot:
    """A robot that knows its own time and each teammate's time on every task it can do (one trial each)."""
    name = robot_name(robot)
    times = problem.times.tolist()
    statistics = TaskStatistics(name, params.trials_kept)
    for j in tasks:
        statistics.record_own(task_name(j), times[robot][j])
        for k in capable[j]:
            if k != robot:
                statistics.record_teammate(robot_name(k), task_name(j), times[k][j])
    return LAllianceRobot(name, [BehaviourSet(task_name(j)) for j in tasks], params, statistics, rng)


def run_team(problem: AllocationProblem, params: LAllianceParams, progress_when_working: bool,
             rng: np.random.Generator) -> TeamOutcome:
    """One mission played by L-ALLIANCE robots with ``params`` (see :meth:`TeamSettings.robot_params` and the
    module docstring for the model). Robots that can do none of the tasks take no part."""
    n, m = problem.robots, problem.tasks
    seeds = rng.spawn(n)
    capable = [problem.capable(j).tolist() for j in range(m)]
    tasks_of: list[list[int]] = [[] for _ in range(n)]
    for j, robots_of_j in enumerate(capable):
        for i in robots_of_j:
            tasks_of[i].append(j)
    team = [i for i in range(n) if tasks_of[i]]
    robots = {i: taught_robot(problem, i, tasks_of[i], capable, params, seeds[i]) for i in team}
    names = [robot_name(i) for i in range(n)]
    neighbours = {i: sorted({k for j in tasks_of[i] for k in capable[j]} - {i}) for i in team}
    present = {i: frozenset(names[k] for k in team if k != i) for i in team}
    labels = [task_name(j) for j in range(m)]
    task_index = {label: j for j, label in enumerate(labels)}

    done = [False] * m
    remaining = m
    progress = [0.0] * m  # the most work done on each task, as a fraction (what PWW lets a newcomer sense)
    activity: list[int | None] = [None] * n
    heard = {i: dict.fromkeys(neighbours[i], -1) for i in team}  # the activity i last heard from each neighbour
    work_start: dict[int, tuple[float, float]] = {}  # robot -> (start time, progress at start)
    finish: dict[int, float] = {}  # robot -> when its copy of the work completes
    due = dict.fromkeys(team, 0.0)
    energy = 0.0
    performer: list[int | None] = [None] * m

    def stop_work(i: int, t: float) -> None:
        nonlocal energy
        j = activity[i]
        start, start_progress = work_start.pop(i)
        finish.pop(i)
        energy += t - start
        progress[j] = min(1.0, max(progress[j], start_progress + (t - start) / problem.times[i, j]))

    def messages_for(i: int, t: float) -> list[Message]:
        """Every teammate's current activity. With tau infinite, a repeat of what i last heard changes nothing
        in i, so only changes are delivered."""
        last = heard[i]
        changed = [k for k in neighbours[i] if last[k] != activity[k]]
        for k in changed:
            last[k] = activity[k]
        return [Message(names[k], t, activity_message(None if activity[k] is None else labels[activity[k]]))
                for k in changed]

    def step(queue: set[int], t: float) -> None:
        budget = 50 * n + 50
        while queue:
            budget -= 1
            if budget < 0:
                raise RuntimeError(f"robots keep changing activity at t={t}: {activity}")
            i = min(queue)
            queue.discard(i)
            feedback = {labels[j]: not done[j] for j in tasks_of[i]}
            chosen, _ = robots[i].step(t, feedback, messages_for(i, t), present[i])
            due[i] = robots[i].next_event_time()
            now = None if chosen is None else task_index[chosen]
            before = activity[i]
            if now == before:
                continue
            if before is not None:
                stop_work(i, t)
            activity[i] = now
            if now is not None:
                start_progress = 0.0
                if progress_when_working:  # the world shows the most work anyone has done, ongoing work included
                    start_progress = max([progress[now]] + [p0 + (t - t0) / problem.times[k, now]
                                                            for k, (t0, p0) in work_start.items()
                                                            if activity[k] == now])
                work_start[i] = (t, start_progress)
                finish[i] = t + (1.0 - start_progress) * problem.times[i, now]
            for j in (before, now):
                if j is not None:
                    queue.update(k for k in capable[j] if k != i)

    t = 0.0
    step(set(team), t)
    while remaining:
        next_robot = min(due.values())
        worker = min(finish, key=finish.__getitem__) if finish else None
        next_finish = finish[worker] if worker is not None else math.inf
        if math.isinf(next_robot) and math.isinf(next_finish):
            raise RuntimeError(f"no robot will ever act again; tasks left: {[j for j in range(m) if not done[j]]}")
        margin = 1e-9 * max(1.0, next_robot)  # step just past the event (the windows' right-closed reading)
        if next_finish <= next_robot + margin:
            t = next_finish
            j = activity[worker]
            done[j] = True
            remaining -= 1
            performer[j] = worker
            progress[j] = 1.0
            step(set(capable[j]), t)
        else:
            t = next_robot + margin
            step({i for i, when in due.items() if when <= t}, t)
    return TeamOutcome(t, energy, tuple(performer))


def optimal_energy(problem: AllocationProblem) -> float:
    """Least total work: every task done once by its fastest capable robot."""
    return float(problem.times.min(axis=0).sum())


def greedy_makespan(problem: AllocationProblem) -> float:
    """A feasible makespan: longest tasks first, each to the capable robot that would finish it earliest."""
    load = np.zeros(problem.robots)
    for j in np.argsort(-problem.times.min(axis=0), kind="stable"):
        finish_at = load + problem.times[:, j]
        load[int(np.argmin(finish_at))] = finish_at.min()
    return float(load.max())


def optimal_time(problem: AllocationProblem) -> float:
    """Least makespan over every assignment of each task to one capable robot (brute force, §4.5.4), level by
    level over the tasks (longest first), dropping partial assignments already longer than a greedy schedule."""
    bound = greedy_makespan(problem) * (1.0 + 1e-12)
    n = problem.robots
    loads = np.zeros((1, n))
    for j in np.argsort(-problem.times.min(axis=0), kind="stable"):
        capable = problem.capable(j)
        rows = np.repeat(loads, len(capable), axis=0)
        rows[np.arange(len(rows)), np.tile(capable, len(loads))] += np.tile(problem.times[capable, j], len(loads))
        loads = rows[rows.max(axis=1) <= bound]
    return float(loads.max(axis=1).min())
