"""L-ALLIANCE: ALLIANCE whose impatience and acquiescence come from learned task times (Parker 1994, ch.4;
§4.4-4.6; Appendix B).

Each robot keeps, per task it can do, the completion times of the last mu trials of itself (per behaviour set)
and of every teammate that shares the task, as measured from its own sensory feedback and the messages it
hears (§4.4.2; :class:`TaskStatistics`). ``task_time_i(k, j, t)`` is their mean plus one standard deviation; a
failure is attributed ``failure_penalty`` times the time attempted, so repeated failures make a task look ever
longer (§4.6). The statistics persist from trial to trial in a human-readable JSON file
(:func:`save_statistics`, :func:`load_statistics`).

From them, at every step (§4.6, App. B):

- ``robots_present(i, t)``: teammates heard from within tau: the radio's set (``Observation.robots_present``),
  or, when the caller passes None, the robot's own from the messages it received and its tau;
- ``task_category_ij``: 1 if r_i expects to do the task at least as fast as every present teammate it has data
  on (for strategy IV also: and no present teammate is announcing it), else 2;
- ``boredom_i``: grows at ``boredom_rate`` while the robot is idle, 0 while it is active;
- ``learned_robot_influence_ij``: 0 (blind to the task) while not bored and the task is in category 2;
- phi, psi per the strategy (Table 4.1): I own/own, II own/team minimum, III performer's/own, IV as II
  (IV differs in its categories and ordering, §4.5.3); delta_slow = theta / phi; lambda = ``lambda_factor`` x
  own time (§4.6: "two or three times");
- delta_fast = theta / delay, the delay mapped into [min_delay, max_delay] from the own time between the lowest
  and highest task times this robot knows: Shortest Task First for strategies I-III (Modified STF, §4.4.3),
  Longest Task First in category 1 and Shortest in category 2 for strategy IV (§4.5.3), or the orderings of the
  study: pure Longest Task First, whose delta_slow also grows with the expected time ("delta_fast and delta_slow
  grow at a rate proportional to the expected completion time", §4.4.3; phi is own time mirrored in
  [low, high], the thesis giving no constant), and Modified Random Task Selection (a delay drawn uniformly in
  the range).

Monitoring (§4.4.2, with §4.2's credit assignment): an own trial runs from activating a set to its task's
feedback falling (success; a fall is read as completion) or to giving the set up (failure). A teammate's runs
from its first message about a task to the task's feedback falling here, or, if it moved on or fell silent and
the task was not done within tau, to its last message about it (failure). Under strategy IV a failing task in
category 1 is taken longest first, so for a robot alone with it the penalty makes it *more* urgent: §4.6's
argument that the penalty ends lock-in holds under Shortest Task First, or once a teammate's better time moves
the task to category 2 (tests: ``test_a_lone_failing_robot_escapes_only_under_shortest_task_first``).

Active learning (training missions): m grows by theta x U(0,1) per second, U drawn afresh at every step, gated
only by sensory feedback, suppression and ``learning_impatience`` (a present teammate has announced the task
this episode): random choice among undone, unclaimed tasks, maximal patience and minimal acquiescence.
Adaptive (live) phase: eq. (3.1) times ``learned_robot_influence``. Learning stays on in both phases unless
``monitor_performance`` is off (the abstract study freezes knowledge, as §4.5.1 assumes learned times).

Ambiguities (spec §3.10), each behind a switch of :class:`LAllianceParams`:

- item 1, which category is blinded: ``blinded_category`` (2, the formula and §4.4.3; 1 is §4.6's text slip).
- item 2, r_i itself in the team minimum: ``psi_team_min_includes_self`` (True: "minimum time of team"; False:
  the App. B formula's min over ``robots_present``, which lacks r_i, falling back to its own time). Robots with
  no data are left out. For the category the two readings agree (category 1 iff own time <= every known present
  teammate's; ties make every tied robot category 1).
- item 3, App. B's typos (task_time without its subscript, "~ 1" for "= 1", "Progress When Active"): read as
  §4.6 writes them; nothing to switch.
- item 4, high == low: ``equal_times_delay`` ("midpoint" of the delay range: no task is then shorter or longer
  than another, so neither end is favoured; or "min_delay"). Footnote 6's alternative, low and high given in
  advance, is ``expected_time_range``.
- item 5, strategies I and II come from Table 4.1; strategy I uses no teammate knowledge, so it has no category
  split (every task category 2 and never blinded) and its low/high span only its own times.
- item 6, boredom's product form: ``boredom_rule`` ("any_set_active": boredom is 0 while any set is active, the
  stated intent; "product_formula": App. B's product, under which a one-set robot never resets it).
- not in the spec's list: the App. B product also zeroes an *active* set whenever learned_robot_influence or
  learning_impatience is 0, so a bored robot would drop a category-2 task the step after taking it (its boredom
  resets on activation). ``learned_gates_while_active`` (default False: they gate activation only, as "considers
  activating" in §4.6 says; True: literal).
- item 7, unspecified values: penalty, boredom threshold and rate, min/max delay, theta, prior task time are
  fields with defaults for missions in seconds; the study sets its own.
- item 8 (n^m < or <= 2^17) belongs to the study: :func:`teamsim.tasks.studies.lalliance.optimal_triples`.
- one standard deviation of the last mu attempts is the population one (a single trial has none).
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable, Mapping, Sequence

import numpy as np

from teamsim.config import ConfigError, setting, validate
from teamsim.controllers.alliance.motivation import AllianceParams, AllianceRobot, BehaviourSet, Claim, StepTrace
from teamsim.files import write_json

STRATEGIES = ("I", "II", "III", "IV")
TASK_ORDERINGS = ("per_strategy", "shortest_first", "longest_first", "random")
PHASES = ("active_learning", "adaptive")
INFLUENCE = "learned_robot_influence"
LEARNING_IMPATIENCE = "learning_impatience"


class TaskStatistics:
    """What one robot has learned (§4.4.2): attributed times of the last mu trials, of itself per behaviour
    set, and of each teammate per task they share (never for tasks the robot cannot do)."""

    def __init__(self, robot: str, trials_kept: int = 5):
        self.robot = robot
        self.trials_kept = trials_kept
        self.own: dict[str, list[float]] = {}
        self.teammates: dict[str, dict[str, list[float]]] = {}
        self.version = 0  # changes whenever a trial is recorded
        self._expected: dict[tuple, float | None] = {}

    def record_own(self, behaviour_set: str, attributed_time: float) -> None:
        self._record(self.own.setdefault(behaviour_set, []), ("own", behaviour_set), attributed_time)

    def record_teammate(self, teammate: str, task: str, attributed_time: float) -> None:
        trials = self.teammates.setdefault(teammate, {}).setdefault(task, [])
        self._record(trials, ("mate", teammate, task), attributed_time)

    def _record(self, trials: list[float], key: tuple, attributed_time: float) -> None:
        if not attributed_time >= 0.0:
            raise ValueError(f"{self.robot}: attributed time {attributed_time!r} for {key} must be >= 0")
        trials.append(float(attributed_time))
        del trials[:-self.trials_kept]
        self._expected.pop(key, None)
        if key[0] == "mate":
            self._expected.pop(("team", key[2]), None)
        self.version += 1

    def own_time(self, behaviour_set: str) -> float | None:
        """task_time_i(i, j, t) of this behaviour set, or None before any trial."""
        return self._lookup(("own", behaviour_set), self.own.get(behaviour_set))

    def teammate_time(self, teammate: str, task: str) -> float | None:
        """task_time_i(k, j, t), or None when this robot has never seen ``teammate`` do ``task``."""
        return self._lookup(("mate", teammate, task), self.teammates.get(teammate, {}).get(task))

    def teammate_times(self, task: str) -> dict[str, float]:
        """task_time_i(k, j, t) of every teammate this robot has seen do ``task``."""
        key = ("team", task)
        if key not in self._expected:
            self._expected[key] = {teammate: mean_plus_sd(tasks[task])
                                   for teammate, tasks in self.teammates.items() if task in tasks}
        return self._expected[key]

    def _lookup(self, key: tuple, trials: list[float] | None) -> float | None:
        if key not in self._expected:
            self._expected[key] = mean_plus_sd(trials) if trials else None
        return self._expected[key]

    def as_dict(self) -> dict:
        return {"robot": self.robot, "trials_kept": self.trials_kept, "own": self.own, "teammates": self.teammates}

    @classmethod
    def from_dict(cls, data: Mapping) -> "TaskStatistics":
        try:
            statistics = cls(str(data["robot"]), int(data["trials_kept"]))
            for behaviour_set, trials in data["own"].items():
                for value in trials:
                    statistics.record_own(behaviour_set, float(value))
            for teammate, tasks in data["teammates"].items():
                for task, trials in tasks.items():
                    for value in trials:
                        statistics.record_teammate(teammate, task, float(value))
        except (KeyError, TypeError, ValueError, AttributeError) as error:
            raise ValueError(f"not L-ALLIANCE task statistics: {error}") from None
        return statistics


def mean_plus_sd(trials: Sequence[float]) -> float:
    """The mean of the trials plus one (population) standard deviation."""
    if len(trials) == 1:
        return trials[0]
    mean = sum(trials) / len(trials)
    return mean + math.sqrt(sum((x - mean) ** 2 for x in trials) / len(trials))


def save_statistics(path: str | Path, statistics: TaskStatistics) -> None:
    """Write the statistics as indented JSON (atomically: write, then rename)."""
    write_json(Path(path), statistics.as_dict())


def load_statistics(path: str | Path) -> TaskStatistics:
    return TaskStatistics.from_dict(json.loads(Path(path).read_text(encoding="utf-8")))


@dataclass(frozen=True)
class LAllianceParams:
    """One robot's L-ALLIANCE parameters (§4.6, App. B). Times are in seconds (or the study's time units)."""

    strategy: str = setting("IV", choices=STRATEGIES,
                            meaning="impatience/acquiescence strategy, Table 4.1 and §4.5.3 (IV: the 'winning' one)")
    task_ordering: str = setting("per_strategy", choices=TASK_ORDERINGS,
                                 meaning="per_strategy: Shortest Task First for I-III, Longest in category 1 and "
                                         "Shortest in category 2 for IV; or the §4.4.3 alternatives")
    phase: str = setting("adaptive", choices=PHASES, meaning="active learning (training) or adaptive (live), §4.4.2")
    trials_kept: int = setting(5, lo=1, hi=1000, meaning="mu, trials per statistic ('about 5', §4.4.2)")
    failure_penalty: float = setting(2.0, lo=1.0, open_lo=True,
                                     meaning="factor on the attempted time attributed to a failure (> 1; no value "
                                             "given, §3.10 item 7)")
    min_delay: float = setting(1.0, lo=0.0, open_lo=True, meaning="minimum allowed idle delay before activation, s")
    max_delay: float = setting(10.0, lo=0.0, open_lo=True, meaning="maximum allowed idle delay before activation, s")
    boredom_rate: float = setting(1.0, lo=0.0, open_lo=True, meaning="boredom gained per idle second")
    boredom_threshold: float = setting(10.0, lo=0.0,
                                       meaning="boredom at which category-2 tasks are considered (with rate 1: "
                                               "max_delay idle seconds)")
    lambda_factor: float = setting(2.0, lo=1.0, meaning="lambda = this x own expected time (§4.6: 'two or three')")
    prior_task_time: float = setting(60.0, lo=0.0, open_lo=True,
                                     meaning="own expected time of a set never tried, s (§4.6 footnote 6 lets the "
                                             "designer give expected times)")
    monitor_performance: bool = setting(True, meaning="record own and teammates' trials as they happen")
    equal_times_delay: str = setting("midpoint", choices=("midpoint", "min_delay"),
                                     meaning="idle delay when every known task time is equal (high = low, "
                                             "§3.10 item 4)")
    boredom_rule: str = setting("any_set_active", choices=("any_set_active", "product_formula"),
                                meaning="boredom resets while any set is active, or App. B's literal product "
                                        "(§3.10 item 6)")
    blinded_category: int = setting(2, choices=(1, 2),
                                    meaning="category the robot is blind to until bored: 2 (formula), 1 (§4.6 text "
                                            "slip; §3.10 item 1)")
    learned_gates_while_active: bool = setting(False,
                                               meaning="learned_robot_influence and learning_impatience also zero "
                                                       "an active set (literal product); False: they gate activation")
    psi_team_min_includes_self: bool = setting(True, meaning="the team minimum of psi includes r_i (§3.10 item 2)")
    expected_time_range: tuple = setting((), meaning="(low, high) task times given in advance (§4.6 footnote 6), "
                                                     "which calibrates idle delays across robots; empty: the "
                                                     "extremes this robot knows")
    alliance: AllianceParams = field(default_factory=AllianceParams)

    def __post_init__(self):
        validate(self)

    def check(self) -> None:
        if self.max_delay < self.min_delay:
            raise ConfigError(f"max_delay={self.max_delay!r}: must be >= min_delay={self.min_delay!r}")
        if self.expected_time_range and not (len(self.expected_time_range) == 2
                                             and 0.0 <= self.expected_time_range[0] <= self.expected_time_range[1]):
            raise ConfigError(f"expected_time_range={self.expected_time_range!r}: must be (low, high) with "
                              "0 <= low <= high")


@dataclass(frozen=True)
class LearnedRates:
    """One set's rates at one step, from task times (§4.6)."""

    theta: float
    delta_fast: float
    psi: float
    lam: float
    patience_time: float  # phi when it does not depend on the teammate: own time (or its LTF mirror)
    performer_times: Mapping[str, float] | None = None  # strategy III judges a teammate by its own time

    def patience(self, teammate: str) -> float:
        """phi_ij(k, t): own time, or (strategy III) the performer's, when known."""
        if self.performer_times is not None:
            return self.performer_times.get(teammate, self.patience_time)
        return self.patience_time

    def slow_rate(self, teammate: str) -> float:
        """delta_slow_ij(k, t) = theta / phi_ij(k, t): the motivation reaches theta after exactly phi."""
        return self.theta / self.patience(teammate)


class LAllianceRobot:
    """The motivational behaviours of one L-ALLIANCE robot: :class:`AllianceRobot` whose rates and extra gate are
    recomputed every step from what it has learned. Same ``step`` as ALLIANCE; usable as the ``selector`` of
    :class:`~teamsim.controllers.alliance.motivation.AllianceController`."""

    def __init__(self, name: str, behaviour_sets: Sequence[BehaviourSet], params: LAllianceParams = LAllianceParams(),
                 statistics: TaskStatistics | None = None, rng: np.random.Generator | None = None):
        if statistics is not None and statistics.robot != name:
            raise ConfigError(f"statistics of {statistics.robot!r} given to robot {name!r}")
        needs_rng = params.phase == "active_learning" or params.task_ordering == "random"
        if needs_rng and rng is None:
            raise ConfigError(f"robot {name}: active learning and random task ordering need an rng")
        self.params = params
        self.core = AllianceRobot(name, behaviour_sets, params.alliance)
        self.statistics = statistics or TaskStatistics(name, params.trials_kept)
        self.rng = rng
        self.boredom = 0.0
        self.categories: dict[str, int] = {}
        self._tasks = frozenset(self.core.tasks)
        self._random_delay: dict[str, float] = {}
        self._unsettled: list[tuple[str, Claim]] = []  # teammates' ended claims awaiting a verdict
        self._settled: dict[str, float] = {}  # teammate -> start of the claim already credited
        self._learned_key: tuple | None = None
        self._learned: dict = {}
        self._boredom_due = math.inf
        theta = params.alliance.threshold
        self._maximal_patience = {s.name: LearnedRates(theta, 1.0, math.inf, math.inf, math.inf)
                                  for s in self.core.sets}

    @property
    def name(self) -> str:
        return self.core.name

    @property
    def sets(self) -> tuple:
        return self.core.sets

    def step(self, time: float, feedback: Mapping[str, bool], messages: Iterable,
             robots_present: frozenset | None) -> tuple[str | None, StepTrace]:
        """As :meth:`AllianceRobot.step` (``robots_present`` None: from this robot's own log and tau, §4.6)."""
        core, p = self.core, self.params
        was_active, active_since = core.active, core.active_since
        dt = 0.0 if core.time is None else time - core.time
        fallen = core.observe(time, feedback, messages)
        if robots_present is None:
            robots_present = core.log.robots_present(time)
        if p.monitor_performance:
            self._judge_teammates(time, fallen)
        growing = was_active is None or (p.boredom_rule == "product_formula" and len(core.sets) == 1)
        self.boredom = self.boredom + p.boredom_rate * dt if growing else 0.0
        if p.phase == "active_learning":
            gates = self._learning_gates(robots_present)
            theta = p.alliance.threshold
            growth = {s.name: theta * float(self.rng.random()) for s in core.sets}
            active, trace = core.update(time, feedback, robots_present, rates=self._maximal_patience, gates=gates,
                                        growth_override=growth, impatience_reset=False, acquiescence=False)
        else:
            rates, gates = self._adaptive_inputs(time, robots_present, feedback)
            active, trace = core.update(time, feedback, robots_present, rates=rates, gates=gates)
        if p.monitor_performance and was_active is not None and active != was_active:
            self._judge_self(trace, was_active, time - active_since)
        self._boredom_due = math.inf
        still_growing = active is None or (p.boredom_rule == "product_formula" and len(core.sets) == 1)
        if still_growing and self.boredom < p.boredom_threshold and INFLUENCE in gates.values():
            self._boredom_due = time + (p.boredom_threshold - self.boredom) / p.boredom_rate
        return active, trace

    def next_event_time(self) -> float:
        """As :meth:`AllianceRobot.next_event_time`, and the moment boredom unblinds category-2 tasks."""
        return min(self.core.next_event_time(), self._boredom_due)

    # ---------------------------------------------------------------- inputs of the adaptive phase

    def _adaptive_inputs(self, time: float, present: frozenset, feedback: Mapping[str, bool]) -> tuple[dict, dict]:
        """This step's rates and learned_robot_influence of every applicable set (the others are held at 0)."""
        p, core = self.params, self.core
        theta = p.alliance.threshold
        static = self._learned_inputs(present)
        if p.task_ordering == "random":
            for s in core.sets:  # a fresh draw for every set starting again from zero
                if core.motivation[s.name] == 0.0 or s.name == core.active:
                    self._random_delay[s.name] = float(self.rng.uniform(p.min_delay, p.max_delay))
        uses_team = p.strategy != "I"
        rates, gates, categories = {}, {}, {}
        for s in core.sets:
            name = s.name
            if not feedback[name]:
                continue
            best, by_category = static[name]
            if best and p.strategy == "IV" and core.log.claimants(s.task, time, present):
                best = False  # the revised category 1 excludes tasks a teammate is doing (§4.5.3)
            category = 1 if best else 2
            categories[name] = category
            r = by_category[category]
            if p.task_ordering == "random":
                r = LearnedRates(theta, theta / self._random_delay[name], r.psi, r.lam, r.patience_time,
                                 r.performer_times)
            rates[name] = r
            blinded = uses_team and self.boredom < p.boredom_threshold and category == p.blinded_category
            gates[name] = INFLUENCE if blinded and (name != core.active or p.learned_gates_while_active) else None
        self.categories = categories
        return rates, gates

    def _learned_inputs(self, present: frozenset) -> dict[str, tuple[bool, dict[int, LearnedRates]]]:
        """Per set, what only the statistics and the teammates present decide: whether r_i is at least as fast
        as every present teammate it knows of (category 1 but for strategy IV's 'not being done' clause), and
        the rates the set would have in each category. Recomputed when either changes."""
        key = (self.statistics.version, present)
        if self._learned_key == key:
            return self._learned
        p, core, statistics = self.params, self.core, self.statistics
        theta = p.alliance.threshold
        uses_team = p.strategy != "I"
        own = {s.name: self._own_time(s.name) for s in core.sets}
        known = list(own.values())
        teams = {}
        for task in core.tasks:
            times = statistics.teammate_times(task) if uses_team else {}
            known += times.values()  # low and high span every time this robot knows (§4.6), present or not
            teams[task] = {k: t for k, t in times.items() if k in present}
        low, high = p.expected_time_range or (min(known), max(known))
        learned = {}
        for s in core.sets:
            mine, team = own[s.name], teams[s.task]
            if p.strategy in ("I", "III"):
                psi = mine
            else:
                candidates = list(team.values())
                if p.psi_team_min_includes_self or not candidates:
                    candidates.append(mine)
                psi = min(candidates)
            performer_times = team if p.strategy == "III" else None
            patience = mine
            if p.task_ordering == "longest_first":  # §4.4.3: delta_slow grows with the expected time too
                patience = max(low + high - mine, p.min_delay)
            by_category = {category: LearnedRates(theta, theta / self._fast_delay(mine, category, low, high), psi,
                                                  p.lambda_factor * mine, patience, performer_times)
                           for category in (1, 2)}
            learned[s.name] = (uses_team and all(mine <= t for t in team.values()), by_category)
        self._learned_key, self._learned = key, learned
        return learned

    def _own_time(self, behaviour_set: str) -> float:
        known = self.statistics.own_time(behaviour_set)
        return self.params.prior_task_time if known is None else known

    def _fast_delay(self, mine: float, category: int, low: float, high: float) -> float:
        """The idle delay theta / delta_fast (§4.6): own time mapped into [min_delay, max_delay] (random task
        selection replaces it with a fresh draw)."""
        p = self.params
        if high == low:
            return 0.5 * (p.min_delay + p.max_delay) if p.equal_times_delay == "midpoint" else p.min_delay
        span = p.max_delay - p.min_delay
        offset = min(max((mine - low) * span / (high - low), 0.0), span)  # a given range may not hold every time
        ordering = p.task_ordering
        longest_first = ordering == "longest_first" or (
            ordering == "per_strategy" and p.strategy == "IV" and category == 1)
        return p.max_delay - offset if longest_first else p.min_delay + offset

    def _learning_gates(self, present: frozenset) -> dict[str, str | None]:
        """learning_impatience (§4.6): blind to a task some present teammate has announced in this episode."""
        core = self.core
        gates = {}
        for s in core.sets:
            heard = any(k in present for k in core.log.first_heard[s.task])
            applies = s.name != core.active or self.params.learned_gates_while_active
            gates[s.name] = LEARNING_IMPATIENCE if heard and applies else None
        return gates

    # ---------------------------------------------------------------- performance monitoring (§4.4.2)

    def _judge_self(self, trace: StepTrace, behaviour_set: str, held: float) -> None:
        """A set given up: success if its task's feedback fell (the task is done), else a penalised failure."""
        succeeded = trace.zeroed.get(behaviour_set) == "sensory_feedback"
        self.statistics.record_own(behaviour_set, held if succeeded else held * self.params.failure_penalty)

    def _judge_teammates(self, time: float, fallen: list[str]) -> None:
        """Credit a teammate with the time from its first message about a task to the task's completion (§4.2,
        assumption 2); a claim that ended without completion within tau is a failure."""
        log, penalty = self.core.log, self.params.failure_penalty
        for teammate, claim in log.ended:
            if claim.task in self._tasks and self._settled.get(teammate) != claim.since:
                self._unsettled.append((teammate, claim))
        for task in fallen:
            for teammate, claim in log.claims.items():
                if claim.task == task and self._settled.get(teammate) != claim.since:
                    self.statistics.record_teammate(teammate, task, time - claim.since)
                    self._settled[teammate] = claim.since
            for teammate, claim in [(k, c) for k, c in self._unsettled if c.task == task]:
                self.statistics.record_teammate(teammate, task, time - claim.since)
            self._unsettled = [(k, c) for k, c in self._unsettled if c.task != task]
        still_open = []
        for teammate, claim in self._unsettled:
            if time - claim.last_heard > log.tau:
                self.statistics.record_teammate(teammate, claim.task, (claim.last_heard - claim.since) * penalty)
            else:
                still_open.append((teammate, claim))
        self._unsettled = still_open
