"""Going places on a position estimate, under Parker's always-on *avoid-obstacles* layer (Fig. 3-4, §3.8.1).

:class:`AvoidObstacles` is the lowest competence layer of every R-2 behaviour set: when a bump sensor fires or
an IR sensor sees something closer than ``avoid_range``, it takes over for a short manoeuvre (move off away from
it, then turn away from the side that sensed it: right when it was dead ahead, a random side when behind), then
hands control back. Parker's move-spill suppresses it while picking up, so that the robot can drive its jaw
around a puck.

:class:`Unstick` lies under it: a robot asked to move that the positioning service shows going nowhere raises
its lift and backs off. Parker's R-2s lowered their jaw onto pucks they could not sense under the fingers and
lifted their own wheels off the floor (§3.8.4, "needed manual rescue"); ours do the same at the goal, where the
delivered pucks lie, and must get out unaided.

:func:`steer_to` is the go-to-point behaviour: turn towards the target on the spot when it is far off the
heading, else drive at it with a proportional turn, slowing down near it. The thesis gives the behaviours'
names, not their control laws, so the laws and every constant in :class:`DriveParams` are assumed.
"""
from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, replace

import numpy as np

from teamsim.controllers.base import Command, Observation
from teamsim.positioning import wrap_angle


@dataclass(frozen=True)
class DriveParams:
    cruise: float = 0.3  # m/s (the R-2's top speed is 0.46 m/s)
    turn_gain: float = 2.5  # rad/s per rad of heading error
    turn_rate: float = 1.5  # rad/s, the largest turn rate asked for
    turn_in_place: float = 0.8  # rad: beyond this heading error the robot turns on the spot
    slow_radius: float = 0.4  # m: speed ramps down inside this distance of the target
    avoid_range: float = 0.15  # m: an IR reading nearer than this triggers avoid-obstacles
    bump_force: float = 1.0  # N on a bumper that counts as a bump
    back_time: float = 0.8  # s of backing off
    back_speed: float = 0.15  # m/s
    turn_time: float = 1.0  # s of turning away afterwards
    # Unstick (see :class:`Unstick`): asked to move (at least stuck_speed or stuck_turn_rate) for stuck_window s
    # while every positioning fix of that time lies within stuck_moved of their mean and stuck_turned of their
    # heading, the robot is stuck. Still fixes scatter by 1.3 cm and 0.05 rad (positioning): 8 of them stay
    # within 5 cm and 0.25 rad; a robot that drives or turns leaves that in a second.
    stuck_speed: float = 0.1  # m/s (the gripper's approach creeps slower: pick-ups never count)
    stuck_turn_rate: float = 0.5  # rad/s
    stuck_window: float = 5.0  # s
    stuck_moved: float = 0.05  # m
    stuck_turned: float = 0.25  # rad
    unstick_back_time: float = 2.0  # s of backing off with the lift up, then turn_time of turning


def steer_to(pose: np.ndarray, target, params: DriveParams, arrive: float) -> tuple[float, float] | None:
    """(v, omega) towards ``target`` from ``pose`` (x, y, heading), or None within ``arrive`` of it."""
    dx, dy = target[0] - pose[0], target[1] - pose[1]
    distance = math.hypot(dx, dy)
    if distance <= arrive:
        return None
    error = wrap_angle(math.atan2(dy, dx) - pose[2])
    omega = float(np.clip(params.turn_gain * error, -params.turn_rate, params.turn_rate))
    if abs(error) > params.turn_in_place:
        return 0.0, omega
    return params.cruise * min(1.0, distance / params.slow_radius) * math.cos(error), omega


def turn_to(pose: np.ndarray, heading: float, params: DriveParams, tolerance: float = 0.1) -> float | None:
    """Turn rate towards ``heading``, or None once within ``tolerance``."""
    error = wrap_angle(heading - pose[2])
    if abs(error) <= tolerance:
        return None
    return float(np.clip(params.turn_gain * error, -params.turn_rate, params.turn_rate))


class AvoidObstacles:
    """Reactive layer over the IR ring and bumpers: ``__call__`` gives an evasive (v, omega) while a manoeuvre
    runs, else None. ``ir_sensors`` and ``bumpers`` are the robot's names, in observation order."""

    def __init__(self, ir_sensors: tuple[str, ...], ir_bearings: np.ndarray, bumpers: tuple[str, ...],
                 rng: np.random.Generator, params: DriveParams = DriveParams()):
        self.bearings = np.asarray(ir_bearings)
        self.bumper_bearings = {name: _BUMPER_BEARING[name.rsplit("_", 1)[-1]] for name in bumpers}
        self.rng = rng
        self.params = params
        self.until = -math.inf
        self.turn = 0.0
        self.away = 0.0
        self.spin = 0.0  # turn rate while moving off: non-zero only when hemmed in
        self.back_until = -math.inf

    def __call__(self, obs: Observation) -> tuple[float, float] | None:
        p = self.params
        bearing = self._threat(obs)
        if bearing is not None and obs.time >= self.back_until:
            ahead = abs(wrap_angle(bearing)) < math.pi / 2
            # Away from the side it is on; from dead ahead, to the right (two robots meeting pass left to left).
            if abs(math.sin(bearing)) > 0.2:
                side = -math.copysign(1.0, bearing)
            else:
                side = -1.0 if ahead else self.rng.choice((-1.0, 1.0))
            self.turn = side * p.turn_rate
            # Something too close where it would move off to as well: turn on the spot for turn_time instead.
            # (Moving off the one and then off the other, an R-2 between delivered pucks and the wall rocked for
            # 1200 s: docs/decisions.md, "Hemmed in".)
            hemmed = self._threat(obs, towards=math.pi if ahead else 0.0) is not None
            self.away, self.spin = (0.0, self.turn) if hemmed else (-p.back_speed if ahead else p.back_speed, 0.0)
            self.back_until = obs.time + (p.turn_time if hemmed else p.back_time)
            self.until = self.back_until + (0.0 if hemmed else p.turn_time)
        if obs.time < self.back_until:
            return self.away, self.spin
        if obs.time < self.until:
            return 0.0, self.turn
        return None

    def _threat(self, obs: Observation, towards: float | None = None) -> float | None:
        """Body-frame bearing of the nearest thing too close (only within 60 degrees of ``towards``, if given),
        or None."""
        p = self.params
        cone = math.cos(math.pi / 3)
        for name, bearing in self.bumper_bearings.items():
            if obs.touch.get(name, 0.0) >= p.bump_force and (towards is None or math.cos(bearing - towards) > cone):
                return bearing
        close = obs.ir_range < p.avoid_range
        if towards is not None:
            close &= np.cos(self.bearings - towards) > cone
        near = np.flatnonzero(close)
        if near.size == 0:
            return None
        return float(self.bearings[near[np.argmin(obs.ir_range[near])]])


_BUMPER_BEARING = {"front": 0.0, "left": math.pi / 2, "right": -math.pi / 2, "back": math.pi}


class Unstick:
    """Get out of places the wheels cannot: the jaw pressed onto a puck (wheels lifted), wedged against a wall or
    a robot with avoid-obstacles off. ``__call__(obs, command)`` passes the command through, or, once the robot
    has been asked to move for ``stuck_window`` s while its positioning fixes stood still (:class:`DriveParams`),
    replaces it with an escape: back off for ``unstick_back_time``, then turn to a random side for ``turn_time``,
    with ``escape_extras`` overriding the command's extras meanwhile (an R-2 raises its lift, freeing the wheels;
    its grip is left as commanded, so a held load stays held). ``escapes`` counts them."""

    def __init__(self, rng: np.random.Generator, params: DriveParams = DriveParams(),
                 escape_extras: dict | None = None):
        self.rng = rng
        self.params = params
        self.escape_extras = dict(escape_extras or {})
        self.fixes: deque = deque()  # (time, x, y, heading) of the fixes since the robot was last asked to stop
        self.back_until = self.until = -math.inf
        self.turn = 0.0
        self.escapes = 0

    def __call__(self, obs: Observation, command: Command) -> Command:
        p = self.params
        if obs.time >= self.until:
            if abs(command.v) < p.stuck_speed and abs(command.omega) < p.stuck_turn_rate:
                self.fixes.clear()
                return command
            self._add_fix(obs.pose)
            if not self._stuck(obs.time):
                return command
            self._begin_escape(obs.time)
        v, omega = (-p.back_speed, 0.0) if obs.time < self.back_until else (0.0, self.turn)
        return replace(command, v=v, omega=omega, extras={**command.extras, **self.escape_extras})

    def _add_fix(self, fix) -> None:
        """Keep a fix not seen before."""
        if fix is not None and (not self.fixes or fix.time > self.fixes[-1][0]):
            self.fixes.append((fix.time, fix.x, fix.y, fix.heading))

    def _begin_escape(self, now: float) -> None:
        p = self.params
        self.fixes.clear()
        self.escapes += 1
        self.back_until = now + p.unstick_back_time
        self.until = self.back_until + p.turn_time
        self.turn = self.rng.choice((-1.0, 1.0)) * p.turn_rate

    def _stuck(self, now: float) -> bool:
        p = self.params
        if not self.fixes or now - self.fixes[0][0] < p.stuck_window:
            return False
        while len(self.fixes) > 1 and now - self.fixes[1][0] >= p.stuck_window:  # one fix stuck_window old stays
            self.fixes.popleft()
        _, x, y, heading = np.array(self.fixes).T
        spread = np.hypot(x - x.mean(), y - y.mean()).max()
        mean_heading = math.atan2(np.sin(heading).mean(), np.cos(heading).mean())
        turned = max(abs(wrap_angle(h - mean_heading)) for h in heading)
        return spread < p.stuck_moved and turned < p.stuck_turned
