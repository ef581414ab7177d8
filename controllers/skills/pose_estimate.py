"""A robot's estimate of its own pose: wheel odometry between positioning fixes, pulled towards each new fix.

Parker's R-2s had a fix every 600 ms, good to 1/2 in standing still and about 6 in while moving (§2.2.3), and
shaft encoders on the wheels (§2.2.1). Steering on raw fixes makes a robot weave by the fix noise; tracking
the extents of a room from raw fixes inflates them by about two standard deviations on every side. So each
robot dead-reckons from its wheel encoders and compass, and blends each new fix in with weight ``fix_gain``
(a fixed-gain complementary filter: the thesis gives no estimator, this is the simplest that uses both
sensors it lists). The heading comes from the compass with each fix and from the encoders in between.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from teamsim.controllers.base import Observation
from teamsim.models.robot import DifferentialSpec
from teamsim.positioning import wrap_angle


@dataclass
class PoseEstimate:
    """(x, y, heading) from encoders and fixes; ``None`` until the first fix."""
    drive: DifferentialSpec
    fix_gain: float = 0.25  # weight of a new fix: noise std drops to about 0.4 of a single fix's
    pose: np.ndarray | None = None
    _last_fix: float = -math.inf
    _last_time: float | None = None

    def update(self, obs: Observation) -> np.ndarray | None:
        fix = obs.pose
        if fix is None:
            return None
        if self.pose is None:
            self.pose = np.array([fix.x, fix.y, fix.heading])
        else:
            dt = obs.time - self._last_time
            speed, turn_rate = self.odometry(obs)
            heading = self.pose[2] + 0.5 * turn_rate * dt  # mid-step heading
            self.pose[:2] += speed * dt * np.array([math.cos(heading), math.sin(heading)])
            self.pose[2] = wrap_angle(self.pose[2] + turn_rate * dt)
            if fix.time > self._last_fix:
                self.pose[:2] += self.fix_gain * (np.array([fix.x, fix.y]) - self.pose[:2])
                self.pose[2] = fix.heading
        self._last_fix, self._last_time = fix.time, obs.time
        return self.pose

    def odometry(self, obs: Observation) -> tuple[float, float]:
        """(forward speed, turn rate) from the wheel encoders (left wheels first, then right, as the drive
        lists them)."""
        half = len(self.drive.left)
        left, right = obs.motor_speeds[:half].mean(), obs.motor_speeds[half:].mean()
        r = self.drive.wheel_radius
        return float(r * (left + right) / 2), float(r * (right - left) / self.drive.track_width)
