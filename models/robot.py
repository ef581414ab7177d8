"""What a robot *is*: its MJCF, and the names of the bodies, sensors and actuators the world drives.

Every robot kind builds a :class:`RobotModel`. Names are local to the robot's MJCF; once attached to an arena
they are prefixed with the robot's name (``red/left``), which is the robot's MJCF model name.
"""
from __future__ import annotations

import hashlib
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from dm_control import mjcf

from teamsim.models.ir import IRModel

# Colours for the first robots, in Parker's naming style (RED, GREEN, BLUE...). Later robots get r<N>.
TEAM_COLOURS: dict[str, tuple[float, float, float, float]] = {
    "red": (0.85, 0.15, 0.15, 1), "green": (0.15, 0.7, 0.2, 1), "blue": (0.15, 0.35, 0.9, 1),
    "yellow": (0.95, 0.85, 0.1, 1), "cyan": (0.1, 0.8, 0.85, 1), "magenta": (0.85, 0.2, 0.8, 1),
    "orange": (1.0, 0.55, 0.1, 1), "purple": (0.5, 0.25, 0.75, 1), "white": (0.95, 0.95, 0.95, 1),
    "black": (0.15, 0.15, 0.15, 1),
}


def team_names(count: int) -> list[str]:
    colours = list(TEAM_COLOURS)
    return [colours[i] if i < len(colours) else f"r{i}" for i in range(count)]


def colour_of(name: str) -> tuple[float, float, float, float]:
    if name in TEAM_COLOURS:
        return TEAM_COLOURS[name]
    # A stable pseudo-random hue for other names, spread round the wheel even for one-letter names.
    hue = int.from_bytes(hashlib.sha256(name.encode()).digest()[:4], "big") / 2**32
    r, g, b = (0.5 + 0.4 * math.cos(2 * math.pi * (hue + k / 3)) for k in range(3))
    return (r, g, b, 1.0)


@dataclass(frozen=True)
class DriveLimits:
    """Limits of the common (v, omega) locomotion command."""
    v_max: float  # m/s
    omega_max: float  # rad/s
    accel_max: float  # m/s^2
    angular_accel_max: float  # rad/s^2


@dataclass(frozen=True)
class DifferentialSpec:
    """Wheels on two sides, every actuator of a side driven at that side's speed (skid-steer tracks too).

    Actuators are velocity servos on wheel hinges whose positive rotation drives the robot forward."""
    wheel_radius: float
    track_width: float
    left: tuple[str, ...]
    right: tuple[str, ...]
    # Skid steering slips: a robot that skids (tracks) closes a loop on its gyro's yaw rate, with this
    # integral gain (1/s). 0 for wheels that roll without scrubbing.
    yaw_rate_gain: float = 0.0

    @property
    def actuators(self) -> tuple[str, ...]:
        return self.left + self.right


@dataclass(frozen=True)
class TricycleSpec:
    """A front wheel that both steers and drives, ``wheelbase`` ahead of the passive rear axle (whose
    midpoint is the robot's reference point). ``steer`` is a position servo, ``drive`` a velocity servo."""
    wheel_radius: float
    wheelbase: float
    steer: str
    drive: str
    steer_max: float  # rad
    steer_rate_max: float  # rad/s

    @property
    def actuators(self) -> tuple[str, ...]:
        return (self.steer, self.drive)


@dataclass(frozen=True)
class Effector:
    """An actuated extra (a gripper's jaws, its lift) commanded in [0, 1] through ``Command.extras[name]``.

    0 and 1 map linearly to the actuators' set-points ``ctrl_at_0`` and ``ctrl_at_1``; the robot feels the
    effector's position, normalised the same way, from ``joint``'s encoder."""
    actuators: tuple[str, ...]
    joint: str
    ctrl_at_0: float
    ctrl_at_1: float


@dataclass(frozen=True)
class RobotModel:
    kind: str
    name: str
    mjcf: mjcf.RootElement
    root_body: str
    ir_sensors: tuple[str, ...]
    ir_bearings: np.ndarray  # bearing of each IR sensor in the body frame, rad, same order as ir_sensors
    ir: IRModel
    drive: object  # DifferentialSpec, TricycleSpec, or a legged robot's gait spec (has .actuators)
    limits: DriveLimits
    footprint_radius: float
    tracking_camera: str
    max_traction: float  # N the locomotion can push with at full effort (calibrates bog drag)
    traversability: float = 1.0  # Chand Table 5.22: share of its speed kept on difficult terrain
    effectors: dict = field(default_factory=dict)  # name -> Effector
    touch: dict = field(default_factory=dict)  # name -> geom names whose contact normal forces it sums, N
    beams: tuple[str, ...] = ()  # rangefinders across a gap: "broken" when they read less than beam_length
    beam_length: float = 0.0
    inclinometer: bool = False

    @property
    def motors(self) -> tuple[str, ...]:
        """Locomotion actuators, in the order the locomotion controller fills them."""
        return tuple(self.drive.actuators)


def polygon_rim(vertices: list[tuple[float, float]]) -> Callable[[float], float]:
    """Distance from the origin to the edge of a convex polygon (around the origin) along a bearing."""
    edges = list(zip(vertices, vertices[1:] + vertices[:1]))

    def rim(bearing: float) -> float:
        c, s = math.cos(bearing), math.sin(bearing)
        hits = []
        for (x1, y1), (x2, y2) in edges:
            ex, ey = x2 - x1, y2 - y1
            denom = c * ey - s * ex
            if abs(denom) < 1e-12:
                continue
            t = (x1 * ey - y1 * ex) / denom  # distance along the ray
            u = (x1 * s - y1 * c) / denom  # position along the edge
            if t > 0 and -1e-9 <= u <= 1 + 1e-9:
                hits.append(t)
        return min(hits)
    return rim


def add_ir_ring(body: mjcf.Element, count: int, radius: float | Callable[[float], float], height: float,
                max_range: float, first_bearing: float = 0.0, centre: tuple[float, float] = (0.0, 0.0),
                prefix: str = "ir") -> tuple[tuple[str, ...], np.ndarray]:
    """Rangefinder sites evenly spaced over 360 degrees at ``height``, looking outward from the body's rim.

    ``radius`` is the rim's distance from ``centre``: a number for a round body, or a function of bearing
    (see :func:`polygon_rim`) for any other outline."""
    root = body.root
    names, bearings = [], []
    for k in range(count):
        bearing = first_bearing + 2 * math.pi * k / count
        c, s = math.cos(bearing), math.sin(bearing)
        r = radius(bearing) if callable(radius) else radius
        site = body.add("site", name=f"{prefix}{k}", pos=[centre[0] + r * c, centre[1] + r * s, height], size=[0.01],
                        zaxis=[c, s, 0], rgba=[1, 0.3, 0.3, 0.6], group=3)
        root.sensor.add("rangefinder", name=f"{prefix}{k}", site=site, cutoff=max_range)
        names.append(f"{prefix}{k}")
        bearings.append(bearing)
    return tuple(names), np.asarray(bearings)


def add_tracking_camera(body: mjcf.Element, distance: float) -> str:
    """A camera that follows the body from behind and above, in the world frame (mode=track)."""
    body.add("camera", name="track", mode="track", pos=[0, -distance, distance],
             xyaxes=[1, 0, 0, 0, 0.7071, 0.7071], fovy=60)
    return "track"
