"""Follow a surface on the robot's right with a ring of rangefinders: a wall round a room, or an object's sides.

The control law keeps the nearest reading on the right (bearings -45 to -135 degrees) at ``gap`` from the rim, turns
left on the spot when something is ahead, and curves right when the surface is lost (the corner of an object or of
an obstacle standing off the wall), as Parker's wall-following competence does (Fig. 3-5). Gains are assumed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from teamsim.positioning import wrap_angle


@dataclass(frozen=True)
class FollowParams:
    gap: float = 0.12  # m from the rim to the surface
    ahead: float = 0.2  # m: a reading this near within 35 degrees of straight ahead means turn left
    speed: float = 0.2  # m/s
    gain: float = 4.0  # rad/s per m of gap error
    turn_rate: float = 0.8  # rad/s
    lost_curve: float = 0.6  # of speed / radius: curving right round a lost surface


class FollowRight:
    """``__call__(ranges) -> (v, omega)`` for the sensors at ``bearings`` (body frame, rad)."""

    def __init__(self, bearings: np.ndarray, params: FollowParams = FollowParams(), lost_radius: float = 0.35):
        b = np.array([wrap_angle(float(x)) for x in bearings])
        self.params = params
        self.front = np.abs(b) < math.radians(35)
        self.right = (b < -math.radians(45)) & (b > -math.radians(135))
        self.right_front = (b < -math.radians(20)) & (b > -math.radians(70))
        self.lost_radius = lost_radius

    def __call__(self, ranges: np.ndarray) -> tuple[float, float]:
        p = self.params
        if ranges[self.front].min(initial=math.inf) < p.ahead:
            return 0.0, p.turn_rate
        right = ranges[self.right].min(initial=math.inf)
        if not math.isfinite(right) or right > 3 * p.gap + 0.2:
            return p.speed * p.lost_curve, -p.speed * p.lost_curve / self.lost_radius
        omega = -p.gain * (right - p.gap)
        if ranges[self.right_front].min(initial=math.inf) < p.gap:  # converging on it ahead-right: ease off
            omega += 0.5 * p.turn_rate
        return p.speed, float(np.clip(omega, -p.turn_rate, p.turn_rate))
