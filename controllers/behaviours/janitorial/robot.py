"""A janitor's ALLIANCE control (Parker §6.2.1, Fig. 6-7): one motivational behaviour per task, choosing sub-tasks.

Each task the robot has tools for is a motivational behaviour over its sub-tasks, and every sub-task has its own
motivation, eq. (3.1) of :mod:`teamsim.controllers.alliance.motivation`, so the robot's behaviour sets are:

- ``empty-garbage f`` for each emitter frequency f: applicable while f is heard; a teammate's "emptying garbage
  frequency f" slows it (the thesis's one impatience rate per pair of frequency detectors);
- ``dust-furniture``: applicable while fewer than the known number of objects are dusted (by anyone heard). It
  grows at the fast rate whatever teammates do; the slow rate applies per object instead, through the ignore list
  it passes to the behaviour set (:class:`~teamsim.controllers.behaviours.janitorial.dusting.DustClaims`);
- ``clean-floor q`` for each quadrant q: applicable until q is completed (by this robot or a teammate heard); a
  teammate's "cleaning quadrant q" slows it. The set first circles the room if this robot does not know its size,
  broadcasting "finding room dimensions" meanwhile;
- ``verify-dusting`` and ``verify-floor`` (§6.2.1, "Confirmation of completed tasks"): low priority and very slow
  impatience, applicable once every object (quadrant) is believed done and one is not yet verified by anyone
  heard. Verification here is doing it again: the duster goes back to the object and circles it, the cleaner
  covers the quadrant afresh (a robot has no sensor that tells a dusted surface or a clean floor).

Broadcasts say what the robot does (the messages of §6.2.1) and carry its completions so far (objects dusted,
quadrants cleaned), so a completion is not lost when the next message slot comes after the robot has moved on.
With the radio off nothing is heard, and each robot finds out by itself: cans go silent, and it dusts and cleans
until its own count says done. Tie-breaks go to the order above (the behaviour-set priority of §3.6).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from teamsim.config import setting
from teamsim.controllers.alliance.motivation import AllianceParams, AllianceRobot, BehaviourSet, MotivationRates
from teamsim.controllers.base import Command, Observation
from teamsim.controllers.behaviours.janitorial.dusting import DustClaims, DustFurniture, DustParams
from teamsim.controllers.behaviours.janitorial.floor import QUADRANTS, CleanFloor, FloorParams
from teamsim.controllers.behaviours.janitorial.garbage import EmptyGarbage, GarbageParams
from teamsim.controllers.skills.goto import Unstick
from teamsim.controllers.skills.pose_estimate import PoseEstimate
from teamsim.models.janitor import CLEAN, DUST, EMPTY, TOOL_OF_TASK
from teamsim.models.robot import RobotModel

DUSTING, FINDING_ROOM = "dusting furniture", "finding room dimensions"  # announcements no set listens to
VERIFY_DUST, VERIFY_FLOOR = "verify-dusting", "verify-floor"


@dataclass(frozen=True)
class SetRates:
    """One behaviour set's ALLIANCE rates (§3.6; :class:`MotivationRates`), /s and s."""
    delta_fast: float = setting(0.5, lo=0.0, open_lo=True, meaning="impatience while nobody does it, /s")
    delta_slow: float = setting(1 / 60, lo=0.0, open_lo=True, meaning="impatience while a teammate does it, /s")
    phi: float = setting(60.0, lo=0.0, open_lo=True, meaning="s a teammate's claim slows this set")
    psi: float = setting(10.0, lo=0.0, open_lo=True, meaning="s active before yielding to a teammate on it")
    lam: float = setting(150.0, lo=0.0, open_lo=True, meaning="s active before giving up")

    def motivation(self) -> MotivationRates:
        return MotivationRates(self.delta_fast, self.delta_slow, self.phi, self.psi, self.lam)


@dataclass(frozen=True)
class JanitorParams:
    """Assumed constants (Parker gives none for this mission)."""
    garbage_rates: SetRates = field(default_factory=SetRates, metadata={
        "meaning": "each frequency's set: a teammate emptying it is given phi s before impatience"})
    dust_rates: SetRates = field(default_factory=lambda: SetRates(psi=60.0, lam=400.0), metadata={
        "meaning": "dust-furniture: theta / delta_slow is how long a teammate's object is left alone"})
    floor_rates: SetRates = field(default_factory=lambda: SetRates(delta_slow=1 / 150, phi=150.0, psi=20.0,
                                                                   lam=400.0), metadata={
        "meaning": "each quadrant's set: a teammate cleaning it is given phi s"})
    verify_rates: SetRates = field(default_factory=lambda: SetRates(
        delta_fast=1 / 60, delta_slow=1 / 600, phi=600.0, psi=60.0, lam=600.0), metadata={
        "meaning": "the verification sets: very slow impatience (§6.2.1, 'Confirmation of completed tasks')"})
    threshold: float = setting(1.0, lo=0.0, open_lo=True, meaning="theta (§3.6)")
    garbage: GarbageParams = field(default_factory=GarbageParams, metadata={"meaning": "empty-garbage constants"})
    dusting: DustParams = field(default_factory=DustParams, metadata={"meaning": "dust-furniture constants"})
    floor: FloorParams = field(default_factory=FloorParams, metadata={"meaning": "clean-floor constants"})


class JanitorRobot:
    """``observation -> Command`` for a janitor with the tools of ``tasks``."""

    def __init__(self, robot: RobotModel, tasks: tuple[str, ...], frequencies: tuple[str, ...], objects: int,
                 rng: np.random.Generator, params: JanitorParams = JanitorParams(), tau: float = 9.0):
        self.params, self.objects = params, objects
        self.tools = {TOOL_OF_TASK[t]: 0.0 for t in tasks}
        names = robot.ir_sensors
        upper = np.array([k for k, n in enumerate(names) if n.startswith("ir")])
        low = np.array([k for k, n in enumerate(names) if n.startswith("low")])
        bearings = robot.ir_bearings
        self.estimate = PoseEstimate(robot.drive)
        self.unstick = Unstick(rng)  # wedged (between a can and an idle teammate, say): back off and turn
        self.behaviours: dict[str, tuple[object, str]] = {}  # set -> (behaviour, sub-task)
        sets = []
        if EMPTY in tasks:
            self.garbage = EmptyGarbage(bearings, upper, low, params.garbage)
            for f in frequencies:
                sets.append(BehaviourSet(f"{EMPTY} {f}", rates=params.garbage_rates.motivation()))
                self.behaviours[sets[-1].name] = (self.garbage, f)
        if DUST in tasks:
            self.dust = DustFurniture(bearings, upper, low, robot.footprint_radius, rng, params.dusting)
            self.claims = DustClaims(params.dust_rates.delta_slow, params.threshold, params.dusting.same_object)
            sets.append(BehaviourSet(DUST, rates=params.dust_rates.motivation()))
            self.behaviours[DUST] = (self.dust, "")
        if CLEAN in tasks:
            self.floor = CleanFloor(bearings, low, robot.footprint_radius, rng, params.floor)
            for q in QUADRANTS:
                sets.append(BehaviourSet(f"{CLEAN} {q}", rates=params.floor_rates.motivation()))
                self.behaviours[sets[-1].name] = (self.floor, q)
        for task, name in ((DUST, VERIFY_DUST), (CLEAN, VERIFY_FLOOR)):  # lowest priority: after every task
            if task in tasks:
                sets.append(BehaviourSet(name, rates=params.verify_rates.motivation()))
                self.behaviours[name] = (self.dust if task == DUST else self.floor, "")
        self.tasks = tasks
        self.verified_floor: set[str] = set()
        self.verified_dust: list[np.ndarray] = []
        self.phi = {s.name: s.rates.phi for s in sets}
        self.name = robot.name
        self.alliance = AllianceRobot(robot.name, sets, AllianceParams(threshold=params.threshold, tau=tau),
                                      precedes=self._precedes)
        self.began: dict[str, tuple[str | None, float]] = {}  # teammate -> (its sub-task, when it began it)
        self.quadrants_done: set[str] = set()
        self.active: str | None = None

    # -- what the robot knows ------------------------------------------------------------------------------------
    def _listen(self, obs: Observation) -> None:
        for message in obs.inbox:
            payload = message.payload if isinstance(message.payload, dict) else {}
            self.began[message.sender] = (payload.get("task"), float(payload.get("since", obs.time)))
            done = payload.get("done", {})
            self.quadrants_done.update(done.get("floor", ()))
            self.verified_floor.update(done.get("floor_verified", ()))
            for at in done.get("dust_verified", ()):
                self._verified_object(at)
            if DUST in self.tasks:
                for at in done.get("dust", ()):
                    self.claims.completed(at)
                dusting = payload.get("task") == DUSTING and payload.get("at") is not None
                self.claims.hear(message.sender, payload.get("at") if dusting else None, obs.time)

    def _feedback(self, obs: Observation) -> dict[str, bool]:
        feedback = {}
        for name, (behaviour, sub_task) in self.behaviours.items():
            if behaviour is getattr(self, "garbage", None):
                feedback[name] = self.garbage.heard(obs, sub_task)
            elif name == DUST:
                feedback[name] = len(self.claims.done) < self.objects
            elif name == VERIFY_DUST:
                feedback[name] = len(self.claims.done) >= self.objects and self._unverified_object() is not None
            elif name == VERIFY_FLOOR:
                feedback[name] = self.quadrants_done >= set(QUADRANTS) and self._unverified_quadrant() is not None
            else:
                feedback[name] = sub_task not in self.quadrants_done
        return feedback

    def _unverified_quadrant(self) -> str | None:
        return next((q for q in QUADRANTS if q not in self.verified_floor), None)

    def _unverified_object(self) -> np.ndarray | None:
        return next((at for at in self.claims.done if self._unverified(at)), None)

    def _verified_current(self, active: str) -> bool:
        """A verification set still active after verifying its quadrant or object (by this robot or a teammate
        heard) goes on to the next unverified one. (Starting only when the set became active, a robot that had
        verified one quadrant stood still until lambda, 600 s: seed 101, floor 92 % at 2400 s.)"""
        if active == VERIFY_FLOOR:
            return self.floor.quadrant in self.verified_floor
        if active == VERIFY_DUST:
            return self.dust.verify_at is None or not self._unverified(self.dust.verify_at)
        return False

    def _unverified(self, at: np.ndarray) -> bool:
        near = self.params.dusting.same_object
        return all(np.hypot(*(at - v)) > near for v in self.verified_dust)

    def _verified_object(self, at) -> None:
        location = np.asarray(at, float)
        if self._unverified(location):
            self.verified_dust.append(location)

    def _precedes(self, task: str, teammate: str) -> bool:
        """Whether psi yields ``task`` to ``teammate``: first come, first served, unless the later one came after
        its impatience with the first ran out (after phi), when the first yields to it (§3.6). Start times are
        the ones teammates' messages carry; a tie goes to the name first in order."""
        their_task, theirs = self.began.get(teammate, (None, 0.0))
        if their_task != task:
            return False
        mine = self.alliance.active_since
        phi = self.phi[task]
        if theirs < mine or (theirs == mine and teammate < self.name):
            return mine - theirs < phi  # they were first, and I did not take it over out of impatience
        return theirs - mine >= phi  # they took it over from me out of impatience

    # -- the control step ----------------------------------------------------------------------------------------
    def __call__(self, obs: Observation) -> Command:
        pose = self.estimate.update(obs)
        if pose is None:  # no positioning fix yet
            return Command(behaviour="idle", extras=dict(self.tools))
        if CLEAN in self.tasks and self.floor.home is None:
            # The perimeter circuit starts from the start pose, beside a wall, whatever the robot did first (taken
            # when clean-floor first ran, after dusting, it circled half the room as the room: seed 101).
            self.floor.home = pose.copy()
        self._listen(obs)
        active, trace = self.alliance.step(obs.time, self._feedback(obs), obs.inbox, obs.robots_present)
        if active is not None and (active != self.active or self._verified_current(active)):
            behaviour, sub_task = self.behaviours[active]
            if active == VERIFY_FLOOR:
                self.floor.start(self._unverified_quadrant(), obs.time, verify=True)
            elif active == VERIFY_DUST:
                self.dust.start("", obs.time, verify_at=self._unverified_object())
            else:
                behaviour.start(sub_task, obs.time)
        self.active = active
        if active is None:
            return Command(behaviour="idle", extras=dict(self.tools), trace=trace, broadcast=self._message(None))
        behaviour, _ = self.behaviours[active]
        if behaviour is getattr(self, "dust", None):
            self.dust.ignore = self.claims.ignore_list(obs.time)
        command = self.unstick(obs, behaviour(obs, pose))
        self._record_completions()
        return Command(v=command.v, omega=command.omega, behaviour=active, extras={**self.tools, **command.extras},
                       trace=trace, broadcast=self._message(active))

    def _record_completions(self) -> None:
        if DUST in self.tasks:
            for at in self.dust.finished:
                self.claims.completed(at)
            for at in self.dust.verified:
                self._verified_object(at)
        if CLEAN in self.tasks:
            self.quadrants_done.update(self.floor.completed)
            self.verified_floor.update(self.floor.verified)

    def _message(self, active: str | None) -> dict:
        """The activity broadcast (§6.2.1's messages) with this robot's completions."""
        done = {}
        if DUST in self.tasks and self.dust.finished:
            done["dust"] = [[round(float(v), 2) for v in at] for at in self.dust.finished]
        if CLEAN in self.tasks and self.floor.completed:
            done["floor"] = list(self.floor.completed)
        if CLEAN in self.tasks and self.floor.verified:
            done["floor_verified"] = list(self.floor.verified)
        if DUST in self.tasks and self.dust.verified:
            done["dust_verified"] = [[round(float(v), 2) for v in at] for at in self.dust.verified]
        message = {"task": active, "done": done, "since": round(self.alliance.active_since, 3)}
        if active == DUST:
            at = self.dust.dusting_at
            message.update(task=DUSTING, at=None if at is None else [round(float(v), 2) for v in at])
        elif active is not None and active.startswith(CLEAN) and self.floor.finding_dimensions:
            message["task"] = FINDING_ROOM
        return message
