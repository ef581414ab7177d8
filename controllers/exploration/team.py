"""One robot of the exploration team (Chand §6.1): it hosts whichever roles the allocation gave it (manager tasks
M1/M2, planner W1, explorer W2; one robot may hold several: MT-SR) and routes the network's messages between
them. Messages are addressed packets (``teamsim.network``); a packet a robot sends to itself, or broadcasts, also
reaches its own roles at once. Every worker reports its achievements (Table 5.30) to the feedback system shortly
before each T_m; that report is also its pulse (§5.6.1). When feedback moves the workers, a robot takes up or
drops the planner and explorer roles accordingly.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from teamsim.controllers.base import Command, Observation
from teamsim.controllers.exploration.explorer import Explorer
from teamsim.controllers.exploration.manager import EXPLORER, PLANNER, FeedbackSystem, GlobalInfo
from teamsim.controllers.exploration.planner import Planner
from teamsim.controllers.exploration.territory import SMALL_MESSAGE
from teamsim.network import Packet

REPORT_LEAD = 1.0  # s before each T_m boundary that a worker reports, so the report is in when the monitor runs
MANAGER_KINDS = frozenset({"request", "map", "reset", "bog", "done", "assigned", "no-environment", "job-done",
                           "report", "scores", "roles"})
PLANNER_KINDS = frozenset({"job", "propose", "assigned", "released", "explored"})
EXPLORER_KINDS = frozenset({"plan", "finished", "wake"})


@dataclass(frozen=True)
class Addresses:
    manager: str  # the robot holding M1 (global information)
    feedback: str  # the robot holding M2 (feedback system)


class TeamRobot:
    """The controller of one robot. ``make_explorer``/``make_planner`` build its worker roles on demand."""

    def __init__(self, name: str, addresses: Addresses, *, t_m: float, global_info: GlobalInfo | None = None,
                 feedback: FeedbackSystem | None = None, make_explorer: Callable[[], Explorer],
                 make_planner: Callable[[], Planner], tasks: frozenset = frozenset()):
        self.name = name
        self.addresses = addresses
        self.t_m = t_m
        self.global_info = global_info
        self.feedback = feedback
        self.make_explorer, self.make_planner = make_explorer, make_planner
        self.explorer: Explorer | None = None
        self.planner: Planner | None = None
        self._take_tasks(tasks)
        self.next_report = t_m - REPORT_LEAD
        self.position = (0.0, 0.0)
        self._outgoing: list[Packet] = []  # this robot's own packets (reports)

    def _take_tasks(self, tasks) -> None:
        if EXPLORER in tasks and self.explorer is None:
            self.explorer = self.make_explorer()
        elif EXPLORER not in tasks:
            self.explorer = None
        if PLANNER in tasks and self.planner is None:
            self.planner = self.make_planner()
        elif PLANNER not in tasks:
            self.planner = None

    @property
    def roles(self) -> list[str]:
        held = [("manager", self.global_info), ("feedback", self.feedback), ("planner", self.planner),
                ("explorer", self.explorer)]
        return [name for name, role in held if role is not None]

    def __call__(self, obs: Observation) -> Command:
        now = obs.time
        if obs.pose is not None:
            self.position = (obs.pose.x, obs.pose.y)
        for delivery in obs.inbox:
            self._route(delivery.sender, delivery.kind, delivery.payload, delivery.size, now)
        v = omega = 0.0
        behaviour = " + ".join(self.roles) or "idle"
        if self.explorer is not None:
            v, omega, behaviour = self.explorer.step(obs)
        self._report(now)
        for role in (self.global_info, self.feedback, self.planner):
            if role is not None:
                role.step(now)
        return Command(v=v, omega=omega, behaviour=behaviour, broadcast=tuple(self._collect(now)))

    def _report(self, now: float) -> None:
        """Achievements to the feedback system once per T_m (also the pulse)."""
        if now + 1e-9 < self.next_report:
            return
        self.next_report += self.t_m
        tasks = {}
        if self.explorer is not None:
            tasks[EXPLORER] = self.explorer.report()
        if self.planner is not None:
            tasks[PLANNER] = self.planner.report()
        if tasks:
            payload = {"tasks": tasks, "position": self.position}
            self._outgoing.append(Packet("report", payload, SMALL_MESSAGE, self.addresses.feedback))
            if self.addresses.manager != self.addresses.feedback:
                self._outgoing.append(Packet("report", payload, SMALL_MESSAGE, self.addresses.manager))

    def _collect(self, now: float) -> list[Packet]:
        """Every role's outbox; what is for this robot (addressed to it, or broadcast) is delivered here at once,
        which may make more."""
        sent = []
        for _ in range(10):  # local deliveries settle within a few rounds
            packets = self._outgoing
            self._outgoing = []
            for role in (self.global_info, self.feedback, self.planner, self.explorer):
                if role is not None:
                    packets.extend(role.outbox)
                    role.outbox = []
            if not packets:
                break
            for packet in packets:
                if packet.to is None or packet.to == self.name:
                    self._route(self.name, packet.kind, packet.payload, packet.size, now, own=True)
                if packet.to != self.name:
                    sent.append(packet)
            for role in (self.global_info, self.feedback, self.planner):
                if role is not None:
                    role.step(now)
        return sent

    def _route(self, sender: str, kind: str, payload, size: int, now: float, own: bool = False) -> None:
        if kind == "roles":
            self._take_tasks({task for task, robots in payload["workers"].items() if self.name in robots})
        if self.global_info is not None and kind in MANAGER_KINDS:
            self.global_info.receive(sender, kind, payload, now)
        if self.feedback is not None and kind == "report":
            self.feedback.receive(sender, kind, payload, now)
        if self.planner is not None and kind in PLANNER_KINDS and not (own and kind == "propose"):
            self.planner.receive(kind, payload, 0 if own else size)
        if self.explorer is not None and kind in EXPLORER_KINDS:
            self.explorer.receive(kind, payload, 0 if own else size)
