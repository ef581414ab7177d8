"""Parker's box pushing behaviour sets (§6.1, Figs 6-1 and 6-2; spec §4.2): R-2s and Genghis-II under ALLIANCE.

A long heavy box is pushed across the room a little at a time, alternately at its two ends. The tasks are
*push-left* and *push-right* (left and right as seen by a robot facing the box from behind). Every robot keeps
:class:`PushKnowledge`: which end was pushed last, from its own pushes and from the "push complete" news that
rides on every broadcast (R-2s cannot sense a teammate's push, §6.1.1). push-left is applicable while the right
end was pushed after the left, in the order the robot learned of the pushes, and the reverse; at the start both
are applicable ("every robot thinks the opposite end was just pushed").

- R-2 (:class:`R2BoxPusher`, Fig. 6-1): push-left and push-right (:class:`PushEnd`), symmetric. An activation
  acquires the end if the robot is not already there (back off, turn along the box, follow it with the side IR
  to its end, back up, turn into the box; something in its way along the box, it turns in where it got to),
  closes in until contact (fingertip IR, bumper, or the wheels crawling), pushes for ``push_time`` keeping
  square to the face with the fingertip IR (holding its heading by the compass while only one fingertip sees the
  face), backs off a little, and records the push complete. Its own end's
  set comes first in its priority order (the tie-break of §3.6: both sets cross theta together at the start).
- Genghis-II (:class:`GenghisBoxPusher`, Fig. 6-2): *push* (applicable while a teammate is heard pushing the
  opposite end) walks into its end, keeping square with its whiskers, for ``genghis_push_time``; *go-home*
  (applicable while nobody is) walks back from the box. It never acquires the other end.

Between pushes a robot announces the end it stands at as its activity (``push-left`` or ``push-right``), not
"idle": see docs/decisions.md, "Box pushing: a robot between pushes announces its end". Rates and times the
thesis does not give are in :class:`BoxPushParams`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from teamsim.config import setting
from teamsim.controllers.alliance.motivation import (IDLE, AllianceController, AllianceParams,
                                                     BehaviourSetDefinition, MotivationRates, activity_message,
                                                     announced_task)
from teamsim.controllers.base import Command, Observation
from teamsim.controllers.skills.goto import DriveParams, steer_to, turn_to
from teamsim.controllers.skills.pose_estimate import PoseEstimate
from teamsim.models.r2 import TIP_IR
from teamsim.models.robot import RobotModel
from teamsim.positioning import wrap_angle

LEFT, RIGHT = "left", "right"
ENDS = (LEFT, RIGHT)
OPPOSITE = {LEFT: RIGHT, RIGHT: LEFT}
GO_HOME = "go-home"
SIDE_IR = {LEFT: "ir_left_front", RIGHT: "ir_right_front"}
WHISKERS = ("whisker_left", "whisker_right")


def push_task(end: str) -> str:
    return f"push-{end}"


@dataclass(frozen=True)
class BoxPushParams:
    """Assumed constants of the box-pushing behaviours (§6.1 names the behaviours and the 5-8 s pause only)."""
    push_time: float = setting(2.0, lo=0.1, meaning="s an R-2 pushes its end per push ('push a little', §6.1)")
    push_speed: float = setting(0.3, lo=0.01, hi=0.45, meaning="m/s an R-2 is asked to drive into the box while "
                                                               "pushing (it moves slower: the box is heavy)")
    genghis_push_time: float = setting(10.0, lo=0.1, meaning="s Genghis-II walks into its end per push")
    # delta_fast: 'the delay between pushes is from imperceptible to about 2 to 3 seconds, depending upon when the
    # .3 Hz communication messages actually get transmitted' (§6.1.2): the radio sets the delay, not theta/delta.
    fast_delay: float = setting(0.3, lo=0.01, meaning="theta / delta_fast, s: how soon an applicable push starts "
                                                      "when nobody else does it")
    # delta_slow_R(R-2) = theta / phi. phi must outlast whatever a live teammate takes over an end it has
    # announced: its whole push turn from its first message after this robot's push (two radio waits of up to 3 s,
    # fast_delay, an approach, push_time, release_time: about 9 s; with phi 7 s a healthy robot was taken over),
    # and an acquisition of the other end (about 20 s; with phi 10 s a revived robot took the end its teammate was
    # acquiring, and the two chased the ends, seed 505). A removed teammate stops announcing, and its claim lapses
    # tau after its last message: that, not phi, sets the pause before a survivor takes its end over (§6.1.2:
    # 'about 5 to 8 seconds'; docs/decisions.md).
    r2_patience: float = setting(30.0, lo=0.1, meaning="phi for an R-2 teammate, s: theta / delta_slow_R(R-2)")
    # delta_slow_R(Genghis-II) < delta_slow_R(R-2) (§6.1.2): a Genghis-II push lasts genghis_push_time and more.
    genghis_patience: float = setting(60.0, lo=0.1, meaning="phi for a Genghis-II teammate, s: theta / "
                                                            "delta_slow_R(Genghis-II)")
    acquiesce_after: float = setting(30.0, lo=0.1, meaning="psi, s active before yielding a push to a teammate "
                                                           "heard doing it")
    give_up_after: float = setting(60.0, lo=0.1, meaning="lambda, s active before giving a push up")
    home_distance: float = setting(1.0, lo=0.1, meaning="m Genghis-II's go-home walks back from where it started")
    drive: DriveParams = field(default_factory=lambda: DriveParams(cruise=0.15, turn_rate=1.0))
    standoff: float = 0.12  # m backed off the face before turning along the box
    follow_distance: float = 0.15  # m from the side IR to the face while following it
    follow_gain: float = 3.0  # rad of heading bend per m of following error
    follow_bend: float = 0.3  # rad: the most the heading bends from along the box while following it
    # m: once the face is seen, a side reading this far beyond follow_distance is past the end, the ray reaching
    # round the corner (measured 0.11-0.14 m along the face, 0.24-0.28 m just past it: steering in on those, a
    # robot wrapped round the end and turned in 0.17 m beyond it, kill:green@34.8, seed 10)
    face_lost: float = 0.08
    end_overrun: float = 0.04  # m driven on after the side IR loses the face: the end is passed
    end_inset: float = 0.15  # m backed up from there: the robot pushes this far in from the end
    contact_range: float = 0.03  # m: a fingertip reading nearer than this is contact
    approach_timeout: float = 4.0  # s closing in without contact: the box is not there, acquire the end again
    # misses in a row (an approach that met nothing, or an activation that ended without a push): the robot cannot
    # reach the box (a broken drive) and, while a teammate claims a task, withdraws from the pushes; it stops
    # announcing its end, so its claim lapses (docs/decisions.md, "A robot that cannot reach the box withdraws")
    miss_limit: int = 3
    # Contact felt through the wheels (shaft encoders, §2.2.1): driving into the heavy box the R-2 crawls (measured
    # 0.01-0.05 m/s against 0.3 asked), closing in freely it is past this speed within 0.2 s (0.5 m/s^2).
    stall_speed: float = 0.1  # m/s
    stall_time: float = 0.6  # s closing in before a crawl counts as contact
    back_slack: float = 0.6  # s to reverse from cruise, allowed a back-up on top of twice its own time
    square_gain: float = 2.0  # rad/s per m of difference between the two fingertip readings
    whisker_gain: float = 0.02  # rad/s per N of difference between the two whiskers' contact forces
    whisker_timeout: float = 8.0  # s Genghis-II walks towards the box before its push time runs without a touch
    genghis_push_delay: float = 1.0  # s: theta / delta_fast_GP, Genghis-II's push (§6.1.1 gives no value)
    go_home_delay: float = 2.0  # s: theta / delta_fast_GH
    release_time: float = 0.3  # s backing off after a push, so the box can turn freely under the other end
    follow_limit: float = 2.5  # m of following without finding the end: give the acquisition up and push here
    # Something in the way along the box (a robot killed at the end being acquired): a fingertip, which looks along
    # the box while following it and never sees the face there (0.6 m off along the ray), reads it this near.
    block_range: float = 0.08  # m
    block_backoff: float = 0.08  # m backed up from it before turning into the box, clear of it while turning
    block_wait: float = 40.0  # s held still first, a teammate heard: longer than phi (r2_patience, 30 s)
    # Blocked before the side IR has seen the face, the robot stands past the end, its jaw beside the box's end
    # face: it steps out from the face again (standoff) and follows on, this many times per activation.
    step_outs: int = 2

    def rates(self, delta_fast_delay: float, patience: float, teammates: dict[str, float]) -> MotivationRates:
        """One set's rates: theta = 1, delta_slow = 1 / patience for every teammate (its kind's patience)."""
        return MotivationRates(delta_fast=1 / delta_fast_delay, delta_slow=1 / patience, phi=patience,
                               psi=self.acquiesce_after, lam=self.give_up_after,
                               teammate_delta_slow=tuple((k, 1 / p) for k, p in teammates.items()),
                               teammate_phi=tuple(teammates.items()))


@dataclass
class PushRecord:
    """One push: who, which end, when the set was activated and when the push was complete."""
    robot: str
    end: str
    activated: float
    completed: float


@dataclass
class PushKnowledge:
    """What this robot knows of the pushes (its own, and the news it heard): when each end was last pushed, which
    is the news it passes on; and for each end, whether it was pushed last."""
    fresh: dict = field(default_factory=lambda: dict.fromkeys(ENDS, True))  # at the start both count as just pushed
    pushed_at: dict = field(default_factory=lambda: dict.fromkeys(ENDS, 0.0))
    pushes: list = field(default_factory=list)  # this robot's own PushRecords

    def applicable(self, end: str) -> bool:
        """The opposite end was just pushed (Fig. 6-1's sensory feedback)."""
        return self.fresh[OPPOSITE[end]]

    def pushed(self, record: PushRecord) -> None:
        self.pushes.append(record)
        self._learn(record.end, record.completed)

    def _learn(self, end: str, when: float) -> None:
        """A push at ``end`` completed at ``when``. It is the latest push unless the other end was pushed later
        (news can arrive after news of a later push: the radio sends at each robot's own slot); at equal times,
        the robots having pushed both ends together, it is the latest push for the robot learning it last."""
        if when > self.pushed_at[end]:
            self.pushed_at[end] = when
            if when >= self.pushed_at[OPPOSITE[end]]:
                self.fresh[end], self.fresh[OPPOSITE[end]] = True, False

    def hear(self, payload) -> None:
        """'push complete' news: a push at an end later than any this robot knew of."""
        news = payload.get("pushed") if isinstance(payload, dict) else None
        if isinstance(news, dict):
            for end in sorted(ENDS, key=lambda e: float(news.get(e, 0.0))):  # the older news first
                self._learn(end, float(news.get(end, 0.0)))

    def message(self) -> dict:
        """The news every broadcast carries: when each end was last pushed."""
        return {"pushed": dict(self.pushed_at)}


@dataclass
class Station:
    """Where an R-2 stands: the end it is at, and the heading that pushes into the box there."""
    end: str | None  # None: between the ends
    heading: float | None = None  # from the compass at the end of each push (the R-2 starts facing its end)
    misses: int = 0  # approaches that met nothing and activations that ended without a push, in a row
    # teammates whose last message claimed a task (None: not tracked, every teammate heard counts): a withdrawn
    # teammate claims none, pushes from nowhere, and is no reason to hold still when blocked
    claimants: frozenset | None = None


class PushEnd:
    """One R-2 behaviour set of Fig. 6-1: acquire ``end`` if not there, push it a little, report it pushed."""

    def __init__(self, robot: RobotModel, end: str, knowledge: PushKnowledge, station: Station,
                 estimate: PoseEstimate, params: BoxPushParams):
        self.robot, self.end, self.knowledge, self.station = robot.name, end, knowledge, station
        self.estimate, self.params = estimate, params
        self.tips = [robot.ir_sensors.index(n) for n in TIP_IR]
        self.side_ir = {e: robot.ir_sensors.index(SIDE_IR[e]) for e in ENDS}
        self.name = push_task(end)
        self.restart()

    def restart(self) -> None:
        self.state, self.since, self.mark = "start", None, None
        self.seen, self.lost_at = False, None  # the side IR has seen the face; where it lost it
        self.blocked_since = None  # since when something has been in the way while following
        self.stepped_out = 0  # times it stepped out from the face, blocked before seeing it

    def __call__(self, obs: Observation) -> Command:
        if self.since is None:
            self.since = obs.time
        if self.station.heading is None:
            self.station.heading = float(obs.pose.heading)
        return getattr(self, f"_{self.state}")(obs)

    def _go(self, state: str, obs: Observation) -> Command:
        self.state, self.mark = state, (obs.time, self.estimate.pose.copy())
        return getattr(self, f"_{state}")(obs)

    def _moved(self) -> float:
        return float(np.hypot(*(self.estimate.pose[:2] - self.mark[1][:2])))

    def _start(self, obs: Observation) -> Command:
        if self.station.end == self.end:
            return self._go("approach", obs)
        self.station.end = None  # leaving its end: between the ends until it has turned into the other
        return self._go("back_off", obs)

    # -- acquiring the end -----------------------------------------------------------------------------------
    def _back_off(self, obs: Observation) -> Command:
        if self._backed(obs, self.params.standoff):
            return self._go("turn_along", obs)
        return self.drive(-self.params.drive.back_speed)

    def _backed(self, obs: Observation, distance: float) -> bool:
        """Backed ``distance`` by the encoders, or as far as it can: the back bumper presses on something (a wall),
        or it has backed twice as long as the distance takes and ``back_slack`` more (docs/decisions.md, "Backing
        ends at a wall")."""
        p = self.params
        pressed = obs.touch.get("bump_back", 0.0) >= p.drive.bump_force
        too_long = obs.time - self.mark[0] >= 2 * distance / p.drive.back_speed + p.back_slack
        return self._moved() >= distance or pressed or too_long

    def along(self) -> float:
        """Heading along the box towards this set's end: the left end lies to the left of the push heading."""
        return self.station.heading + (math.pi / 2 if self.end == LEFT else -math.pi / 2)

    def _turn_along(self, obs: Observation) -> Command:
        omega = turn_to(self.estimate.pose, self.along(), self.params.drive, tolerance=0.05)
        return self.drive(0.0, omega) if omega is not None else self._go("follow", obs)

    def _follow(self, obs: Observation) -> Command:
        """Drive along the face with it on the side away from the end (on the right going left), holding
        ``follow_distance`` on that side's front IR, until that IR has lost the face for ``end_overrun``; or until
        a fingertip sees something in the way within ``block_range``. Then, with no teammate heard within tau, push
        the end from as near it as the robot got (§6.1.1 "push a little on the right end"): a teammate killed at
        its end stands there, and driving on into it wedged the survivor for lambda (60 s) every time it came for
        that end (kill:green@124.4, seed 0). With a teammate heard claiming a task (a withdrawn one claims none),
        the robot in the way may be that teammate, pushing from nearer the middle than the end: first hold still
        for ``block_wait``, longer than phi, so the way can clear or the teammate's impatience take this end over
        (taking the end at once, a revived R-2 and the survivor pushed the same half of the box and turned it 90
        degrees, kill:red@100.5 revive:red@219.7, seed 3); only then push from here (holding still for good, two
        R-2s met head-on, each waiting for the other, until lambda, again and again: radio-off:green@177.4
        radio-on:green@242.4, seed 2). Blocked before the side IR has seen the face, the robot is past the end and
        the block is the box's own end face: it steps out from the face and follows again (``_face_box``)."""
        p = self.params
        side = OPPOSITE[self.end]
        reading = obs.ir_range[self.side_ir[side]]
        # Only a reading within the band sees the face: a first one beyond it (backed off too far) steers towards the
        # face but, counted as seen, was lost on the next tick, 4 cm along a 1.5 m face; the robot backed in past
        # the far end and lost the box for good (kill:red@63.7, seed 106; 105 and 152 alike).
        near = math.isfinite(reading) and reading <= p.follow_distance + p.face_lost
        alongside = near or (math.isfinite(reading) and not self.seen)
        if min(obs.ir_range[self.tips]) < p.block_range:
            if not (self.seen or alongside) and self.stepped_out < p.step_outs:  # the box's own end ahead
                self.stepped_out += 1
                return self._go("face_box", obs)
            if self.blocked_since is None:
                self.blocked_since = obs.time
            if self._teammate_working(obs) and obs.time - self.blocked_since < p.block_wait:
                return self.drive()
            return self._go("clear", obs)
        self.blocked_since = None
        if alongside:
            # Steer for a heading along the box bent towards it (or away) by the distance error, at most
            # follow_bend: steering on the error alone turned the robot into the face, where the oblique ray reads
            # long and asks for more turn (a robot wedged itself against the box for 60 s, seed 100).
            self.seen, self.lost_at = self.seen or near, None
            towards = -1.0 if side == RIGHT else 1.0
            bend = towards * float(np.clip(p.follow_gain * (reading - p.follow_distance), -p.follow_bend,
                                           p.follow_bend))
            omega = turn_to(self.estimate.pose, self.along() + bend, p.drive, tolerance=0.0) or 0.0
            return self.drive(p.drive.cruise, omega)
        if self.seen:
            if self.lost_at is None:
                self.lost_at = self.estimate.pose[:2].copy()
            if np.hypot(*(self.estimate.pose[:2] - self.lost_at)) >= p.end_overrun:
                return self._go("back_in", obs)
        if self._moved() >= p.follow_limit:
            return self._go("turn_in", obs)
        return self.drive(p.drive.cruise, turn_to(self.estimate.pose, self.along(), p.drive, 0.02) or 0.0)

    def _face_box(self, obs: Observation) -> Command:
        """Turn back to the push heading, to back off the face and follow it again. Blocked before the side IR
        saw the face, the robot stood past the end: it had pushed overhanging it, backed off ``standoff`` with its
        jaw still beside the box's end face, and turning along met that face. Taken for a teammate in the way, the
        end was pushed from there under the other end's name, and the next acquisition ran off past the box
        (kill:green@61.6, seed 24: the box lost at 1.99 m)."""
        turning = self._turn_to_push_heading()
        return turning if turning is not None else self._go("back_off", obs)

    def _turn_to_push_heading(self) -> Command | None:
        """A turn on the spot towards the push heading; None once it faces it."""
        omega = turn_to(self.estimate.pose, self.station.heading, self.params.drive, tolerance=0.05)
        return None if omega is None else self.drive(0.0, omega)

    def _teammate_working(self, obs: Observation) -> bool:
        heard = obs.robots_present
        return bool(heard if self.station.claimants is None else heard & self.station.claimants)

    def _back_in(self, obs: Observation) -> Command:
        if self._backed(obs, self.params.end_overrun + self.params.end_inset):
            return self._go("turn_in", obs)
        return self.drive(-self.params.drive.back_speed)

    def _clear(self, obs: Observation) -> Command:
        """Blocked while following: back up ``block_backoff`` along the box, then turn into it here."""
        if self._backed(obs, self.params.block_backoff):
            return self._go("turn_in", obs)
        return self.drive(-self.params.drive.back_speed)

    def _turn_in(self, obs: Observation) -> Command:
        turning = self._turn_to_push_heading()
        if turning is not None:
            return turning
        self.station.end = self.end
        return self._go("approach", obs)

    # -- pushing ---------------------------------------------------------------------------------------------
    def square(self, obs: Observation) -> float:
        """Turn rate that squares the jaw up to the face (towards the nearer fingertip reading) while both
        fingertips see it; else one that holds the push heading by the compass. (Squaring on one fingertip turned
        a robot at the corner 30 degrees off the box; the wheels slip while pushing, so the encoders' heading
        does too.)"""
        left, right = obs.ir_range[self.tips]
        if math.isfinite(left) and math.isfinite(right):
            return float(np.clip(self.params.square_gain * (right - left), -0.3, 0.3))
        error = wrap_angle(self.station.heading - obs.pose.heading)
        return float(np.clip(self.params.drive.turn_gain * error, -0.3, 0.3))

    def _approach(self, obs: Observation) -> Command:
        """Close in until contact: a fingertip reads it, the front bumper feels it, or (the fingertips blinded)
        the wheels crawl against the box. Nothing met within ``approach_timeout``, the box is not there: no push,
        acquire the end again. (Pushing anyway, an R-2 with a broken motor spinning by its end reported a push
        every 6.5 s and the box's other end alone was pushed, break-motor:red@111.1, seed 0.)"""
        p = self.params
        closing = obs.time - self.mark[0]
        contact = min(obs.ir_range[self.tips]) < p.contact_range
        crawling = obs.velocity is not None and closing >= p.stall_time and obs.velocity[0] < p.stall_speed
        if contact or crawling or obs.touch.get("bump_front", 0.0) >= p.drive.bump_force:
            self.station.misses = 0
            return self._go("push", obs)
        if closing >= p.approach_timeout:
            self.station.misses += 1
            self.station.end = None
            return self._go("back_off", obs)
        return self.drive(p.push_speed, self.square(obs))

    def _push(self, obs: Observation) -> Command:
        p = self.params
        if obs.time - self.mark[0] >= p.push_time:
            # Both fingertips at the face: square to it, its normal by the compass (the encoders slip while
            # pushing). Else it pushed a corner and turned with it: the heading it had stays (docs/decisions.md,
            # "Box pushing: the push heading").
            if (obs.ir_range[self.tips] < p.contact_range).all():
                self.station.heading = float(obs.pose.heading)
            return self._go("release", obs)
        return self.drive(p.push_speed, self.square(obs))

    def _release(self, obs: Observation) -> Command:
        if obs.time - self.mark[0] < self.params.release_time:
            return self.drive(-self.params.drive.back_speed)
        self.knowledge.pushed(PushRecord(self.robot, self.end, self.since, obs.time))
        self.state = "done"
        return self.drive()

    def _done(self, obs: Observation) -> Command:
        return self.drive()

    @property
    def finished(self) -> bool:
        return self.state == "done"

    def drive(self, v: float = 0.0, omega: float = 0.0) -> Command:
        return Command(v=v, omega=omega, behaviour=self.name)


class R2BoxPusher:
    """One R-2's controller: push-knowledge, pose estimate and ALLIANCE over push-left and push-right, its own
    end's set first (only that one if it does not ``acquire`` ends). ``teammates`` maps each teammate to its
    patience phi (its kind's).

    ``waiting``: set down behind a teammate at its end (add-robot to a full team), as Genghis-II's
    :class:`GenghisBoxPusher` is. Until its first push it listens for tau before any push, claims no end between
    pushes, and news of a teammate's newer push at an end takes that end's set's feedback down for a tick (a new
    episode, so patience phi restarts while that end is being pushed). Without this it drove into its teammate's
    back 0.4 s after joining and logged that as a push (add-robot:green@0,kind=r2 beside Genghis-II, seed 0)."""

    def __init__(self, robot: RobotModel, end: str, params: BoxPushParams, teammates: dict[str, float],
                 acquires: bool = True, alliance: AllianceParams = AllianceParams(), waiting: bool = False):
        self.tau, self.waiting, self.on_since, self.news_at = alliance.tau, waiting, None, frozenset()
        self.knowledge = PushKnowledge()
        self.estimate = PoseEstimate(robot.drive)
        self.station = Station(end)
        rates = params.rates(params.fast_delay, params.r2_patience, teammates)
        self.sets = {}
        for e in (end, OPPOSITE[end]) if acquires else (end,):
            self.sets[push_task(e)] = PushEnd(robot, e, self.knowledge, self.station, self.estimate, params)
        # A finished push takes its set's feedback down for a tick, so that the set ends and starts afresh even when
        # news of the other end's push arrives at once (at equal push times both robots' own ends are applicable
        # again at once, and a set that stayed active sat in its finished state for good: seed 206).
        definitions = [BehaviourSetDefinition(name, lambda obs, s=s: self.applicable(s), s, rates=rates)
                       for name, s in self.sets.items()]
        self.alliance = AllianceController(robot.name, definitions, alliance)
        self.active = IDLE
        self.miss_limit, self.give_up_after = params.miss_limit, params.give_up_after
        self.claiming: dict[str, bool] = {}  # teammate -> whether its last message claimed a task
        self.now = 0.0

    @property
    def withdrawn(self) -> bool:
        """``miss_limit`` misses in a row while a teammate claims a task and the box is being pushed (a push heard
        of within lambda): it cannot reach the box and leaves the pushes to that teammate, neither pushing nor
        claiming an end. Alone it keeps trying (a survivor that had lost the box withdrew, and nobody pushed again:
        break-motor:red@244, seed 9), and it tries again once nobody has pushed for lambda (a teammate with a
        broken drive claimed its end for good while the healthy red, which had lost the box, stayed withdrawn:
        break-motor:green@73.7, seed 1)."""
        pushed_lately = self.now - max(self.knowledge.pushed_at.values()) < self.give_up_after
        return self.station.misses >= self.miss_limit and bool(self.station.claimants) and pushed_lately

    @property
    def pushes(self) -> list:
        return self.knowledge.pushes

    def applicable(self, push: PushEnd) -> bool:
        """The opposite end was just pushed, this activation has not pushed yet, and the robot has not
        withdrawn; waiting, it has listened for tau and heard of no newer push at that end this tick."""
        held = self.waiting and (self.now - self.on_since < self.tau or push.end in self.news_at)
        return self.knowledge.applicable(push.end) and not push.finished and not self.withdrawn and not held

    def __call__(self, obs: Observation) -> Command:
        self.now = obs.time
        if self.on_since is None:
            self.on_since = obs.time
        pushed_before = dict(self.knowledge.pushed_at)
        for message in obs.inbox:
            self.knowledge.hear(message.payload)
            self.claiming[message.sender] = announced_task(message.payload) is not None
        self.news_at = frozenset(e for e in ENDS if self.knowledge.pushed_at[e] > pushed_before[e])
        if self.waiting and self.knowledge.pushes:
            self.waiting = False  # it has pushed: it stands at its end now
        self.station.claimants = frozenset(name for name, claims in self.claiming.items() if claims)
        if self.estimate.update(obs) is None:
            return Command(behaviour=IDLE)
        command = self.alliance(obs)
        if command.behaviour != self.active:
            if self.active in self.sets:
                ended = self.sets[self.active]
                self.station.misses = 0 if ended.finished else self.station.misses + 1
                ended.restart()
            self.active = command.behaviour
        standing = push_task(self.station.end) if self.station.end and not (self.withdrawn or self.waiting) else None
        return announce(command, standing, self.knowledge)


def announce(command: Command, standing_task: str | None, knowledge: PushKnowledge) -> Command:
    """The broadcast: the active set's task, or between pushes the end the robot stands at (None: at neither, idle);
    and the push news."""
    task = announced_task(command.broadcast) if command.behaviour != IDLE else standing_task
    return replace(command, broadcast=activity_message(task, knowledge.message()))


class GenghisPush:
    """Fig. 6-2's *push*: walk into the box at this robot's end, square to it by the whiskers, for a given time."""

    def __init__(self, robot: RobotModel, end: str, knowledge: PushKnowledge, params: BoxPushParams):
        self.robot, self.end, self.knowledge, self.params = robot.name, end, knowledge, params
        self.v_max = robot.limits.v_max
        self.name = push_task(end)
        self.restart()

    def restart(self) -> None:
        self.since = self.touched = None
        self.done = False

    def __call__(self, obs: Observation) -> Command:
        p = self.params
        if self.since is None:
            self.since = obs.time
        left, right = (obs.touch.get(w, 0.0) for w in WHISKERS)
        if self.touched is None and (left > 0.0 or right > 0.0 or obs.time - self.since >= p.whisker_timeout):
            self.touched = obs.time
        if self.touched is not None and obs.time - self.touched >= p.genghis_push_time:
            if obs.time - self.touched < p.genghis_push_time + p.release_time:
                return Command(v=-self.v_max, behaviour=self.name)
            if not self.done:
                self.knowledge.pushed(PushRecord(self.robot, self.end, self.since, obs.time))
                self.done = True
            return Command(behaviour=self.name)
        omega = float(np.clip(p.whisker_gain * (left - right), -0.2, 0.2))
        return Command(v=self.v_max, omega=omega, behaviour=self.name)


class GoHome:
    """Fig. 6-2's *go-home*: walk back to a point ``home_distance`` behind where the robot started."""
    name = GO_HOME

    def __init__(self, params: BoxPushParams, v_max: float, omega_max: float):
        self.params = params
        self.drive = replace(params.drive, cruise=v_max, turn_rate=omega_max)
        self.home: np.ndarray | None = None

    def restart(self) -> None:
        """Nothing to forget between activations: home stays where the robot was first switched on."""

    def place(self, fix) -> None:
        if self.home is None:
            self.home = np.array([fix.x, fix.y]) - self.params.home_distance * np.array(
                [math.cos(fix.heading), math.sin(fix.heading)])

    def __call__(self, obs: Observation) -> Command:
        fix = obs.pose
        step = steer_to(np.array([fix.x, fix.y, fix.heading]), self.home, self.drive, arrive=0.2)
        v, omega = step or (0.0, 0.0)
        return Command(v=v, omega=omega, behaviour=self.name)


class GenghisBoxPusher:
    """Genghis-II's controller (Fig. 6-2): ALLIANCE over push (its end) and go-home. A teammate is pushing the
    opposite end while it was heard announcing that end's task within tau.

    ``waiting``: it was set down behind a teammate already at its end (add-robot to a full team). Until its first
    push it announces nothing between pushes (it is not at the end, so it claims no end), and news of a teammate's
    newer push at its end takes its push's feedback down for a tick (``news_at_end``): a new episode (§3.6), so the
    teammate seen pushing restarts its patience phi. With both, a Genghis-II added behind a working R-2 waits; it
    walks into the box once that R-2 falls silent for tau (killed or removed). Without them the two slowed each
    other by their standing claims until Genghis-II's phi (30 s) ran out, and it walked into the R-2's back for
    the rest of the run, the R-2 never pushing again (add-robot:newcomer@40.1,kind=genghis2, seed 0)."""

    def __init__(self, robot: RobotModel, end: str, params: BoxPushParams, alliance: AllianceParams = AllianceParams(),
                 waiting: bool = False):
        self.knowledge = PushKnowledge()
        self.end, self.tau = end, alliance.tau
        self.waiting, self.news_at_end = waiting, False
        self.heard: dict[str, tuple[str | None, float]] = {}  # teammate -> (announced task, when)
        self.push = GenghisPush(robot, end, self.knowledge, params)
        self.home = GoHome(params, robot.limits.v_max, robot.limits.omega_max)
        self.sets = {self.push.name: self.push, GO_HOME: self.home}
        rates = params.rates(params.genghis_push_delay, params.r2_patience, {})  # (phi: an R-2 pushing its end)
        definitions = [
            BehaviourSetDefinition(self.push.name, lambda obs: self.opposite_pushed(obs) and not self.push.done
                                   and not self.news_at_end and not self.listening(obs), self.push, rates=rates),
            BehaviourSetDefinition(GO_HOME, lambda obs: self.nobody_pushes(obs), self.home,
                                   rates=params.rates(params.go_home_delay, params.r2_patience, {}))]
        self.alliance = AllianceController(robot.name, definitions, alliance)
        self.active = IDLE
        self.went_home_at: float | None = None  # when go-home last became active
        self.on_since: float | None = None  # when it first sensed (switched on)

    @property
    def pushes(self) -> list:
        return self.knowledge.pushes

    def listening(self, obs: Observation) -> bool:
        """Waiting behind a teammate, it has not yet listened for tau: it may not have heard that teammate, and
        would take the end over at delta_fast (it did 1.5 s after joining, before green's radio slot came round,
        add-robot:newcomer@188,kind=genghis2, seed 3)."""
        return self.waiting and obs.time - self.on_since < self.tau

    def opposite_pushed(self, obs: Observation) -> bool:
        task = push_task(OPPOSITE[self.end])
        return any(t == task and obs.time - when < self.tau for t, when in self.heard.values())

    def nobody_pushes(self, obs: Observation) -> bool:
        """Nobody heard at the opposite end within tau, having listened for tau (switched on, it has heard
        nobody yet: it went home for a moment before its teammate's first message, seeds 404-419)."""
        if self.on_since is None:
            self.on_since = obs.time
        return obs.time - self.on_since >= self.tau and not self.opposite_pushed(obs)

    def __call__(self, obs: Observation) -> Command:
        pushed_here = self.knowledge.pushed_at[self.end]
        for message in obs.inbox:
            self.knowledge.hear(message.payload)
            self.heard[message.sender] = (announced_task(message.payload), obs.time)
        # (only while waiting: at its own end, news of another's push there comes only from a robot it replaced)
        self.news_at_end = self.waiting and self.knowledge.pushed_at[self.end] > pushed_here
        if obs.pose is None:
            return Command(behaviour=IDLE)
        if self.on_since is None:
            self.on_since = obs.time
        self.home.place(obs.pose)
        command = self.alliance(obs)
        if command.behaviour != self.active:
            if self.active in self.sets:
                self.sets[self.active].restart()
            self.active = command.behaviour
            if self.active == GO_HOME:
                self.went_home_at = obs.time
        if self.waiting and self.push.done:
            self.waiting = False  # it has pushed: it stands at its end now
        return announce(command, None if self.waiting else push_task(self.end), self.knowledge)

