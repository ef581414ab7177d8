"""The robot interface: an :class:`Observation` in, a :class:`Command` out.

A controller never touches MuJoCo. The world samples sensors at the control period and hands each robot an
observation; the robot's controller returns a command in the common locomotion form (v, omega) plus whatever
extras its robot has (gripper, ...), the message it wants to broadcast, and the name of its current behaviour
(shown in videos and timelines, and timed per robot).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping, Protocol, Sequence

import numpy as np


@dataclass(frozen=True)
class Observation:
    time: float
    robot: str
    ir_raw: np.ndarray  # raw IR readings (0 = nothing)
    ir_range: np.ndarray  # range estimates from the robot's own calibration, m (inf = nothing)
    ir_bearings: np.ndarray  # body-frame bearing of each IR sensor, rad
    pose: Any  # latest positioning fix (teamsim.positioning.PoseFix) or None before the first
    inbox: tuple = ()  # radio messages received since the last tick
    robots_present: frozenset = frozenset()
    motor_speeds: np.ndarray = field(default_factory=lambda: np.zeros(0))  # locomotion encoders, rad/s
    velocity: tuple[float, float] | None = None  # odometry: (forward speed m/s, turn rate rad/s) of the chassis
    touch: dict = field(default_factory=dict)  # touch sensor -> summed contact normal force, N (bumpers, fingers)
    break_beams: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))  # True where a beam is broken
    inclination: tuple | None = None  # (roll, pitch) in rad, for robots with an inclinometer
    effectors: dict = field(default_factory=dict)  # effector -> position in [0, 1] from its encoder
    drive_effort: float | None = None  # mean share of the locomotion motors' force limit in use ("PWM effort")
    signals: dict = field(default_factory=dict)  # the mission's own sensors (``Mission.sense``), e.g. sound detectors


class TraceEvent(Protocol):
    """Something a motivational behaviour did at a step: ``kind`` (e.g. "activate", "acquiescence"), the behaviour
    set, the teammate concerned (or None) and a free-text detail."""

    kind: str
    behaviour_set: str
    teammate: str | None
    detail: str


class MotivationTrace(Protocol):
    """One step of a controller's action selection: ``motivation`` maps every behaviour set, in priority order
    and the same sets at every step, to its level; a set is activated when its level exceeds ``threshold``."""

    time: float
    threshold: float
    active: str | None
    motivation: Mapping[str, float]
    events: Sequence[TraceEvent]


@dataclass(frozen=True)
class Command:
    v: float = 0.0  # forward speed, m/s
    omega: float = 0.0  # turn rate, rad/s (counter-clockwise positive)
    behaviour: str = "idle"
    broadcast: Any = None  # payload for the next radio slot; None keeps the previous one
    extras: dict = field(default_factory=dict)  # effector set-points in [0, 1], e.g. {"grip": 0.0, "lift": 1.0}
    trace: MotivationTrace | None = None  # action selection by motivation at this step, recorded by the world


class Controller(Protocol):
    def __call__(self, observation: Observation) -> Command: ...
