"""L-ALLIANCE's failure penalty on chosen behaviour sets of an ALLIANCE robot (Parker §4.4.2, §4.6; spec §2.2's
caveat, §3.2).

Under plain ALLIANCE a robot whose gripper breaks can stay "stuck forever" on move-spill: acquiescence (lambda)
makes it give the set up, but its impatience brings it straight back (Parker p.~48). L-ALLIANCE fixes this by
learning from the robot's own trials: each activation of a set is a trial, a success when the set's task is
done (its sensory feedback falls) and a failure when the robot gives it up; the time attributed to a failure is
``failure_penalty`` times the time attempted, so repeated failures make the expected time grow, and a robot
with a long expected time is slow to start the task again.

:class:`LearnedAcquiescence` is an ALLIANCE selector (:class:`teamsim.controllers.alliance.motivation.Selector`) that
does exactly that for the sets it is given and keeps ALLIANCE's fixed rates everywhere else:

- task_time = mean + 1 s.d. of the last ``trials_kept`` own trials (:class:`TaskStatistics`), or
  ``prior_task_time`` before the first (§4.6 footnote 6: the designer may give expected times);
- lambda = ``lambda_factor`` x task_time (§4.6: "two or three times"), but never less than ``min_lambda``: a
  cleanup load's time varies enormously (ch.5), and with lambda = 3 x a few short loads healthy robots gave up
  long searches, were penalised and waited; the cleanup then failed (seed 4 with red killed, measured);
- after a failed trial, and until the next success, delta_fast = theta / task_time: the robot waits its own
  expected time before it tries again, longer after every further failure (the set's slow rate is capped at
  the same value, keeping delta_slow <= delta_fast). After a success its configured rates apply again.

Choices (the thesis does not give them): only the robot's own trials are learned (the teammates' times, task
categories and boredom of full L-ALLIANCE would change how every set is shared;
``teamsim.controllers.alliance.lalliance`` has them); a set given up for a teammate (psi) counts as a failure too, as in
§4.4.2's monitoring; the control step at which a set is given up still holds its old rate until the next step (the
outcome is known only then).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable, Mapping

from teamsim.config import setting
from teamsim.controllers.alliance.lalliance import TaskStatistics
from teamsim.controllers.alliance.motivation import AllianceRobot, MotivationRates, StepTrace


@dataclass(frozen=True)
class LearningParams:
    """L-ALLIANCE's learning constants for the learned sets (§4.6; no values are given in the thesis)."""
    enabled: bool = setting(False, meaning="learn from own trials (L-ALLIANCE), so a robot that keeps failing "
                                           "gives up; false: plain ALLIANCE, whose broken-gripper robot stays on "
                                           "move-spill for ever (§3.7.2)")
    failure_penalty: float = setting(2.0, lo=1.0, open_lo=True,
                                     meaning="factor on the attempted time attributed to a failure (> 1)")
    lambda_factor: float = setting(3.0, lo=1.0, meaning="lambda = this x own expected time (§4.6: 'two or three')")
    min_lambda: float = setting(600.0, lo=0.0, meaning="lambda is never shorter than this, s: task times vary "
                                                       "enormously (ch.5), and a long search is not a failure")
    prior_task_time: float = setting(200.0, lo=0.0, open_lo=True,
                                     meaning="own expected time before the first trial, s")
    trials_kept: int = setting(5, lo=1, hi=1000, meaning="mu, trials per statistic ('about 5', §4.4.2)")


@dataclass(frozen=True)
class _Learned:
    """A learned set's rates at one step (:class:`teamsim.controllers.alliance.motivation.Rates`)."""
    configured: MotivationRates
    delta_fast: float
    lam: float

    @property
    def psi(self) -> float:
        return self.configured.psi

    def slow_rate(self, teammate: str) -> float:
        return min(self.configured.slow_rate(teammate), self.delta_fast)

    def patience(self, teammate: str) -> float:
        return self.configured.patience(teammate)


class LearnedAcquiescence:
    """ALLIANCE over ``core``'s sets, with L-ALLIANCE's learned lambda and failure penalty on ``learned`` sets."""

    def __init__(self, core: AllianceRobot, learned: Iterable[str], params: LearningParams = LearningParams(),
                 statistics: TaskStatistics | None = None):
        """``statistics``: what the robot learned in earlier missions (else it starts from the prior)."""
        self.core = core
        self.params = params
        self.sets = core.sets
        self.learned = tuple(learned)
        self.statistics = statistics or TaskStatistics(core.name, params.trials_kept)
        self.failed_last = dict.fromkeys(self.learned, False)

    def expected_time(self, name: str) -> float:
        known = self.statistics.own_time(name)
        return self.params.prior_task_time if known is None else known

    def rates(self) -> dict[str, object]:
        theta = self.core.params.threshold
        rates: dict[str, object] = {s.name: s.rates for s in self.sets}
        for name in self.learned:
            configured = rates[name]
            expected = self.expected_time(name)
            fast = theta / expected if self.failed_last[name] else configured.delta_fast
            lam = max(self.params.lambda_factor * expected, self.params.min_lambda)
            rates[name] = _Learned(configured, fast, lam)
        return rates

    def step(self, time: float, feedback: Mapping[str, bool], messages: Iterable,
             robots_present: frozenset | None) -> tuple[str | None, StepTrace]:
        core = self.core
        if not self.params.enabled:
            return core.step(time, feedback, messages, robots_present)
        was_active, since = core.active, core.active_since
        core.observe(time, feedback, messages)
        active, trace = core.update(time, feedback, robots_present, rates=self.rates())
        if was_active in self.failed_last and active != was_active:
            self._judge(was_active, trace, time - since)
        return active, trace

    def _judge(self, name: str, trace: StepTrace, held: float) -> None:
        """A learned set stopped: a success if its feedback fell (the task is done), else a penalised failure."""
        succeeded = trace.zeroed.get(name) == "sensory_feedback"
        self.failed_last[name] = not succeeded
        self.statistics.record_own(name, held if succeeded else held * self.params.failure_penalty)
