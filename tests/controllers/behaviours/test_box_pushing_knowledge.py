"""Box pushing's push knowledge and broadcast, without physics (Parker §6.1.1, Fig. 6-1's sensory feedback).

An R-2 cannot sense a teammate's push: it knows which end was pushed last from its own pushes and from the
"push complete" news riding on every broadcast (when each end was last pushed). push-left is applicable while the
right end was pushed last (at equal times: the push this robot learned of last); at the start both are applicable.
"""
from __future__ import annotations

import math

import pytest

from teamsim.controllers.alliance.motivation import IDLE, activity_message, announced_task
from teamsim.controllers.base import Command
from teamsim.controllers.behaviours.box_pushing import (LEFT, RIGHT, BoxPushParams, PushEnd, PushKnowledge,
                                                        PushRecord, Station, announce)
from teamsim.controllers.skills.pose_estimate import PoseEstimate
from teamsim.models import r2
from teamsim.models.r2 import TIP_IR

ROBOT = r2.build("red")


def applicable(k: PushKnowledge) -> set[str]:
    return {end for end in (LEFT, RIGHT) if k.applicable(end)}


def after_own_left_push(completed: float = 3.5) -> PushKnowledge:
    k = PushKnowledge()
    k.pushed(PushRecord("red", LEFT, 1.0, completed))
    return k


def test_at_the_start_both_ends_are_applicable():
    """'every robot thinks the opposite end was just pushed'."""
    k = PushKnowledge()
    assert applicable(k) == {LEFT, RIGHT}
    assert k.pushed_at == {LEFT: 0.0, RIGHT: 0.0}
    assert k.pushes == []


def test_after_its_own_left_push_only_push_right_is_applicable():
    k = after_own_left_push(3.5)
    assert applicable(k) == {RIGHT}
    assert k.pushed_at == {LEFT: 3.5, RIGHT: 0.0}
    assert k.pushes == [PushRecord("red", LEFT, 1.0, 3.5)]


def test_news_of_a_newer_right_push_makes_push_left_applicable_again():
    k = after_own_left_push(3.5)
    k.hear({"task": "push-right", "pushed": {LEFT: 3.5, RIGHT: 8.4}})
    assert applicable(k) == {LEFT}
    assert k.pushed_at == {LEFT: 3.5, RIGHT: 8.4}
    assert len(k.pushes) == 1  # news is not this robot's own push


@pytest.mark.parametrize("news", [
    {LEFT: 2.0, RIGHT: 0.0},  # both older than (or as old as) what it knows
    {LEFT: 3.5, RIGHT: 0.0},  # the same push again: not newer
    {LEFT: 3.0},  # one end only, older
])
def test_stale_news_changes_nothing(news):
    k = after_own_left_push(3.5)
    k.hear({"pushed": news})
    assert applicable(k) == {RIGHT}
    assert k.pushed_at == {LEFT: 3.5, RIGHT: 0.0}


@pytest.mark.parametrize("stale", [
    {LEFT: 1.0, RIGHT: 8.0},  # an old message from a slow teammate
    {LEFT: 3.0, RIGHT: 2.0},  # older pushes whose order (left last) would flip the ends if they were learned
])
def test_stale_news_after_fresh_news_changes_nothing(stale):
    k = after_own_left_push(3.5)
    k.hear({"pushed": {LEFT: 3.5, RIGHT: 8.4}})
    k.hear({"pushed": stale})
    assert applicable(k) == {LEFT}
    assert k.pushed_at == {LEFT: 3.5, RIGHT: 8.4}


def test_news_of_a_push_older_than_the_other_ends_is_passed_on_but_not_the_latest():
    """News can arrive after news of a later push (each robot sends in its own radio slot): a right push at 3.0 s,
    heard after this robot's own left push at 3.5 s, is recorded (and passed on) but the left end stays the one
    pushed last."""
    k = after_own_left_push(3.5)
    k.hear({"pushed": {LEFT: 0.0, RIGHT: 3.0}})
    assert k.pushed_at == {LEFT: 3.5, RIGHT: 3.0}
    assert applicable(k) == {RIGHT}


def test_at_equal_times_the_push_learned_last_is_the_latest():
    """The two robots start together and finish their first pushes in the same tick: each, learning of the
    other's push after its own, takes the other end as pushed last, so each pushes its own end again."""
    red, green = after_own_left_push(3.2), PushKnowledge()
    green.pushed(PushRecord("green", RIGHT, 0.4, 3.2))
    red.hear(green.message())
    green.hear(red.message())
    assert applicable(red) == {LEFT} and applicable(green) == {RIGHT}
    assert red.pushed_at == green.pushed_at == {LEFT: 3.2, RIGHT: 3.2}


@pytest.mark.parametrize("news, later_end", [
    ({LEFT: 10.0, RIGHT: 8.0}, LEFT),
    ({LEFT: 8.0, RIGHT: 10.0}, RIGHT),
])
def test_news_of_both_ends_is_learned_oldest_first_so_the_later_end_wins(news, later_end):
    k = after_own_left_push(3.5)
    k.hear({"pushed": news})
    assert k.pushed_at == news
    other = RIGHT if later_end == LEFT else LEFT
    assert applicable(k) == {other}  # the end pushed last is the one not to push again


@pytest.mark.parametrize("payload", [None, "push-left", {"task": "push-left"}, {"pushed": "yesterday"}])
def test_payloads_without_push_news_are_ignored(payload):
    k = after_own_left_push(3.5)
    k.hear(payload)
    assert applicable(k) == {RIGHT}
    assert k.pushed_at == {LEFT: 3.5, RIGHT: 0.0}


def test_message_carries_when_each_end_was_last_pushed():
    k = after_own_left_push(3.5)
    k.hear({"pushed": {LEFT: 0.0, RIGHT: 8.4}})
    message = k.message()
    assert message == {"pushed": {LEFT: 3.5, RIGHT: 8.4}}
    message["pushed"][LEFT] = 99.0  # a copy: a broadcast cannot change what the robot knows
    assert k.pushed_at[LEFT] == 3.5
    other = PushKnowledge()
    other.hear(k.message())  # a teammate hearing it learns the later end last
    assert applicable(other) == {LEFT} and other.pushed_at == {LEFT: 3.5, RIGHT: 8.4}


def test_an_idle_robot_announces_its_standing_end_and_the_news():
    k = after_own_left_push(3.5)
    command = Command(behaviour=IDLE, broadcast=activity_message(None))
    out = announce(command, "push-left", k)
    assert announced_task(out.broadcast) == "push-left"  # not "idle": it is standing at its end
    assert out.broadcast["pushed"] == {LEFT: 3.5, RIGHT: 0.0}
    assert out.behaviour == IDLE and (out.v, out.omega) == (0.0, 0.0)


def test_an_active_robot_keeps_its_task_in_the_broadcast():
    k = after_own_left_push(3.5)
    command = Command(v=0.3, omega=0.1, behaviour="push-right", broadcast=activity_message("push-right"))
    out = announce(command, "push-left", k)  # standing at the left end, acquiring the right one
    assert announced_task(out.broadcast) == "push-right"
    assert out.broadcast["pushed"] == {LEFT: 3.5, RIGHT: 0.0}
    assert (out.v, out.omega, out.behaviour) == (0.3, 0.1, "push-right")


# -- acquiring an end with something in the way (no physics: observations made up) --------------------------------
def follow_observation(time: float, tips: tuple[float, float], speed: float = 0.15, heading: float = -math.pi / 2,
                       present: frozenset = frozenset()):
    """An R-2 following the box's back face towards its right end (heading -pi/2, the face 0.15 m to its left),
    hearing the teammates ``present``."""
    import numpy as np

    from teamsim.controllers.base import Observation
    from teamsim.positioning import PoseFix

    ir = np.full(len(ROBOT.ir_sensors), np.inf)
    ir[ROBOT.ir_sensors.index("ir_left_front")] = 0.15
    ir[[ROBOT.ir_sensors.index(n) for n in TIP_IR]] = tips
    wheels = len(ROBOT.drive.left) + len(ROBOT.drive.right)
    return Observation(time=time, robot="red", ir_raw=np.zeros(len(ir)), ir_range=ir, ir_bearings=ROBOT.ir_bearings,
                       pose=PoseFix(0.0, -0.1 - speed * time, heading, time),
                       motor_speeds=np.full(wheels, speed / ROBOT.drive.wheel_radius), velocity=(speed, 0.0),
                       robots_present=present)


def following(params: BoxPushParams) -> tuple[PushEnd, PoseEstimate, Station]:
    estimate, station = PoseEstimate(ROBOT.drive), Station(None, heading=0.0)
    return PushEnd(ROBOT, RIGHT, PushKnowledge(), station, estimate, params), estimate, station


@pytest.mark.parametrize("tips, keeps", [((0.0, 0.0), False), ((0.0, 0.12), True), ((0.003, math.inf), True)])
def test_the_push_heading_is_taken_from_the_compass_only_when_square_to_the_face(tips, keeps):
    """At the end of a push the compass gives the face's normal only if both fingertips touch it. Pushing the box's
    corner (one fingertip at it, the other 0.12 m off or seeing nothing) the robot turns with the corner: taken as
    the push heading, that turn sent a lone survivor round the end to the box's far side (kill:green@34.8, seed
    10: 16 degrees off, 1.37 m at 1800 s)."""
    params = BoxPushParams()
    push, estimate, station = following(params)
    station.heading = -math.pi / 2
    obs = follow_observation(0.0, tips, speed=0.02, heading=-math.pi / 2 - 0.3)  # turned 17 degrees while pushing
    estimate.update(obs)
    push.state, push.since, push.mark = "push", 0.0, (-params.push_time, estimate.pose.copy())
    push(obs)
    assert push.state == "release"
    assert station.heading == pytest.approx(-math.pi / 2 if keeps else -math.pi / 2 - 0.3)


def side_reading_follower(params: BoxPushParams):
    """An R-2 following the box's face, and ``step(t, reading)``: one control tick with its left side IR at
    ``reading`` (its command)."""
    push, estimate, _ = following(params)
    side = ROBOT.ir_sensors.index("ir_left_front")

    def step(t, reading):
        obs = follow_observation(t, (math.inf, math.inf))
        obs.ir_range[side] = reading
        estimate.update(obs)
        if push.mark is None:
            push.state, push.since, push.mark = "follow", t, (t, estimate.pose.copy())
        return push(obs)

    return push, step


def test_a_side_reading_jumping_past_face_lost_is_the_end_of_the_box():
    """Following the face at 0.11-0.14 m, the side IR read 0.24-0.28 m just past the box's end (the ray reaching
    round the corner to the end face); steering in on that, a robot wrapped round the end and turned in 0.17 m
    beyond it (kill:green@34.8, seed 10). A reading that far past follow_distance ends the face: the robot drives
    end_overrun on and backs in."""
    params = BoxPushParams()
    push, step = side_reading_follower(params)

    step(0.0, 0.13)
    states = [(step(0.1 * k, params.follow_distance + params.face_lost + 0.03), push.state)[1] for k in range(1, 6)]
    assert states[-1] == "back_in"


def test_a_first_side_reading_beyond_the_band_steers_in_but_does_not_see_the_face():
    """Backed off 0.19 m instead of 0.12 m, a lone R-2 turned along the box with its side IR at 0.239 m, just past
    follow_distance + face_lost: counted as the face seen and, on the next tick, lost, it backed in past the box's
    far end and never found the box again (kill:red@63.7, seed 106: 0.74 m at 1800 s). Such a reading steers it
    towards the face without seeing it; a reading within the band sees it, and the face is then lost as before."""
    params = BoxPushParams()
    push, step = side_reading_follower(params)
    band = params.follow_distance + params.face_lost

    commands = [step(0.1 * k, band + 0.009) for k in range(10)]
    assert push.state == "follow" and not push.seen
    assert all(c.omega > 0 for c in commands[1:])  # the face is on its left: it turns towards it
    step(1.0, params.follow_distance)
    assert push.seen
    states = [(step(1.0 + 0.1 * k, band + 0.03), push.state)[1] for k in range(1, 6)]
    assert states[-1] == "back_in"


def test_an_acquisition_blocked_along_the_box_pushes_the_end_from_there():
    """Something in the fingertips' way while following the box, with no teammate heard (a teammate killed at
    that end, §6.1.2's failure without the seizure), ends the following: the R-2 backs off a little, turns into
    the box and pushes there, taking that end; it does not drive on into it (which wedged it until lambda,
    kill:green@124.4 at seed 0)."""
    params = BoxPushParams()
    push, estimate, station = following(params)

    def step(t, tips, **kwargs):
        obs = follow_observation(t, tips, **kwargs)
        estimate.update(obs)
        if push.mark is None:
            push.state, push.since, push.mark = "follow", t, (t, estimate.pose.copy())
        return push(obs)

    for t, tips in ((0.0, (math.inf, math.inf)), (0.1, (0.2, 0.21))):  # the face alongside; something ahead, far
        assert step(t, tips).v > 0 and push.state == "follow"
    command = step(0.2, (params.block_range - 0.01, params.block_range))
    assert push.state == "clear" and command.v < 0  # backs off along the box ...
    blocked_at, t = push.mark[1][:2].copy(), 0.2
    while push.state == "clear":
        t += 0.1
        step(t, (0.1, 0.1), speed=-params.drive.back_speed)
        assert t < 2.0
    assert push.state == "turn_in" and station.end is None  # ... by block_backoff ...
    assert math.dist(estimate.pose[:2], blocked_at) >= params.block_backoff
    t += 0.1
    step(t, (0.1, 0.1), speed=0.0, heading=0.0)  # ... turns into the box where it is and takes that end
    assert push.state == "approach" and station.end == RIGHT


def test_blocked_before_the_face_is_seen_it_steps_out_from_the_face_and_follows_again():
    """Blocked before the side IR has seen the face, the robot stands past the end with the box's own end face
    ahead (it pushed overhanging the end, and backing off standoff left its jaw beside it). Taken for a teammate in
    the way, that end was pushed under the other end's name and the next acquisition ran off past the box
    (kill:green@61.6, seed 24). It turns back to the push heading, backs off standoff again and follows on; only
    after step_outs of these does a block end the following."""
    params = BoxPushParams()
    push, estimate, station = following(params)
    side = ROBOT.ir_sensors.index("ir_left_front")
    t = 0.0

    def step(tips, speed=0.15, heading=-math.pi / 2, face=math.inf):
        nonlocal t
        t += 0.1
        obs = follow_observation(t, tips, speed=speed, heading=heading)
        obs.ir_range[side] = face  # the face not seen alongside
        estimate.update(obs)
        if push.mark is None:
            push.state, push.since, push.mark = "follow", t, (t, estimate.pose.copy())
        return push(obs)

    blocked = (params.block_range - 0.02, math.inf)
    for attempt in range(params.step_outs):
        step((math.inf, math.inf))
        assert push.state == "follow"
        command = step(blocked)
        assert push.state == "face_box" and command.v == 0.0 and command.omega > 0  # turning back towards heading 0
        step((math.inf, math.inf), speed=0.0, heading=0.0)  # faces the box: backs off the face
        assert push.state == "back_off"
        start = estimate.pose[:2].copy()
        while push.state == "back_off":
            assert step((math.inf, math.inf), speed=-params.drive.back_speed, heading=0.0).v <= 0
        assert push.state == "turn_along" and math.dist(estimate.pose[:2], start) >= params.standoff
        step((math.inf, math.inf), speed=0.0)  # along the box again: follows
        assert push.state == "follow" and station.end is None
    step((math.inf, math.inf))
    step(blocked)
    assert push.state == "clear"  # out of step-outs: the block ends the following as before


def test_blocked_with_the_face_alongside_it_does_not_step_out_and_a_restart_gives_its_step_outs_back():
    """A block with the side IR reading the face now (the first tick of the following) is something in the way
    along the face, not the box's end: the old path (clear). And each activation starts with its step-outs."""
    params = BoxPushParams()
    push, estimate, station = following(params)
    obs = follow_observation(0.0, (params.block_range - 0.02, math.inf))  # the face at 0.15 m on the side IR
    estimate.update(obs)
    push.state, push.since, push.mark = "follow", 0.0, (0.0, estimate.pose.copy())
    push(obs)
    assert push.state == "clear"
    push.stepped_out = params.step_outs
    push.restart()
    assert push.stepped_out == 0 and push.state == "start"


def test_blocked_with_a_teammate_heard_it_holds_still_first_then_pushes_from_there():
    """The robot in the way may be a live teammate standing between the ends (it pushed beside a dead robot that
    has since been revived): the R-2 first holds still for block_wait (longer than phi, so the teammate's
    impatience can take the end over), following on if the way clears; blocked for longer (two R-2s met head-on,
    each waiting for the other), it pushes from where it is."""
    params = BoxPushParams()
    push, estimate, station = following(params)
    heard, near = frozenset({"green"}), (params.block_range / 2, params.block_range / 2)

    def step(t, tips, speed=0.0):
        obs = follow_observation(t, tips, speed=speed, present=heard)
        estimate.update(obs)
        return push(obs)

    step(0.0, (math.inf, math.inf), speed=0.15)
    push.state, push.since, push.mark = "follow", 0.0, (0.0, estimate.pose.copy())
    for k in range(1, 20):
        command = step(0.1 * k, near)
        assert (command.v, command.omega) == (0.0, 0.0) and push.state == "follow" and station.end is None
    assert step(2.0, (math.inf, math.inf)).v > 0 and push.state == "follow"  # the way cleared: on it goes
    t = 2.1
    while t < 2.1 + params.block_wait - 0.05:  # blocked again: the wait starts afresh
        assert step(t, near).v == 0.0 and push.state == "follow"
        t += 0.1
    t += 0.1
    assert step(t, near).v < 0 and push.state == "clear"  # waited long enough: backs off to push from there


# -- a robot that cannot reach the box (a limp motor) ----------------------------------------------------------------
def test_an_approach_that_meets_nothing_is_no_push_and_the_end_is_acquired_again():
    """Closing in for approach_timeout with nothing felt (no fingertip contact, no bump, no crawl: driving freely),
    the box is not there: no push is recorded, and the robot goes to acquire its end again. (Pushing anyway, an R-2
    with a limp motor reported a push every 6.5 s and the box turned 120 degrees, break-motor:red@111.1, seed 0.)"""
    params = BoxPushParams()
    push, estimate, station = following(params)
    station.end = RIGHT
    t = 0.0
    while push.state in ("start", "approach"):
        obs = follow_observation(t, (math.inf, math.inf), speed=0.3, heading=0.0)
        estimate.update(obs)
        push(obs)
        t += 0.1
        assert t < params.approach_timeout + 0.5
    assert push.state == "back_off" and station.end is None and station.misses == 1
    assert push.knowledge.pushes == [] and not push.finished


def test_after_miss_limit_misses_in_a_row_the_robot_withdraws_and_claims_no_end():
    """Three activations in a row that ended without a push, with a teammate claiming a task: the robot neither
    pushes nor announces its end, so the teammate's impatience is no longer held back by its claim; a push in
    between sets the count back, and with no teammate claiming anything it keeps trying."""
    from teamsim.controllers.behaviours.box_pushing import R2BoxPusher

    brain = R2BoxPusher(ROBOT, LEFT, BoxPushParams(), {"green": 30.0})
    left, right = brain.sets["push-left"], brain.sets["push-right"]
    assert brain.applicable(left) and not brain.withdrawn

    def activation(finished: bool, green_claims: str | None = "push-right"):
        from dataclasses import replace

        from teamsim.radio import Message

        brain.active = "push-left"
        left.state = "done" if finished else "follow"
        brain.alliance = lambda obs: Command(behaviour=IDLE)  # the set ended: ALLIANCE went idle
        heard = [Message("green", 0.0, activity_message(green_claims))]
        return brain(replace(follow_observation(0.0, (math.inf, math.inf)), inbox=heard))

    for finished in (False, False, True, False, False):
        activation(finished)
    assert brain.station.misses == 2 and not brain.withdrawn
    activation(False, green_claims=None)  # the teammate claims nothing: alone, the robot keeps trying
    assert brain.station.misses == 3 and not brain.withdrawn and brain.applicable(left)
    command = activation(False)
    assert brain.withdrawn and not brain.applicable(left) and not brain.applicable(right)
    assert announced_task(command.broadcast) is None  # standing at its end, it claims it no more


def test_a_withdrawn_robot_tries_again_once_nobody_has_pushed_for_lambda():
    """Withdrawn while a teammate claims an end, the robot comes back when no push has been heard of for lambda:
    the claiming teammate is not pushing either (its drive broken too, break-motor:green@73.7 seed 1, where the
    healthy red had lost the box, withdrawn, and both stood still for the rest of the mission)."""
    from dataclasses import replace

    from teamsim.controllers.behaviours.box_pushing import R2BoxPusher
    from teamsim.radio import Message

    params = BoxPushParams()
    brain = R2BoxPusher(ROBOT, LEFT, params, {"green": 30.0})
    brain.station.misses = params.miss_limit
    brain.alliance = lambda obs: Command(behaviour=IDLE)

    def heard_at(time: float, pushed_right: float = 0.0):
        payload = {**activity_message("push-right"), "pushed": {LEFT: 0.0, RIGHT: pushed_right}}
        brain(replace(follow_observation(time, (math.inf, math.inf)), inbox=[Message("green", time, payload)]))

    heard_at(10.0, pushed_right=10.0)  # green claims its end and pushes it
    assert brain.withdrawn
    heard_at(10.0 + params.give_up_after - 1.0, pushed_right=10.0)
    assert brain.withdrawn
    heard_at(10.0 + params.give_up_after + 1.0, pushed_right=10.0)  # still claiming, no push for lambda
    assert not brain.withdrawn and brain.applicable(brain.sets["push-left"])


def test_blocked_beside_a_withdrawn_teammate_it_pushes_from_there_at_once():
    """A withdrawn teammate still talks but claims no task: it is not pushing from anywhere, so it is no reason to
    hold still (held for block_wait each time, green alone took 110 s a push, break-motor:red@244 seed 9)."""
    params = BoxPushParams()
    push, estimate, station = following(params)
    station.claimants = frozenset()  # green is heard, and claims nothing
    obs = follow_observation(0.0, (math.inf, math.inf), present=frozenset({"green"}))
    estimate.update(obs)
    push(obs)
    push.state, push.since, push.mark = "follow", 0.0, (0.0, estimate.pose.copy())
    near = (params.block_range / 2, params.block_range / 2)
    obs = follow_observation(0.1, near, speed=0.0, present=frozenset({"green"}))
    estimate.update(obs)
    assert push(obs).v < 0 and push.state == "clear"
    station.claimants = frozenset({"green"})  # claiming an end: wait for it first, as before
    push.state, push.blocked_since = "follow", None
    obs = follow_observation(0.2, near, speed=0.0, present=frozenset({"green"}))
    estimate.update(obs)
    assert push(obs).v == 0.0 and push.state == "follow"


@pytest.mark.parametrize("bump_back", [31.6, 0.0])
def test_backing_against_a_wall_ends_on_the_back_bumper_or_after_twice_its_time(bump_back):
    """Backing in from past an end with its back on the wall, encoders still (kill:green@33.1, seed 8: 0.17 of the
    0.19 m, 31.6 N on the back bumper, for the last 214 s of the run): the back-up ends at once on the bumper, and
    without it after twice the time the distance takes and back_slack more. Then the robot turns in."""
    params = BoxPushParams()
    push, estimate, station = following(params)
    station.end = RIGHT
    obs = follow_observation(0.0, (math.inf, math.inf), speed=0.0)
    estimate.update(obs)
    push.state, push.since, push.mark = "back_in", 0.0, (0.0, estimate.pose.copy())
    limit = 2 * (params.end_overrun + params.end_inset) / params.drive.back_speed + params.back_slack
    t = 0.0
    while push.state == "back_in":
        t = round(t + 0.1, 6)
        obs = follow_observation(t, (math.inf, math.inf), speed=0.0)
        obs = obs.__class__(**{**obs.__dict__, "touch": {"bump_back": bump_back}})
        estimate.update(obs)
        push(obs)
        assert t <= limit + 0.2, "still backing into the wall"
    assert push.state == "turn_in"
    assert t == pytest.approx(0.1 if bump_back else limit, abs=0.11)
