"""The hazardous-waste cleanup behaviour sets of Parker's R-2s (§3.8.1, Figs 3-4 to 3-8; spec §4.1).

Every robot carries :class:`CleanupKnowledge`: what it believes about the mission (its home by the entrance, the
room's extents, the spill and goal locations, when the team last reported, when the spill was last found
empty), built from its own sensing and from teammates' broadcasts. The behaviour sets' sensory feedback is read from it:

- find-initial-final-locations (task ``find-locations``): applicable while the locations are unknown. Two
  versions: *methodical* (Fig. 3-5, :class:`FindMethodical`) follows the walls with the side IR, keeping the
  wall on the right, until back home; *wander* (Fig. 3-6, :class:`FindWander`) drives west, north, east and
  south for a fixed time each. Both track the extremes of the robot's position and compute the centre of the
  front third of the room (the spill) and the back centre (the goal) from them (:func:`locations_from_extents`).
- move-spill (Fig. 3-7, :class:`MoveSpill`): applicable while the locations are known and the robot believes
  pucks remain. One activation moves one load: go to the spill, sweep straight lines through it scanning with
  the fingertip IR (a front bump stops the line, backs off and looks round), zero in, grasp and lift, carry to
  the goal, lower and release. Its feedback falls for one control period after each delivery (the load is
  moved), so the robot chooses afresh: that is when report-progress, if due, can win (ch.5: "the only time a
  robot tries to initiate the report-progress task is after it has completed the transport of a spill object").
  A report that falls due while the robot sweeps the spill in vain wins too: on an exhausted spill it would
  otherwise never come (:attr:`MoveSpill.searching_in_vain`).
- report-progress (Fig. 3-8, :class:`ReportProgress`): applicable when a report is due (``report_interval``
  since the last report this robot knows of) and it has delivered since. It drives to the entrance and reports,
  by radio, which satisfies its teammates.

The robot that finds the locations broadcasts them (the virtual sensor of §3.8.2), and every broadcast also
carries the last report time and when the spill was found empty (that belief lapses after ``empty_rest``). With
the radio off nothing is shared, so every capable robot finds the locations and reports for itself (ch.5's "no
awareness").

The avoid-obstacles layer (:class:`teamsim.controllers.skills.goto.AvoidObstacles`) runs under every set except while
move-spill sweeps and picks up (Fig. 3-4). Constants the thesis does not give are in :class:`CleanupParams`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from teamsim.config import setting
from teamsim.controllers.alliance.lalliance import TaskStatistics
from teamsim.controllers.alliance.learned_acquiescence import LearnedAcquiescence, LearningParams
from teamsim.controllers.alliance.motivation import (AllianceController, AllianceParams, AllianceRobot,
                                                     BehaviourSetDefinition, MotivationRates)
from teamsim.controllers.base import Command, Observation
from teamsim.controllers.skills import gripper as G
from teamsim.controllers.skills.goto import AvoidObstacles, DriveParams, Unstick, steer_to, turn_to
from teamsim.controllers.skills.pose_estimate import PoseEstimate
from teamsim.models.r2 import TIP_IR
from teamsim.models.robot import RobotModel
from teamsim.positioning import wrap_angle

FIND, MOVE, REPORT = "find-locations", "move-spill", "report-progress"
METHODICAL, WANDER = "find-locations-methodical", "find-locations-wander"
RIGHT_SIDE_IR = ("ir_right_front", "ir_right_rear")
JAW_AHEAD = 0.13  # m from the R-2's axle to the middle of its jaw


@dataclass(frozen=True)
class CleanupParams:
    """Assumed constants of the cleanup behaviours (Parker names the behaviours, not their numbers)."""
    report_interval: float = setting(240.0, lo=1.0, meaning="s between team progress reports ('about every 4 "
                                                            "minutes', §3.8)")
    wall_distance: float = 0.12  # m from the side IR to the wall while wall-following
    wall_ahead: float = 0.22  # m: a fingertip reading nearer than this is a wall (or robot) ahead: turn left
    follow_speed: float = 0.25  # m/s
    home_leave: float = 2.0  # m: wall-following ends back within home_return of home after going this far
    home_return: float = 0.8
    # s of curving right without the wall before it is sought again straight ahead to the right: a full circle
    # at the lost-wall curve takes 7 s, and a robot pushed 0.4 m off the wall circled on the spot for 1800 s
    wall_lost_time: float = 8.0
    # find-wander (see FindWander): m of progress along each compass direction (more than the 7.9 m room is long),
    # and at most wander_leg_limit s per direction in all. A leg cut short puts the room's end where the robot
    # stood: a wall-following teammate held a wanderer back for up to 86 s (radio off, seeds 108 and 121), so the
    # limit is twice that (docs/decisions.md, "Wander find")
    wander_leg: float = 9.0
    wander_leg_limit: float = 180.0
    # Blocked for wander_patience during a leg (a teammate driving the same way moves on first), find-wander steps
    # wander_sidestep to its right and carries on: a wall stays in the way, a robot is passed (a teammate switched
    # off by the wall ended the leg there and put the goal 1.3 m short). Right is away from the previous leg's
    # wall, the legs turning right each time. Blocked after wander_sidesteps sidesteps, the leg is at a wall.
    wander_patience: float = 3.0
    wander_sidestep: float = 0.5
    wander_sidesteps: int = 2
    # sidesteps blocked before half their length that do not count, per leg: a teammate beside the robot boxes it
    # in until it moves (kill-red seed 191: green took dead red for the east wall with blue beside it); in a corner
    # the wall beside it stays, and after these the sidesteps count again
    wander_boxed: int = 4
    # m: blocked further than this along the leg from where it was first blocked, what blocks it has moved (a
    # teammate), and the sidesteps count afresh: a wall is met at the same place (docs/decisions.md, "Wander find")
    wall_stays: float = 0.2
    spill_vicinity: float = 1.0  # m from the believed spill centre where sweeping starts
    spill_radius: float = 0.6  # m: sweep lines pass within this of the believed spill centre
    sweep_overshoot: float = 0.6  # m a sweep line runs past its random point
    sweep_speed: float = 0.2  # m/s while scanning: 2 cm per control period
    # A sweep that bumps something with the front bumper (a puck beside the jaw, which neither the fingertips nor
    # the beams see) backs off bump_backoff m and turns look_angle rad each way at look_rate rad/s scanning with
    # the fingertips: 3 cm per tick past a puck 0.27 m ahead (docs/decisions.md, "Pucks on the bumper")
    bump_backoff: float = 0.2
    look_angle: float = 0.5
    look_rate: float = 0.5
    widen_every: int = 4  # empty sweep lines
    hint_lines: int = 4  # empty sweep lines around where it last had a puck before it searches the spill again
    # consecutive sweep lines without a puck: the spill is gone. By the 32nd the area has widened to 5.4 m, the whole
    # room: with 16 (3 m) a team stopped with 5 pucks at the goal and one 0.5 m from the spill (kill-red seed 5)
    empty_lines: int = 32
    # s a spill-empty belief holds before the robots look again. Held for good, a team that found nothing in 32
    # lines at 1000 s with 7 pucks home waited out the mission while idle robots parked by two of the pucks
    empty_rest: float = 120.0
    goal_spread: float = 0.25  # m: deliveries land this far either side of the believed goal
    # m: pucks this near the believed goal are never searched for (they are delivered). Delivered pucks were
    # measured up to 0.8 m from it; with 1.5 m, pucks pushed just out of the goal zone by robots arriving to
    # deliver (0.9-1.3 m from it) were never searched for and two missions ended 1-2 pucks short
    goal_keepout: float = 0.9
    goal_clearance: float = 0.45  # m: the drop point stands this far in from the goal-side extent
    arrive: float = 0.2  # m: a waypoint is reached within this
    lane_offset: float = 0.5  # m to the right of the direct line while travelling (keep right)
    lane_merge: float = 1.0  # m: the lane merges into the direct line within this of the target
    entrance_arrive: float = 0.5  # m: close enough to the entrance to report from
    drive: DriveParams = field(default_factory=DriveParams)
    # An approach ends within 12 s: 0.3 m of IR range at 6 cm/s plus the blind 4 s; longer means the fingertips
    # saw a robot (Parker's R-2s also took each other's fingers for pucks, §3.8.4).
    gripper: G.GripperParams = field(default_factory=lambda: G.GripperParams(approach_timeout=12.0))
    # move-spill may learn from its own loads (L-ALLIANCE's failure penalty; off by default): then a robot whose
    # gripper breaks gives it up
    learning: LearningParams = field(default_factory=LearningParams)


def locations_from_extents(extents: np.ndarray, home: np.ndarray, clearance: float) -> dict:
    """Spill, goal and entrance from the extremes (xmin, xmax, ymin, ymax) a robot reached, §3.8.1.

    The entrance wall is the one nearest home (the robots start at the entrance). The spill is the centre of
    the third of the room nearest it; the goal is the centre of the opposite wall, ``clearance`` in from the
    extreme so a robot can stand there; the entrance is the middle of the entrance-side extreme."""
    xmin, xmax, ymin, ymax = extents
    gaps = np.array([home[0] - xmin, xmax - home[0], home[1] - ymin, ymax - home[1]])
    wall = int(np.argmin(gaps))
    axis, sign = wall // 2, (1.0 if wall % 2 == 0 else -1.0)  # +1: the room extends in +axis from the entrance
    low, high = extents[2 * axis], extents[2 * axis + 1]
    near, far = (low, high) if sign > 0 else (high, low)
    other = 0.5 * (extents[2 * (1 - axis)] + extents[2 * (1 - axis) + 1])

    def point(along: float) -> tuple[float, float]:
        return (along, other) if axis == 0 else (other, along)

    return {"spill": point(near + sign * (high - low) / 6), "goal": point(far - sign * clearance),
            "entrance": point(near), "extents": tuple(float(e) for e in extents)}


@dataclass
class CleanupKnowledge:
    """One robot's beliefs about the mission, and its own tallies (transports, reports)."""
    report_interval: float
    empty_rest: float = CleanupParams.empty_rest
    home: np.ndarray | None = None
    spill: tuple | None = None
    goal: tuple | None = None
    entrance: tuple | None = None
    extents: tuple | None = None  # (xmin, xmax, ymin, ymax) the finder reached: where a robot can be in the room
    last_report: float = 0.0  # the mission's start counts as a report
    delivered_since_report: bool = False
    just_delivered: bool = False
    emptied_at: float | None = None  # when this robot, or a teammate it heard, last found the spill empty
    hint: tuple | None = None  # where this robot last had a puck: the next search starts there
    transports: int = 0
    reports: int = 0

    @property
    def located(self) -> bool:
        return self.goal is not None

    def spill_empty(self, now: float) -> bool:
        return self.emptied_at is not None and now - self.emptied_at < self.empty_rest

    def found_empty(self, now: float) -> None:
        self.emptied_at = now

    def learn_locations(self, locations: dict) -> None:
        if not self.located:
            self.spill, self.goal, self.entrance, self.extents = (
                tuple(locations[k]) for k in ("spill", "goal", "entrance", "extents"))

    def hear(self, payload) -> None:
        """Merge a teammate's broadcast."""
        if not isinstance(payload, dict):
            return
        if "goal" in payload:
            self.learn_locations(payload)
        if payload.get("report", -math.inf) > self.last_report:
            self.last_report = payload["report"]
            self.delivered_since_report = False
        heard = payload.get("emptied_at")
        if heard is not None and (self.emptied_at is None or heard > self.emptied_at):
            self.emptied_at = heard

    def message(self) -> dict:
        """What this robot tells its teammates in every broadcast."""
        shared = {"report": self.last_report, "emptied_at": self.emptied_at}
        if self.located:
            shared.update(spill=self.spill, goal=self.goal, entrance=self.entrance, extents=self.extents)
        return shared

    def delivered(self) -> None:
        self.transports += 1
        self.delivered_since_report = self.just_delivered = True

    def reported(self, now: float) -> None:
        self.reports += 1
        self.last_report = now
        self.delivered_since_report = False

    def report_due(self, now: float) -> bool:
        return self.delivered_since_report and now - self.last_report >= self.report_interval


class SetController:
    """A behaviour set's competence layers: ``__call__`` on the robot's observation and pose estimate while the
    set is active; ``restart`` when it stops being active, so the next activation begins afresh."""
    name = ""

    def __init__(self, knowledge: CleanupKnowledge, estimate: PoseEstimate, avoid: AvoidObstacles,
                 params: CleanupParams):
        self.knowledge, self.estimate, self.avoid, self.params = knowledge, estimate, avoid, params

    def restart(self) -> None:
        pass

    def drive(self, v: float = 0.0, omega: float = 0.0, **extras) -> Command:
        return Command(v=v, omega=omega, behaviour=self.name, extras={"grip": G.OPEN, "lift": G.DOWN, **extras})

    def go(self, obs: Observation, target, arrive: float) -> Command | None:
        """One step of go-to-point under avoid-obstacles; None on arrival."""
        evasion = self.avoid(obs)
        if evasion is not None:
            return self.drive(*evasion)
        step = steer_to(self.estimate.pose, self.lane(target), self.params.drive, arrive)
        return None if step is None else self.drive(*step)

    def lane(self, target) -> np.ndarray:
        """Keep right: far from ``target``, aim ``lane_offset`` to the right of it, so robots travelling in
        opposite directions between the same places pass each other instead of meeting head on."""
        p, here = self.params, self.estimate.pose[:2]
        ahead = np.asarray(target, float) - here
        distance = float(np.hypot(*ahead))
        if distance <= p.lane_merge:
            return np.asarray(target, float)
        right = np.array([ahead[1], -ahead[0]]) / distance
        return np.asarray(target, float) + right * p.lane_offset * min(1.0, (distance - p.lane_merge) / p.lane_merge)


class ExtentTracker(SetController):
    """Shared by both find versions: track the extremes of the robot's position, then compute the locations."""

    def restart(self) -> None:
        self.extents = None

    def track(self) -> None:
        x, y = self.estimate.pose[:2]
        if getattr(self, "extents", None) is None:
            self.extents = np.array([x, x, y, y])
        self.extents = np.array([min(self.extents[0], x), max(self.extents[1], x),
                                 min(self.extents[2], y), max(self.extents[3], y)])

    def conclude(self) -> Command:
        self.knowledge.learn_locations(locations_from_extents(self.extents, self.knowledge.home,
                                                              self.params.goal_clearance))
        return self.drive()


class FindMethodical(ExtentTracker):
    """Fig. 3-5: wall-follow with the right-side IR, wall on the right, from home until back home."""
    name = METHODICAL

    def __init__(self, robot: RobotModel, *args):
        super().__init__(*args)
        self.side = [robot.ir_sensors.index(n) for n in RIGHT_SIDE_IR]
        self.tips = [robot.ir_sensors.index(n) for n in TIP_IR]
        self.restart()

    def restart(self) -> None:
        super().restart()
        self.found_wall = False
        self.far_from_home = False
        self.seek_heading = -math.pi / 2  # the first wall is sought to the south
        self.wall_lost: tuple | None = None  # (time, heading) when the side IR last lost the wall

    def __call__(self, obs: Observation) -> Command:
        p, home = self.params, self.knowledge.home
        self.track()
        distance_home = float(np.hypot(*(self.estimate.pose[:2] - home)))
        self.far_from_home |= distance_home > p.home_leave
        if self.far_from_home and distance_home < p.home_return:
            return self.conclude()
        ahead = min(obs.ir_range[self.tips])
        front, rear = obs.ir_range[self.side]
        if ahead < p.wall_ahead:
            self.found_wall, self.wall_lost = True, None
            return self.drive(0.0, p.drive.turn_rate)  # a corner (or a robot): turn left
        if not self.found_wall:
            omega = turn_to(self.estimate.pose, self.seek_heading, p.drive)
            return self.drive(0.0 if omega else p.follow_speed, omega or 0.0)
        if not (np.isfinite(front) or np.isfinite(rear)):
            return self._lost_wall(obs.time)
        self.wall_lost = None
        nearest = min(front, rear)
        omega = -3.0 * (nearest - p.wall_distance)
        if np.isfinite(front) and np.isfinite(rear):
            omega -= 4.0 * (front - rear)
        return self.drive(p.follow_speed, float(np.clip(omega, -p.drive.turn_rate, p.drive.turn_rate)))

    def _lost_wall(self, now: float) -> Command:
        """Curve right round the corner the wall turned; if no wall comes back within ``wall_lost_time`` (the
        robot was pushed off it), seek it straight ahead in the direction it was in when lost: to the right."""
        p = self.params
        if self.wall_lost is None:
            self.wall_lost = (now, float(self.estimate.pose[2]))
        if now - self.wall_lost[0] >= p.wall_lost_time:
            self.found_wall, self.seek_heading = False, self.wall_lost[1] - math.pi / 2
            self.wall_lost = None
            return self.drive()
        return self.drive(0.5 * p.follow_speed, -0.6 * p.drive.turn_rate)


class FindWander(ExtentTracker):
    """Fig. 3-6: drive west, north, east and south in turn, tracking the extremes reached.

    Parker gives each direction "a fixed time period". Here a leg ends after ``wander_leg`` m of progress along
    its heading (more than the room is long), so time lost to teammates in the way or pushing against them does
    not cut a leg short and put the goal short of the goal zone (measured: three robots wandering from the
    entrance at once, radio off). A leg also ends at a wall: blocked for ``wander_patience`` it sidesteps to its
    right and carries on, up to ``wander_sidesteps`` times; blocked once more at the same place along the leg, what
    is ahead is the room's extent. A robot in the way is passed or moves on, a wall stays. No leg lasts more than
    ``wander_leg_limit`` s."""
    name = WANDER
    HEADINGS = (math.pi, math.pi / 2, 0.0, -math.pi / 2)

    def __init__(self, robot: RobotModel, *args):
        super().__init__(*args)
        self.tips = [robot.ir_sensors.index(n) for n in TIP_IR]
        self.restart()

    def restart(self) -> None:
        super().restart()
        self.leg = 0
        self.leg_began: float | None = None
        self.leg_from: np.ndarray | None = None  # where this leg began
        self.sidesteps = 0
        self.boxed = 0  # sidesteps this leg that were blocked at once and did not count
        self.sidestep_from: np.ndarray | None = None  # where the current sidestep began
        self.blocked_since: float | None = None
        self.wall_at = 0.0  # how far along the leg's heading it was first blocked (since the sidesteps began)

    def next_leg(self, now: float) -> None:
        self.leg += 1
        self.leg_began, self.leg_from = now, self.estimate.pose[:2].copy()
        self.sidesteps, self.sidestep_from, self.blocked_since, self.boxed = 0, None, None, 0

    def __call__(self, obs: Observation) -> Command:
        p = self.params
        if self.leg_began is None:
            self.leg_began, self.leg_from = obs.time, self.estimate.pose[:2].copy()
        self.track()
        if self.leg < len(self.HEADINGS) and (self._progress() >= p.wander_leg
                                              or obs.time - self.leg_began >= p.wander_leg_limit):
            self.next_leg(obs.time)
        if self.leg >= len(self.HEADINGS):
            return self.conclude()
        heading = self.HEADINGS[self.leg]
        blocked = min(obs.ir_range[self.tips]) < p.wall_ahead or obs.touch.get("bump_front", 0.0) >= p.drive.bump_force
        if self.sidestep_from is not None:
            return self._sidestep(heading - math.pi / 2, blocked)
        omega = turn_to(self.estimate.pose, heading, p.drive)
        if omega is not None:
            return self.drive(0.0, omega)
        if not blocked:
            self.blocked_since = None
            return self.drive(p.drive.cruise)
        if self.blocked_since is None:
            self.blocked_since = obs.time
        if obs.time - self.blocked_since >= p.wander_patience:
            along = float(np.dot(self.estimate.pose[:2], (math.cos(heading), math.sin(heading))))
            if self.sidesteps and abs(along - self.wall_at) > p.wall_stays:
                self.sidesteps = 0  # not where it was blocked before: that was a teammate, which moved on
            if self.sidesteps == 0:
                self.wall_at = along
            if self.sidesteps < p.wander_sidesteps:
                self.sidesteps += 1
                self.sidestep_from, self.blocked_since = self.estimate.pose[:2].copy(), None
            else:
                self.next_leg(obs.time)  # a wall
        return self.drive()

    def _progress(self) -> float:
        """m made good along this leg's heading since it began."""
        heading = self.HEADINGS[self.leg]
        return float(np.dot(self.estimate.pose[:2] - self.leg_from, (math.cos(heading), math.sin(heading))))

    def _sidestep(self, heading: float, blocked: bool) -> Command:
        """Turn right and drive ``wander_sidestep`` (or until blocked); then the leg's heading is taken again."""
        p = self.params
        omega = turn_to(self.estimate.pose, heading, p.drive)
        if omega is not None:
            return self.drive(0.0, omega)
        stepped = float(np.hypot(*(self.estimate.pose[:2] - self.sidestep_from)))
        if blocked or stepped >= p.wander_sidestep:
            if stepped < p.wander_sidestep / 2 and self.boxed < p.wander_boxed:
                self.sidesteps -= 1  # boxed in, a teammate beside it (or a corner): the way past was not tried
                self.boxed += 1
            self.sidestep_from = None
            return self.drive()
        return self.drive(p.drive.cruise)


class MoveSpill(SetController):
    """Fig. 3-7: move one load from the spill to the goal, with the gripper behaviours of
    :mod:`teamsim.controllers.skills.gripper`; avoid-obstacles is off while sweeping and picking up."""
    name = MOVE
    LINE_DRAWS = 20  # tries for a sweep line's point inside the room: the area is never mostly outside it

    def __init__(self, robot: RobotModel, rng: np.random.Generator, *args):
        super().__init__(*args)
        self.sensors = G.GripperSensors.of(robot)
        self.rng = rng
        self.restart()

    def restart(self) -> None:
        self.state = "to_spill"
        self.line: tuple | None = None  # (heading, length, time scanning began or None while turning)
        self.looks: list[float] = []  # headings still to turn to while looking round a bump
        self.backing_since = 0.0
        self.empty_lines = 0
        self.step: G.Sequence | None = None
        self.drop_point: tuple | None = None

    def __call__(self, obs: Observation) -> Command:
        handler = getattr(self, f"_{self.state}")
        return handler(obs)

    @property
    def searching_in_vain(self) -> bool:
        """Sweeping the spill with no load, after a line that found nothing: a report that falls due now wins
        (docs/decisions.md, "A due report interrupts a fruitless search")."""
        return self.state in ("to_spill", "sweep", "back_off", "look") and self.empty_lines > 0

    def _to_spill(self, obs: Observation) -> Command:
        command = self.go(obs, self._search_centre(), self.params.spill_vicinity)
        if command is not None:
            return command
        self.state = "sweep"
        return self._sweep(obs)

    def _sweep(self, obs: Observation) -> Command:
        """"Wander in a straight line" through the spill area (Fig. 3-7 step 2): face a random point of it,
        then drive straight past it, scanning with the fingertip IR; avoid-obstacles is off."""
        p = self.params
        if np.hypot(*(self.estimate.pose[:2] - self._search_centre())) > p.spill_vicinity + self._reach():
            self.state, self.line = "to_spill", None  # a failed pick-up can leave it far off
            return self._to_spill(obs)
        if self.line is None:
            self.line = self._new_line()
        heading, length, scanning_since = self.line
        if scanning_since is None:
            omega = turn_to(self.estimate.pose, heading, p.drive, tolerance=0.05)
            if omega is not None:
                return self.drive(0.0, omega)
            self.line = (heading, length, obs.time)
            return self.drive()
        if self._sees_something(obs):
            self.line = None
            return self._begin_pick(obs)
        if obs.touch.get("bump_front", 0.0) >= p.drive.bump_force:  # pushing what it cannot see: stop
            self.line, self.state, self.backing_since = None, "back_off", obs.time
            return self._back_off(obs)
        if obs.time - scanning_since > length / p.sweep_speed:
            self.line = None
            self._nothing_found(obs.time)
            return self.drive(-p.sweep_speed)
        return self.drive(p.sweep_speed)

    def _sees_something(self, obs: Observation) -> bool:
        """Something ahead of the jaw (a fingertip reading), or already in it (a beam broken)."""
        seen = np.isfinite(obs.ir_range[[self.sensors.tip_left, self.sensors.tip_right]]).any()
        return bool(seen or any(self.sensors.beams(obs)))

    def _begin_pick(self, obs: Observation) -> Command:
        g = self.sensors, self.params.gripper
        return self._begin("pick", [G.Approach(*g), G.Grasp(*g), G.Lift(*g)], obs)

    def _back_off(self, obs: Observation) -> Command:
        """Reverse off what the bumper met, then look round for it (:meth:`_look`). Left on the bumper, a puck
        beside the jaw was pushed 1-2 m into the entrance wall, out of the search's reach (docs/decisions.md,
        "Pucks on the bumper")."""
        p = self.params
        if obs.time - self.backing_since < p.bump_backoff / p.sweep_speed:
            return self.drive(-p.sweep_speed)
        heading = self.estimate.pose[2]
        self.state, self.looks = "look", [heading + p.look_angle, heading - p.look_angle, heading]
        return self._look(obs)

    def _look(self, obs: Observation) -> Command:
        """Turn to each of ``looks`` in turn, scanning with the fingertips; a sighting starts a pick-up."""
        if self._sees_something(obs):
            return self._begin_pick(obs)
        while self.looks:
            error = wrap_angle(self.looks[0] - self.estimate.pose[2])
            if abs(error) > 0.05:
                return self.drive(0.0, math.copysign(self.params.look_rate, error))
            self.looks.pop(0)
        self.state = "sweep"
        self._nothing_found(obs.time)
        return self.drive()

    def _nothing_found(self, now: float) -> None:
        """A sweep line brought no puck: it ran its length, or what the fingertips saw could not be picked up (a
        wall, a teammate, a puck the jaw missed). Counting only the first kind, three robots seeing each other
        round the spill never widened the search, and three pucks pushed 3-4 m down the carry lane were never
        found (seed 3, 3 robots, no fault: 7 pucks home by 480 s and no more in 1800 s)."""
        p = self.params
        self.empty_lines += 1
        if self.knowledge.hint is not None and self.empty_lines >= p.hint_lines:
            self.knowledge.hint, self.empty_lines = None, 0  # nothing left there: back to the spill
        elif self.empty_lines >= p.empty_lines:
            self.knowledge.found_empty(now)

    def _new_line(self) -> tuple:
        """(heading, length, None): through a random point near the search centre, and ``sweep_overshoot``
        beyond it. The area widens by ``spill_radius`` every ``widen_every`` lines that find nothing. The point
        is drawn again (up to ``LINE_DRAWS`` times) while it lies outside the room or among the delivered pucks
        (:meth:`_searchable`): widened past the room's width, most of the area is beyond the walls."""
        p = self.params
        for _ in range(self.LINE_DRAWS):
            radius, bearing = self._reach() * math.sqrt(self.rng.random()), self.rng.uniform(-math.pi, math.pi)
            point = np.asarray(self._search_centre()) + radius * np.array([math.cos(bearing), math.sin(bearing)])
            if self._searchable(point):
                break
        dx, dy = point - self.estimate.pose[:2]
        return math.atan2(dy, dx), math.hypot(dx, dy) + p.sweep_overshoot, None

    def _searchable(self, point: np.ndarray) -> bool:
        """Within the extents the finder reached (the room, less the robot's own clearance) and not at the
        goal."""
        xmin, xmax, ymin, ymax = self.knowledge.extents
        inside = xmin <= point[0] <= xmax and ymin <= point[1] <= ymax
        return inside and not self._at_goal(point)

    def _at_goal(self, point) -> bool:
        """Within ``goal_keepout`` of the believed goal, where the delivered pucks lie."""
        return math.dist(point, self.knowledge.goal) <= self.params.goal_keepout

    def _reach(self) -> float:
        """Radius of the search area: pucks get pushed about, so it widens as lines find nothing. (The robot may
        sweep out to it: with the area's first radius as the limit, lines towards a widened edge were cut short
        and pucks pushed 2-3 m off the spill were never found.)"""
        p = self.params
        return p.spill_radius * (1.0 + self.empty_lines / p.widen_every)

    def _begin(self, state: str, behaviours: list, obs: Observation) -> Command:
        self.state, self.step = state, G.Sequence(behaviours)
        return getattr(self, f"_{state}")(obs)

    def _pick(self, obs: Observation) -> Command:
        command = self.step(obs)
        if self.step.status == G.FAILED:
            self._nothing_found(obs.time)
            return self._begin("recover", [G.Release(self.sensors, self.params.gripper)], obs)
        if self.step.status == G.SUCCEEDED:
            # Pucks get pushed about: look for the next one where this one was (the jaw is ahead of the pose).
            self.knowledge.hint = self._jaw_position()
            goal = np.asarray(self.knowledge.goal)
            self.drop_point = tuple(goal + self._across_goal() * self.rng.uniform(-1, 1) * self.params.goal_spread)
            return self._begin("carry", [G.Carry(self.sensors, self._route_to_goal, self.params.gripper)], obs)
        return replace(command, behaviour=self.name)

    def _jaw_position(self) -> tuple[float, float]:
        x, y, heading = self.estimate.pose
        return x + JAW_AHEAD * math.cos(heading), y + JAW_AHEAD * math.sin(heading)

    def _search_centre(self) -> tuple:
        return self.knowledge.hint or self.knowledge.spill

    def _across_goal(self) -> np.ndarray:
        """Unit vector along the goal wall (across the room's long axis)."""
        k = self.knowledge
        along = np.asarray(k.goal) - np.asarray(k.entrance)
        return np.array([-along[1], along[0]]) / max(np.hypot(*along), 1e-9)

    def _route_to_goal(self, obs: Observation):
        evasion = self.avoid(obs)
        if evasion is not None:
            return evasion
        return steer_to(self.estimate.pose, self.drop_point, self.params.drive, self.params.arrive)

    def _carry(self, obs: Observation) -> Command:
        command = self.step(obs)
        if self.step.status == G.FAILED:  # lost the load on the way: open up and look for it here
            lost_at = self._jaw_position()
            if not self._at_goal(lost_at):
                self.knowledge.hint = lost_at  # (near the goal it is as good as delivered: leave it)
            return self._begin("recover", [G.Release(self.sensors, self.params.gripper)], obs)
        if self.step.status == G.SUCCEEDED:
            g = self.sensors, self.params.gripper
            return self._begin("drop", [G.Lower(*g), G.Release(*g)], obs)
        return replace(command, behaviour=self.name)

    def _drop(self, obs: Observation) -> Command:
        command = self.step(obs)
        if self.step.status != G.RUNNING:
            self.knowledge.delivered()
            self.restart()
            return self.drive()
        return replace(command, behaviour=self.name)

    def _recover(self, obs: Observation) -> Command:
        command = self.step(obs)
        if self.step.status != G.RUNNING:
            self.state = "sweep"
            return self.drive()
        return replace(command, behaviour=self.name)


class ReportProgress(SetController):
    """Fig. 3-8: return to the entrance and report (Parker's buzzer tune; here a radio broadcast)."""
    name = REPORT

    def __call__(self, obs: Observation) -> Command:
        command = self.go(obs, self.knowledge.entrance, self.params.entrance_arrive)
        if command is not None:
            return command
        self.knowledge.reported(obs.time)
        return self.drive()


# Motivation rates (App. A's parameters; the thesis gives none for the cleanup, §1.6 item 7). theta = 1.
# find: methodical activates after 2 s, wander after 8 s, so a robot with working side IR prefers methodical and
#   a wander-only robot has heard (radio every 3 s) that a teammate took the task before its own activation.
# move-spill is shared: every robot may carry loads at once (ch.5's time model divides the moves by n), so a
#   teammate's claim slows it only briefly (phi) and it never yields to one (psi infinite).
# report-progress activates within 1 s when due; a teammate's report satisfies it, and one on its way slows it
#   for phi = 90 s.
RATES = {
    METHODICAL: MotivationRates(delta_fast=1 / 2, delta_slow=1 / 300, phi=300.0, psi=300.0, lam=600.0),
    WANDER: MotivationRates(delta_fast=1 / 8, delta_slow=1 / 300, phi=300.0, psi=300.0, lam=600.0),
    MOVE: MotivationRates(delta_fast=1 / 3, delta_slow=1 / 30, phi=0.5, psi=math.inf, lam=600.0),  # lam: learned
    # (CleanupParams.learning: 3 x its expected time per load, at least 600 s; this 600 s with learning off)
    REPORT: MotivationRates(delta_fast=1.0, delta_slow=1 / 90, phi=90.0, psi=60.0, lam=180.0),
}


class CleanupRobot:
    """One R-2's whole controller: beliefs, pose estimate and ALLIANCE over the cleanup behaviour sets.

    ``methodical``: whether the robot has working side IR, so the methodical find is in its repertoire
    (GRC_RED = A; GRC_BLUE = GRC_GREEN lack it, §3.8.2). The set order is the priority order of ties."""

    def __init__(self, robot: RobotModel, rng: np.random.Generator, params: CleanupParams = CleanupParams(),
                 methodical: bool = True, alliance: AllianceParams = AllianceParams(),
                 learned: TaskStatistics | None = None):
        self.knowledge = CleanupKnowledge(params.report_interval, params.empty_rest)
        self.estimate = PoseEstimate(robot.drive)
        bumpers = tuple(name for name in robot.touch if name.startswith("bump_"))
        avoid = AvoidObstacles(robot.ir_sensors, robot.ir_bearings, bumpers, rng, params.drive)
        common = (self.knowledge, self.estimate, avoid, params)
        k = self.knowledge
        move = MoveSpill(robot, rng, *common)
        sets = [(METHODICAL, FIND, FindMethodical(robot, *common), lambda obs: not k.located)] if methodical else []
        sets += [(WANDER, FIND, FindWander(robot, *common), lambda obs: not k.located),
                 (REPORT, REPORT, ReportProgress(*common), lambda obs: k.report_due(obs.time)),
                 (MOVE, MOVE, move, lambda obs: k.located and not k.spill_empty(obs.time) and not k.just_delivered
                  and not (k.report_due(obs.time) and move.searching_in_vain))]
        self.sets = {name: controller for name, _, controller, _ in sets}
        definitions = [BehaviourSetDefinition(name, applicable, controller, task=task, rates=RATES[name])
                       for name, task, controller, applicable in sets]
        core = AllianceRobot(robot.name, [d.behaviour_set for d in definitions], alliance)
        self.learning = LearnedAcquiescence(core, (MOVE,), params.learning, learned)
        self.alliance = AllianceController(robot.name, definitions, alliance, selector=self.learning)
        self.unstick = Unstick(rng, params.drive, escape_extras={"lift": G.UP})
        self.active = "idle"

    def __call__(self, obs: Observation) -> Command:
        k = self.knowledge
        for message in obs.inbox:
            k.hear(message.payload)
        pose = self.estimate.update(obs)
        if pose is None:
            return Command(behaviour="idle")
        if k.home is None:
            k.home = pose[:2].copy()
        delivered_last_tick = k.just_delivered
        command = self.unstick(obs, self.alliance(obs))
        if delivered_last_tick:  # move-spill's feedback has been down for one tick: it is done with that load
            k.just_delivered = False
        if command.behaviour != self.active:
            if self.active in self.sets:
                self.sets[self.active].restart()
            self.active = command.behaviour
        return replace(command, broadcast={**command.broadcast, **k.message()})
