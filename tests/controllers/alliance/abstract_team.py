"""A small abstract team for ALLIANCE and L-ALLIANCE tests: robots, tasks and time, no physics.

Each robot runs an :class:`~teamsim.controllers.alliance.motivation.AllianceController` (one behaviour set per task it
can do, applicable while the task is needed). Messages go through the real :class:`~teamsim.radio.RadioBus`, so
rate, loss, latency and the tau timeout of ``robots_present`` are real; ``radio=None`` switches every radio off
(rho = 0). A robot active on a task wears it down at 1/duration per second (Progress When Working, Condition 3);
a task may require others to be done first, and may recur some time after it is done or when another
task is done. Faults: ``kill`` (the
robot stops and falls silent), ``fail`` (it keeps running and talking but achieves nothing: Parker's
"persistent, yet failing robot"), ``revive`` (a killed robot restarts with a fresh controller).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Mapping, Sequence

import numpy as np

from teamsim.config import RadioConfig
from teamsim.controllers.alliance.motivation import AllianceController, BehaviourSetDefinition
from teamsim.controllers.base import Command, Observation
from teamsim.radio import RadioBus
from teamsim.rng import RandomStreams

NO_IR = np.zeros(0)


@dataclass(frozen=True)
class Task:
    name: str
    requires: tuple = ()
    recurs_after: float | None = None  # seconds after completion when it is needed again (None: once)
    renewed_by: str | None = None  # needed again when this other task is done (box pushing's two ends)


def _stand_still(observation: Observation) -> Command:
    return Command()


class AbstractTeam:
    """``durations[robot][task]``: seconds the robot needs for the task (it can do exactly those tasks).
    ``make_selector(robot, sets)`` builds each robot's action selector (AllianceRobot, LAllianceRobot...); a
    robot's behaviour sets come in the order of ``tasks`` (their priority)."""

    def __init__(self, tasks: Sequence[Task], durations: Mapping[str, Mapping[str, float]],
                 make_selector: Callable, radio: RadioConfig | None, seed: int = 0, dt: float = 0.5,
                 record_traces: bool = False):
        self.tasks = {task.name: task for task in tasks}
        self.durations = {robot: dict(times) for robot, times in durations.items()}
        self.robots = list(durations)
        self.make_selector = make_selector
        self.dt = dt
        self.ticks = 0
        streams = RandomStreams(seed)
        self.bus = RadioBus(radio or RadioConfig(), {r: streams.get("robot", r, "radio") for r in self.robots})
        self.radio_on = radio is not None
        for robot in self.robots:
            self.bus.set_enabled(robot, self.radio_on)
        self.positions = {robot: np.zeros(3) for robot in self.robots}
        self.remaining = dict.fromkeys(self.tasks, 1.0)
        self.due_again: dict[str, float] = {}
        self.completions: dict[str, list[float]] = {name: [] for name in self.tasks}
        self.dead: set[str] = set()
        self.failing: set[str] = set()
        self.behaviour = dict.fromkeys(self.robots, "idle")
        self.history: list[tuple[float, dict]] = []  # (time, behaviour of every robot) per tick
        self.record_traces = record_traces
        self.traces: dict[str, list] = {robot: [] for robot in self.robots}
        self.controllers = {robot: self._controller(robot) for robot in self.robots}

    @property
    def time(self) -> float:
        return self.ticks * self.dt

    def _controller(self, robot: str) -> AllianceController:
        definitions = [BehaviourSetDefinition(task, lambda obs, task=task: self.needed(task), _stand_still)
                       for task in self.tasks if task in self.durations[robot]]
        selector = self.make_selector(robot, [d.behaviour_set for d in definitions])
        return AllianceController(robot, definitions, selector=selector)

    def needed(self, task: str) -> bool:
        return self.remaining[task] > 0.0 and all(self.remaining[r] == 0.0 for r in self.tasks[task].requires)

    def done(self, tasks=None) -> bool:
        return all(self.remaining[t] == 0.0 for t in (self.tasks if tasks is None else tasks))

    def kill(self, robot: str) -> None:
        self.dead.add(robot)
        self.bus.set_enabled(robot, False)
        self.behaviour[robot] = "dead"

    def fail(self, robot: str) -> None:
        self.failing.add(robot)

    def revive(self, robot: str) -> None:
        self.dead.discard(robot)
        self.bus.set_enabled(robot, self.radio_on)
        self.bus.take_inbox(robot)
        self.controllers[robot] = self._controller(robot)

    def tick(self) -> None:
        now = self.time
        self.bus.update(now, self.positions)
        for robot in self.robots:
            if robot in self.dead:
                continue
            observation = Observation(time=now, robot=robot, ir_raw=NO_IR, ir_range=NO_IR, ir_bearings=NO_IR,
                                      pose=None, inbox=tuple(self.bus.take_inbox(robot)),
                                      robots_present=self.bus.robots_present(robot, now))
            command = self.controllers[robot](observation)
            self.bus.set_outbox(robot, command.broadcast)
            self.behaviour[robot] = command.behaviour
            if self.record_traces:
                self.traces[robot].append(self.controllers[robot].last_trace)
        self.history.append((now, dict(self.behaviour)))
        for robot, task in self.behaviour.items():
            if task in self.tasks and robot not in self.dead and robot not in self.failing and self.needed(task):
                self.remaining[task] = max(0.0, self.remaining[task] - self.dt / self.durations[robot][task])
                if self.remaining[task] == 0.0:
                    self.completions[task].append(now + self.dt)
                    if self.tasks[task].recurs_after is not None:
                        self.due_again[task] = now + self.dt + self.tasks[task].recurs_after
                    for other in self.tasks.values():
                        if other.renewed_by == task and self.remaining[other.name] == 0.0:
                            self.remaining[other.name] = 1.0
        for task, when in list(self.due_again.items()):
            if when <= now + self.dt + 1e-9:
                self.remaining[task] = 1.0
                del self.due_again[task]
        self.ticks += 1

    def run(self, until: float, stop_when_done: bool = True, events: Mapping[float, Callable] | None = None) -> None:
        """Tick until ``until`` seconds (or every task is done); ``events`` maps a time to a call made then."""
        pending = sorted((events or {}).items())
        while self.time < until - 1e-9:
            while pending and pending[0][0] <= self.time + 1e-9:
                pending.pop(0)[1]()
            if stop_when_done and self.done():
                return
            self.tick()

    def first_time(self, robot: str, behaviour: str, after: float = 0.0) -> float | None:
        """When ``robot`` was first seen with ``behaviour`` at or after ``after``."""
        for time, behaviours in self.history:
            if time >= after and behaviours[robot] == behaviour:
                return time
        return None

