"""Locomotion: the common (v, omega) command turned into actuator set-points, one class per drive.

Every drive first clips the command to the robot's speed limits and slews it by its acceleration limits over
one control period, as Chand's dynamic window assumes (eq. 3.11-3.12). ``command`` is called once per control
tick; ``targets(t)`` gives the actuator set-points, in the order of the drive spec's ``actuators``. A drive
whose set-points change between ticks (a gait) sets ``continuous``, and the world asks it again during the
period. A drive may define ``feedback(yaw_rate)``: the world then gives it the robot's gyro reading (rad/s)
before each ``command``.
"""
from __future__ import annotations

import importlib
import math

import numpy as np


class SlewLimiter:
    """(v, omega) clipped to the speed limits and slewed by the acceleration limits, per control period."""

    def __init__(self, limits, control_dt: float):
        self.limits = limits
        self.dt = control_dt
        self.v = 0.0
        self.omega = 0.0

    def __call__(self, v: float, omega: float) -> tuple[float, float]:
        lim = self.limits
        v = min(max(v, -lim.v_max), lim.v_max)
        omega = min(max(omega, -lim.omega_max), lim.omega_max)
        dv, dw = lim.accel_max * self.dt, lim.angular_accel_max * self.dt
        self.v += min(max(v - self.v, -dv), dv)
        self.omega += min(max(omega - self.omega, -dw), dw)
        return self.v, self.omega

    def reset(self) -> None:
        self.v = self.omega = 0.0


class DifferentialDrive:
    """``w_left = (v - omega b/2) / r``, ``w_right = (v + omega b/2) / r`` for track ``b``, wheel radius ``r``;
    every actuator of a side gets its side's speed (the co-driven rollers of a skid-steer track too).

    Skid steering turns much slower than this kinematic model says, because the track ends scrub sideways.
    With ``spec.yaw_rate_gain`` > 0 the drive adds an integral correction from the gyro's yaw rate to the
    turn it asks of the tracks, as a tracked robot's low-level controller does; the correction is bounded to
    four times the robot's turn-rate limit and bleeds away while the robot is asked not to turn."""
    continuous = False

    def __init__(self, spec, limits, control_dt: float):
        self.spec = spec
        self.slew = SlewLimiter(limits, control_dt)
        self._sides = np.array([0] * len(spec.left) + [1] * len(spec.right))
        self._speeds = np.zeros(2)
        self._yaw_rate = 0.0
        self._correction = 0.0

    def feedback(self, yaw_rate: float) -> None:
        self._yaw_rate = yaw_rate

    def command(self, v: float, omega: float) -> None:
        v, omega = self.slew(v, omega)
        gain = self.spec.yaw_rate_gain
        if gain:
            bound = 4 * self.slew.limits.omega_max
            self._correction += gain * (omega - self._yaw_rate) * self.slew.dt
            self._correction = min(max(self._correction, -bound), bound)
        half = (omega + self._correction) * self.spec.track_width / 2
        self._speeds = np.array([v - half, v + half]) / self.spec.wheel_radius

    def targets(self, time: float) -> np.ndarray:
        return self._speeds[self._sides]

    def stop(self) -> None:
        """Immediate stop (a dead robot's motors are unpowered, not ramped)."""
        self.slew.reset()
        self._speeds = np.zeros(2)
        self._correction = 0.0


STEER_REQUEST = 0.01  # rad/s: the turn-only command (0, +-this) that turns a standing tricycle's wheel


def next_steer(steer: float, v: float, omega: float, commanded: tuple[float, float], geometry, dt: float) -> float:
    """A tricycle's front-wheel angle one control period on, at most ``steer_rate_max dt`` from ``steer`` and
    within +-``steer_max`` (``geometry``: anything with wheelbase, steer_max and steer_rate_max). Moving (the
    slewed speed ``v`` above 1 mm/s) the wheel turns towards atan(omega L / v), the bicycle model's angle for
    (v, omega). Standing, it holds, unless the command (``commanded``, before slewing) is a turn alone,
    (0, omega != 0): the robot cannot turn in place, but its steering servo can, and the wheel turns towards
    the lock on that side, ready to move off turning that way. The navigation controllers ask for it when a
    stop beside an obstacle has left the wheel turned towards it (Chand's Fig 3.8 wedge; see
    ``teamsim.controllers.navigation.dynamic_window``); the thesis does not say whether its tricycle steered at rest."""
    if abs(v) > 1e-3:
        wanted = math.atan(omega * geometry.wheelbase / v)
    elif commanded[0] == 0.0 and commanded[1] != 0.0:
        wanted = math.copysign(geometry.steer_max, commanded[1])
    else:
        wanted = steer
    wanted = min(max(wanted, -geometry.steer_max), geometry.steer_max)
    step = geometry.steer_rate_max * dt
    return steer + min(max(wanted - steer, -step), step)


class TricycleDrive:
    """Front wheel steered to ``delta = atan(omega L / v)`` and driven at ``v / cos(delta)`` so the rear-axle
    midpoint moves at (v, omega) (bicycle model, wheelbase ``L``). The steering angle changes no faster than
    ``steer_rate_max``, and with v = 0 the robot cannot turn: it has no point turns (Chand §3.6); a turn-only
    command turns its wheel (``next_steer``)."""
    continuous = False

    def __init__(self, spec, limits, control_dt: float):
        self.spec = spec
        self.slew = SlewLimiter(limits, control_dt)
        self.dt = control_dt
        self.steer = 0.0
        self.wheel_speed = 0.0

    def command(self, v: float, omega: float) -> None:
        commanded = (v, omega)
        v, omega = self.slew(v, omega)
        self.steer = next_steer(self.steer, v, omega, commanded, self.spec, self.dt)
        self.wheel_speed = v / max(math.cos(self.steer), 0.05) / self.spec.wheel_radius

    def targets(self, time: float) -> np.ndarray:
        return np.array([self.steer, self.wheel_speed])

    def stop(self) -> None:
        self.slew.reset()
        self.wheel_speed = 0.0


LOCOMOTION_FOR_SPEC: dict[str, str] = {
    "DifferentialSpec": "teamsim.controllers.skills.locomotion:DifferentialDrive",
    "TricycleSpec": "teamsim.controllers.skills.locomotion:TricycleDrive",
    "GaitSpec": "teamsim.controllers.skills.gait:TripodGait",  # legged robots (Genghis-II)
}


def make_locomotion(spec, limits, control_dt: float):
    """The locomotion controller for a robot's drive spec, looked up by the spec's class name."""
    module, _, cls = LOCOMOTION_FOR_SPEC[type(spec).__name__].partition(":")
    return getattr(importlib.import_module(module), cls)(spec, limits, control_dt)
