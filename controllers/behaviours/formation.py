"""Keeping formation (Parker ch.7, §7.2; spec §4.5): a side-by-side line whose leader follows a route.

The line is named left to right with one group leader (Fig. 7-1: A B C D, B leads). Robot i's place is
``o_i = (L - i) x spacing`` to the leader's left, across the line's heading. Every robot runs avoid-obstacles
under its other layers; the leader runs follow-route (:class:`RouteLeader`), the others KEEP_FORMATION
(:class:`KeepFormation`), the only competence the strategies vary (:func:`place`):

- **I**, local only: follow an assigned neighbour, the next robot towards the leader, at a preset offset and
  direction in that neighbour's frame (A left of B, C right of B, D right of C).
- **II**, plus the global goal: the place across the group leader's heading, ``leader + o_i n(heading)``.
- **III**, plus the next waypoint, which the leader announces at each turn: the line is laid across the way from
  where the leader was when it announced the waypoint to the waypoint, so robots head for their places in the line
  as it will be after the turn, and a leader turning on the spot no longer swings the line.
- **IV**, plus the full route: each robot knows its own lane (the route offset by o_i, corners mitred) and keeps
  abreast of the leader along the leader's leg, clipped to its own lane's leg, so a robot on the inside of a turn
  reaches its corner, and stops there, before the leader reaches the leader's.

Every follower drives at its place with the tracked reference's speed fed forward plus a proportional pull
(the "moderate speed to stay aligned" of §7.2, used by all four). Teammates are sensed locally (the mission's
``formation`` signal: relative poses with the positioning model's noise) and tracked with an alpha-beta filter in
the world frame of the robot's own pose estimate. The leader slows while a neighbour it senses is far from its
place by the strategy in use. Every robot bends its way round near IR readings (:func:`swerve`), and the robots of
a crossing team give way (:class:`Crossing`). A robot that has failed (ALLIANCE's tau, spec §1.4:
:meth:`FormationRobot.judge`) leaves its place empty: its neighbours re-link past it, and if it led, the living
robot nearest its place takes over follow-route along its own lane (:class:`Line`, :meth:`KeepFormation.take_lead`).
The thesis gives no control laws: docs/decisions.md, "Keeping formation".
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from teamsim.config import setting
from teamsim.controllers.base import Command, Observation
from teamsim.controllers.skills.goto import AvoidObstacles, DriveParams, steer_to, turn_to
from teamsim.controllers.skills.pose_estimate import PoseEstimate
from teamsim.models.robot import RobotModel
from teamsim.positioning import wrap_angle

STRATEGIES = ("I", "II", "III", "IV")
SIGNAL = "formation"  # Observation.signals key: {robot: (dx, dy, dheading, time)} in the sensing robot's frame


@dataclass(frozen=True)
class KeepFormationParams:
    """Assumed constants (ch.7 names the competences and strategies, not their laws)."""
    cruise: float = setting(0.3, lo=0.01, hi=2.0, meaning="m/s the leader drives its route at while the line keeps up")
    catch_up: float = setting(0.5, lo=0.01, hi=2.0, meaning="m/s the most a follower drives at to reach its place")
    pull: float = setting(0.8, lo=0.01, hi=10.0, meaning="1/s: a follower's speed towards its place per m away, on "
                                                         "top of its reference's speed")
    lag_slow: float = setting(0.5, lo=0.0, hi=10.0, meaning="m: the leader slows while a neighbour is farther than "
                                                            "this from its place")
    lag_stop: float = setting(1.5, lo=0.01, hi=20.0, meaning="m: ... and stops at this")
    arrive: float = 0.3  # m: the leader has reached a waypoint
    settle: float = 0.1  # m: nearer its place than this, a follower turns to the line's heading
    back_within: float = 0.6  # m: a place behind and nearer than this is backed into (I, II)
    lookahead: float = 1.0  # m along the lane a lane keeper steers for (III, IV)
    still: float = 0.1  # m/s: a place moving slower than this stands still (the tracker's noise is below it)
    track_alpha: float = 0.5  # alpha-beta tracker of a sensed teammate (position)
    track_beta: float = 0.2  # (velocity)
    heading_gain: float = 0.5  # share of a new sensed heading taken in
    next_leg: float = 1.0  # m: within this of its waypoint, the leader counts as turning onto the next leg (IV)
    give_way: float = 0.5  # m: a crossing robot stops while its front IR sees something nearer than this
    give_way_for: float = 15.0  # s: ... for at most this long
    lost_after: float = 3.0  # s: a teammate not sensed for this long is out of sight (its track is dropped)
    dead_after: float = 10.0  # s: a teammate silent on the radio and sensed standing this long has failed
    still_move: float = 0.5  # m: a tracked teammate moving less than this from where it stood is standing
    back_move: float = 2.0  # m: a failed teammate seen this far from where it failed is back (tracks drift less)
    swerve_range: float = 0.6  # m: a follower steers away from IR readings nearer than this (neighbours: 0.7 m)
    swerve_gain: float = 1.5  # push per reading at zero range, against a unit wish
    drive: DriveParams = field(default_factory=lambda: DriveParams(cruise=0.3, turn_rate=1.0, turn_gain=2.0,
                                                                   turn_in_place=0.8, avoid_range=0.25,
                                                                   slow_radius=0.01))


@dataclass(frozen=True)
class Line:
    """The formation's shape: robots left to right, the leader, the spacing between neighbours; and the robots
    known to have failed (``failed``). Every robot keeps its place; with robots failed, each re-links to the
    nearest living robot on each side and the living robot nearest the leader's place acts as leader (ALLIANCE:
    a teammate takes over a failed robot's task, spec §1; docs/decisions.md, "Keeping formation")."""
    names: tuple[str, ...]
    leader: str
    spacing: float
    failed: frozenset = frozenset()

    def offset(self, name: str) -> float:
        """o_i: m to the leader's left of robot ``name``'s place."""
        return (self.names.index(self.leader) - self.names.index(name)) * self.spacing

    @property
    def acting(self) -> str | None:
        """Who leads: the leader, or once it has failed the living robot nearest its place in the line (ties: the
        one nearer the line's middle, so the line's band stays the same, then the left); None if all failed."""
        if self.leader not in self.failed:
            return self.leader
        living = [i for i, n in enumerate(self.names) if n not in self.failed]
        if not living:
            return None
        lead, middle = self.names.index(self.leader), (len(self.names) - 1) / 2
        return self.names[min(living, key=lambda i: (abs(i - lead), abs(i - middle), i))]

    def reference(self, name: str) -> str | None:
        """Strategy I's assigned neighbour: the next living robot towards the (acting) leader."""
        acting = self.acting
        if acting is None or acting == name:
            return None
        i, lead = self.names.index(name), self.names.index(acting)
        step = 1 if i < lead else -1
        return next(self.names[j] for j in range(i + step, lead + step, step) if self.names[j] not in self.failed)

    def neighbours(self, name: str) -> tuple[str, ...]:
        """The nearest living robot on each side, left first."""
        i = self.names.index(name)
        left = next((self.names[j] for j in range(i - 1, -1, -1) if self.names[j] not in self.failed), None)
        right = next((self.names[j] for j in range(i + 1, len(self.names)) if self.names[j] not in self.failed),
                     None)
        return tuple(n for n in (left, right) if n is not None)

    def sensed(self, name: str, strategy: str) -> tuple[str, ...]:
        """Whom robot ``name`` senses: its neighbours, and from strategy II on the group leader."""
        acting = self.acting
        extra = (acting,) if strategy != "I" and name != acting and acting is not None else ()
        return tuple(dict.fromkeys(self.neighbours(name) + extra))

    def lead(self, poses: dict[str, np.ndarray]) -> np.ndarray | None:
        """(x, y, heading) of the leader's place, from the acting leader's pose in ``poses`` (its own place is
        offset from it across its heading); None while the acting leader's pose is unknown."""
        acting = self.acting
        if acting is None or acting not in poses:
            return None
        pose = poses[acting]
        if acting == self.leader:
            return pose
        x, y = pose[:2] - self.offset(acting) * normal(pose[2])
        return np.array([x, y, pose[2]])


def cross(a, b) -> float:
    """The z component of the 2-D cross product a x b."""
    return float(a[0] * b[1] - a[1] * b[0])


def normal(heading: float) -> np.ndarray:
    """The unit vector to the left of ``heading``."""
    return np.array([-math.sin(heading), math.cos(heading)])


class Lanes:
    """Strategy IV's route knowledge: the route's legs, and for an offset o each leg's span along the track on the
    lane o to the left, between its mitred corners (Parker: robots on the inside of a turn stop earlier)."""

    def __init__(self, route: np.ndarray):
        self.points = np.asarray(route, float)
        legs = np.diff(self.points, axis=0)
        self.lengths = np.linalg.norm(legs, axis=1)
        self.directions = legs / self.lengths[:, None]
        self.headings = np.arctan2(self.directions[:, 1], self.directions[:, 0])

    def corner_shift(self, k: int, offset: float) -> float:
        """How far along leg k the lane at ``offset`` meets leg k-1's lane, from the route's waypoint k (positive:
        later); 0 at the route's start. ``offset * tan(turn / 2)``, turns capped at 150 degrees."""
        if k == 0:
            return -math.inf
        turn = wrap_angle(self.headings[k] - self.headings[k - 1])
        return offset * math.tan(float(np.clip(turn, -math.radians(150), math.radians(150))) / 2)

    def lane(self, offset: float) -> np.ndarray:
        """The lane at ``offset`` as waypoints: the route's start, corners and end moved ``offset`` to the left,
        each corner mitred (where the two legs' lanes meet)."""
        points = [self.points[0] + offset * normal(self.headings[0])]
        for k in range(1, len(self.points) - 1):
            points.append(self.points[k] + self.corner_shift(k, offset) * self.directions[k]
                          + offset * normal(self.headings[k]))
        points.append(self.points[-1] + offset * normal(self.headings[-1]))
        return np.array(points)

    def span(self, k: int, offset: float) -> tuple[float, float]:
        """(start, end) along leg k of the lane at ``offset``, measured from waypoint k."""
        end = self.lengths[k] if k == len(self.lengths) - 1 else self.lengths[k] - self.corner_shift(k + 1, offset)
        return self.corner_shift(k, offset), end

    def place(self, k: int, offset: float, leader: np.ndarray) -> tuple[np.ndarray, float, bool]:
        """The place on leg k's lane abreast of ``leader``, clipped to the lane's leg; the leg's heading; whether
        the place moves with the leader (False where it is clipped: the robot waits at its corner)."""
        abreast = float(np.dot(leader - self.points[k], self.directions[k]))
        start, end = self.span(k, offset)
        along = float(np.clip(abreast, start, max(start, end)))
        point = self.points[k] + along * self.directions[k] + offset * normal(self.headings[k])
        return point, float(self.headings[k]), along == abreast

    def leg_of(self, k: int, leader: np.ndarray, heading: float, near: float) -> int:
        """The leader's leg, given it was on leg k: the next once it is within ``near`` of their waypoint and
        heading nearer the next leg's way, or on the next leg past the waypoint (one leg per call)."""
        if k + 1 >= len(self.lengths):
            return k
        corner, way = self.points[k + 1], self.directions[k + 1]
        turned = abs(wrap_angle(heading - self.headings[k + 1])) < abs(wrap_angle(heading - self.headings[k]))
        offset = leader - corner
        past = float(np.dot(offset, way)) > near and abs(cross(way, offset)) < near
        return k + 1 if (np.linalg.norm(offset) < near and turned) or past else k


@dataclass(frozen=True)
class Goal:
    """Where a robot should be: the place, the line's heading there, the teammate whose speed the place moves with
    (None while it stands still), and whether the robot keeps to a lane (III, IV: steer onto the line through the
    place along the heading, close up along it by speed alone) or makes for the point (I, II)."""
    point: np.ndarray
    heading: float
    pace_of: str | None
    lane: bool

    def lag(self, position: np.ndarray) -> float:
        """How far ``position`` is behind the place along the line's heading, m (negative: ahead)."""
        return float(np.dot(self.point - position, (math.cos(self.heading), math.sin(self.heading))))

    def aside(self, position: np.ndarray) -> float:
        """How far ``position`` is off the lane through the place, m."""
        return abs(cross((math.cos(self.heading), math.sin(self.heading)), position - self.point))

    def shortfall(self, position: np.ndarray) -> float:
        """How far a robot at ``position`` has still to go to its place: all the way for a point; for a lane, what
        it lags and what it is off the lane (a robot ahead waits for the line to come up, it lacks nothing)."""
        if not self.lane:
            return float(np.linalg.norm(self.point - position))
        return math.hypot(max(self.lag(position), 0.0), self.aside(position))


def place(strategy: str, line: Line, name: str, poses: dict[str, np.ndarray], news: tuple | None,
          lanes: Lanes | None, leg: int) -> Goal | None:
    """Robot ``name``'s :class:`Goal` under ``strategy``, from the (x, y, heading) ``poses`` it knows; None while
    it lacks what the strategy needs. ``news``: strategy III's (where the leader announced, the waypoint
    announced); ``lanes`` and ``leg``: strategy IV's route and the leader's leg on it."""
    offset = line.offset(name)
    if strategy == "I":
        ref = line.reference(name)
        if ref not in poses:
            return None
        x, y, heading = poses[ref]
        return Goal(np.array([x, y]) + (offset - line.offset(ref)) * normal(heading), float(heading), ref, False)
    lead = line.lead(poses)  # the leader's place, from whoever leads
    if lead is None:
        return None
    if strategy == "IV" and lanes is not None:
        point, heading, moving = lanes.place(leg, offset, lead[:2])
        return Goal(point, heading, line.acting if moving else None, True)
    heading = float(lead[2])
    if strategy == "III" and news is not None:
        (x0, y0), (x1, y1) = news
        heading = math.atan2(y1 - y0, x1 - x0)
    return Goal(lead[:2] + offset * normal(heading), heading, line.acting, strategy == "III")


def swerve(obs: Observation, params: KeepFormationParams) -> np.ndarray:
    """A push away from what the IR sees within ``swerve_range``, in the body frame, to add to the unit vector of
    the way a robot wants to go: ``swerve_gain`` x (1 - range / swerve_range) away from each such reading. It lets a
    follower whose way is blocked by a robot standing still steer round it instead of backing off and meeting it
    again (avoid-obstacles, underneath, still takes over nearer than its ``avoid_range``)."""
    near = obs.ir_range < params.swerve_range
    if not np.any(near):
        return np.zeros(2)
    weight = params.swerve_gain * (1.0 - obs.ir_range[near] / params.swerve_range)
    bearings = np.asarray(obs.ir_bearings)[near]
    return -np.array([np.sum(weight * np.cos(bearings)), np.sum(weight * np.sin(bearings))])


class Track:
    """An alpha-beta tracker of a sensed teammate in the world frame: position, velocity and heading."""

    def __init__(self, params: KeepFormationParams):
        self.params = params
        self.position: np.ndarray | None = None
        self.velocity = np.zeros(2)
        self.heading = 0.0
        self.time = 0.0
        self.stood: tuple[np.ndarray, float] | None = None  # (where it stood, since when): within still_move of it

    def update(self, measured: np.ndarray, heading: float, time: float) -> None:
        if self.position is None:
            self.position, self.heading, self.time = measured.copy(), heading, time
            self.stood = (self.position.copy(), time)
            return
        dt = max(time - self.time, 1e-3)
        predicted = self.position + self.velocity * dt
        residual = measured - predicted
        self.position = predicted + self.params.track_alpha * residual
        self.velocity = self.velocity + self.params.track_beta * residual / dt
        self.heading = wrap_angle(self.heading + self.params.heading_gain * wrap_angle(heading - self.heading))
        self.time = time
        if np.linalg.norm(self.position - self.stood[0]) > self.params.still_move:  # filtered: noise stays within
            self.stood = (self.position.copy(), time)

    @property
    def standing_for(self) -> float:
        """s it has been sensed within ``still_move`` of one spot."""
        return self.time - self.stood[1] if self.stood is not None else 0.0

    def pose(self, time: float) -> np.ndarray:
        x, y = self.position + self.velocity * (time - self.time)
        return np.array([x, y, self.heading])

    @property
    def speed(self) -> float:
        return float(np.linalg.norm(self.velocity))


class FormationRobot:
    """What every robot of the line shares: its own pose estimate, avoid-obstacles, the tracks of the teammates it
    senses (from ``Observation.signals[SIGNAL]``, relative to itself), which teammates it judges failed
    (:meth:`judge`), steering that swerves round near things, and follow-route (:meth:`follow_route`), which the
    leader runs and a follower takes over when the leader has failed."""

    def __init__(self, robot: RobotModel, line: Line, strategy: str, params: KeepFormationParams,
                 rng: np.random.Generator, route: np.ndarray):
        self.name, self.line, self.strategy, self.params = robot.name, line, strategy, params
        self.estimate = PoseEstimate(robot.drive)
        self.avoid = AvoidObstacles(robot.ir_sensors, robot.ir_bearings, (), rng, params.drive)
        self.tracks: dict[str, Track] = {}
        self.lanes = Lanes(route) if strategy == "IV" else None
        self.course = self.lanes or Lanes(route)  # the route, as follow-route knows it (any robot may lead)
        self.leg = 0
        self.push = np.zeros(2)  # this tick's swerve, body frame
        self.view = line  # the line as this robot knows it: with the teammates it judges failed
        self.watched: dict[str, float] = {}  # teammate -> since when this robot has looked for it
        self.failed_at: dict[str, np.ndarray | None] = {}  # failed teammate -> where it was last seen
        # follow-route: the waypoints it drives to, the next one's index, when it reached the last
        self.route: np.ndarray | None = None
        self.target = 1
        self.announce = True
        self.finished_at: float | None = None

    def sense(self, obs: Observation, pose: np.ndarray) -> dict[str, np.ndarray]:
        """Fold this tick's fresh readings into the tracks and judge who has failed; the poses now of the
        teammates in sight (a track not refreshed for ``lost_after`` is out of sight, not extrapolated)."""
        for name, (dx, dy, dheading, when) in obs.signals.get(SIGNAL, {}).items():
            track = self.tracks.setdefault(name, Track(self.params))
            if when > track.time or track.position is None:
                c, s = math.cos(pose[2]), math.sin(pose[2])
                track.update(pose[:2] + np.array([c * dx - s * dy, s * dx + c * dy]),
                             wrap_angle(pose[2] + dheading), when)
        self.judge(obs)
        return {name: t.pose(obs.time) for name, t in self.tracks.items()
                if t.position is not None and obs.time - t.time <= self.params.lost_after}

    def judge(self, obs: Observation) -> None:
        """Which teammates of the line have failed (spec §1.4, tau: "before assuming that that robot has ceased to
        function"): one not heard on the radio within tau (``robots_present``) that is also out of sight for
        ``lost_after`` s, or sensed standing for ``dead_after`` s. Standing is asked for too because a robot whose
        radio alone failed still drives; and a robot that hears nobody at all doubts its own radio (§3.2: the
        medium is not assumed), so it judges by sight alone. A failed robot heard, or seen moving, again is back."""
        heard, failed = obs.robots_present, set(self.failed)
        for name in self.line.names:
            since = self.watched.get(name)
            if name == self.name or since is None:
                continue
            track = self.tracks.get(name)
            known = track is not None and track.position is not None
            out_of_sight = obs.time - (track.time if known else since) > self.params.lost_after
            if name in failed:  # back once heard, or seen well away from where it failed (its track, seen
                was = self.failed_at.get(name)  # from a moving robot, drifts by its own pose error)
                if name in heard or (known and not out_of_sight and was is not None
                                     and np.linalg.norm(track.position - was) > self.params.back_move):
                    failed.discard(name)
            elif name not in heard and (out_of_sight or (heard and known
                                                         and track.standing_for >= self.params.dead_after)):
                failed.add(name)
                self.failed_at[name] = track.position.copy() if known and not out_of_sight else None
        if failed != self.failed:
            self.view = replace(self.line, failed=frozenset(failed))
        for name in self.sensing():
            self.watched.setdefault(name, obs.time)

    @property
    def failed(self) -> frozenset:
        return self.view.failed

    def sensing(self) -> tuple[str, ...]:
        """Whom this robot looks for (the mission's ``formation`` signal): whom the line says it senses, re-linked
        past failed teammates, and the failed ones too (a robot standing dead is still there to be seen)."""
        return tuple(dict.fromkeys(self.line.sensed(self.name, self.strategy)
                                   + self.view.sensed(self.name, self.strategy) + tuple(sorted(self.failed))))

    def steer(self, speed: float, bearing: float, drive: DriveParams | None = None) -> tuple[float, float]:
        """(v, omega) for a bearing to steer by, bent away from what the IR sees near (:func:`swerve`): on the spot
        beyond ``turn_in_place``."""
        drive = drive or self.params.drive
        way = np.array([math.cos(bearing), math.sin(bearing)]) + self.push
        bearing = math.atan2(way[1], way[0])
        omega = float(np.clip(drive.turn_gain * bearing, -drive.turn_rate, drive.turn_rate))
        return (0.0 if abs(bearing) > drive.turn_in_place else speed * math.cos(bearing)), omega

    def face(self, pose: np.ndarray, heading: float) -> float:
        """Turn rate towards ``heading`` (goto's turn_to, with no dead band)."""
        return turn_to(pose, heading, self.params.drive, tolerance=0.0) or 0.0

    def follow_leg(self, poses: dict[str, np.ndarray]) -> None:
        """The leader's leg of the route, from the leader's place as sensed (IV's lanes; follow-route's start
        when this robot takes the lead)."""
        lead = self.view.lead(poses)
        if lead is not None:
            self.leg = self.course.leg_of(self.leg, lead[:2], float(lead[2]), self.params.next_leg)

    def hear_progress(self, obs: Observation) -> None:
        """Follow-route's next waypoint, raised to the furthest one a teammate of the line announced: a robot that
        takes the lead, or takes it back with a fresh controller, goes on from there, not from the route's start."""
        for message in obs.inbox:
            payload = message.payload
            if message.sender in self.line.names and isinstance(payload, dict) and "waypoint" in payload:
                near = np.linalg.norm(self.course.points - np.asarray(payload["waypoint"], float), axis=1)
                if near.min() < 1e-6:
                    self.target = max(self.target, int(np.argmin(near)))

    def news(self) -> dict | None:
        """What follow-route broadcasts: the route's waypoint it is making for (strategy III's news)."""
        return {"waypoint": [float(v) for v in self.course.points[self.target]]} if self.announce else None

    def pace(self, poses: dict[str, np.ndarray], pose: np.ndarray) -> float:
        """Share of cruise speed: 1 while every sensed neighbour's shortfall (:meth:`Goal.shortfall`) is within
        lag_slow, 0 at lag_stop."""
        p = self.params
        known = {**poses, self.name: pose}
        news = (self.course.points[self.target - 1], self.course.points[self.target])
        lag = 0.0
        for name in self.view.neighbours(self.name):
            goal = place(self.strategy, self.view, name, known, news, self.lanes, self.leg)
            if goal is not None and name in poses:
                lag = max(lag, goal.shortfall(poses[name][:2]))
        return float(np.clip((p.lag_stop - lag) / max(p.lag_stop - p.lag_slow, 1e-6), 0.0, 1.0))

    def follow_route(self, obs: Observation, pose: np.ndarray, poses: dict[str, np.ndarray]) -> Command:
        """follow-route under avoid-obstacles: through ``route``'s waypoints from ``target``, announcing each,
        at ``cruise`` scaled down while a neighbour is far from its place (:meth:`pace`); it holds at the last
        waypoint, facing the last leg's way."""
        broadcast = self.news()
        evade = self.avoid(obs)
        if evade is not None:
            return Command(*evade, behaviour="avoid-obstacles", broadcast=broadcast)
        self.push = swerve(obs, self.params)
        self.follow_leg({**poses, self.name: pose})
        share = self.pace(poses, pose)
        last = self.target == len(self.route) - 1
        drive = replace(self.params.drive, cruise=self.params.cruise * share,
                        turn_rate=self.params.drive.turn_rate * max(share, 0.2),
                        slow_radius=0.4 if last else self.params.drive.slow_radius)
        command = steer_to(pose, self.route[self.target], drive, self.params.arrive)
        while command is None and not last:
            self.target += 1
            last = self.target == len(self.route) - 1
            broadcast = self.news()
            command = steer_to(pose, self.route[self.target], drive, self.params.arrive)
        if command is None:  # at the last waypoint: face the last leg's way, where the line is laid across
            if self.finished_at is None:
                self.finished_at = obs.time
            way = self.route[-1] - self.route[-2]
            turn = turn_to(pose, math.atan2(way[1], way[0]), self.params.drive, tolerance=0.02)
            return Command(0.0, turn or 0.0, behaviour="hold", broadcast=broadcast)
        if np.any(self.push):  # something near: the same way bent round it (steer_to's law otherwise)
            way = self.route[self.target] - pose[:2]
            speed = drive.cruise * min(1.0, float(np.linalg.norm(way)) / drive.slow_radius)
            command = self.steer(speed, wrap_angle(math.atan2(way[1], way[0]) - pose[2]), drive)
        return Command(*command, behaviour="follow-route", broadcast=broadcast)


class KeepFormation(FormationRobot):
    """A follower: KEEP_FORMATION by its strategy, under avoid-obstacles. Strategy III listens for the leader's
    announced waypoint (``{"waypoint": [x, y]}`` riding on its broadcasts). Once the leader has failed and this
    robot is the living one nearest the leader's place (:attr:`Line.acting`), it takes over follow-route
    (ALLIANCE, spec §1: a capable teammate takes over a failed robot's task) along its own lane: the route offset
    by its place, corners mitred, so that every place, the leader's empty one too, stays where it was."""

    def __init__(self, robot: RobotModel, line: Line, strategy: str, params: KeepFormationParams,
                 rng: np.random.Generator, route: np.ndarray):
        super().__init__(robot, line, strategy, params, rng, route)
        self.news_heard: tuple | None = None  # (where the leader was, the waypoint it announced there)

    def __call__(self, obs: Observation) -> Command:
        pose = self.estimate.update(obs)
        if pose is None:
            return Command(behaviour="keep-formation")
        poses = self.sense(obs, pose)
        self.hear_progress(obs)
        if self.view.acting == self.name:
            return self.take_lead(obs, pose, poses)
        self.listen(obs, poses)
        evade = self.avoid(obs)
        if evade is not None:
            return Command(*evade, behaviour="avoid-obstacles")
        self.push = swerve(obs, self.params)
        self.follow_leg(poses)
        goal = place(self.strategy, self.view, self.name, poses, self.news_heard, self.lanes, self.leg)
        if goal is None:
            return Command(behaviour="keep-formation")
        pace = self.tracks[goal.pace_of].speed if goal.pace_of is not None else 0.0
        drive = self.keep_lane if goal.lane else self.make_for
        return Command(*drive(pose, goal, pace), behaviour="keep-formation")

    def take_lead(self, obs: Observation, pose: np.ndarray, poses: dict[str, np.ndarray]) -> Command:
        """follow-route along this robot's lane, from the waypoint the leader last announced or, if further, the
        one after the leg it was last sensed on."""
        if self.route is None:
            self.route = self.course.lane(self.line.offset(self.name))
            self.target = min(max(self.target, self.leg + 1), len(self.route) - 1)
        return self.follow_route(obs, pose, poses)

    def listen(self, obs: Observation, poses: dict[str, np.ndarray]) -> None:
        """Strategy III's news: a waypoint the leader announces, with where the leader is as it is heard."""
        acting = self.view.acting
        lead = self.view.lead(poses)
        for message in obs.inbox:
            payload = message.payload
            if message.sender == acting and isinstance(payload, dict) and "waypoint" in payload \
                    and lead is not None:
                waypoint = tuple(float(v) for v in payload["waypoint"])
                if self.news_heard is None or self.news_heard[1] != waypoint:
                    self.news_heard = (tuple(lead[:2]), waypoint)

    def make_for(self, pose: np.ndarray, goal: Goal, pace: float) -> tuple[float, float]:
        """I and II: towards the place at ``pace`` (the speed it moves at) along the line's heading plus a pull to
        it. A place a little behind is backed into, facing the line's heading, rather than turned round to."""
        p = self.params
        error = goal.point - pose[:2]
        wanted = pace * np.array([math.cos(goal.heading), math.sin(goal.heading)]) + p.pull * error
        speed = min(float(np.linalg.norm(wanted)), p.catch_up)
        if np.linalg.norm(error) < p.settle and pace < p.still:
            return 0.0, self.face(pose, goal.heading)
        bearing = wrap_angle(math.atan2(wanted[1], wanted[0]) - pose[2])
        if abs(bearing) > math.pi / 2 and np.linalg.norm(error) < p.back_within:
            return speed * math.cos(bearing), self.face(pose, goal.heading)
        return self.steer(speed, bearing)

    def keep_lane(self, pose: np.ndarray, goal: Goal, pace: float) -> tuple[float, float]:
        """III and IV (§7.2: "aim toward the waypoint and moderate speed to stay aligned"): steer for a point on
        the lane ``lookahead`` ahead of abreast of the robot (abreast, while ahead of its place), at ``pace``
        plus a pull by the lag along the lane, never backwards while the place moves. A robot ahead of its place
        only closes on its lane, at a speed by its distance from it, then waits there facing the lane's way; once
        the place stands still (the line stopped short of it), it goes back to it as I and II do."""
        p = self.params
        way = np.array([math.cos(goal.heading), math.sin(goal.heading)])
        lag = goal.lag(pose[:2])
        if pace < p.still and lag < -p.settle:  # the line has stopped short of it (the route's end): go back
            return self.make_for(pose, goal, pace)
        aside = goal.aside(pose[:2])
        speed = float(np.clip(pace + p.pull * lag, 0.0, p.catch_up))
        if aside > p.settle:
            speed = max(speed, min(p.pull * aside, p.catch_up))
        if speed < 0.02:
            return 0.0, self.face(pose, goal.heading)
        ahead = p.lookahead if lag > 0 else 0.0  # ahead of its place: straight across to its lane, no further on
        aim = goal.point + (float(np.dot(pose[:2] - goal.point, way)) + ahead) * way
        return self.steer(speed, wrap_angle(math.atan2(aim[1] - pose[1], aim[0] - pose[0]) - pose[2]))

class RouteLeader(FormationRobot):
    """The group leader: follow-route through the waypoints (:meth:`FormationRobot.follow_route`), announcing each
    new one (strategy III's news), waiting for its neighbours (re-linked past failed ones). With no line (``line``
    of itself alone) it is a plain route follower (:class:`Crossing` drives one)."""

    def __init__(self, robot: RobotModel, line: Line, strategy: str, params: KeepFormationParams,
                 rng: np.random.Generator, route: np.ndarray, announce: bool = True):
        super().__init__(robot, line, strategy, params, rng, route)
        self.route = np.asarray(route, float)
        self.announce = announce

    def __call__(self, obs: Observation) -> Command:
        self.hear_progress(obs)  # a teammate led while it was down (a fresh controller after a revive)
        pose = self.estimate.update(obs)
        if pose is None:
            return Command(behaviour="follow-route", broadcast=self.news())
        return self.follow_route(obs, pose, self.sense(obs, pose))


class Crossing:
    """A robot of the second team that crosses the line's route: it sets off at ``start_at`` and drives its own
    route (``driver``, a route leader with no line), giving way: while its front IR sees something nearer than
    ``give_way`` it stops, for at most ``give_way_for`` s, before going on under avoid-obstacles. (Two robots
    avoiding each other with the same manoeuvre can meet again and again; one that waits breaks the tie.)"""

    def __init__(self, driver: RouteLeader, robot: RobotModel, start_at: float):
        self.driver, self.start_at, self.params = driver, start_at, driver.params
        self.front = np.abs(np.asarray(robot.ir_bearings)) < math.radians(60)
        self.blocked_since: float | None = None

    def __call__(self, obs: Observation) -> Command:
        blocked = bool(np.any(obs.ir_range[self.front] < self.params.give_way))
        self.blocked_since = (self.blocked_since if self.blocked_since is not None else obs.time) if blocked else None
        if obs.time < self.start_at or (blocked and obs.time - self.blocked_since < self.params.give_way_for):
            self.driver.estimate.update(obs)  # it keeps its pose estimate while it waits
            return Command(behaviour="wait" if obs.time < self.start_at else "give-way")
        return self.driver(obs)
