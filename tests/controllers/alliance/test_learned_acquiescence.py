"""L-ALLIANCE's failure penalty on an ALLIANCE robot (§4.6): a robot that keeps failing a set gives it up and
waits ever longer before trying again; plain ALLIANCE comes straight back (the "stuck forever" caveat)."""
from __future__ import annotations

import pytest

from teamsim.controllers.alliance.learned_acquiescence import LearnedAcquiescence, LearningParams
from teamsim.controllers.alliance.motivation import AllianceRobot, BehaviourSet, MotivationRates

RATES = MotivationRates(delta_fast=1 / 3, delta_slow=1 / 30, phi=0.5, psi=float("inf"), lam=600.0)
DT = 0.1


def robot(**learning) -> LearnedAcquiescence:
    core = AllianceRobot("green", [BehaviourSet("move-spill", rates=RATES)])
    params = LearningParams(**{"min_lambda": 0.0, "enabled": True, **learning})
    return LearnedAcquiescence(core, ("move-spill",), params)


def activations(selector: LearnedAcquiescence, until: float, done_after: float | None = None, time: float = 0.0):
    """(start, end) of every activation from ``time`` while the task stays to do; with ``done_after`` each
    activation completes the task after that long (its feedback falls for one step)."""
    spans, start, falling = [], None, False
    while time < until:
        active, _ = selector.step(round(time, 6), {"move-spill": not falling}, [], frozenset())
        falling = False
        if active and start is None:
            start = time
        elif not active and start is not None:
            spans.append((start, time))
            start = None
        if active and done_after is not None and time - start >= done_after:
            falling = True
        time += DT
    return spans


def test_a_failing_robot_gives_up_and_waits_ever_longer():
    selector = robot(prior_task_time=20.0, lambda_factor=2.0, failure_penalty=2.0)
    spans = activations(selector, 1400.0)
    first, second, third = spans[:3]
    assert first[1] - first[0] == pytest.approx(40.0, abs=0.25)  # lambda = 2 x the prior 20 s
    # the failure is attributed 2 x 40 s; the robot waits its expected time (80 s) before trying again ...
    assert selector.statistics.own["move-spill"][0] == pytest.approx(80.0, abs=0.5)
    # (less a little: the tick that gives up still grows at the configured fast rate, 1/3 of theta a second)
    assert 80.0 * (1 - DT * RATES.delta_fast) - 0.3 <= second[0] - first[1] <= 80.5
    # ... and lambda is now twice that expected time: 160 s; the third wait is longer still
    assert second[1] - second[0] == pytest.approx(160.0, abs=0.5)
    assert third[0] - second[1] > second[0] - first[1]
    assert len(spans) < 6  # it has effectively given the task up


def test_plain_alliance_comes_straight_back():
    spans = activations(robot(enabled=False), 1300.0)
    assert [round(end - start) for start, end in spans[:2]] == [600, 600]  # the configured lambda
    assert spans[1][0] - spans[0][1] < 4.0  # about theta / delta_fast = 3 s


def test_successes_keep_the_configured_rates_and_learn_the_time():
    selector = robot(prior_task_time=200.0, lambda_factor=3.0)
    spans = activations(selector, 200.0, done_after=30.0)
    assert len(spans) >= 5
    assert all(not failed for failed in selector.failed_last.values())
    assert selector.expected_time("move-spill") == pytest.approx(30.0, abs=0.5)  # every trial alike: sd 0
    gaps = [b[0] - a[1] for a, b in zip(spans, spans[1:])]
    assert max(gaps) < 4.0  # back within theta / delta_fast after each success
    assert selector.rates()["move-spill"].lam == pytest.approx(90.0, abs=1.5)  # 3 x 30 s


def test_lambda_never_falls_below_its_floor():
    selector = robot(prior_task_time=10.0, lambda_factor=2.0, min_lambda=50.0)
    assert selector.rates()["move-spill"].lam == 50.0
    spans = activations(selector, 60.0)
    assert spans[0][1] - spans[0][0] == pytest.approx(50.0, abs=0.25)


def test_a_success_after_failures_restores_the_fast_rate():
    selector = robot(prior_task_time=10.0, lambda_factor=1.0)
    activations(selector, 15.0)  # one failure at lambda = 10 s, attributed 20 s
    assert selector.failed_last["move-spill"]
    assert selector.rates()["move-spill"].delta_fast == pytest.approx(1 / 20, rel=0.02)
    rates = selector.rates()["move-spill"]
    assert rates.slow_rate("red") <= rates.delta_fast  # delta_slow never above delta_fast
    spans = activations(selector, 120.0, done_after=5.0, time=15.0)  # the fix: now it succeeds
    assert not selector.failed_last["move-spill"]
    assert selector.rates()["move-spill"].delta_fast == RATES.delta_fast
    gaps = [b[0] - a[1] for a, b in zip(spans, spans[1:])]
    assert gaps and max(gaps[1:] or gaps) < 4.0
