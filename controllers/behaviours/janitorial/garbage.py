"""The *empty-garbage* behaviour set (Parker §6.2.1, Fig. 6-8): follow one frequency's gradient to a can, empty it.

Each can carries an emitter at one of a few frequencies; an emptied can goes silent. A garbage robot has two
detectors per frequency, on the front of its rim to the left and right (the mission's sound model,
``teamsim.tasks.worlds.janitorial``). The set listens to the frequency its motivational behaviour chose: it turns
towards the louder detector and drives on; something in the way that is not the can (the level is still low) is
passed by turning away from it. At the can (loud, and the upper ring sees it close ahead) the emptier goes out and
is held there while the robot creeps up; when that frequency's level drops, the can has gone silent, and the robot
backs off and follows the gradient on to the next can of the frequency, if any. Constants are assumed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from teamsim.controllers.base import Command, Observation
from teamsim.positioning import wrap_angle


@dataclass(frozen=True)
class GarbageParams:
    detect: float = 0.005  # summed level of a frequency's two detectors above which it is heard (the feedback)
    near: float = 0.8  # summed level: a can is close (about 1 m away)
    steer_gain: float = 2.0  # rad/s per unit of (left - right) / (left + right)
    cruise: float = 0.3  # m/s
    creep: float = 0.06  # m/s towards the can with the emptier out
    at_can: float = 0.05  # m from the rim: close enough, stop and hold
    avoid: float = 0.3  # m from the rim: something this near ahead that is not the can is avoided
    avoid_time: float = 1.5  # s of driving on past an obstacle before the gradient steers again
    emptied: float = 0.5  # the level falls below this share of its level on arrival: the can is empty
    back_time: float = 2.0  # s backing off an emptied can
    turn_rate: float = 1.0


class EmptyGarbage:
    """Competences of the set for one frequency (``start`` says which)."""

    def __init__(self, bearings: np.ndarray, upper_ring: np.ndarray, low_ring: np.ndarray,
                 params: GarbageParams = GarbageParams()):
        self.params = params
        self.upper, self.low = upper_ring, low_ring
        b = np.array([wrap_angle(float(x)) for x in np.asarray(bearings)[upper_ring]])
        self.front = np.abs(b) < math.radians(35)
        self.left = b > 0
        self.frequency: str | None = None
        self.emptied = 0
        self._state = "seek"
        self._until = 0.0
        self._arrival_level = 0.0
        self._turn = 1.0

    def start(self, frequency: str, time: float) -> None:
        self.frequency, self._state = frequency, "seek"

    @staticmethod
    def level(obs: Observation, frequency: str) -> tuple[float, float]:
        return tuple(obs.signals.get("sound", {}).get(frequency, (0.0, 0.0)))

    def heard(self, obs: Observation, frequency: str) -> bool:
        return sum(self.level(obs, frequency)) > self.params.detect

    def __call__(self, obs: Observation, pose: np.ndarray) -> Command:
        p = self.params
        left, right = self.level(obs, self.frequency)
        loud = left + right
        ahead = min(obs.ir_range[self.upper][self.front].min(), obs.ir_range[self.low][self.front].min())
        if self._state == "back":
            if obs.time < self._until:
                return Command(v=-0.15, omega=0.0)
            self._state = "seek"
        if self._state == "empty":
            if loud < p.emptied * self._arrival_level:  # gone silent: emptied
                self.emptied += 1
                self._state, self._until = "back", obs.time + p.back_time
                return Command(v=-0.15)
            upper_ahead = obs.ir_range[self.upper][self.front].min()
            return Command(v=p.creep if upper_ahead > p.at_can else 0.0,
                           omega=self._steer(left, right) * 0.3, extras={"emptier": 1.0})
        if ahead < p.avoid + 0.1 and loud > p.near:  # the can
            self._state, self._arrival_level = "empty", loud
            return Command(v=0.0, extras={"emptier": 1.0})
        if self._state == "avoid":
            if obs.time < self._until:
                return Command(v=p.cruise * 0.6, omega=0.0) if ahead > p.avoid else Command(omega=self._turn)
            self._state = "seek"
        if ahead < p.avoid:  # an obstacle: turn away from the side that sees more, then drive past it
            near = obs.ir_range[self.upper] < 2 * p.avoid
            self._turn = -p.turn_rate if np.count_nonzero(near & self.left) > np.count_nonzero(near & ~self.left) \
                else p.turn_rate
            self._state, self._until = "avoid", obs.time + p.avoid_time
            return Command(omega=self._turn)
        omega = self._steer(left, right)
        return Command(v=p.cruise * max(0.0, 1.0 - abs(omega) / p.turn_rate), omega=omega, extras={"emptier": 0.0})

    def _steer(self, left: float, right: float) -> float:
        total = left + right
        if total <= 0.0:
            return 0.0
        return float(np.clip(self.params.steer_gain * (left - right) / total, -1, 1) * self.params.turn_rate)
