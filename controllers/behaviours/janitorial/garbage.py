"""The *empty-garbage* behaviour set (Parker §6.2.1, Fig. 6-8): follow one frequency's gradient to a can, empty it.

Each can carries an emitter at one of a few frequencies; an emptied can goes silent. A garbage robot has two
detectors per frequency, on the front of its rim to the left and right (the mission's sound model,
``teamsim.tasks.worlds.janitorial``). The set listens to the frequency its motivational behaviour chose: it turns
towards the louder detector and drives on; something in the way that is not the can (the level is still low) is gone
round, following it on the right for a while (longer each time one is met on the way to the same can). At the can
(loud, and the upper ring sees it close ahead) the emptier goes out and is held there while the robot creeps up;
when that frequency's level drops, the can has gone silent, and the robot backs off and follows the gradient on to
the next can of the frequency, if any. Constants are assumed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from teamsim.controllers.base import Command, Observation
from teamsim.controllers.skills.follow_surface import FollowParams, FollowRight
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
    detour_time: float = 4.0  # s following an obstacle round before the gradient steers again (longer each time)
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
        self.frequency: str | None = None
        self.emptied = 0
        self._state = "seek"
        self._until = 0.0
        self._arrival_level = 0.0
        self._detours = 0  # obstacles met on the way to this can
        self.follow = FollowRight(np.asarray(bearings)[low_ring], FollowParams(gap=0.15, speed=0.2))

    def start(self, frequency: str, time: float) -> None:
        self.frequency, self._state, self._detours = frequency, "seek", 0

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
                self._state, self._until, self._detours = "back", obs.time + p.back_time, 0
                return Command(v=-0.15)
            upper_ahead = obs.ir_range[self.upper][self.front].min()
            return Command(v=p.creep if upper_ahead > p.at_can else 0.0,
                           omega=self._steer(left, right) * 0.3, extras={"emptier": 1.0})
        if ahead < p.avoid + 0.1 and loud > p.near:  # the can
            self._state, self._arrival_level = "empty", loud
            return Command(v=0.0, extras={"emptier": 1.0})
        if self._state == "detour":
            if obs.time < self._until:  # round the obstacle with it on the right, then the gradient again
                v, omega = self.follow(obs.ir_range[self.low])
                return Command(v=v, omega=omega, extras={"emptier": 0.0})
            self._state = "seek"
        if ahead < p.avoid:  # an obstacle (not the can): go round it for a while
            self._detours += 1
            self._state, self._until = "detour", obs.time + p.detour_time * min(self._detours, 4)
            return Command(omega=p.turn_rate, extras={"emptier": 0.0})
        omega = self._steer(left, right)
        return Command(v=p.cruise * max(0.0, 1.0 - abs(omega) / p.turn_rate), omega=omega, extras={"emptier": 0.0})

    def _steer(self, left: float, right: float) -> float:
        total = left + right
        if total <= 0.0:
            return 0.0
        return float(np.clip(self.params.steer_gain * (left - right) / total, -1, 1) * self.params.turn_rate)
