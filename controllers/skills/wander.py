"""Wander with IR obstacle avoidance: the smoke-test behaviour of the ``wander`` mission.

Drive forward at cruise speed, drifting onto a new random heading every few seconds; slow down as the
nearest obstacle ahead gets close, and turn away from the side that sees more. When the way ahead stays
blocked, back off while turning: a tricycle cannot turn on the spot, and a reversing turn gets anything out
of a corner. A plain reactive layer, after Parker's *wander* and *avoid-obstacles* behaviours (§3.8.2): no
map and no plan. Distances and speeds scale with the robot's IR range and drive limits.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from teamsim.controllers.base import Command, Observation


@dataclass(frozen=True)
class WanderParams:
    cruise_speed: float = 0.3  # m/s (at most 60 % of the robot's top speed)
    turn_rate: float = 0.4  # rad/s (at most 90 % of the robot's turn-rate limit)
    avoid_distance: float = 0.8  # m from the robot's rim; closer than this ahead, turn away (<= 90 % IR range)
    stop_fraction: float = 0.375  # of avoid_distance: closer than this ahead, stop driving forward
    front_half_angle: float = np.radians(60)
    drift_period: float = 4.0  # s between random heading drifts
    blocked_patience: float = 1.0  # s blocked ahead before backing off
    reverse_time: float = 1.5  # s spent backing off

    def for_robot(self, v_max: float, omega_max: float, ir_range: float) -> "WanderParams":
        return WanderParams(cruise_speed=min(self.cruise_speed, 0.6 * v_max),
                            turn_rate=min(self.turn_rate, 0.9 * omega_max),
                            avoid_distance=min(self.avoid_distance, 0.9 * ir_range),
                            stop_fraction=self.stop_fraction, front_half_angle=self.front_half_angle,
                            drift_period=self.drift_period, blocked_patience=self.blocked_patience,
                            reverse_time=self.reverse_time)


class WanderController:
    def __init__(self, ir_bearings: np.ndarray, rng: np.random.Generator, params: WanderParams = WanderParams()):
        self.params = params
        self.rng = rng
        bearings = (np.asarray(ir_bearings) + np.pi) % (2 * np.pi) - np.pi
        self.front = np.abs(bearings) <= params.front_half_angle
        self.left_weight = np.sin(bearings)  # + for sensors on the left, - on the right
        self.drift = 0.0
        self.next_drift = 0.0
        self.turn = 0.0  # latched turn direction while avoiding: re-deciding every tick dithers in corners
        self.blocked_since: float | None = None
        self.reverse_until = -1.0

    def __call__(self, obs: Observation) -> Command:
        p = self.params
        if obs.time >= self.next_drift:
            self.drift = float(self.rng.uniform(-0.5, 0.5)) * p.turn_rate
            self.next_drift = obs.time + p.drift_period * float(self.rng.uniform(0.5, 1.5))
        if obs.time < self.reverse_until:
            return Command(v=-0.5 * p.cruise_speed, omega=-self.turn * p.turn_rate, behaviour="reverse")
        ahead = obs.ir_range[self.front]
        nearest = float(ahead.min()) if ahead.size else np.inf
        if nearest > p.avoid_distance:
            self.turn = 0.0
            self.blocked_since = None
            return Command(v=p.cruise_speed, omega=self.drift, behaviour="wander")
        if not self.turn:
            # Closeness in [0, 1] per sensor; turn away from the side with more of it.
            closeness = np.clip(1.0 - obs.ir_range / p.avoid_distance, 0.0, 1.0) * self.front
            side = float(closeness @ self.left_weight)
            self.turn = -np.sign(side) if abs(side) > 1e-3 else (1.0 if self.drift >= 0 else -1.0)
        stop_distance = p.stop_fraction * p.avoid_distance
        if nearest <= stop_distance:
            self.blocked_since = obs.time if self.blocked_since is None else self.blocked_since
            if obs.time - self.blocked_since >= p.blocked_patience:
                self.reverse_until = obs.time + p.reverse_time
                self.blocked_since = None
        else:
            self.blocked_since = None
        speed = p.cruise_speed * np.clip((nearest - stop_distance) / (p.avoid_distance - stop_distance), 0, 1)
        return Command(v=float(speed), omega=float(self.turn * p.turn_rate), behaviour="avoid")
