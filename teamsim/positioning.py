"""Positioning service: Parker's radio/sonar triangulation system (§2.2.3).

Every ``period`` seconds each robot receives a noisy fix of its (x, y) and a compass heading. Noise is
Gaussian per axis with standard deviation ``noise_still`` when the robot is still and ``noise_moving`` while
it moves (motor interference degraded the sonar fix from 1/2 in to about 6 in). Between updates the robot
keeps its last fix, as the real robots did.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from teamsim.config import PositioningConfig


@dataclass(frozen=True)
class PoseFix:
    x: float
    y: float
    heading: float
    time: float


def wrap_angle(angle: float) -> float:
    """``angle`` in [-pi, pi). (The modulo alone can round up to exactly +pi.)"""
    wrapped = (angle + np.pi) % (2 * np.pi) - np.pi
    return wrapped - 2 * np.pi if wrapped >= np.pi else wrapped


class PositioningService:
    def __init__(self, config: PositioningConfig, rngs: dict[str, np.random.Generator]):
        self.config = config
        self._rngs = rngs
        self._next_update = 0.0
        self._fixes: dict[str, PoseFix] = {}

    def update(self, now: float, poses: dict[str, np.ndarray], speeds: dict[str, float]) -> bool:
        """Issue fresh fixes if an update is due. ``poses`` holds true (x, y, heading). Returns True if updated."""
        if now + 1e-9 < self._next_update:
            return False
        cfg = self.config
        for name, pose in poses.items():
            sigma = cfg.noise_moving if speeds[name] > cfg.moving_speed else cfg.noise_still
            noise = self._rngs[name].standard_normal(3)
            heading = wrap_angle(pose[2] + cfg.heading_noise * noise[2])
            self._fixes[name] = PoseFix(float(pose[0] + sigma * noise[0]), float(pose[1] + sigma * noise[1]),
                                        float(heading), now)
        behind = math.floor((now + 1e-9 - self._next_update) / cfg.period) - 1
        if behind > 0:  # a period far shorter than the control period: skip whole periods rather than count them
            self._next_update += behind * cfg.period
        while self._next_update <= now + 1e-9:
            self._next_update += cfg.period
        return True

    def fix(self, robot: str) -> PoseFix | None:
        """The robot's latest fix, or None before the first one."""
        return self._fixes.get(robot)
