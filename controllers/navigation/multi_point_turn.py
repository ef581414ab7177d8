"""A tricycle's turn on the spot: the multi-point turn of a trapped FRC (issue 22; docs/decisions.md, "Multi-point
turn").

A differential drive that escapes a trap first turns in place to face its plan (``trap_escape``). A tricycle has no
point turns (§3.6), and between boxes the dynamic window cannot turn it round: with the plan behind it every
candidate is scaled down by alpha_3 alike, left and right score the same, and the robot rocks to and fro along its
heading or stands with its wheel at the lock. This turns it the way a driver does, in legs:
  - backwards with the wheel at the lock away from the plan's side (the nose swings towards the plan), then
    forwards with the wheel at the lock on the plan's side, and so on; the side is read at the start of each leg;
  - the first leg is whichever has the more room; a leg ends when its arc has less than its braking distance plus
    ``room`` left before the circle, enlarged by ``margin``, would touch a seen obstacle (DC_cd of the window,
    (3.33)), or after ``leg`` m;
  - the wheel is set only while the robot stands (a turn-only command, ``locomotion.next_steer``); speed changes
    no faster than both the drive's linear and angular accelerations allow at the lock, so the wheel stays there;
  - a robot moving the other way, or on another curvature (a turn begun on the move), first brakes to a stop.
The caller stops asking once the plan lies within ``TrapEscape``'s facing angle. Not in the thesis.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from teamsim.controllers.skills.locomotion import STEER_REQUEST


@dataclass(frozen=True)
class TurnParams:
    speed: float = 0.06  # m/s along a leg (slow, to stop short: 4 cm at A's limits at the lock)
    leg: float = 1.5  # m: a leg's longest
    room: float = 0.03  # m of arc a leg keeps free beyond its braking distance
    margin: float = 0.05  # m added to the robot's circle when measuring a leg's room
    lock_tolerance: float = 0.05  # rad: the wheel counts as at its lock within this


class MultiPointTurn:
    """Legs of a multi-point turn for the tricycle whose dynamic window is ``window``."""

    def __init__(self, window, params: TurnParams = TurnParams()):
        self.window = window
        self.params = params
        self.direction = 0  # +1 forwards, -1 backwards; 0 before the first leg
        self.side = 1.0  # the plan's side during this leg: +1 left, -1 right
        self.travelled = 0.0  # m along the current leg
        self.idle_legs = 0  # legs in a row that ended before moving
        steering = window.steering
        lock_curvature = math.tan(steering.steer_max) / steering.wheelbase
        # the speed step per cycle that keeps omega = v c within the angular acceleration too
        self.speed_step = min(window.limits.accel_max, window.limits.angular_accel_max / lock_curvature) * window.dt

    def restart(self) -> None:
        """A new turn: its first leg is chosen afresh."""
        self.direction, self.travelled, self.idle_legs = 0, 0.0, 0

    def command(self, state, points: np.ndarray, bearing: float) -> tuple[float, float] | None:
        """(v, omega) for this cycle, or None when neither leg has room (two legs in a row ended before moving);
        ``state``: the drive state (v, omega, steer); ``points``: obstacle points relative to the centre, robot
        frame; ``bearing``: the plan's way relative to the heading (left > 0)."""
        p = self.params
        if self.direction == 0:
            self.side = _side(bearing)
            self.direction = 1 if self._room(1, points) >= self._room(-1, points) else -1
        steer = self._steer(self.direction)
        if state.v != 0.0 and (state.v * self.direction < 0 or abs(steer - state.steer) > p.lock_tolerance):
            return self._brake(state)  # moving the other way, or on another curvature: stop first
        stopping = state.v ** 2 * self.window.dt / (2 * self.speed_step)
        if self.travelled >= p.leg or self._room(self.direction, points) < stopping + p.room + p.speed * self.window.dt:
            if state.v != 0.0:
                return self._brake(state)
            # the leg is over: the next goes the other way, on the side the plan now lies
            self.idle_legs = self.idle_legs + 1 if self.travelled == 0.0 else 0
            self.direction, self.travelled = -self.direction, 0.0
            self.side = _side(bearing)
            return None if self.idle_legs >= 2 else (0.0, 0.0)
        if state.v == 0.0 and abs(steer - state.steer) > p.lock_tolerance:
            return 0.0, math.copysign(STEER_REQUEST, steer)
        v = self.direction * min(abs(state.v) + self.speed_step, max(p.speed, abs(state.v) - self.speed_step))
        self.travelled += abs(v) * self.window.dt
        return v, self._turn_rate(v, steer)

    def _brake(self, state) -> tuple[float, float]:
        """Slow down along the wheel's present curvature, to exactly 0."""
        v = math.copysign(max(abs(state.v) - self.speed_step, 0.0), state.v)
        return v, self._turn_rate(v, state.steer)

    def _turn_rate(self, v: float, steer: float) -> float:
        """omega of the bicycle model at speed ``v`` with the wheel at ``steer``."""
        return v * math.tan(steer) / self.window.steering.wheelbase

    def _steer(self, direction: int) -> float:
        """The wheel's lock for a leg: on the plan's side forwards, away from it backwards."""
        return direction * self.side * self.window.steering.steer_max

    def _room(self, direction: int, points: np.ndarray) -> float:
        """How far the centre can go along the leg's arc before the enlarged circle touches a point (DC_cd)."""
        v = direction * self.params.speed
        omega = self._turn_rate(v, self._steer(direction))
        return float(self.window.collision_distances(np.array([v]), np.array([omega]), points,
                                                     self.params.margin)[0])


def _side(bearing: float) -> float:
    """The plan's side: +1 left (bearing >= 0), -1 right."""
    return 1.0 if bearing >= 0 else -1.0
