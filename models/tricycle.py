"""``tricycle``: Chand's Scratchy (Robot A of Table 3.1, Robot1/2 of Table 5.22; §3.6-3.7).

Thesis values: a pentagon body of enclosing radius 0.5 m; a front wheel that steers and drives, so no point
turns (it reverses to turn round); v <= 0.5 m/s in simulation (0.3 measured), omega <= pi/7 rad/s (sim);
measured limits +-0.1 m/s^2 and +-0.15 rad/s^2 (Table 3.4); eleven 1.5 m IR sensors evenly over 360 degrees;
difficult-terrain traversability 0.3. Wheelbase, wheel sizes, mass, steering limits and motor torques are not
in the thesis (the mechanical details are in a reference it does not reproduce) and are assumed below.

The robot's frame (and so its pose and its (v, omega) reference point) is the midpoint of the rear axle; the
pentagon's centre lies ``wheelbase / 2`` ahead of it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

from dm_control import mjcf

from teamsim.models.ir import IRModel
from teamsim.models.parts import TYRE_FRICTION, add_livery, add_velocity_motor, add_wheel, max_traction
from teamsim.models.robot import (DriveLimits, RobotModel, TricycleSpec, add_ir_ring, add_tracking_camera,
                                  colour_of, polygon_rim)


@dataclass(frozen=True)
class TricycleDims:
    radius: float = 0.5  # enclosing radius of the pentagon, Table 3.1
    ir_count: int = 11  # Table 3.1
    ir_range: float = 1.5
    v_max: float = 0.5  # Table 3.1 (simulation); Table 3.4 measured 0.3
    omega_max: float = math.pi / 7  # Table 3.1
    accel_max: float = 0.1  # Table 3.4
    angular_accel_max: float = 0.15  # Table 3.4
    traversability: float = 0.3  # Table 5.22
    # Assumed (not in the thesis):
    wheelbase: float = 0.5  # front wheel to rear axle
    rear_track: float = 0.56
    wheel_radius: float = 0.1
    wheel_width: float = 0.04
    height: float = 0.45
    ground_clearance: float = 0.06
    mass: float = 20.0
    front_load: float = 0.33  # share of the weight on the driven front wheel (body centred on the wheelbase)
    drive_torque: float = 12.0  # N m at the front wheel
    drive_servo_gain: float = 40.0
    steer_max: float = math.radians(60)
    steer_rate_max: float = 1.0  # rad/s: the steering motor's slew limit
    steer_kp: float = 300.0  # N m/rad of the steering position servo (stiff: holds the angle against tyre scrub)
    ir_height: float = 0.25


def pentagon(radius: float) -> list[tuple[float, float]]:
    """Vertices of a regular pentagon of circumradius ``radius`` with one vertex pointing forward (+x)."""
    return [(radius * math.cos(2 * math.pi * k / 5), radius * math.sin(2 * math.pi * k / 5)) for k in range(5)]


def build(name: str, **overrides) -> RobotModel:
    """The robot called ``name``; ``overrides`` replace TricycleDims fields."""
    dims = replace(TricycleDims(), **overrides)
    model = mjcf.RootElement(model=name)
    centre = dims.wheelbase / 2
    outline = pentagon(dims.radius)
    half = (dims.height - dims.ground_clearance) / 2
    vertices = [c for x, y in outline for c in ((centre + x, y, -half), (centre + x, y, half))]
    model.asset.add("mesh", name="pentagon", vertex=[v for vertex in vertices for v in vertex])
    chassis = model.worldbody.add("body", name="chassis")
    chassis.add("geom", name="shell", type="mesh", mesh="pentagon", pos=[0, 0, dims.ground_clearance + half],
                mass=dims.mass, rgba=[0.4, 0.38, 0.34, 1])
    add_livery(chassis, colour_of(name), dims.height, dims.radius * 0.6, centre_x=centre)
    for side, y in (("rear_left", 1), ("rear_right", -1)):
        add_wheel(chassis, side, [0, y * dims.rear_track / 2, dims.wheel_radius], dims.wheel_radius,
                  dims.wheel_width, mass=0.8, damping=0.02)
    fork = chassis.add("body", name="fork", pos=[dims.wheelbase, 0, dims.wheel_radius])
    fork.add("joint", name="steer", type="hinge", axis=[0, 0, 1], range=[-dims.steer_max, dims.steer_max],
             limited=True, damping=1.0, armature=0.01)
    fork.add("geom", name="fork", type="box", size=[0.02, 0.04, 0.02], pos=[0, 0, 0.1], mass=0.3,
             contype=0, conaffinity=0, rgba=[0.3, 0.3, 0.3, 1])
    add_wheel(fork, "drive", [0, 0, 0], dims.wheel_radius, dims.wheel_width, mass=1.0)
    # The front wheel turns inside a well in the shell; MuJoCo only filters parent-child contacts.
    model.contact.add("exclude", body1="chassis", body2="drive_wheel")
    model.actuator.add("position", name="steer", joint="steer", kp=dims.steer_kp, kv=10.0,
                       ctrlrange=[-dims.steer_max, dims.steer_max], ctrllimited=True,
                       forcerange=[-30, 30], forcelimited=True)
    add_velocity_motor(model, "drive", dims.drive_servo_gain, dims.drive_torque,
                       2 * dims.v_max / dims.wheel_radius)
    ir_names, bearings = add_ir_ring(chassis, dims.ir_count, polygon_rim(outline), dims.ir_height,
                                     dims.ir_range, centre=(centre, 0.0))
    limits = DriveLimits(dims.v_max, dims.omega_max, dims.accel_max, dims.angular_accel_max)
    drive = TricycleSpec(dims.wheel_radius, dims.wheelbase, steer="steer", drive="drive",
                         steer_max=dims.steer_max, steer_rate_max=dims.steer_rate_max)
    return RobotModel(kind="tricycle", name=name, mjcf=model, root_body="chassis", ir_sensors=ir_names,
                      ir_bearings=bearings, ir=IRModel.for_range(dims.ir_range), drive=drive, limits=limits,
                      footprint_radius=dims.radius, tracking_camera=add_tracking_camera(chassis, distance=2.5),
                      max_traction=max_traction(dims.drive_torque / dims.wheel_radius, dims.mass * dims.front_load,
                                                TYRE_FRICTION[0]),
                      traversability=dims.traversability)
