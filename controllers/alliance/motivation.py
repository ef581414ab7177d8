"""ALLIANCE: Parker's fault-tolerant, behaviour-based action selection (MIT AI-TR 1465, 1994, ch.3; App. A).

Each robot owns behaviour sets a_ij (§3.4), each mapped to a task h_i(a_ij) of the mission (§3.3, several sets
may serve one task). One *motivational behaviour* per set computes, every control step, eq. (3.1) (the thesis
prints it as (3.1) and cites it as (3.2), spec §1.6 item 1)::

    m_ij(t) = [m_ij(t-1) + impatience_ij(t)] x sensory_feedback_ij(t) x activity_suppression_ij(t)
              x impatience_reset_ij(t) x acquiescence_ij(t)

and the set becomes active when m_ij exceeds the one threshold theta (§3.6). Only one set is active per robot
(cross-inhibition, §3.4); simultaneous crossings go to the fixed behaviour-set priority, the order in which the
sets are given (§3.6 "Suppression", footnote 4). While a set is active the robot broadcasts its current task;
an idle robot broadcasts that it is idle, which keeps it in its teammates' ``robots_present`` (§4.6: presence
counts "the most recent broadcast message of any type").

A robot learns about teammates only from the radio messages it actually receives: :class:`CommunicationLog`
keeps, per task, when each teammate was first and last heard about it, which is all ``comm_received``
(§3.6) ever asks. There is no shared matrix and no global knowledge.

Time is continuous: rates are in motivation per second and m grows by rate x dt. The rate (and whether the
set may grow at all) decided at one step is held until the next, so stepping from event to event integrates
the motivations exactly (:meth:`AllianceRobot.next_event_time` says when the next event is due); at a fixed
control period this is eq. (3.1) with a one-step lag. A window (t1, t2) of ``comm_received`` is read as
right-closed, so a condition that lapses at t has lapsed at t, not one instant later (a measure-zero choice).

Ambiguities of the thesis (spec §1.6) and how they are resolved, each behind a switch of :class:`AllianceParams`:

- item 2, ``impatience_reset`` while the set is active: ``reset_while_active`` (default False: the reset
  applies only to an inactive set, as the §3.5 narrative and DESIGN.md require; True is the literal formula,
  which drops an active task the moment a teammate is first heard about it, bypassing psi).
- item 3, recurring tasks: ``episode_rule``. "feedback_rise" (default) starts a new episode of a task when its
  sensory feedback rises 0 -> 1, forgetting who was first heard about it; "mission" is the literal reading
  (first-heard bookkeeping from mission start, so a teammate's second episode never gets the slow rate or a
  reset).
- item 4, "exceeds" theta: ``activate_at_threshold`` (default False: strictly greater, as the text says).
- item 5, delta-t is "time since last communication check": the reset fires for the teammates first heard in
  the messages handed to this step; no switch.
- items 6-7: one theta for every set (this module has no per-set threshold); every value is a config field.
- Not in the spec's list, but open too: whether a teammate's newer message about another activity ends its
  claim on the previous task at once. ``latest_message_supersedes`` (default True: a teammate announcing another
  activity has left the old task, and holding its claim would slow this robot for up to tau for nothing; False is
  the literal ``comm_received(i,k,j,t-tau,t)``: the old claim stands until tau passes without a message about it).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Callable, Iterable, Mapping, Protocol, Sequence

from teamsim.config import ConfigError, setting, validate
from teamsim.controllers.base import Command, Controller, Observation

ACTIVITY_KEY = "task"
IDLE = "idle"


def activity_message(task: str | None, extras: Mapping[str, Any] | None = None) -> dict:
    """The broadcast of §3.5: "my current activity" (the sender's id travels in the radio Message).

    ``extras`` are mission data riding along (spill location, push complete, ...).
    """
    return {**(extras or {}), ACTIVITY_KEY: task}


def announced_task(payload: Any) -> str | None:
    """The task a payload says its sender is doing; None for "idle" and for payloads that are not ALLIANCE's."""
    if isinstance(payload, dict):
        task = payload.get(ACTIVITY_KEY)
        return task if isinstance(task, str) else None
    return None


@dataclass(frozen=True)
class AllianceParams:
    """One robot's ALLIANCE parameters (App. A). Rates live per behaviour set in :class:`MotivationRates`."""

    threshold: float = setting(1.0, lo=0.0, open_lo=True,
                               meaning="theta, the activation threshold (§3.6); one value for every set and robot "
                                       "(§4.6 requires it uniform); no value is given (§1.6 item 7)")
    tau: float = setting(9.0, lo=0.0, open_lo=True,
                         meaning="tau_i, s: silence after which a teammate is taken as gone (§3.6); 'several times "
                                 "one's own delay between messages' (§4.6): 3 x 3 s at the R-2's 1/3 Hz")
    reset_while_active: bool = setting(False, meaning="apply impatience_reset to an active set too (literal App. A); "
                                                      "False: only while the set is inactive (§1.6 item 2)")
    episode_rule: str = setting("feedback_rise", choices=("feedback_rise", "mission"),
                                meaning="when first-heard bookkeeping of a task restarts: when its sensory feedback "
                                        "rises 0->1, or never (literal; §1.6 item 3)")
    latest_message_supersedes: bool = setting(True, meaning="a teammate's newer message about another activity ends "
                                                            "its claim at once; False: a claim lasts tau (literal)")
    activate_at_threshold: bool = setting(False, meaning="activate when m >= theta; False: when m exceeds theta, "
                                                         "as §3.6 says (§1.6 item 4)")

    def __post_init__(self):
        validate(self)


@dataclass(frozen=True)
class MotivationRates:
    """The impatience and acquiescence parameters of one behaviour set (§3.6, App. A). No values are given
    anywhere in the thesis for the physical or simulated runs (§1.6 item 7): the defaults are placeholders for a
    mission to override. Rates are in motivation units per second, so they scale with theta.
    """

    delta_fast: float = setting(1 / 3, lo=0.0, open_lo=True,
                                meaning="delta_fast_ij, /s: impatience when nobody else is doing the task")
    delta_slow: float = setting(1 / 30, lo=0.0, open_lo=True,
                                meaning="delta_slow_ij(k), /s: impatience while teammate k does the task "
                                        "(< delta_fast, §3.6)")
    phi: float = setting(30.0, lo=0.0, open_lo=True,
                         meaning="phi_ij(k), s: how long k's messages may slow this set down (inf: maximal "
                                 "patience, Condition 2)")
    psi: float = setting(60.0, lo=0.0, open_lo=True,
                         meaning="psi_ij, s: time active before yielding to a teammate doing the same task")
    lam: float = setting(120.0, lo=0.0, open_lo=True,
                         meaning="lambda_ij, s: time active before giving up to try another set")
    teammate_delta_slow: tuple = setting((), meaning="((robot, delta_slow), ...): per-teammate slow rates (§6.1.2: "
                                                     "a smaller rate for a slower teammate)")
    teammate_phi: tuple = setting((), meaning="((robot, phi), ...): per-teammate patience")

    def __post_init__(self):
        validate(self)

    def check(self) -> None:
        for robot, rate in ((None, self.delta_slow), *self.teammate_delta_slow):
            if not 0.0 < rate < self.delta_fast:
                who = f" for {robot}" if robot else ""
                raise ConfigError(f"delta_slow{who}={rate!r}: must be in (0, delta_fast={self.delta_fast!r}) "
                                  "(§3.6 assumes delta_fast > delta_slow > 0)")
        for robot, phi in self.teammate_phi:
            if not phi > 0.0:
                raise ConfigError(f"teammate_phi for {robot}={phi!r}: must be > 0")

    def slow_rate(self, teammate: str) -> float:
        return dict(self.teammate_delta_slow).get(teammate, self.delta_slow)

    def patience(self, teammate: str) -> float:
        return dict(self.teammate_phi).get(teammate, self.phi)


DEFAULT_RATES = MotivationRates()


class Rates(Protocol):
    """What a motivational behaviour needs to know at a step: fixed in ALLIANCE, learned in L-ALLIANCE."""

    delta_fast: float
    psi: float
    lam: float

    def slow_rate(self, teammate: str) -> float: ...

    def patience(self, teammate: str) -> float: ...


@dataclass(frozen=True)
class BehaviourSet:
    """a_ij: a named behaviour set, the task h_i(a_ij) it serves (§3.3; its own name by default), its rates.
    A robot's sets are given in priority order, highest first (the tie-break of §3.6)."""

    name: str
    task: str = ""
    rates: MotivationRates = DEFAULT_RATES

    def __post_init__(self):
        if not self.name or self.name == IDLE:
            raise ConfigError(f"behaviour set name {self.name!r}: must be non-empty and not {IDLE!r}")
        if not self.task:
            object.__setattr__(self, "task", self.name)


@dataclass
class Claim:
    """A teammate's announced activity as this robot heard it: the task (None: idle), since when, last heard."""

    task: str | None
    since: float
    last_heard: float


class CommunicationLog:
    """Everything ``comm_received(i, k, j, t1, t2)`` (§3.6) asks, kept from the messages this robot received.

    Per task of this robot: when each teammate was first heard about it in the current episode, and last heard;
    per teammate: its current claim. A message's time is the step at which it is handed to the robot.
    """

    def __init__(self, tasks: Iterable[str], params: AllianceParams):
        self.tau = params.tau
        self.supersede = params.latest_message_supersedes
        self.first_heard: dict[str, dict[str, float]] = {task: {} for task in tasks}
        self.last_heard: dict[str, dict[str, float]] = {task: {} for task in self.first_heard}
        self.episode = dict.fromkeys(self.first_heard, 0)
        self.claims: dict[str, Claim] = {}
        self.claiming: dict[str | None, dict[str, None]] = {}  # task -> teammates whose current claim it is
        self.ended: list[tuple[str, Claim]] = []  # claims that ended at the latest step: (teammate, claim)

    def new_episode(self, task: str) -> None:
        self.first_heard[task].clear()
        self.episode[task] += 1

    def hear(self, teammate: str, task: str | None, time: float) -> bool:
        """Record one message; True when it is the teammate's first about ``task`` in this episode."""
        claim = self.claims.get(teammate)
        if claim is not None and claim.task == task and claim.last_heard > time - self.tau:
            claim.last_heard = time
        else:
            if claim is not None:
                self._end(teammate, claim)
            self.claims[teammate] = Claim(task, time, time)
            self.claiming.setdefault(task, {})[teammate] = None
        if task not in self.first_heard:
            return False
        self.last_heard[task][teammate] = time
        first = self.first_heard[task]
        if teammate in first:
            return False
        first[teammate] = time
        return True

    def expire(self, time: float) -> None:
        """End the claims of teammates silent for tau (they are taken as gone, §3.6)."""
        if math.isinf(self.tau):
            return
        for teammate, claim in list(self.claims.items()):
            if claim.last_heard <= time - self.tau:
                self._end(teammate, claim)
                del self.claims[teammate]

    def _end(self, teammate: str, claim: Claim) -> None:
        del self.claiming[claim.task][teammate]
        if claim.task is not None:
            self.ended.append((teammate, claim))

    def claimants(self, task: str, time: float, present: frozenset) -> list[str]:
        """The teammates k with comm_received(i, k, j, t - tau, t) = 1 for this task, among those present."""
        if self.supersede:
            claims = self.claims
            return [k for k in self.claiming.get(task, ()) if claims[k].last_heard > time - self.tau and k in present]
        return [k for k, last in self.last_heard[task].items() if last > time - self.tau and k in present]

    def robots_present(self, time: float) -> frozenset:
        """robots_present(i, t) (§4.6): the teammates heard from, about anything, within tau."""
        return frozenset(k for k, claim in self.claims.items() if claim.last_heard > time - self.tau)

    def last_heard_about(self, task: str, teammate: str) -> float:
        if self.supersede:
            return self.claims[teammate].last_heard
        return self.last_heard[task][teammate]


@dataclass(frozen=True)
class MotivationEvent:
    """Something a motivational behaviour did at a step.

    kind: "activate", "deactivate" (detail: the input that zeroed it), "impatience_reset" (teammate first heard;
    detail: "episode N"), "acquiescence" (detail: "psi" or "lambda"), "impatience" (detail: "slow", with the
    teammate whose slow rate now applies, or "fast").
    """

    kind: str
    behaviour_set: str
    teammate: str | None = None
    detail: str = ""


@dataclass(frozen=True)
class StepTrace:
    """One step of one robot: theta, m_ij(t) per set, the growth rate held until the next step, the input that
    zeroed each zeroed set, and the events. It is the :class:`~teamsim.controllers.base.MotivationTrace` that
    :class:`AllianceController` returns in its command, so every physics trial records it."""

    time: float
    threshold: float
    active: str | None
    motivation: dict
    growth: dict
    zeroed: dict
    events: tuple


class AllianceRobot:
    """The motivational behaviours of one robot (§3.5-3.6): feed it, every control step, the time, the sensory
    feedback of each behaviour set, the radio messages received since the last step and the teammates
    present; it returns the active set (or None) and a :class:`StepTrace`."""

    def __init__(self, name: str, behaviour_sets: Sequence[BehaviourSet], params: AllianceParams = AllianceParams(),
                 precedes: Callable[[str, str], bool] | None = None):
        names = [s.name for s in behaviour_sets]
        if not names or len(set(names)) != len(names):
            raise ConfigError(f"robot {name}: behaviour set names must be unique and at least one: {names}")
        self.name = name
        self.params = params
        # precedes(task, k): whether teammate k's claim on the task came before this robot's, so that psi yields
        # to it; None: psi yields to any claimant (§3.6). A mission whose robots start a sub-task together needs
        # the order, or both yield at once and meet again (docs/decisions.md, "Janitorial service").
        self.precedes = precedes
        self.sets = tuple(behaviour_sets)
        self.tasks = tuple(dict.fromkeys(s.task for s in self.sets))
        self.log = CommunicationLog(self.tasks, params)
        self.motivation = dict.fromkeys(names, 0.0)
        self.growth = dict.fromkeys(names, 0.0)  # dm/dt held until the next step (0 while a gate holds m at 0)
        self.active: str | None = None
        self.active_since = 0.0
        self.time: float | None = None
        self._task_needed = dict.fromkeys(self.tasks, False)
        self._first_heard_now: dict[str, list[str]] = {}
        self._slow_teammate: dict[str, str | None] = dict.fromkeys(names)
        self._next_event = math.inf

    def step(self, time: float, feedback: Mapping[str, bool], messages: Iterable,
             robots_present: frozenset | None) -> tuple[str | None, StepTrace]:
        """One control step of eq. (3.1) for every set, with the rates each set was configured with.
        ``robots_present``: the teammates the radio has heard within tau (``Observation.robots_present``), or
        None to take them from this robot's own log and tau."""
        self.observe(time, feedback, messages)
        return self.update(time, feedback, robots_present)

    def observe(self, time: float, feedback: Mapping[str, bool], messages: Iterable) -> list[str]:
        """Take in this step's sensory feedback and messages. Returns the tasks whose feedback fell to 0."""
        needed = dict.fromkeys(self.tasks, False)
        for s in self.sets:
            if feedback[s.name]:
                needed[s.task] = True
        fallen = []
        for task, now in needed.items():
            before = self._task_needed[task]
            if now and not before and self.params.episode_rule == "feedback_rise":
                self.log.new_episode(task)
            elif before and not now:
                fallen.append(task)
        self._task_needed = needed
        self.log.ended.clear()
        first: dict[str, list[str]] = {}
        for message in messages:
            if message.sender == self.name:
                continue
            task = announced_task(message.payload)
            if self.log.hear(message.sender, task, time):
                first.setdefault(task, []).append(message.sender)
        self.log.expire(time)
        self._first_heard_now = first
        return fallen

    def update(self, time: float, feedback: Mapping[str, bool], robots_present: frozenset | None,
               rates: Mapping[str, Rates] | None = None, gates: Mapping[str, str | None] | None = None,
               growth_override: Mapping[str, float] | None = None, impatience_reset: bool = True,
               acquiescence: bool = True) -> tuple[str | None, StepTrace]:
        """Eq. (3.1) for every set, after :meth:`observe`.

        ``rates`` replaces each set's configured rates for this step (L-ALLIANCE learns them); ``gates`` names,
        per set, an extra input that holds its motivation at 0 this step (L-ALLIANCE's
        learned_robot_influence); ``growth_override`` replaces the impatience rate (the random increment of
        active learning); ``impatience_reset`` and ``acquiescence`` switch those two inputs off (active learning
        has neither).
        """
        dt = 0.0 if self.time is None else time - self.time
        if dt < 0.0:
            raise ValueError(f"robot {self.name}: time went back from {self.time} to {time}")
        self.time = time
        if robots_present is None:
            robots_present = self.log.robots_present(time)
        theta = self.params.threshold
        was_active = self.active
        events: list[MotivationEvent] = []
        zeroed: dict[str, str] = {}
        claimants_of: dict[str, list[str]] = {}

        def claimants(task: str) -> list[str]:
            if task not in claimants_of:
                claimants_of[task] = self.log.claimants(task, time, robots_present)
            return claimants_of[task]

        for s in self.sets:
            name = s.name
            is_active = name == was_active
            newly_heard = self._first_heard_now.get(s.task, ()) if impatience_reset else ()
            reset = bool(newly_heard) and (not is_active or self.params.reset_while_active)
            if reset:
                episode = f"episode {self.log.episode[s.task]}"
                events += [MotivationEvent("impatience_reset", name, k, episode) for k in newly_heard]
            if not feedback[name]:  # not applicable: held at 0, whatever the other inputs say
                self.motivation[name] = 0.0
                zeroed[name] = "sensory_feedback"
                continue
            gave_up = ""
            if is_active and acquiescence:
                r = rates[name] if rates is not None else s.rates
                held = time - self.active_since
                if held > r.psi and self._yields(s.task, claimants(s.task)):
                    gave_up = "psi"
                elif held > r.lam:
                    gave_up = "lambda"
                if gave_up:
                    events.append(MotivationEvent("acquiescence", name, None, gave_up))
            if was_active is not None and not is_active:
                cause = "activity_suppression"
            elif reset:
                cause = "impatience_reset"
            elif gave_up:
                cause = "acquiescence"
            else:
                cause = gates.get(name) if gates is not None else None
            if cause:
                self.motivation[name] = 0.0
                zeroed[name] = cause
            else:
                self.motivation[name] += self.growth[name] * dt
        if was_active is not None and was_active in zeroed:
            events.append(MotivationEvent("deactivate", was_active, None, zeroed[was_active]))
            self.active = None
        elif was_active is None:
            self._select(time, theta, zeroed, events)
        self._hold_rates(time, theta, feedback, rates, gates, growth_override, claimants, events)
        trace = StepTrace(time, theta, self.active, dict(self.motivation), dict(self.growth), zeroed, tuple(events))
        return self.active, trace

    def _yields(self, task: str, claimants: list[str]) -> bool:
        """Whether psi would yield to one of the teammates claiming ``task``."""
        if self.precedes is None:
            return bool(claimants)
        return any(self.precedes(task, k) for k in claimants)

    def _select(self, time: float, theta: float, zeroed: dict, events: list) -> None:
        """An idle robot activates its highest-priority set above theta; the others are suppressed at once."""
        inclusive = self.params.activate_at_threshold
        for s in self.sets:
            m = self.motivation[s.name]
            if m > theta or (inclusive and m >= theta):
                self.active, self.active_since = s.name, time
                events.append(MotivationEvent("activate", s.name))
                for other in self.sets:
                    if other is not s and self.motivation[other.name] > 0.0:
                        self.motivation[other.name] = 0.0
                        zeroed[other.name] = "activity_suppression"
                return

    def _hold_rates(self, time: float, theta: float, feedback: Mapping[str, bool], rates, gates, growth_override,
                    claimants, events: list) -> None:
        """The growth of each set until the next step, and when the next event is due if nothing changes."""
        next_event = math.inf
        active = self.active
        for s in self.sets:
            name = s.name
            if not feedback[name] or (active is not None and active != name) or (gates is not None and gates.get(name)):
                self.growth[name] = 0.0  # held at 0 until an input changes
                continue
            r = rates[name] if rates is not None else s.rates
            if name == active:
                next_event = min(next_event, self.active_since + r.lam)
                if self._yields(s.task, claimants(s.task)):
                    next_event = min(next_event, self.active_since + r.psi)
            if growth_override is not None:
                growth = growth_override[name]
            else:
                growth, lapse = self._impatience(s, r, time, claimants(s.task), events)
                next_event = min(next_event, lapse)
            self.growth[name] = growth
            if name != active:
                next_event = min(next_event, time + max(theta - self.motivation[name], 0.0) / growth)
        self._next_event = next_event

    def _impatience(self, s: BehaviourSet, r: Rates, time: float, claimants: list[str],
                    events: list) -> tuple[float, float]:
        """impatience_ij(t) of §3.6 and the time it may next change.

        The smallest delta_slow over the teammates heard about the task within tau (comm_received(t - tau, t))
        and first heard about it less than phi ago (no comm_received(0, t - phi), 0 being the episode start);
        delta_fast if there is none.
        """
        first = self.log.first_heard[s.task]
        slow, slow_teammate, lapse = math.inf, None, math.inf
        for k in claimants:
            patience = r.patience(k)
            started = first.get(k)  # None: heard about it only before this episode began
            if started is None or started > time - patience:
                rate = r.slow_rate(k)
                if rate < slow:
                    slow, slow_teammate = rate, k
                if started is not None:
                    lapse = min(lapse, started + patience)
            lapse = min(lapse, self.log.last_heard_about(s.task, k) + self.log.tau)
        previous = self._slow_teammate[s.name]
        if slow_teammate != previous:
            self._slow_teammate[s.name] = slow_teammate
            events.append(MotivationEvent("impatience", s.name, slow_teammate or previous,
                                          "slow" if slow_teammate else "fast"))
        return (slow if slow_teammate else r.delta_fast), lapse

    def next_event_time(self) -> float:
        """When the motivations would next change course if no message, feedback or presence changed: a set
        crossing theta, a slow rate lapsing (phi or tau), or psi or lambda running out. An event-driven
        simulation steps the robot just after this time (see the module's note on windows)."""
        return self._next_event


@dataclass(frozen=True)
class BehaviourSetDefinition:
    """What a mission gives :class:`AllianceController` for one behaviour set: its name, the task it serves
    (its name by default), its sensory feedback (is the set applicable, from the observation: physical or
    virtual sensors, §3.6), the controller of its competence layers, run while it is active, and its rates."""

    name: str
    applicable: Callable[[Observation], bool]
    controller: Controller
    task: str = ""
    rates: MotivationRates = DEFAULT_RATES

    @property
    def behaviour_set(self) -> BehaviourSet:
        return BehaviourSet(self.name, self.task, self.rates)


class Selector(Protocol):
    """An action selector over behaviour sets: :class:`AllianceRobot` or L-ALLIANCE's robot."""

    sets: tuple

    def step(self, time: float, feedback: Mapping[str, bool], messages: Iterable,
             robots_present: frozenset) -> tuple[str | None, StepTrace]: ...


class AllianceController:
    """A robot controller in the house style: ``observation -> Command``.

    Every call evaluates each set's sensory feedback on the observation, runs the motivational behaviours on the
    radio inbox and ``robots_present``, then runs the active set's controller. The command's ``behaviour`` is
    the active set's name ("idle" when none), its ``broadcast`` is the activity message (merged over any dict the
    set's controller broadcast) and its ``trace`` is the step's :class:`StepTrace`, which the world records in
    ``events.jsonl`` and ``timeline.png`` plots (``last_trace`` keeps the latest). Pass ``selector`` to run
    L-ALLIANCE (or any selector) over the same definitions.
    """

    def __init__(self, robot: str, definitions: Sequence[BehaviourSetDefinition],
                 params: AllianceParams = AllianceParams(), selector: Selector | None = None):
        self.definitions = {d.name: d for d in definitions}
        self.selector = selector or AllianceRobot(robot, [d.behaviour_set for d in definitions], params)
        selector_sets = [s.name for s in self.selector.sets]
        if selector_sets != [d.name for d in definitions]:
            raise ConfigError(f"robot {robot}: the selector's behaviour sets {selector_sets} differ from the "
                              f"definitions {[d.name for d in definitions]}")
        self.last_trace: StepTrace | None = None

    def __call__(self, observation: Observation) -> Command:
        feedback = {name: bool(d.applicable(observation)) for name, d in self.definitions.items()}
        active, trace = self.selector.step(observation.time, feedback, observation.inbox,
                                           observation.robots_present)
        self.last_trace = trace
        if active is None:
            return Command(behaviour=IDLE, broadcast=activity_message(None), trace=trace)
        definition = self.definitions[active]
        command = definition.controller(observation)
        extras = command.broadcast if isinstance(command.broadcast, dict) else None
        return replace(command, behaviour=active,
                       broadcast=activity_message(definition.behaviour_set.task, extras), trace=trace)
