"""``tracked``: Chand's rectangular tracked robot (Robot C of Table 3.1; Robot4/8 of Table 5.22; the
RoboProbe tank platform, §5.4).

Thesis values: rectangular body with enclosing radius 0.6 m (ch.5; 0.67 m for Robot C in ch.3),
v <= 0.4 m/s (ch.5; 0.3 m/s for Robot C), omega <= pi/7 rad/s, fourteen 1.5 m IR sensors over 360 degrees,
difficult-terrain traversability 1.0 (it crosses bogs). MuJoCo has no belts (mujoco#3220), so each track is
approximated by co-driven rollers on one side, all driven at that side's speed: skid steering. Aspect ratio,
mass, rollers and torques are assumed.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

from dm_control import mjcf

from teamsim.models.ir import IRModel
from teamsim.models.parts import add_livery, add_velocity_motor, add_wheel, max_traction
from teamsim.models.robot import (DifferentialSpec, DriveLimits, RobotModel, add_ir_ring, add_tracking_camera,
                                  colour_of, polygon_rim)


@dataclass(frozen=True)
class TrackedDims:
    radius: float = 0.6  # enclosing radius, Table 5.22 (Robot C: 0.67)
    ir_count: int = 14  # Tables 3.1, 5.22
    ir_range: float = 1.5
    v_max: float = 0.4  # Table 5.22 (Robot C: 0.3)
    omega_max: float = math.pi / 7  # Table 3.1
    traversability: float = 1.0  # Table 5.22
    # Assumed (not in the thesis):
    aspect: float = 1.3  # length / width of the body
    accel_max: float = 0.2
    angular_accel_max: float = 0.3
    height: float = 0.4
    ground_clearance: float = 0.08
    mass: float = 30.0
    rollers_per_side: int = 4
    roller_radius: float = 0.1
    roller_width: float = 0.08
    roller_torque: float = 10.0  # N m per roller: skid steering must scrub the track ends sideways
    roller_servo_gain: float = 40.0
    roller_friction: float = 0.8
    # The end rollers (idlers) ride this much higher, so on flat ground the load is on the middle rollers and
    # the track can skid round; with all rollers level the ends' sideways scrub out-pulls the tracks' grip.
    idler_lift: float = 0.01
    ir_height: float = 0.3
    yaw_rate_gain: float = 2.0  # 1/s, integral gain of the gyro loop that makes up for skid (locomotion.py)

    @property
    def half_length(self) -> float:
        return self.radius * self.aspect / math.hypot(self.aspect, 1.0)

    @property
    def half_width(self) -> float:
        return self.radius / math.hypot(self.aspect, 1.0)


def build(name: str, **overrides) -> RobotModel:
    """The robot called ``name``; ``overrides`` replace TrackedDims fields (e.g. radius=0.67, v_max=0.3)."""
    dims = replace(TrackedDims(), **overrides)
    model = mjcf.RootElement(model=name)
    a, b = dims.half_length, dims.half_width
    half = (dims.height - dims.ground_clearance) / 2
    chassis = model.worldbody.add("body", name="chassis")
    chassis.add("geom", name="shell", type="box", size=[a, b - dims.roller_width, half],
                pos=[0, 0, dims.ground_clearance + half], mass=dims.mass, rgba=[0.33, 0.36, 0.3, 1])
    add_livery(chassis, colour_of(name), dims.height, min(a, b) * 0.7)
    track_y = b - dims.roller_width / 2
    roller_xs = [a - dims.roller_radius - k * (2 * (a - dims.roller_radius) / (dims.rollers_per_side - 1))
                 for k in range(dims.rollers_per_side)]
    sides = {"left": [], "right": []}
    max_speed = 2 * dims.v_max / dims.roller_radius
    for side, sign in (("left", 1), ("right", -1)):
        # The belt, drawn over the rollers (visual only).
        chassis.add("geom", name=f"{side}_belt", type="box", size=[a, dims.roller_width / 2, dims.roller_radius],
                    pos=[0, sign * track_y, dims.roller_radius], rgba=[0.12, 0.12, 0.12, 1],
                    contype=0, conaffinity=0, mass=0.01)
        for k, x in enumerate(roller_xs):
            joint = f"{side}{k}"
            z = dims.roller_radius + (dims.idler_lift if k in (0, dims.rollers_per_side - 1) else 0.0)
            add_wheel(chassis, joint, [x, sign * track_y, z], dims.roller_radius,
                      dims.roller_width * 0.9, mass=0.6, friction=(dims.roller_friction, 0.01, 0.001))
            add_velocity_motor(model, joint, dims.roller_servo_gain, dims.roller_torque, max_speed)
            sides[side].append(joint)
    outline = [(a, b), (-a, b), (-a, -b), (a, -b)]
    ir_names, bearings = add_ir_ring(chassis, dims.ir_count, polygon_rim(outline), dims.ir_height, dims.ir_range)
    limits = DriveLimits(dims.v_max, dims.omega_max, dims.accel_max, dims.angular_accel_max)
    drive = DifferentialSpec(dims.roller_radius, 2 * track_y, left=tuple(sides["left"]), right=tuple(sides["right"]),
                             yaw_rate_gain=dims.yaw_rate_gain)
    return RobotModel(kind="tracked", name=name, mjcf=model, root_body="chassis", ir_sensors=ir_names,
                      ir_bearings=bearings, ir=IRModel.for_range(dims.ir_range), drive=drive, limits=limits,
                      footprint_radius=dims.radius, tracking_camera=add_tracking_camera(chassis, distance=2.8),
                      max_traction=max_traction(2 * dims.rollers_per_side * dims.roller_torque / dims.roller_radius,
                                                dims.mass, dims.roller_friction),
                      traversability=dims.traversability)
