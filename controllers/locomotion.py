"""Locomotion: the common (v, omega) command turned into actuator set-points.

Differential drive (also used for skid-steer tracks): wheel angular speeds
``w_left = (v - omega * b / 2) / r`` and ``w_right = (v + omega * b / 2) / r`` for track width ``b`` and wheel
radius ``r``. The command is first clipped to the robot's speed limits and then slewed by its acceleration
limits over one control period, as Chand's dynamic window assumes (eq. 3.11-3.12).
"""
from __future__ import annotations

import numpy as np


class DifferentialDrive:
    def __init__(self, wheel_radius: float, track_width: float, limits, control_dt: float):
        self.r = wheel_radius
        self.b = track_width
        self.limits = limits
        self.dt = control_dt
        self.v = 0.0
        self.omega = 0.0

    def wheel_speeds(self, v: float, omega: float) -> np.ndarray:
        """(left, right) wheel speeds in rad/s after speed and acceleration limiting."""
        lim = self.limits
        v = min(max(v, -lim.v_max), lim.v_max)
        omega = min(max(omega, -lim.omega_max), lim.omega_max)
        dv, dw = lim.accel_max * self.dt, lim.angular_accel_max * self.dt
        self.v += min(max(v - self.v, -dv), dv)
        self.omega += min(max(omega - self.omega, -dw), dw)
        half = self.omega * self.b / 2
        return np.array([(self.v - half) / self.r, (self.v + half) / self.r])

    def stop(self) -> np.ndarray:
        """Immediate stop (a dead robot's motors are unpowered, not ramped)."""
        self.v = self.omega = 0.0
        return np.zeros(2)
