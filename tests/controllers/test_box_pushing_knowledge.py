"""Box pushing's push knowledge and broadcast, without physics (Parker §6.1.1, Fig. 6-1's sensory feedback).

An R-2 cannot sense a teammate's push: it knows which end was pushed last from its own pushes and from the
"push complete" news riding on every broadcast (when each end was last pushed). push-left is applicable while the
right end was pushed last (at equal times: the push this robot learned of last); at the start both are applicable.
"""
from __future__ import annotations

import pytest

from teamsim.controllers.alliance.motivation import IDLE, activity_message, announced_task
from teamsim.controllers.base import Command
from teamsim.controllers.behaviours.box_pushing import LEFT, RIGHT, PushKnowledge, PushRecord, announce


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
