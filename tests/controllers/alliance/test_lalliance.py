"""L-ALLIANCE (teamsim.controllers.alliance.lalliance): task statistics and their JSON file, the learned rates of Table
4.1 and §4.6, categories, boredom and learned robot influence, the two phases, the ambiguity switches, and
learning from what the radio delivers on an abstract team."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from teamsim.config import ConfigError, RadioConfig
from teamsim.controllers.alliance.lalliance import (LAllianceParams, LAllianceRobot, TaskStatistics, load_statistics,
                                                    mean_plus_sd, save_statistics)
from teamsim.controllers.alliance.motivation import AllianceParams, BehaviourSet, activity_message
from teamsim.radio import Message

from tests.controllers.alliance.abstract_team import AbstractTeam, Task

THETA = 1.0


def taught(own: dict, team: dict | None = None, name: str = "me", rng=None, **params) -> LAllianceRobot:
    """A robot with one set per task in ``own`` (task -> own time) and ``team`` (teammate -> task -> time)."""
    statistics = TaskStatistics(name)
    for task, time in own.items():
        statistics.record_own(task, time)
    for teammate, times in (team or {}).items():
        for task, time in times.items():
            statistics.record_teammate(teammate, task, time)
    params.setdefault("min_delay", 1.0)
    params.setdefault("max_delay", 10.0)
    return LAllianceRobot(name, [BehaviourSet(task) for task in own], LAllianceParams(**params), statistics, rng)


def heard(sender, task, time=0.0):
    return Message(sender, time, activity_message(task))


def step(r, time, messages=(), present=frozenset({"k"}), feedback=None):
    return r.step(time, feedback or {s.name: True for s in r.sets}, messages, present)


# ---------------------------------------------------------------- task statistics and their file


def test_task_time_is_mean_plus_one_sd_of_the_last_mu_trials():
    statistics = TaskStatistics("me", trials_kept=5)
    for value in (100.0, 10.0, 20.0, 30.0, 40.0, 50.0):
        statistics.record_own("x", value)
    window = [10.0, 20.0, 30.0, 40.0, 50.0]
    assert statistics.own_time("x") == pytest.approx(np.mean(window) + np.std(window))
    assert statistics.own_time("y") is None and statistics.teammate_time("k", "x") is None
    assert mean_plus_sd([7.0]) == 7.0


def test_statistics_persist_in_readable_json(tmp_path):
    statistics = TaskStatistics("red", trials_kept=3)
    statistics.record_own("find-methodical", 120.0)
    statistics.record_teammate("green", "find", 300.0)
    path = tmp_path / "red.json"
    save_statistics(path, statistics)
    text = path.read_text()
    assert '"find-methodical": [\n      120.0' in text  # indented, one value per line
    loaded = load_statistics(path)
    assert loaded.as_dict() == statistics.as_dict()
    assert loaded.teammate_time("green", "find") == 300.0
    path.write_text(json.dumps({"robot": "red"}))
    with pytest.raises(ValueError, match="not L-ALLIANCE task statistics"):
        load_statistics(path)


def test_repeated_failures_look_ever_longer():
    """§4.6: a failure is attributed penalty x attempted time, so the expected time grows monotonically."""
    r = taught({"x": 10.0}, failure_penalty=3.0, lambda_factor=2.0)
    expected, time = [], 0.0
    for _ in range(4):
        while True:
            time = round(time + 0.5, 9)
            _, trace = step(r, time, present=frozenset())
            if any(e.kind == "acquiescence" for e in trace.events):
                break
        expected.append(r.statistics.own_time("x"))
    assert all(later > earlier for earlier, later in zip(expected, expected[1:]))
    assert r.statistics.own["x"][1] == pytest.approx(3.0 * (2.0 * 10.0 + 0.5))  # gave up just past lambda


# ---------------------------------------------------------------- learned rates (Table 4.1, §4.6)


@pytest.mark.parametrize("strategy, ordering, first", [("I", "per_strategy", "short"), ("IV", "per_strategy", "long"),
                                                       ("II", "longest_first", "long"), ("III", "random", None)])
def test_idle_delay_orders_tasks(strategy, ordering, first):
    """delta_fast = theta / delay, delay in [min_delay, max_delay] from own time between low and high."""
    r = taught({"short": 10.0, "middle": 20.0, "long": 30.0}, strategy=strategy, task_ordering=ordering,
               rng=np.random.default_rng(3))
    _, trace = step(r, 0.0, present=frozenset())
    delays = {s: THETA / g for s, g in trace.growth.items()}
    if first is None:
        assert all(1.0 <= d <= 10.0 for d in delays.values()) and len(set(delays.values())) == 3
        return
    assert delays[first] == pytest.approx(1.0) and delays["middle"] == pytest.approx(5.5)
    assert max(delays.values()) == pytest.approx(10.0)


def test_random_delays_are_drawn_afresh_for_each_selection():
    r = taught({"x": 10.0, "y": 20.0}, task_ordering="random", rng=np.random.default_rng(0))
    draws, time = [], 0.0
    while len(draws) < 3:
        feedback = {"x": True, "y": True}
        if r.core.active:  # the active task is done at once: a new selection round begins
            feedback[r.core.active] = False
        _, trace = r.step(time, feedback, (), frozenset())
        if r.core.active is None and trace.growth["x"] > 0 and (not draws or trace.growth["x"] != draws[-1]):
            draws.append(trace.growth["x"])
        time = round(time + 0.5, 9)
    assert len(set(draws)) == 3


@pytest.mark.parametrize("choice, delay", [("midpoint", 5.5), ("min_delay", 1.0)])
def test_equal_task_times_do_not_divide_by_zero(choice, delay):
    r = taught({"x": 10.0}, equal_times_delay=choice)
    _, trace = step(r, 0.0, present=frozenset())
    assert THETA / trace.growth["x"] == pytest.approx(delay)


@pytest.mark.parametrize("strategy, patience, yields_after", [("I", 75.0, 100.0), ("II", 75.0, 75.0),
                                                              ("III", 100.0, 100.0), ("IV", 75.0, 75.0)])
def test_table_4_1_worked_example(strategy, patience, yields_after):
    """§4.5.1: r1 needs 75 per task, r2 100. phi of r1 with r2 at work, psi of r2 with r1 at work."""
    r1 = taught({"a3": 75.0}, {"r2": {"a3": 100.0}}, name="r1", strategy=strategy, boredom_threshold=0.0)
    _, trace = step(r1, 0.0, [heard("r2", "a3")], frozenset({"r2"}))
    assert THETA / trace.growth["a3"] == pytest.approx(patience)
    r2 = taught({"a3": 100.0}, {"r1": {"a3": 75.0}}, name="r2", strategy=strategy, boredom_threshold=0.0)
    time = 0.0
    while r2.core.active is None:
        time = round(time + 0.5, 9)
        step(r2, time, present=frozenset({"r1"}))
    started = r2.core.active_since
    while r2.core.active:
        time = round(time + 0.5, 9)
        step(r2, time, [heard("r1", "a3", time)], frozenset({"r1"}))
    assert time - started == pytest.approx(yields_after + 0.5)


@pytest.mark.parametrize("include_self, psi", [(True, 50.0), (False, 80.0)])
def test_team_minimum_of_psi_with_or_without_self(include_self, psi):
    r = taught({"x": 50.0}, {"k": {"x": 80.0}}, strategy="II", psi_team_min_includes_self=include_self,
               boredom_threshold=0.0)
    time = 0.0
    while r.core.active is None:
        time = round(time + 0.5, 9)
        step(r, time)
    started = r.core.active_since
    while r.core.active:
        time = round(time + 0.5, 9)
        step(r, time, [heard("k", "x", time)])
    assert time - started == pytest.approx(psi + 0.5)


# ---------------------------------------------------------------- categories, boredom, learned influence


def test_category_2_is_blinded_until_bored():
    r = taught({"slow": 100.0, "mine": 10.0}, {"k": {"slow": 50.0}}, boredom_threshold=20.0)
    traces = [step(r, t)[1] for t in np.arange(0.0, 15.0, 0.5)]
    assert r.categories == {"slow": 2, "mine": 1}
    assert traces[1].zeroed["slow"] == "learned_robot_influence"
    assert traces[-1].active == "mine"  # category 1 first; boredom resets on activation
    mine_done = {"slow": True, "mine": False}
    idle = [step(r, t, feedback=mine_done)[1] for t in np.arange(15.0, 60.0, 0.5)]
    first = next(t for t in idle if t.active == "slow")
    assert 15.0 + 20.0 < first.time <= 15.0 + 20.0 + 10.0 + 0.5  # bored after 20 s, then at most max_delay


def test_absent_teammates_do_not_count():
    r = taught({"x": 100.0}, {"k": {"x": 50.0}})
    step(r, 0.0, present=frozenset())
    assert r.categories == {"x": 1}


def test_strategy_iv_puts_a_claimed_task_in_category_2():
    for strategy, category in (("II", 1), ("IV", 2)):
        r = taught({"x": 10.0}, {"k": {"x": 50.0}}, strategy=strategy)
        step(r, 0.0, [heard("k", "x")])
        assert r.categories == {"x": category}


def test_blinded_category_is_a_switch():
    r = taught({"slow": 100.0, "mine": 10.0}, {"k": {"slow": 50.0}}, blinded_category=1)
    _, trace = step(r, 0.0)
    assert trace.zeroed == {"mine": "learned_robot_influence"}


@pytest.mark.parametrize("literal", [False, True])
def test_learned_influence_on_an_active_set_is_a_switch(literal):
    r = taught({"x": 100.0}, {"k": {"x": 50.0}}, boredom_threshold=2.0, learned_gates_while_active=literal)
    traces = [step(r, t)[1] for t in np.arange(0.0, 40.0, 0.5)]
    activated = [t for t in traces if any(e.kind == "activate" for e in t.events)]
    if literal:  # boredom resets on activation, so the bored robot drops its category-2 task at once: thrashing
        assert len(activated) > 1 and any(t.zeroed.get("x") == "learned_robot_influence" and
                                          any(e.kind == "deactivate" for e in t.events) for t in traces)
    else:
        assert len(activated) == 1 and traces[-1].active == "x"


@pytest.mark.parametrize("rule, keeps_growing", [("any_set_active", False), ("product_formula", True)])
def test_boredom_of_a_one_set_robot(rule, keeps_growing):
    r = taught({"x": 10.0}, boredom_rule=rule)
    for t in np.arange(0.0, 20.0, 0.5):
        step(r, float(t), present=frozenset())
    assert r.core.active == "x"
    assert (r.boredom > 5.0) == keeps_growing


def test_next_event_time_includes_boredom():
    r = taught({"x": 100.0}, {"k": {"x": 50.0}}, boredom_threshold=7.0)
    step(r, 0.0)
    assert r.next_event_time() == pytest.approx(7.0)


def test_configuration_is_checked():
    with pytest.raises(ConfigError, match="max_delay"):
        LAllianceParams(min_delay=5.0, max_delay=1.0)
    with pytest.raises(ConfigError, match="strategy"):
        LAllianceParams(strategy="V")
    with pytest.raises(ConfigError, match="rng"):
        LAllianceRobot("me", [BehaviourSet("x")], LAllianceParams(task_ordering="random"))
    with pytest.raises(ConfigError, match="statistics of"):
        LAllianceRobot("me", [BehaviourSet("x")], statistics=TaskStatistics("you"))


# ---------------------------------------------------------------- learning on an abstract team

RADIO = RadioConfig(rate_hz=2.0)
TWO_SPECIALISTS = {"a": {"x": 5.0, "y": 20.0}, "b": {"x": 20.0, "y": 5.0}}


def lalliance_team(durations, phase, strategy="IV", statistics=None, seed=0, **params):
    settings = LAllianceParams(phase=phase, strategy=strategy, min_delay=0.5, max_delay=3.0, boredom_threshold=3.0,
                               prior_task_time=10.0, alliance=AllianceParams(tau=RADIO.timeout), **params)
    streams = {name: np.random.default_rng([seed, k]) for k, name in enumerate(durations)}

    def make(name, sets):
        return LAllianceRobot(name, sets, settings, (statistics or {}).get(name), streams[name])

    tasks = sorted({t for times in durations.values() for t in times})
    return AbstractTeam([Task(t) for t in tasks], durations, make, RADIO, seed=seed, dt=0.25)


def run_and_observe(team: AbstractTeam, until: float) -> None:
    """Run until every task is done, and one more second so that the robots see the last completion."""
    team.run(until)
    team.run(team.time + 1.0, stop_when_done=False)


def test_active_learning_picks_unclaimed_tasks_and_learns_everyone():
    durations = {"a": {f"t{j}": 4.0 + j for j in range(6)}, "b": {f"t{j}": 6.0 for j in range(6)},
                 "c": {f"t{j}": 3.0 for j in range(3)}}
    team = lalliance_team(durations, "active_learning")
    run_and_observe(team, 200.0)
    assert team.done()
    performers = {}
    for _, behaviours in team.history:
        for robot, task in behaviours.items():
            if task.startswith("t"):
                performers.setdefault(task, set()).add(robot)
    assert sum(len(p) > 1 for p in performers.values()) <= 1  # a duplicate only when two start within a slot
    for robot, times in durations.items():
        statistics = team.controllers[robot].selector.statistics
        for task in statistics.own:  # own trials are the task durations, to a control period
            assert statistics.own_time(task) == pytest.approx(times[task], abs=0.3)
        for teammate, tasks in statistics.teammates.items():
            for task in tasks:  # teammates' trials as heard: to a radio period (0.5 s) and a control period
                assert statistics.teammate_time(teammate, task) == pytest.approx(durations[teammate][task], abs=0.8)
                assert task in times  # only for tasks this robot can do itself


def test_learning_carries_over_through_the_json_file(tmp_path):
    """Training missions, statistics saved and reloaded each time, then a live mission: each specialist does
    its own task (§4.4.2)."""
    files = {robot: tmp_path / f"{robot}.json" for robot in TWO_SPECIALISTS}
    for trial in range(4):
        statistics = {r: load_statistics(f) for r, f in files.items() if f.exists()}
        team = lalliance_team(TWO_SPECIALISTS, "active_learning", statistics=statistics, seed=trial)
        run_and_observe(team, 100.0)
        assert team.done()
        for robot, path in files.items():
            save_statistics(path, team.controllers[robot].selector.statistics)
    statistics = {r: load_statistics(f) for r, f in files.items()}
    assert statistics["a"].teammate_time("b", "x") == pytest.approx(20.0, abs=0.8)
    live = lalliance_team(TWO_SPECIALISTS, "adaptive", statistics=statistics)
    run_and_observe(live, 100.0)
    assert live.first_time("a", "x") is not None and live.first_time("a", "y") is None
    assert live.first_time("b", "y") is not None and live.first_time("b", "x") is None
    assert max(max(c) for c in live.completions.values()) < 10.0


def test_silent_teammate_is_charged_a_failure():
    durations = {"a": {"x": 30.0}, "b": {"x": 30.0}}
    team = lalliance_team(durations, "adaptive", strategy="II", failure_penalty=2.0)
    team.run(10.0)
    worker = next(r for r, b in team.behaviour.items() if b == "x")
    watcher = ({"a", "b"} - {worker}).pop()
    started = team.first_time(worker, "x")
    team.kill(worker)
    run_and_observe(team, 60.0)
    assert team.done()
    statistics = team.controllers[watcher].selector.statistics
    # Heard from about its start to its death (10 s), charged twice that.
    assert statistics.teammate_time(worker, "x") == pytest.approx(2.0 * (10.0 - started), abs=2.0)


def test_failure_penalty_ends_lock_in_on_a_task_the_robot_cannot_do():
    """Claim 13 (§4.6): robot a learned it was quick at x, then broke its gripper: it can still do y but never x.
    Charged a penalty for its failure, it stops taking x, which its slower teammate then does."""
    durations = {"a": {"x": math.inf, "y": 8.0}, "b": {"x": 12.0}}
    before = {"a": TaskStatistics("a"), "b": TaskStatistics("b")}
    for value in (6.0, 6.0):
        before["a"].record_own("x", value)
        before["b"].record_teammate("a", "x", value)
    before["a"].record_own("y", 8.0)
    before["a"].record_teammate("b", "x", 12.0)
    before["b"].record_own("x", 12.0)
    statistics, tries = before, []
    for trial in range(3):
        team = lalliance_team(durations, "adaptive", strategy="II", statistics=statistics, seed=trial,
                              failure_penalty=2.0, lambda_factor=3.0)
        run_and_observe(team, 120.0)
        assert team.done()
        tries.append(sum(1 for _, b in team.history if b["a"] == "x"))
        statistics = {r: team.controllers[r].selector.statistics for r in durations}
    assert tries[0] > 0 and tries[1:] == [0, 0]
    assert statistics["a"].own_time("x") > statistics["a"].teammate_time("b", "x")


def test_robots_present_from_the_robot_own_log_and_tau():
    """§4.6: a teammate counts from its first message until silent for tau; one message brings it back."""
    r = taught({"x": 100.0}, {"k": {"x": 50.0}}, alliance=AllianceParams(tau=9.0))
    step(r, 0.0, [heard("k", None, 0.0)], present=None)
    assert r.categories == {"x": 2}  # k, present, is faster
    step(r, 8.5, present=None)
    assert r.categories == {"x": 2}
    step(r, 9.0, present=None)
    assert r.categories == {"x": 1}  # silent for tau: taken as gone
    step(r, 9.5, [heard("k", None, 9.5)], present=None)
    assert r.categories == {"x": 2}


@pytest.mark.parametrize("strategy, x_time, escapes", [("II", 8.0, True), ("IV", 12.0, False)])
def test_a_lone_failing_robot_escapes_only_under_shortest_task_first(strategy, x_time, escapes):
    """§4.6 argues that penalised failures slow the failed task's impatience, so the robot turns to a task it
    can do. That holds for Shortest Task First; strategy IV takes category-1 tasks longest first, so a robot
    alone with the failing task makes it look longer, hence more urgent, and keeps coming back to it."""
    r = taught({"x": x_time, "y": 10.0}, strategy=strategy, failure_penalty=2.0)
    picks, time = [], 0.0
    while time < 300.0:
        time = round(time + 0.5, 9)
        _, trace = step(r, time, feedback={"x": True, "y": "y" not in picks}, present=frozenset())
        picks += [e.behaviour_set for e in trace.events if e.kind == "activate"]
    assert picks[0] == "x"  # it fails at x (never done) and is charged for it
    assert ("y" in picks) == escapes
