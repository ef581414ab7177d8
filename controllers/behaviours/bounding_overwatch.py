"""Parker's bounding overwatch behaviour sets (§6.3, Fig. 6-14, pp.173-177; spec §4.4) under ALLIANCE.

Two kinds of robot split into two subgroups with an equal share of each kind, gather, elect a leader per group,
then bound along a route in turn: one group's leader leads it to its next waypoint while the other group
overwatches, and the completed bound, broadcast, triggers the other leader. The sets, in priority order:

- *join-group* (:class:`JoinGroup`): wait a random time in [0, ``max_wait``] counting the groups' members and
  kinds from the broadcasts, then pick the group with the fewest of my kind, else the fewest members, else at
  random (the thesis's rule, verbatim), broadcast it and drive to my slot at the group's gathering point.
  Two robots deciding within one radio period cannot hear each other (the thesis's "interference"): a robot
  that then finds its group holding two or more of its kind beyond the other group, and is the latest of them
  to join, moves over (:meth:`Knowledge.should_switch`; docs/decisions.md).
- *emerge-leader*: applicable once I have visited my gathering point and my group has no leader (none heard
  within tau). Its impatience ``1 / leader_delay`` differs per robot, so the first to arrive leads at the start
  and the most impatient survivor when a leader falls silent; simultaneous claims go to the earlier claim, then
  to the fixed robot priority.
- *lead-to-waypoint* (:class:`Lead`): a leader whose group's turn it is (the bounds completed so far, an even
  number for the first group, an odd one for the second) drives to the route's next waypoint; arriving, it
  broadcasts the bound complete. Bound k goes to ``route[k]``; the groups alternate, so they leapfrog.
- *follow-leader* (:class:`Follow`): a non-leader whose leader is leading keeps its wedge slot behind it.
- *overwatch*: once everyone heard has gathered and both groups have leaders: hold position (no danger is
  modelled, as in the thesis).

A robot knows positions only from its own fixes (blended with odometry, :class:`DeadReckoning`) and from its
teammates' broadcasts, which carry their fix, group, kind, leadership and the bounds completed. Constants the
thesis does not give are in :class:`OverwatchParams`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from teamsim.config import setting
from teamsim.controllers.alliance.motivation import (IDLE, AllianceController, AllianceParams,
                                                     BehaviourSetDefinition, MotivationRates, activity_message)
from teamsim.controllers.base import Command, Observation
from teamsim.controllers.navigation.polar_histogram import wrap
from teamsim.positioning import wrap_angle

GROUPS = ("A", "B")  # A bounds first (the thesis's "first team")
JOIN, EMERGE, LEAD, FOLLOW, OVERWATCH = "join-group", "emerge-leader", "lead-to-waypoint", "follow-leader", "overwatch"
SETS = (JOIN, EMERGE, LEAD, FOLLOW, OVERWATCH)  # priority order (the §3.6 tie-break)
LONG = 1e6  # s: psi and lambda of sets that are never handed over or given up
WAYPOINT = "waypoint"  # the leader's own entries in its approach stalls: near its waypoint,
TRAPPED = "trapped"  # and farther off
PROGRESS = 0.5  # m a stalled teammate must gain to be waited for again (Stalls, OverwatchParams.patience)


@dataclass(frozen=True)
class OverwatchParams:
    """Assumed constants of the bounding-overwatch behaviours (§6.3 gives none)."""
    max_wait: float = setting(10.0, lo=0.0, hi=600.0, meaning="s: join-group's random wait is drawn from "
                                                              "[0, max_wait] (§6.3 'some prespecified maximum')")
    rebalance: bool = setting(True, meaning="a robot of a surplus kind that joined its group last moves over "
                                            "(teamsim's remedy for simultaneous joins); false: the thesis's rule "
                                            "alone")
    arrive: float = setting(0.5, lo=0.05, hi=5.0, meaning="m from its waypoint at which a leader has arrived "
                                                          "(its bound is complete)")
    blocked_radius: float = setting(2.0, lo=0.05, hi=50.0, meaning="m from its waypoint within which a leader that "
                                    "gets no nearer (by 0.5 m) for patience s has arrived: something stands there "
                                    "(half the default bound)")
    gather_radius: float = setting(1.5, lo=0.1, hi=10.0, meaning="m from its gathering point at which a robot has "
                                                                 "visited it (and stops, leaving room for others)")
    wedge_back: float = setting(1.6, lo=0.5, hi=10.0, meaning="m each row of the follow wedge lies behind the "
                                                             "one ahead")
    wedge_side: float = setting(1.1, lo=0.3, hi=10.0, meaning="m between a wedge slot and the leader's track")
    lead_speed: float = setting(0.25, lo=0.05, hi=1.0, meaning="m/s a leader drives at (followers catch up)")
    follow_speed: float = setting(0.45, lo=0.05, hi=1.0, meaning="m/s a follower may drive at")
    move_speed: float = setting(0.35, lo=0.05, hi=1.0, meaning="m/s to a gathering slot")
    lag: float = setting(4.0, lo=0.5, hi=50.0, meaning="m a follower may lag its slot before the leader slows; "
                                                       "at twice this the leader waits")
    patience: float = setting(30.0, lo=1.0, hi=1e4, meaning="s a leader waits for a member that gets no nearer "
                                                            "(by 0.5 m) to the gathering point, or slows or waits "
                                                            "for a follower lagging beyond lag that gets no nearer "
                                                            "its slot; then it goes on without it")
    leader_delay: float = setting(1.0, lo=0.01, hi=600.0, meaning="theta / delta_fast of emerge-leader, s, for "
                                                                  "the robot of priority 0")
    leader_step: float = setting(0.3, lo=0.0, hi=600.0, meaning="s added to leader_delay per priority rank: the "
                                                                "relative impatience that picks a new leader")
    set_delay: float = setting(0.5, lo=0.01, hi=60.0, meaning="theta / delta_fast of the other sets, s")
    avoid_range: float = setting(0.6, lo=0.05, hi=1.5, meaning="m: IR readings nearer than this push the robot "
                                                               "away")
    stop_range: float = setting(0.2, lo=0.0, hi=1.0, meaning="m: something this near ahead stops the robot")
    avoid_gain: float = setting(1.5, lo=0.0, hi=20.0, meaning="weight of the IR push against the goal direction")
    turn_gain: float = setting(1.5, lo=0.1, hi=20.0, meaning="rad/s per rad of heading error")
    stuck_time: float = setting(6.0, lo=0.5, hi=600.0, meaning="s asked to move while the pose estimate moves less "
                                                           "than stuck_moved and turns less than 0.3 rad: stuck")
    stuck_moved: float = setting(0.15, lo=0.0, hi=5.0, meaning="m (see stuck_time)")
    escape_time: float = setting(2.5, lo=0.1, hi=60.0, meaning="s a stuck robot backs off, turning towards its goal")
    swerve: float = setting(0.7, lo=0.0, hi=5.0, meaning="weight of the sidestep to the right of whatever the IR "
                                                         "sees, which breaks head-on deadlocks")


@dataclass
class Member:
    """A teammate as this robot last heard it."""
    group: str | None = None
    kind: str = ""
    joined: float = math.inf
    priority: int = 0
    visited: bool = False
    leader_since: float | None = None  # None: not a leader
    leading: int | None = None  # the bound it is leading, if any
    at: tuple | None = None  # its broadcast pose fix (x, y, heading) and speed, and when it was sent
    speed: float = 0.0
    sent: float = 0.0
    heard: float = -math.inf


@dataclass
class Record:
    """One bound (group, leader, waypoint index, start, end) or one leadership (group, robot, from, to)."""
    group: str
    robot: str
    start: float
    end: float | None = None
    bound: int | None = None


class DeadReckoning:
    """(x, y, heading) from the chassis odometry between positioning fixes, each new fix blended in with weight
    ``gain`` (the thesis gives no estimator; as :class:`~teamsim.controllers.skills.pose_estimate.PoseEstimate`,
    but from ``Observation.velocity``, which every wheeled kind has)."""

    def __init__(self, gain: float = 0.3):
        self.gain, self.pose, self.last_fix, self.time = gain, None, -math.inf, None

    def update(self, obs: Observation) -> np.ndarray | None:
        fix = obs.pose
        if fix is None:
            return None
        if self.pose is None:
            self.pose = np.array([fix.x, fix.y, fix.heading], float)
        else:
            v, w = obs.velocity or (0.0, 0.0)
            dt = obs.time - self.time
            mid = self.pose[2] + 0.5 * w * dt
            self.pose[:2] += v * dt * np.array([math.cos(mid), math.sin(mid)])
            self.pose[2] = wrap_angle(self.pose[2] + w * dt)
            if fix.time > self.last_fix:
                self.pose[:2] += self.gain * (np.array([fix.x, fix.y]) - self.pose[:2])
                self.pose[2] = fix.heading
        self.last_fix, self.time = fix.time, obs.time
        return self.pose


class Knowledge:
    """What one robot knows of the team: itself and every teammate as last heard, and the bounds completed."""

    def __init__(self, name: str, kind: str, priority: int, tau: float, route_length: int):
        self.name, self.tau, self.route_length = name, tau, route_length
        self.me = Member(kind=kind, priority=priority)
        self.others: dict[str, Member] = {}
        self.bounds = 0  # bounds completed, as far as this robot knows
        self.now = 0.0
        self.refresh()

    # -- hearing -------------------------------------------------------------------------------------------------
    def hear(self, sender: str, payload, sent: float, now: float) -> None:
        if not isinstance(payload, dict) or "kind" not in payload:
            return
        m = self.others.setdefault(sender, Member())
        m.group, m.kind, m.priority = payload.get("group"), payload["kind"], int(payload.get("prio", 0))
        m.joined = float(payload["joined"]) if payload.get("joined") is not None else math.inf
        m.visited = bool(payload.get("visited"))
        m.leader_since = payload.get("leader")
        m.leading = payload.get("leading")
        if payload.get("at") is not None:
            m.at, m.speed, m.sent = tuple(payload["at"]), float(payload.get("v", 0.0)), sent
        m.heard = now
        self.bounds = max(self.bounds, int(payload.get("bounds", 0)))

    def payload(self, pose: np.ndarray | None, speed: float) -> dict:
        me = self.me
        return {"group": me.group, "kind": me.kind, "prio": me.priority,
                "joined": None if math.isinf(me.joined) else round(me.joined, 2), "visited": me.visited,
                "leader": None if me.leader_since is None else round(me.leader_since, 2), "leading": me.leading,
                "at": None if pose is None else [round(float(v), 3) for v in pose], "v": round(speed, 3),
                "bounds": self.bounds}

    # -- what it implies -----------------------------------------------------------------------------------------
    def refresh(self) -> None:
        """Recompute who is present and who leads, after hearing or after a change of my own state."""
        self._present = {n: m for n, m in self.others.items() if m.heard > self.now - self.tau}
        self._live = {**self._present, self.name: self.me}
        self._leaders = {}
        for g in GROUPS:
            claims = [(m.leader_since, m.priority, n) for n, m in self._live.items()
                      if m.group == g and m.leader_since is not None]
            self._leaders[g] = min(claims)[2] if claims else None

    def present(self) -> dict[str, Member]:
        """Teammates heard within tau (the others are taken as gone, §3.6)."""
        return self._present

    def everyone(self) -> dict[str, Member]:
        return {**self.others, self.name: self.me}

    def counts(self, group: str, kind: str) -> tuple[int, int]:
        """(members of my kind, members) of ``group``, as heard, me included if I am in it."""
        members = [m for m in self.everyone().values() if m.group == group]
        return sum(m.kind == kind for m in members), len(members)

    def choose(self, draw: float) -> str:
        """The join-group rule (§6.3): fewest of my kind, then fewest members, then arbitrary (``draw`` in
        [0, 1) picks among the tied)."""
        scores = {g: self.counts(g, self.me.kind) for g in GROUPS}
        best = min(scores.values())
        tied = [g for g in GROUPS if scores[g] == best]
        return tied[min(int(draw * len(tied)), len(tied) - 1)]

    def should_switch(self) -> bool:
        """My group holds two or more of my kind beyond the other group, and I joined it last of them (ties to
        the lower priority): I move over. Every robot hearing the same finds the same one."""
        me = self.me
        if me.group is None:
            return False
        other = GROUPS[1 - GROUPS.index(me.group)]
        mine, _ = self.counts(me.group, me.kind)
        theirs, _ = self.counts(other, me.kind)
        if mine - theirs < 2:
            return False
        same = [(m.joined, m.priority, n) for n, m in self.everyone().items() if m.group == me.group
                and m.kind == me.kind]
        return max(same)[2] == self.name

    def leader(self, group: str) -> str | None:
        """The group's leader: of the claims heard within tau (and mine), the earliest, then the highest
        priority."""
        return self._leaders.get(group)

    def member(self, name: str) -> Member:
        return self.me if name == self.name else self.others[name]

    def turn(self) -> str | None:
        """The group whose turn it is to bound, None once the route is done."""
        return GROUPS[self.bounds % 2] if self.bounds < self.route_length else None

    def group_gathered(self, group: str) -> bool:
        return all(m.visited for m in self._live.values() if m.group == group)

    def all_gathered(self) -> bool:
        return all(m.group is not None and m.visited for m in self._live.values())

    def followers(self, group: str, leader: str) -> list[str]:
        """The group's live non-leaders in priority order: their wedge slots."""
        return [n for n, m in sorted(self._live.items(), key=lambda nm: (nm[1].priority, nm[0]))
                if m.group == group and n != leader]


def wedge(rank: int, params: OverwatchParams) -> tuple[float, float]:
    """Follower ``rank``'s slot in the leader's frame (x ahead, y left): a wedge whose row r (1, 2, ...) holds
    r + 1 slots, ``wedge_back`` behind the row ahead; within a row the slots nearest the track fill first."""
    row, first = 1, 0
    while rank >= first + row + 1:
        first += row + 1
        row += 1
    spots = sorted(((row / 2 - j) * 2 * params.wedge_side for j in range(row + 1)), key=lambda y: (abs(y), -y))
    return -row * params.wedge_back, spots[rank - first]


class Driver:
    """Goal-seeking with IR avoidance (the thesis gives no control laws): head for a goal direction pushed away
    from whatever the IR ring sees nearer than ``avoid_range``, slowing down for anything ahead; a kind without
    point turns (the tricycle) keeps creeping forward while it turns and backs off what it nears ahead
    (docs/decisions.md, bounding overwatch, "Driving")."""

    def __init__(self, params: OverwatchParams, omega_max: float, point_turns: bool):
        self.params, self.omega_max, self.point_turns = params, omega_max, point_turns
        self.ahead: np.ndarray | None = None  # the IR sensors looking ahead
        self.track: list = []  # (time, x, y, heading) while asked to move
        self.escape_until, self.escape_turn, self.escapes = -math.inf, 0.0, 0

    def __call__(self, obs: Observation, pose: np.ndarray, direction: np.ndarray, speed: float,
                 through_gap: bool = False) -> tuple[float, float]:
        """``through_gap``: head for the clear IR direction nearest the goal's instead of the goal pushed away from
        what the IR sees (:meth:`OverwatchRobot._trapped`)."""
        if obs.time < self.escape_until:
            return -0.12, self.escape_turn
        v, omega, error = self._steer(obs, pose, direction, speed, through_gap)
        if not self.point_turns and self.closest_ahead(obs) < self.params.stop_range:
            return self._back_off(obs.time, error)
        self._watch(obs.time, pose, v, omega, error)
        return v, omega

    def _back_off(self, now: float, error: float) -> tuple[float, float]:
        """Back off for ``escape_time``, turning towards the goal side: with the nose swinging that way the robot
        then drives off past what was ahead (a three-point turn for the tricycle). (Backing one control step at a
        time, with the turn reversed to keep its wheel angle, a tricycle undid each creep's turn and stood 0.2 m
        from its dead predecessor for 820 s: kill:@leader@14, seed 126.)"""
        self.escape_until, self.escape_turn = now + self.params.escape_time, math.copysign(0.4, error)
        return -0.12, self.escape_turn

    def _watch(self, now: float, pose: np.ndarray, v: float, omega: float, error: float) -> None:
        """Stuck (wedged against a dead robot, a tricycle nose-on to something): back off, turning to the goal."""
        p = self.params
        if abs(v) < 0.03 and abs(omega) < 0.2:
            self.track.clear()
            return
        self.track.append((now, float(pose[0]), float(pose[1]), float(pose[2])))
        t0, x0, y0, h0 = self.track[0]
        if now - t0 < p.stuck_time:
            return
        moved = max(math.hypot(x - x0, y - y0) for _, x, y, _ in self.track)
        turned = max(abs(wrap_angle(h - h0)) for _, _, _, h in self.track)
        if moved < p.stuck_moved and turned < 0.3:
            self._back_off(now, error)
            self.escapes += 1
        self.track.clear()

    def _steer(self, obs: Observation, pose: np.ndarray, direction: np.ndarray, speed: float,
               through_gap: bool) -> tuple[float, float, float]:
        p = self.params
        ranges, bearings = obs.ir_range, obs.ir_bearings
        near = ranges < p.avoid_range
        push = np.zeros(2)
        if near.any():
            weight = (p.avoid_range - ranges[near]) / p.avoid_range
            angles = pose[2] + bearings[near]
            push = -np.array([np.sum(weight * np.cos(angles)), np.sum(weight * np.sin(angles))])
            push += p.swerve * np.array([push[1], -push[0]])  # and to its right: two robots pass left to left
        closest = self.closest_ahead(obs)
        norm = float(np.hypot(*direction))
        goal = direction / norm if norm > 1e-9 else np.zeros(2)
        want = self._gap(obs, pose, goal) if through_gap else goal + p.avoid_gain * push
        if float(np.hypot(*want)) < 1e-6:
            return 0.0, 0.0, 0.0
        error = wrap_angle(math.atan2(want[1], want[0]) - pose[2])
        omega = float(np.clip(p.turn_gain * error, -self.omega_max, self.omega_max))
        if self.point_turns:
            v = 0.0 if abs(error) > 0.8 else speed * math.cos(error)
        else:
            v = speed * max(math.cos(error), 0.3)
        if p.avoid_range > p.stop_range:
            v *= float(np.clip((closest - p.stop_range) / (p.avoid_range - p.stop_range), 0.0, 1.0))
            if not self.point_turns and closest > p.stop_range and abs(error) > 0.3:
                v = max(v, 0.05)  # a tricycle turns only while it rolls
        return v, omega, error

    def _gap(self, obs: Observation, pose: np.ndarray, goal: np.ndarray) -> np.ndarray:
        """The direction of the IR ray reading clear (beyond ``avoid_range``) nearest the goal's; the goal's if
        every ray sees something."""
        clear = obs.ir_range >= self.params.avoid_range
        if not clear.any():
            return goal
        angles = pose[2] + obs.ir_bearings[clear]
        best = angles[np.argmin(np.abs(wrap(angles - math.atan2(goal[1], goal[0]))))]
        return np.array([math.cos(best), math.sin(best)])

    def closest_ahead(self, obs: Observation) -> float:
        if self.ahead is None:
            self.ahead = np.array([abs(wrap_angle(float(b))) < 0.6 for b in obs.ir_bearings], bool)
        return float(obs.ir_range[self.ahead].min()) if self.ahead.any() else math.inf

    def blocked(self, obs: Observation) -> bool:
        return self.closest_ahead(obs) < self.params.avoid_range


class Stalls:
    """Per teammate, since when its distance to where it should be has not shrunk by ``PROGRESS``: one that has
    stalled for ``patience`` seconds is no longer waited for (:meth:`OverwatchRobot._gathered`, ``_lag``)."""

    def __init__(self):
        self.since: dict[str, tuple[float, float]] = {}  # teammate -> (when it last gained ground, its distance)

    def stalled(self, name: str, now: float, distance: float, patience: float) -> bool:
        if name not in self.since or distance < self.since[name][1] - PROGRESS:
            self.since[name] = (now, distance)  # just heard, or it gains ground: wait for it
        return now - self.since[name][0] > patience

    def forget(self, name: str) -> None:
        self.since.pop(name, None)

    def clear(self) -> None:
        self.since.clear()


class OverwatchRobot:
    """One robot's controller: ALLIANCE over the five sets of Fig. 6-14 (``observation -> Command``).

    ``route``: the waypoints, bound k going to ``route[k]``; ``gather``: each group's gathering point (A, B);
    ``priority``: the fixed robot priority (0 first); ``leader_delay``: theta / delta_fast of its emerge-leader;
    ``rng``: its seeded stream (the join-group wait and the tie draw)."""

    def __init__(self, name: str, kind: str, route, gather, priority: int, leader_delay: float,
                 rng: np.random.Generator, params: OverwatchParams = OverwatchParams(), tau: float = 3.0,
                 omega_max: float = math.pi / 7, point_turns: bool = True):
        self.name, self.params = name, params
        self.route = [tuple(map(float, w)) for w in route]
        self.gather = {g: tuple(map(float, c)) for g, c in zip(GROUPS, gather)}
        self.k = Knowledge(name, kind, priority, tau, len(self.route))
        self.wait = float(rng.uniform(0.0, params.max_wait))
        self.draws = rng  # the tie draws of join-group
        self.estimate = DeadReckoning()
        self.drive = Driver(params, omega_max, point_turns)
        self.pose: np.ndarray | None = None
        self.speed = 0.0
        self.joins: list[tuple[str, float]] = []  # (group, when) for each decision, switches included
        self.leaderships: list[Record] = []
        self.bound_log: list[Record] = []
        self.lagging = Stalls()  # followers beyond lag from their slots
        self.approach = Stalls()  # the leader itself, near its waypoint
        self.arriving = Stalls()  # members not yet at the gathering point
        fast = {s: MotivationRates(delta_fast=1 / params.set_delay, delta_slow=1 / (10 * params.set_delay),
                                   phi=LONG, psi=LONG, lam=LONG) for s in SETS}
        fast[JOIN] = replace(fast[JOIN], delta_fast=20.0, delta_slow=2.0)  # all activate it at the start
        fast[EMERGE] = MotivationRates(delta_fast=1 / leader_delay, delta_slow=1 / (10 * leader_delay), phi=LONG,
                                       psi=LONG, lam=LONG)
        own = {JOIN, FOLLOW, OVERWATCH}  # a robot's own tasks; emerge-leader and lead-to-waypoint are its group's
        actions = {JOIN: self._join, EMERGE: self._emerge, LEAD: self._lead, FOLLOW: self._follow,
                   OVERWATCH: self._hold}
        applicable = {JOIN: self.joining, EMERGE: self.may_emerge, LEAD: self.may_lead, FOLLOW: self.may_follow,
                      OVERWATCH: self.may_overwatch}
        definitions = [BehaviourSetDefinition(s, lambda obs, s=s: applicable[s](), _Act(s, actions[s]),
                                              task=f"{s} {name}" if s in own else s, rates=fast[s]) for s in SETS]
        self.alliance = AllianceController(name, definitions, AllianceParams(tau=tau))
        self.active = IDLE

    # -- sensory feedback of each set -------------------------------------------------------------------------------
    @property
    def group(self) -> str | None:
        return self.k.me.group

    @property
    def is_leader(self) -> bool:
        return self.group is not None and self.k.leader(self.group) == self.name

    def joining(self) -> bool:
        return not self.k.me.visited

    def may_emerge(self) -> bool:
        return self.k.me.visited and self.k.leader(self.group) is None

    def may_lead(self) -> bool:
        return (self.k.me.visited and self.is_leader and self.k.turn() == self.group
                and (self.k.me.leading is not None or self._gathered()))

    def _gathered(self) -> bool:
        """My group has collected (§6.3: a bound starts "as soon as its team has collected"): every live member
        heard has visited our gathering point, but for one that has got no nearer to it (by ``PROGRESS``, by its
        broadcasts) for ``patience`` seconds: wedged among robots round the other group's point, say, it is not
        waited for (as :meth:`_lag`; docs/bounding-overwatch.md)."""
        k, p = self.k, self.params
        point = np.array(self.gather[self.group])
        for name, m in k.present().items():
            if m.group != self.group or m.visited:
                self.arriving.forget(name)
                continue
            if m.at is None:
                return False
            away = float(np.hypot(*(point - np.array(m.at[:2]))))
            if not self.arriving.stalled(name, k.now, away, p.patience):
                return False
        return k.me.visited

    def _leader_leading(self) -> Member | None:
        leader = self.k.leader(self.group) if self.group is not None else None
        if leader is None or leader == self.name:
            return None
        m = self.k.member(leader)
        return m if m.leading is not None and m.leading == self.k.bounds and m.at is not None else None

    def may_follow(self) -> bool:
        return self.k.me.visited and self._leader_leading() is not None

    def may_overwatch(self) -> bool:
        k = self.k
        return (k.me.visited and k.all_gathered() and all(k.leader(g) is not None for g in GROUPS)
                and not self.may_lead() and not self.may_follow())

    # -- the control step -----------------------------------------------------------------------------------------
    def __call__(self, obs: Observation) -> Command:
        k = self.k
        k.now = obs.time
        for message in obs.inbox:
            if message.sender != self.name:
                k.hear(message.sender, message.payload, message.sent_at, obs.time)
        k.refresh()
        pose = self.estimate.update(obs)
        if pose is None:
            return Command(behaviour=IDLE)
        self.pose = pose
        self.speed = float(obs.velocity[0]) if obs.velocity is not None else 0.0
        if k.me.group is None and obs.time >= self.wait:
            self._decide(obs.time)
        elif self.params.rebalance and not self._bounding_begun() and k.should_switch():
            self._decide(obs.time, switch=True)
        self._track_leadership(obs.time)
        # ALLIANCE hears only the robot's own group: the other group's claims on a set are not its business
        if obs.inbox:
            same = tuple(m for m in obs.inbox if isinstance(m.payload, dict) and self.group is not None
                         and m.payload.get("group") == self.group)
            obs = replace(obs, inbox=same)
        command = self.alliance(obs)
        self.active = command.behaviour
        task = None if command.behaviour == IDLE else command.behaviour
        return replace(command, broadcast=activity_message(task, k.payload(pose, self.speed)))

    def _bounding_begun(self) -> bool:
        k = self.k
        return k.bounds > 0 or k.me.leading is not None or any(m.leading is not None for m in k.present().values())

    def _decide(self, now: float, switch: bool = False) -> None:
        me = self.k.me
        if switch:
            group = GROUPS[1 - GROUPS.index(me.group)]
        else:
            group = self.k.choose(float(self.draws.random()))
        me.group, me.joined, me.visited, me.leader_since = group, now, False, None
        self.joins.append((group, now))
        self.k.refresh()

    def _track_leadership(self, now: float) -> None:
        """Log my leaderships; step down when an earlier (or higher-priority) claim in my group is heard."""
        me = self.k.me
        if me.leader_since is not None and self.k.leader(self.group) != self.name:
            me.leader_since, me.leading = None, None
            self.k.refresh()
        current = self.leaderships[-1] if self.leaderships and self.leaderships[-1].end is None else None
        if current is not None and me.leader_since is None:
            current.end = now

    # -- the behaviour sets -----------------------------------------------------------------------------------------
    def _join(self, obs: Observation) -> Command:
        me, p = self.k.me, self.params
        if me.group is None:
            return Command()  # waiting, listening
        offset = np.array(self.gather[me.group]) - self.pose[:2]
        distance = float(np.hypot(*offset))
        # Visited: within gather_radius, or within twice that, blocked, by a gathered member of my group
        if distance <= p.gather_radius or (distance <= 2 * p.gather_radius and self.drive.blocked(obs)
                                           and self._gathered_member_near(2.0)):
            me.visited = True
            self.k.refresh()
            return Command()
        v, w = self.drive(obs, self.pose, offset, p.move_speed)
        return Command(v=v, omega=w)

    def _gathered_member_near(self, radius: float) -> bool:
        return any(m.group == self.group and m.visited and m.at is not None
                   and math.hypot(m.at[0] - self.pose[0], m.at[1] - self.pose[1]) < radius
                   for m in self.k.present().values())

    def _emerge(self, obs: Observation) -> Command:
        me = self.k.me
        if me.leader_since is None:
            me.leader_since = obs.time
            self.leaderships.append(Record(self.group, self.name, obs.time))
            self.k.refresh()
        return Command()

    def _lead(self, obs: Observation) -> Command:
        me, p, bound = self.k.me, self.params, self.k.bounds
        if me.leading != bound:
            me.leading = bound
            self.bound_log.append(Record(self.group, self.name, obs.time, bound=bound))
            self.lagging.clear()  # each bound waits afresh for its laggards
            self.approach.clear()
        target = np.array(self.route[bound])
        offset = target - self.pose[:2]
        distance = float(np.hypot(*offset))
        lag = self._lag(obs.time)
        slow = float(np.clip((2 * p.lag - lag) / p.lag, 0.0, 1.0))
        if distance <= p.arrive or self._blocked(obs.time, distance, slow):
            self.bound_log[-1].end = obs.time
            self.k.bounds, me.leading = bound + 1, None
            return Command()
        v, w = self.drive(obs, self.pose, offset, p.lead_speed * slow * min(1.0, distance / 1.0 + 0.3),
                          through_gap=self._trapped(obs.time, distance, slow))
        return Command(v=v, omega=w)

    def _trapped(self, now: float, distance: float, slow: float) -> bool:
        """Beyond ``blocked_radius`` of its waypoint, not held back for its followers, and no nearer by PROGRESS
        for ``patience`` seconds: boxed in, it steers through the clear gap nearest its waypoint until it gains
        ground. (Pushed by the IR from three robots at 0.14-0.19 m, its dead predecessor among them, the next
        leader spun in place at the gathering point for 850 s: kill:@leader@48.9, seed 167.)"""
        if distance <= self.params.blocked_radius or slow < 1.0:
            self.approach.forget(TRAPPED)
            return False
        return self.approach.stalled(TRAPPED, now, distance, self.params.patience)

    def _blocked(self, now: float, distance: float, slow: float) -> bool:
        """Within ``blocked_radius`` of its waypoint and no nearer by PROGRESS for ``patience`` seconds, and not
        held back for its followers now: something stands at the waypoint, and this is as near as the leader gets.
        (The leader killed beside its waypoint, by the wall, kept the next one 1.0-1.8 m off it, pushed away by
        the IR, for 830 s: kill:@leader@66.9, seed 41.)"""
        p = self.params
        if distance > p.blocked_radius:
            self.approach.forget(WAYPOINT)
            return False
        return self.approach.stalled(WAYPOINT, now, distance, p.patience) and slow >= 1.0

    def _lag(self, now: float) -> float:
        """How far the farthest live follower the leader still waits for is from its wedge slot, by their
        broadcasts. A follower lagging beyond ``lag`` that has got no nearer (by ``PROGRESS``) for ``patience``
        seconds is not waited for (a broken motor, a robot wedged for good: the group must not wait forever,
        docs/bounding-overwatch.md) until it comes within ``lag`` again or gains ground."""
        p, worst = self.params, 0.0
        for rank, name in enumerate(self.k.followers(self.group, self.name)):
            m = self.k.member(name)
            if m.at is None:
                continue
            lag = float(np.hypot(*(self._slot(rank, self.pose) - np.array(m.at[:2]))))
            if lag <= p.lag:
                self.lagging.forget(name)
            elif self.lagging.stalled(name, now, lag, p.patience):
                continue
            worst = max(worst, lag)
        return worst

    def _slot(self, rank: int, leader_pose) -> np.ndarray:
        ax, ay = wedge(rank, self.params)
        c, s = math.cos(leader_pose[2]), math.sin(leader_pose[2])
        return np.array([leader_pose[0] + ax * c - ay * s, leader_pose[1] + ax * s + ay * c])

    def _follow(self, obs: Observation) -> Command:
        p = self.params
        leader_name = self.k.leader(self.group)
        m = self.k.member(leader_name)
        age = max(0.0, obs.time - m.sent)
        x, y, h = m.at
        leader = np.array([x + m.speed * age * math.cos(h), y + m.speed * age * math.sin(h), h])
        rank = self.k.followers(self.group, leader_name).index(self.name)
        offset = self._slot(rank, leader) - self.pose[:2]
        heading = np.array([math.cos(h), math.sin(h)])
        along = float(offset @ heading)
        distance = float(np.hypot(*offset))
        if along < 0.0 and distance < 2 * p.wedge_back:  # the slot is behind me: let it come, keep the heading
            direction = heading + 0.5 * (offset - along * heading)
            speed = max(0.0, m.speed + 0.5 * along)
        elif distance < 0.3:
            direction, speed = heading, m.speed
        else:
            direction, speed = offset, min(p.follow_speed, max(m.speed, 0.0) + 0.4 * distance)
        v, w = self.drive(obs, self.pose, direction, speed)
        return Command(v=v, omega=w)

    def _hold(self, obs: Observation) -> Command:
        return Command()


class _Act:
    """A behaviour set's competence: a bound method, with the set's name."""

    def __init__(self, name: str, act):
        self.name, self.act = name, act

    def __call__(self, obs: Observation) -> Command:
        return replace(self.act(obs), behaviour=self.name)


def robot_rates(priority: int, params: OverwatchParams) -> float:
    """theta / delta_fast of emerge-leader for the robot of ``priority``."""
    return params.leader_delay + params.leader_step * priority

