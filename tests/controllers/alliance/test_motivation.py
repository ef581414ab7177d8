"""ALLIANCE (teamsim.controllers.alliance.motivation): the motivational behaviour's inputs one by one, the ambiguity
switches, the controller adapter, and the termination properties P1-P6 of spec §2.3 on an abstract team whose
messages go through the real RadioBus."""
from __future__ import annotations

import math
from dataclasses import replace

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from teamsim.config import ConfigError, RadioConfig
from teamsim.controllers.alliance.motivation import (AllianceController, AllianceParams, AllianceRobot, BehaviourSet,
                                                     BehaviourSetDefinition, MotivationRates, activity_message,
                                                     announced_task)
from teamsim.controllers.base import Command, Observation
from teamsim.radio import Message

from tests.controllers.alliance.abstract_team import NO_IR, AbstractTeam, Task

FAST = MotivationRates(delta_fast=0.25, delta_slow=0.05, phi=20.0, psi=30.0, lam=60.0)


def heard(sender: str, task: str | None, time: float = 0.0) -> Message:
    return Message(sender, time, activity_message(task))


def robot(*names: str, rates: MotivationRates = FAST, **params) -> AllianceRobot:
    return AllianceRobot("me", [BehaviourSet(n, rates=rates) for n in names or ("x",)], AllianceParams(**params))


def run(r: AllianceRobot, times, messages=None):
    """Step ``r`` at each time, every set applicable, teammates b and c present; ``messages`` maps a time to the
    messages handed over then. Returns the traces."""
    feedback = {s.name: True for s in r.sets}
    return [r.step(t, feedback, (messages or {}).get(t, ()), frozenset({"b", "c"}))[1] for t in times]


def grid(start: float, stop: float, dt: float = 0.5):
    return [round(start + k * dt, 9) for k in range(int(round((stop - start) / dt)) + 1)]


def kinds(trace, kind):
    return [e for e in trace.events if e.kind == kind]


# ---------------------------------------------------------------- the inputs of eq. (3.1)


@pytest.mark.parametrize("inclusive, activation_time", [(False, 4.5), (True, 4.0)])
def test_motivation_grows_at_delta_fast_and_activates_past_theta(inclusive, activation_time):
    r = robot(activate_at_threshold=inclusive)
    traces = run(r, grid(0, 6))
    assert traces[4].motivation["x"] == pytest.approx(0.25 * 2.0)  # m = delta_fast x t
    first_active = next(t.time for t in traces if t.active == "x")
    assert first_active == activation_time  # m = 1 = theta at 4 s: "exceeds" needs one more step


def test_first_message_resets_once_then_slow_rate_until_phi():
    r = robot()
    messages = {t: [heard("b", "x", t)] for t in grid(2, 30, 1.0)}  # b keeps announcing x from 2 s
    traces = {t.time: t for t in run(r, grid(0, 30), messages=messages)}
    resets = [e for t in traces.values() for e in kinds(t, "impatience_reset")]
    assert [(e.teammate, e.behaviour_set, e.detail) for e in resets] == [("b", "x", "episode 1")]
    assert traces[2.0].motivation["x"] == 0.0 and traces[2.0].zeroed["x"] == "impatience_reset"
    assert traces[2.0].growth["x"] == FAST.delta_slow
    assert traces[21.5].growth["x"] == FAST.delta_slow
    assert traces[22.0].growth["x"] == FAST.delta_fast  # first heard at 2 s: phi = 20 s has run out
    assert [(e.teammate, e.detail) for e in kinds(traces[22.0], "impatience")] == [("b", "fast")]


def test_teammate_silent_for_tau_no_longer_slows_the_robot():
    r = robot()
    messages = {2.0: [heard("b", "x", 2.0)], 5.0: [heard("b", "x", 5.0)]}
    traces = {t.time: t for t in run(r, grid(0, 20), messages=messages)}
    assert traces[13.5].growth["x"] == FAST.delta_slow
    assert traces[14.0].growth["x"] == FAST.delta_fast  # last heard at 5 s, tau = 9 s


def test_slowest_teammate_still_within_phi_sets_the_rate():
    rates = replace(FAST, teammate_delta_slow=(("b", 0.02),), teammate_phi=(("b", 5.0),))
    r = robot(rates=rates)
    messages = {1.0: [heard("b", "x"), heard("c", "x")]}
    traces = {t.time: t for t in run(r, grid(0, 8), messages=messages)}
    assert traces[1.0].growth["x"] == 0.02  # min over b (0.02) and c (0.05)
    assert traces[6.5].growth["x"] == FAST.delta_slow  # b's phi (5 s) has lapsed: c's rate now


def test_priority_breaks_simultaneous_activations():
    r = robot("first", "second")
    trace = next(t for t in run(r, grid(0, 6)) if t.active)
    assert trace.active == "first"
    assert trace.motivation["second"] == 0.0 and trace.zeroed["second"] == "activity_suppression"
    assert [e.behaviour_set for e in kinds(trace, "activate")] == ["first"]


def test_sensory_feedback_zeroes_and_deactivates():
    r = robot()
    run(r, grid(0, 5))
    assert r.active == "x"
    _, trace = r.step(5.5, {"x": False}, (), frozenset())
    assert trace.active is None and trace.zeroed["x"] == "sensory_feedback"
    assert [e.detail for e in kinds(trace, "deactivate")] == ["sensory_feedback"]


@pytest.mark.parametrize("literal", [False, True])
def test_impatience_reset_while_active_is_a_switch(literal):
    r = robot(reset_while_active=literal)
    run(r, grid(0, 5))
    _, trace = r.step(5.5, {"x": True}, [heard("b", "x", 5.5)], frozenset({"b"}))
    if literal:  # App. A as written: the active task is dropped the moment b is first heard
        assert trace.active is None and trace.zeroed["x"] == "impatience_reset"
    else:  # DESIGN.md: only an inactive set is reset; the robot keeps working until psi
        assert trace.active == "x" and not kinds(trace, "impatience_reset")


def test_acquiescence_psi_needs_a_claimant_lambda_does_not():
    r = robot()
    traces = run(r, grid(0, 40))
    assert all(t.active == "x" for t in traces[9:])  # active from 4.5 s, psi = 30 s, but nobody else is on x
    _, trace = r.step(40.5, {"x": True}, [heard("b", "x", 40.5)], frozenset({"b"}))
    assert trace.active is None and [e.detail for e in kinds(trace, "acquiescence")] == ["psi"]
    lone = robot()
    times = grid(0, 70)
    given_up = next(t for t in run(lone, times) if kinds(t, "acquiescence"))
    assert given_up.time == pytest.approx(4.5 + 60.0 + 0.5) and kinds(given_up, "acquiescence")[0].detail == "lambda"


@pytest.mark.parametrize("rule, second_episode_reset", [("feedback_rise", True), ("mission", False)])
def test_recurring_task_episodes(rule, second_episode_reset):
    r = robot(episode_rule=rule)
    present = frozenset({"b"})
    r.step(0.0, {"x": True}, [heard("b", "x", 0.0)], present)
    r.step(40.0, {"x": False}, [heard("b", None, 40.0)], present)  # the task is done ...
    r.step(41.0, {"x": True}, (), present)  # ... and needed again
    _, trace = r.step(42.0, {"x": True}, [heard("b", "x", 42.0)], present)
    assert bool(kinds(trace, "impatience_reset")) == second_episode_reset
    # Literal reading: b was first heard about x at 0 s, more than phi ago, so no slow rate for its new episode.
    assert trace.growth["x"] == (FAST.delta_slow if second_episode_reset else FAST.delta_fast)


@pytest.mark.parametrize("supersede", [True, False])
def test_newer_activity_ends_a_claim_only_with_the_switch(supersede):
    r = robot("x", "y", latest_message_supersedes=supersede)
    present = frozenset({"b"})
    r.step(0.0, {"x": True, "y": True}, [heard("b", "x", 0.0)], present)
    _, trace = r.step(1.0, {"x": True, "y": True}, [heard("b", "y", 1.0)], present)
    assert trace.growth["x"] == (FAST.delta_fast if supersede else FAST.delta_slow)
    assert trace.growth["y"] == FAST.delta_slow


def test_absent_teammate_does_not_slow_the_robot():
    r = robot()
    _, trace = r.step(0.0, {"x": True}, [heard("b", "x")], frozenset())
    assert trace.growth["x"] == FAST.delta_fast


def test_without_a_radio_view_presence_comes_from_the_robot_own_log():
    r = robot()
    _, trace = r.step(0.0, {"x": True}, [heard("b", "x")], None)
    assert trace.growth["x"] == FAST.delta_slow and r.log.robots_present(0.0) == {"b"}
    _, trace = r.step(9.0, {"x": True}, (), None)  # silent for tau = 9 s
    assert trace.growth["x"] == FAST.delta_fast and r.log.robots_present(9.0) == frozenset()


def test_next_event_time_is_the_crossing():
    r = robot()
    r.step(0.0, {"x": True}, (), frozenset())
    assert r.next_event_time() == pytest.approx(4.0)
    assert r.step(4.0, {"x": True}, (), frozenset())[0] is None  # m = theta exactly: not yet
    assert r.step(4.0 + 1e-9, {"x": True}, (), frozenset())[0] == "x"
    assert r.next_event_time() == pytest.approx(4.0 + FAST.lam)  # while active, nobody claiming x: lambda


def test_config_is_validated():
    with pytest.raises(ConfigError, match="delta_slow"):
        MotivationRates(delta_fast=0.1, delta_slow=0.1)
    with pytest.raises(ConfigError, match="threshold"):
        AllianceParams(threshold=0.0)
    with pytest.raises(ConfigError, match="episode_rule"):
        AllianceParams(episode_rule="sometimes")
    with pytest.raises(ConfigError, match="unique"):
        AllianceRobot("me", [BehaviourSet("x"), BehaviourSet("x")])
    with pytest.raises(ValueError, match="time went back"):
        r = robot()
        r.step(1.0, {"x": True}, (), frozenset())
        r.step(0.5, {"x": True}, (), frozenset())


def test_activity_messages():
    assert announced_task(activity_message("x", {"spill": (1, 2)})) == "x"
    assert announced_task(activity_message(None)) is None
    assert announced_task("not ours") is None and announced_task({"task": 3}) is None


# ---------------------------------------------------------------- the controller adapter


def test_controller_runs_the_active_set_and_broadcasts_its_task():
    spill = {"found": False}
    definitions = [
        BehaviourSetDefinition("find-methodical", lambda obs: not spill["found"],
                               lambda obs: Command(v=0.2, broadcast={"corner": 3}), task="find", rates=FAST),
        BehaviourSetDefinition("move", lambda obs: spill["found"], lambda obs: Command(v=0.4), rates=FAST),
    ]
    controller = AllianceController("red", definitions)

    def observe(t):
        return controller(Observation(time=t, robot="red", ir_raw=NO_IR, ir_range=NO_IR, ir_bearings=NO_IR, pose=None))

    idle = observe(0.0)
    assert replace(idle, trace=None) == Command(behaviour="idle", broadcast={"task": None})
    assert idle.trace.time == 0.0 and idle.trace.active is None and idle.trace.threshold == 1.0
    command = [observe(t) for t in grid(0.5, 5)][-1]
    assert command.behaviour == "find-methodical" and command.v == 0.2
    assert command.broadcast == {"corner": 3, "task": "find"}
    assert command.trace is controller.last_trace and command.trace.active == "find-methodical"
    spill["found"] = True
    assert observe(5.5).behaviour == "idle"
    assert [observe(t) for t in grid(6, 11)][-1].broadcast == {"task": "move"}
    with pytest.raises(ConfigError, match="differ"):
        AllianceController("red", definitions, selector=AllianceRobot("red", [BehaviourSet("move")]))


# ---------------------------------------------------------------- P1-P6 on an abstract team

ROBOTS = ("r0", "r1", "r2", "r3")


@st.composite
def missions(draw, max_robots=4, max_tasks=5, dependencies=False):
    """Tasks (maybe with ordering dependencies on earlier tasks), each doable by a non-empty set of robots."""
    robots = ROBOTS[:draw(st.integers(1, max_robots))]
    names = [f"t{j}" for j in range(draw(st.integers(1, max_tasks)))]
    durations = {r: {} for r in robots}
    tasks = []
    for j, name in enumerate(names):
        for r in draw(st.lists(st.sampled_from(robots), min_size=1, unique=True)):
            durations[r][name] = float(draw(st.integers(1, 8)))
        requires = tuple(draw(st.lists(st.sampled_from(names[:j]), unique=True))) if dependencies and j else ()
        tasks.append(Task(name, requires))
    return tasks, {r: times for r, times in durations.items() if times}


radios = st.builds(RadioConfig, rate_hz=st.sampled_from([0.5, 1.0, 2.0]), loss=st.sampled_from([0.0, 0.2]),
                   latency=st.sampled_from([0.0, 1.0]))

PATIENT = MotivationRates(delta_fast=0.5, delta_slow=1 / 15, phi=math.inf, psi=math.inf, lam=math.inf)
IMPATIENT = MotivationRates(delta_fast=0.5, delta_slow=0.1, phi=10.0, psi=15.0, lam=30.0)


def alliance_team(tasks, durations, rates, radio, seed=0, **kwargs) -> AbstractTeam:
    params = AllianceParams(tau=radio.timeout if radio else 9.0)

    def make(name, sets):
        return AllianceRobot(name, [replace(s, rates=rates) for s in sets], params)

    return AbstractTeam(tasks, durations, make, radio, seed=seed, **kwargs)


def horizon(tasks, durations, per_task: float) -> float:
    longest = {t.name: max(d[t.name] for d in durations.values() if t.name in d) for t in tasks}
    return 2 * sum(longest.values()) + per_task * len(tasks) + 60.0


FAST_PROPERTY = settings(max_examples=50, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@FAST_PROPERTY
@given(missions(), radios, st.integers(0, 2**16))
def test_p1_reliable_aware_maximally_patient_team_always_completes(mission, radio, seed):
    tasks, durations = mission
    team = alliance_team(tasks, durations, PATIENT, radio, seed)
    team.run(horizon(tasks, durations, 1 / PATIENT.delta_slow + 1 / PATIENT.delta_fast))
    assert team.done(), team.remaining


@FAST_PROPERTY
@given(missions(dependencies=True), radios, st.integers(0, 2**16), st.sampled_from(["kill", "fail"]),
       st.floats(0.0, 20.0), st.data())
def test_p2_a_failed_robot_only_strands_what_depends_on_it(mission, radio, seed, fault, when, data):
    tasks, durations = mission
    failed = data.draw(st.sampled_from(sorted(durations)))
    stranded: set[str] = set()
    for task in tasks:  # tasks only the failed robot can do, and every task that needs one of them
        others = [r for r in durations if r != failed and task.name in durations[r]]
        if not others or stranded & set(task.requires):
            stranded.add(task.name)
    team = alliance_team(tasks, durations, IMPATIENT, radio, seed)
    action = team.kill if fault == "kill" else team.fail
    team.run(horizon(tasks, durations, IMPATIENT.phi + IMPATIENT.lam + 20.0), stop_when_done=False,
             events={round(when * 2) / 2: lambda: action(failed)})
    assert team.done([t.name for t in tasks if t.name not in stranded]), team.remaining


@FAST_PROPERTY
@given(missions(), st.integers(0, 2**16))
def test_p3_missions_complete_without_communication(mission, seed):
    tasks, durations = mission
    team = alliance_team(tasks, durations, IMPATIENT, radio=None, seed=seed)
    team.run(horizon(tasks, durations, 1 / IMPATIENT.delta_fast))
    assert team.done(), team.remaining
    assert all(team.bus.robots_present(r, team.time) == frozenset() for r in durations)


@FAST_PROPERTY
@given(missions(), radios, st.integers(0, 2**16), st.floats(0.0, 30.0), st.booleans())
def test_p4_p5_p6_on_traces(mission, radio, seed, fault_time, literal_reset):
    """Recurring tasks and a persistent, failing robot, so resets and episodes recur."""
    tasks, durations = mission
    tasks = [replace(t, recurs_after=5.0) for t in tasks]
    params = AllianceParams(tau=radio.timeout, reset_while_active=literal_reset)

    def make(name, sets):
        return AllianceRobot(name, [replace(s, rates=IMPATIENT) for s in sets], params)

    team = AbstractTeam(tasks, durations, make, radio, seed=seed, record_traces=True)
    team.run(90.0, stop_when_done=False, events={round(fault_time): lambda: team.fail(sorted(durations)[0])})
    for name, traces in team.traces.items():
        resets = [(e.teammate, e.behaviour_set, e.detail) for t in traces for e in t.events
                  if e.kind == "impatience_reset"]
        assert len(resets) == len(set(resets)), f"P5: {name} reset twice in one episode"
        active = None
        for previous, trace in zip([None] + traces, traces):
            for event in trace.events:  # P6: an activation only from idle, a deactivation only of the active set
                if event.kind == "activate":
                    assert active is None, f"P6: {name} activated {event.behaviour_set} while {active} was active"
                    active = event.behaviour_set
                elif event.kind == "deactivate":
                    assert event.behaviour_set == active
                    active = None
            assert trace.active == active
            if active is not None:
                assert all(m == 0.0 for s, m in trace.motivation.items() if s != active)
            if previous is None or previous.active is not None:
                continue
            for s, m in trace.motivation.items():  # P4: idle, applicable, not zeroed: strictly increasing
                if s not in trace.zeroed and s not in previous.zeroed:
                    assert m > previous.motivation[s], f"P4: {name}.{s} at {trace.time}"


def a_dies_at_30_s(rates_a: MotivationRates, rates_b: MotivationRates, task_time: float, until: float):
    """Robots a and b share task x (radio at 1 Hz, tau = 3 s); a is killed at 30 s. (team, radio, death time)."""
    radio = RadioConfig(rate_hz=1.0)

    def make(name, sets):
        return AllianceRobot(name, [replace(s, rates=rates_a if name == "a" else rates_b) for s in sets],
                             AllianceParams(tau=radio.timeout))

    team = AbstractTeam([Task("x")], {"a": {"x": task_time}, "b": {"x": task_time}}, make, radio, dt=0.1)
    death = 30.0
    team.run(until, events={death: lambda: team.kill("a")})
    return team, radio, death


def test_takeover_after_a_death_within_phi_tau_and_one_period():
    """Claim 1 (§6.1.2): the robot doing the task dies; its capable teammate takes over in bounded time."""
    eager = MotivationRates(delta_fast=0.5, delta_slow=1 / 60, phi=60.0, psi=100.0, lam=200.0)
    team, radio, death = a_dies_at_30_s(eager, replace(eager, delta_fast=0.2), task_time=100.0, until=150.0)
    assert team.first_time("a", "x") < 5.0
    takeover = team.first_time("b", "x")
    assert death < takeover <= death + eager.phi + radio.timeout + team.dt
    assert team.done()


def test_a_silent_claim_lapses_after_tau():
    """The takeover's tau part: with patience phi far longer than the trial, the teammate can only take the task
    over because the dead robot's claim lapses tau after its last message; then it grows at delta_fast."""
    patient = MotivationRates(delta_fast=0.25, delta_slow=1 / 2000, phi=1000.0, psi=100.0, lam=500.0)
    slower = replace(patient, delta_fast=0.1)  # b would start after 10 s: it hears a's claim first
    team, radio, death = a_dies_at_30_s(patient, slower, task_time=200.0, until=60.0)
    assert team.first_time("a", "x") < team.first_time("b", "x")
    takeover = team.first_time("b", "x")
    # the last message came at most one broadcast period (1 s) before the death
    assert death + radio.timeout - 1.0 < takeover <= death + radio.timeout + 1 / slower.delta_fast + 2 * team.dt


def test_division_of_labour_returns_when_a_robot_is_revived():
    """Claims 1-2 (§6.1.2, box pushing): each end is needed again once the other end has been pushed. With its
    teammate dead the survivor pushes both ends; revived, the teammate takes its end back."""
    radio = RadioConfig(rate_hz=1.0)
    keen = MotivationRates(delta_fast=1.0, delta_slow=0.05, phi=20.0, psi=30.0, lam=100.0)
    reluctant = replace(keen, delta_fast=0.2)  # acquiring the far end of the box takes a while
    own_end = {"a": "push-left", "b": "push-right"}

    def make(name, sets):
        return AllianceRobot(name, [replace(s, rates=keen if s.name == own_end[name] else reluctant) for s in sets],
                             AllianceParams(tau=radio.timeout))

    tasks = [Task("push-left", renewed_by="push-right"), Task("push-right", renewed_by="push-left")]
    durations = {"a": {"push-left": 10.0, "push-right": 10.0}, "b": {"push-left": 10.0, "push-right": 10.0}}
    team = AbstractTeam(tasks, durations, make, radio, dt=0.25)
    team.run(300.0, stop_when_done=False, events={60.0: lambda: team.kill("b"), 160.0: lambda: team.revive("b")})

    def window(start, stop):
        return [b for t, b in team.history if start <= t < stop]

    def ends(robot, behaviours):
        return {b[robot] for b in behaviours} - {"idle", "dead"}

    assert ends("a", window(0, 60)) == {"push-left"} and ends("b", window(0, 60)) == {"push-right"}
    assert ends("a", window(90, 160)) == {"push-left", "push-right"}  # the survivor alternates both ends
    assert ends("a", window(200, 300)) == {"push-left"} and ends("b", window(200, 300)) == {"push-right"}
