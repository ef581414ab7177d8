"""Tripod gait: the common (v, omega) command turned into the twelve leg set-points of Genghis-II.

Parker (§2.2.2) gives Genghis-II six legs of two degrees of freedom each (swing and lift) and no gait details;
DESIGN.md says it walked with a tripod gait, as the original Genghis did. Everything about the gait below is
therefore assumed: a fixed step frequency, a 50 % duty cycle, a straight-line stance stroke and a smooth
(cosine) return stroke with the foot raised on a half sine.

Legs 1, 3, 5 (left front, left rear, right middle) are in stance while 2, 4, 6 swing, then they swap. A stance
foot moves back relative to the body at the speed the body should move forward over it: for a body twist
(v, omega) a foot at lateral offset ``y`` must move at ``v - omega y``, so turning is a difference in stride
between the left and right legs, and with v = 0 the sides step in opposite directions (turning on the spot).
A two-DOF leg cannot move its foot sideways, so in a turn the front and rear feet slip and the body turns
slower than that ideal; the spec's ``turn_gain`` (calibrated in simulation) scales the turning part of the
stride up to make it good, giving ``v - turn_gain omega y``. Stride, not
frequency, carries the command: ``stride = foot speed / (2 f)``, since each stance lasts half a cycle. When one
leg would have to step beyond its swing range, every stride is scaled down together, which keeps the
commanded path curvature. Phase is a function of simulated time only, so a run is deterministic. With no
motion commanded the robot stands with all six feet down.
"""
from __future__ import annotations

import numpy as np

from teamsim.controllers.skills.locomotion import SlewLimiter

STANDING_STRIDE = 1e-4  # m; strides all below this mean "stand still"


class TripodGait:
    continuous = True

    def __init__(self, spec, limits, control_dt: float):
        self.spec = spec
        self.slew = SlewLimiter(limits, control_dt)
        self._offset = np.asarray(spec.phase_offset, dtype=float)
        self._foot_y = np.asarray(spec.foot_y, dtype=float)
        self.stride = np.zeros(len(spec.legs))  # m of foot travel per stance, per leg; positive walks forward

    def command(self, v: float, omega: float) -> None:
        v, omega = self.slew(v, omega)
        foot_speed = v - self.spec.turn_gain * omega * self._foot_y
        peak = float(np.abs(foot_speed).max())
        if peak > self.spec.foot_speed_max:
            foot_speed = foot_speed * (self.spec.foot_speed_max / peak)
        self.stride = foot_speed / (2 * self.spec.frequency)

    def phases(self, time: float) -> np.ndarray:
        """Each leg's gait phase in [0, 1): stance in [0, 0.5), swing in [0.5, 1)."""
        return (self.spec.frequency * time + self._offset) % 1.0

    def targets(self, time: float) -> np.ndarray:
        """(swing, lift) set-points of each leg in turn, rad, in the order of ``spec.actuators``."""
        spec = self.spec
        out = np.empty(2 * len(spec.legs))
        if float(np.abs(self.stride).max()) < STANDING_STRIDE:
            out[0::2] = 0.0
            out[1::2] = spec.lift_stance
            return out
        phase = self.phases(time)
        stance = phase < 0.5
        swing_phase = 2 * np.pi * (phase - 0.5)  # 0 .. pi over the swing
        # Foot position along the stroke: +1 at the front, -1 at the back.
        stroke = np.where(stance, 1.0 - 4.0 * phase, -np.cos(swing_phase))
        out[0::2] = np.arcsin(stroke * self.stride / (2 * spec.reach))
        raise_by = np.where(stance, 0.0, np.sin(swing_phase))
        out[1::2] = spec.lift_stance + (spec.lift_swing - spec.lift_stance) * raise_by
        return out

    def stop(self) -> None:
        """Immediate stop (a killed robot): every leg back to neutral with its foot down."""
        self.slew.reset()
        self.stride = np.zeros(len(self.spec.legs))
