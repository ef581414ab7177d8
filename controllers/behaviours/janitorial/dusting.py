"""The *dust-furniture* behaviour set (Parker §6.2.1, Fig. 6-9): wander to find a dustable object, circle it dusting.

An object is dustable when it triggers the lower IR ring and not the upper one (it is lower than the upper ring;
walls, cans, tall furniture and robots trigger both). The robot searches by a random walk (Parker's "simple
wandering technique": straight legs, a new random heading away from whatever ends one, the least familiar of a few
drawn, from its memory of where it has been: an unbiased walk kept two robots in half of a cluttered room for 700 s)
until it sees one away from every location on its ignore list (objects dusted, or being dusted by a teammate whose
claim it still honours: :class:`DustClaims`), drives to it, swings the duster out and circles the object with it on
its right (:mod:`teamsim.controllers.skills.follow_surface`). The object's location is the centroid of the surface
points the lower ring saw on the right while circling; a full turn round it, with the surface seen from all round,
completes the object. Constants
are assumed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from teamsim.controllers.base import Command, Observation
from teamsim.controllers.navigation.polar_histogram import wrap
from teamsim.controllers.skills.follow_surface import FollowParams, FollowRight
from teamsim.controllers.skills.goto import DriveParams, steer_to, turn_to
from teamsim.positioning import wrap_angle


@dataclass(frozen=True)
class DustParams:
    see: float = 0.8  # m from the rim: a lower-ring reading this near with the upper ring clear is an object
    confirm: int = 3  # consecutive control periods it must be seen (one noisy upper reading is not an object)
    upper_clear: float = 0.3  # m: the upper reading at that bearing exceeds the lower one by this (or is empty)
    same_object: float = 0.8  # m: a sighting this near an ignored location is that object
    approach_gap: float = 0.15  # m from the rim: close enough to start circling
    approach_timeout: float = 20.0  # s
    circle_turn: float = 2 * math.pi  # rad round the object, and its surface seen in seen_sectors of 12 directions
    seen_sectors: int = 11  # (a teammate in the way pushes the robot off a side, which it then has not dusted)
    circle_timeout: float = 150.0  # s: an object not circled by then is taken as done (its sides are blocked) if
    # the robot got half round it; short of that it lost the object, which stays to be found
    follow: FollowParams = FollowParams(gap=0.08, speed=0.15, ahead=0.15)
    drive: DriveParams = DriveParams(cruise=0.25, turn_rate=1.0)
    bounce: float = 0.35  # m from the rim: the search's random walk turns away from anything this near ahead
    candidates: int = 6  # new headings drawn at a bounce; the one leading through the least-visited cells wins
    memory_cell: float = 0.5  # m: the cells of the robot's memory of where it has been
    look_ahead: float = 2.5  # m along a candidate heading that count


class DustClaims:
    """Which objects a robot leaves alone (§6.2.1): those dusted (by anyone), and each object a teammate announces
    dusting until this robot's impatience with it, growing at ``delta_slow`` from the first announcement, reaches
    theta. Then the object is "fair game"."""

    def __init__(self, delta_slow: float, threshold: float, same_object: float):
        self.patience = threshold / delta_slow
        self.same_object = same_object
        self.done: list[np.ndarray] = []
        self.claims: dict[str, tuple[np.ndarray, float]] = {}  # teammate -> (location, first announced)

    def hear(self, teammate: str, at, time: float) -> None:
        if at is None:
            self.claims.pop(teammate, None)
            return
        location = np.asarray(at, float)
        held = self.claims.get(teammate)
        if held is None or np.hypot(*(held[0] - location)) > self.same_object:
            self.claims[teammate] = (location, time)

    def completed(self, at) -> None:
        location = np.asarray(at, float)
        if not any(np.hypot(*(d - location)) < self.same_object for d in self.done):
            self.done.append(location)

    def ignore_list(self, time: float) -> list[np.ndarray]:
        return self.done + [loc for loc, since in self.claims.values() if time - since < self.patience]


class DustFurniture:
    def __init__(self, bearings: np.ndarray, upper_ring: np.ndarray, low_ring: np.ndarray, rim: float,
                 rng: np.random.Generator, params: DustParams = DustParams()):
        self.params = params
        self.rim = rim  # m from the centre to the rings
        self.upper, self.low = upper_ring, low_ring
        self.bearings = np.asarray(bearings)[low_ring]
        self.rng = rng
        self.front = np.abs(np.array([wrap_angle(float(b)) for b in bearings])) < math.radians(35)
        self._heading: float | None = None  # the random walk's current heading
        self._visits: dict[tuple[int, int], int] = {}  # control periods spent in each memory cell
        self.follow = FollowRight(self.bearings, params.follow)
        self.ignore: list[np.ndarray] = []
        self.target: np.ndarray | None = None  # the surface point being approached, then the object's centroid
        self.finished: list[np.ndarray] = []  # objects this robot dusted (their centroids)
        self.verified: list[np.ndarray] = []  # dusted objects it went back to and circled again
        self._verifying = False
        self.verify_at: np.ndarray | None = None
        self.tall: list[np.ndarray] = []  # sightings the upper ring saw too, close up: not dustable
        self._candidate: tuple[np.ndarray, int] | None = None  # a sighting and how many periods running
        self._state = "search"
        self._since = 0.0
        self._hits: list[np.ndarray] = []
        self._swept = 0.0  # rad round the object, clockwise (it is on the right)
        self._sighted = np.zeros(2)  # where the object being dusted was first seen
        self._last_angle: float | None = None

    @property
    def dusting_at(self) -> np.ndarray | None:
        return None if self._state == "search" else self.target

    def start(self, _instance: str, time: float, verify_at: np.ndarray | None = None) -> None:
        """Search for an object to dust; or, ``verify_at``, go back to a dusted one and circle it again."""
        self._state, self.target, self._verifying = "search", None, verify_at is not None
        self.verify_at = verify_at  # the dusted object this verification goes back to, kept once it is circled
        if verify_at is not None:
            self._state, self._since, self.target, self._sighted = "approach", time, verify_at, verify_at

    def __call__(self, obs: Observation, pose: np.ndarray) -> Command:
        p = self.params
        if self._state == "search":
            sighting = self._confirmed(self._sighting(obs, pose))
            if sighting is None:
                return self._walk(obs, pose)
            self._state, self._since, self.target, self._sighted = "approach", obs.time, sighting, sighting
        if self._state == "approach":
            near, facing = self._near_target(obs, pose)
            if near < p.approach_gap:
                if obs.ir_range[self.upper][facing].min() < near + p.upper_clear:  # tall after all
                    self.tall.append(self.target)
                    self._state = "search"
                    return Command(extras={"duster": 0.0})
                self._state, self._since, self._hits, self._swept, self._last_angle = "circle", obs.time, [], 0.0, None
            elif obs.time - self._since > p.approach_timeout * (3 if self._verifying else 1):
                if self._verifying:  # could not get back to it: verified as far as it can be
                    self.verified.append(self.verify_at.copy())
                self._state = "search"
                return Command(extras={"duster": 0.0})
            else:
                v, omega = steer_to(pose, self.target, p.drive, 0.0) or (0.0, 0.0)
                return Command(v=v, omega=omega, extras={"duster": 0.0})
        return self._circle(obs, pose)

    def _near_target(self, obs: Observation, pose: np.ndarray) -> tuple[float, np.ndarray]:
        """The lower ring's nearest reading ahead that is of the target (the surface it reads lies within
        ``same_object`` / 2 of the sighting, ``same_object`` of a dusted object's centre being verified), and the
        sensors that looked. Anything else ahead (the can just emptied, the object just circled) is not the
        target: judged by it, the target was taken for tall and ignored for good, or "circled" from metres away
        (janitorial-rho study, seeds 7, 6 and 2; docs/decisions.md, janitorial, "Dusting")."""
        p = self.params
        to = self.target - pose[:2]
        toward = math.atan2(to[1], to[0]) - pose[2]
        facing = (np.abs(self.bearings) < math.radians(40)) & (np.abs(wrap(self.bearings - toward)) < math.radians(40))
        low = obs.ir_range[self.low]
        tolerance = p.same_object if self._verifying else p.same_object / 2
        near = math.inf
        for k in np.flatnonzero(facing & np.isfinite(low)):
            bearing = pose[2] + self.bearings[k]
            seen = pose[:2] + (self.rim + low[k]) * np.array([math.cos(bearing), math.sin(bearing)])
            if np.hypot(*(seen - self.target)) < tolerance:
                near = min(near, float(low[k]))
        return near, facing

    def _circle(self, obs: Observation, pose: np.ndarray) -> Command:
        p = self.params
        ranges = obs.ir_range[self.low]
        seen = self._object_points(obs, pose, np.where(self.follow.right, ranges, np.inf), p.follow.gap * 3 + 0.2)
        # The right side only (the object circled), and near where it was first seen (not a neighbour's side).
        self._hits += [q for q in seen if np.hypot(*(q - self._sighted)) < p.same_object]
        if self._hits:
            self.target = np.mean(self._hits, axis=0)
            angle = math.atan2(pose[1] - self.target[1], pose[0] - self.target[0])
            if self._last_angle is not None:
                self._swept -= wrap_angle(angle - self._last_angle)  # clockwise round it is progress
            self._last_angle = angle
        if (self._swept >= p.circle_turn and self._seen_round() >= p.seen_sectors) or \
                obs.time - self._since > p.circle_timeout:
            if self._verifying:
                self.verified.append(self.verify_at.copy())  # as it was announced, so teammates match it
            elif self._swept >= p.circle_turn / 2:
                self.finished.append(self.target.copy())
            # else: timed out short of half round it, the follower lost it (rho 0.5 seed 2: it followed the wall
            # round the room instead, and the object counted done at 38 % of its sides): it stays to be found.
            self._state, self.target = "search", None
            return Command(extras={"duster": 0.0})
        v, omega = self.follow(ranges)
        return Command(v=v, omega=omega, extras={"duster": 1.0})

    def _seen_round(self) -> int:
        """In how many of 12 directions from the object's centroid the lower ring has seen its surface."""
        offsets = np.array(self._hits) - self.target
        sectors = np.floor((np.arctan2(offsets[:, 1], offsets[:, 0]) + math.pi) / (math.pi / 6)).astype(int) % 12
        return len(set(sectors.tolist()))

    def _object_points(self, obs: Observation, pose: np.ndarray, low: np.ndarray, reach: float) -> list[np.ndarray]:
        """World points of the lower ring's readings within ``reach`` that the upper ring does not share."""
        upper = obs.ir_range[self.upper]
        points = []
        for k in np.flatnonzero(low < reach):
            if upper[k] > low[k] + self.params.upper_clear:
                bearing = pose[2] + self.bearings[k]
                distance = self.rim + low[k]
                points.append(pose[:2] + distance * np.array([math.cos(bearing), math.sin(bearing)]))
        return points

    def _walk(self, obs: Observation, pose: np.ndarray) -> Command:
        """The search: a random walk of straight legs, each ended by something ahead, then a new heading drawn
        within 90 degrees of straight back."""
        p = self.params
        if self._heading is None:
            self._heading = float(self.rng.uniform(-math.pi, math.pi))
        cell = (int(math.floor(pose[0] / p.memory_cell)), int(math.floor(pose[1] / p.memory_cell)))
        self._visits[cell] = self._visits.get(cell, 0) + 1
        if obs.ir_range[self.front].min() < p.bounce and abs(wrap_angle(self._heading - pose[2])) < 0.3:
            candidates = pose[2] + math.pi + self.rng.uniform(-math.pi / 2, math.pi / 2, size=p.candidates)
            self._heading = wrap_angle(float(min(candidates, key=lambda h: self._visited_along(pose, h))))
        omega = turn_to(pose, self._heading, p.drive, tolerance=0.3)
        if omega is not None and abs(wrap_angle(self._heading - pose[2])) > 0.6:
            return Command(omega=omega, extras={"duster": 0.0})
        return Command(v=p.drive.cruise, omega=omega or 0.0, extras={"duster": 0.0})

    def _visited_along(self, pose: np.ndarray, heading: float) -> int:
        """How often this robot has been in the memory cells along ``look_ahead`` m of a heading."""
        p = self.params
        total = 0
        for d in np.arange(1, int(p.look_ahead / p.memory_cell) + 1) * p.memory_cell:
            x, y = pose[0] + d * math.cos(heading), pose[1] + d * math.sin(heading)
            total += self._visits.get((int(math.floor(x / p.memory_cell)), int(math.floor(y / p.memory_cell))), 0)
        return total

    def _confirmed(self, sighting: np.ndarray | None) -> np.ndarray | None:
        """The sighting once it has been seen ``confirm`` periods running (within ``same_object`` / 2)."""
        if sighting is None:
            self._candidate = None
            return None
        if self._candidate is not None and np.hypot(*(self._candidate[0] - sighting)) < self.params.same_object / 2:
            self._candidate = (sighting, self._candidate[1] + 1)
        else:
            self._candidate = (sighting, 1)
        return sighting if self._candidate[1] >= self.params.confirm else None

    def _sighting(self, obs: Observation, pose: np.ndarray) -> np.ndarray | None:
        """The nearest dustable surface point seen, away from the ignore list, or None."""
        points = self._object_points(obs, pose, obs.ir_range[self.low], self.params.see)
        for point in sorted(points, key=lambda q: float(np.hypot(*(q - pose[:2])))):
            if all(np.hypot(*(point - ignored)) > self.params.same_object for ignored in self.ignore + self.tall):
                return point
        return None
