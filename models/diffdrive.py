"""``diffdrive``: Chand's circular differential-drive robot (Robot B of Table 3.1; MARVIN base, Table 5.22).

Thesis values: enclosing radius 0.35 m (ch.3) or 0.40 m (ch.5), v <= 0.5 m/s, omega <= pi/7 rad/s, ten 1.5 m IR
sensors evenly over 360 degrees. Everything else (mass, height, wheels, casters, motor torque, acceleration) is
not in the thesis and is assumed below, in one place.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

from dm_control import mjcf

from teamsim.models.ir import IRModel
from teamsim.models.parts import TYRE_FRICTION, add_caster, add_livery, add_velocity_motor, add_wheel, max_traction
from teamsim.models.robot import (DifferentialSpec, DriveLimits, RobotModel, add_ir_ring, add_tracking_camera,
                                  colour_of)


@dataclass(frozen=True)
class DiffDriveDims:
    radius: float = 0.35  # Table 3.1 (0.40 in ch.5, Table 5.22)
    ir_count: int = 10  # Table 3.1
    ir_range: float = 1.5  # Table 3.1
    traversability: float = 0.1  # Table 5.22 (Robots 3, 5-7)
    v_max: float = 0.5  # Table 3.1
    omega_max: float = math.pi / 7  # Table 3.1
    # Chand gives acceleration limits only for Scratchy (Table 3.4); we apply them to this robot too.
    accel_max: float = 0.1
    angular_accel_max: float = 0.15
    # Assumed (not in the thesis):
    height: float = 0.35
    mass: float = 12.0
    ground_clearance: float = 0.04
    wheel_radius: float = 0.08
    wheel_width: float = 0.03
    wheel_inset: float = 0.08  # wheel centre inside the rim, so wheels sit in body slots
    wheel_torque: float = 6.0  # N m per wheel motor (stall)
    wheel_servo_gain: float = 30.0  # N m per rad/s of speed error: stiff enough to hold speed within ~1 %
    caster_radius: float = 0.03
    caster_gap: float = 0.004  # casters ride this far above the floor so the wheels carry the load
    battery_mass: float = 3.0  # kg, ahead of the axle: the robot leans on its front caster, not its back one
    battery_x: float = 0.1
    ir_height: float = 0.2

    @property
    def track_width(self) -> float:
        return 2 * (self.radius - self.wheel_inset)


def build(name: str, **overrides) -> RobotModel:
    """The robot called ``name``; ``overrides`` replace DiffDriveDims fields (e.g. radius=0.40)."""
    dims = replace(DiffDriveDims(), **overrides)
    model = mjcf.RootElement(model=name)
    chassis = model.worldbody.add("body", name="chassis")
    body_half = (dims.height - dims.ground_clearance) / 2
    chassis.add("geom", name="shell", type="cylinder", size=[dims.radius, body_half],
                pos=[0, 0, dims.ground_clearance + body_half], mass=dims.mass, rgba=[0.35, 0.35, 0.38, 1])
    add_livery(chassis, colour_of(name), dims.height, dims.radius * 0.9)
    chassis.add("geom", name="battery", type="box", size=[0.06, 0.1, 0.05], mass=dims.battery_mass,
                pos=[dims.battery_x, 0, dims.ground_clearance + 0.06], contype=0, conaffinity=0, group=3)
    for side, x in (("front", 1), ("back", -1)):
        add_caster(chassis, side, x * (dims.radius - 0.08), dims.caster_radius, dims.caster_gap)
    max_wheel_speed = 1.5 * dims.v_max / dims.wheel_radius
    for side, y in (("left", 1), ("right", -1)):
        add_wheel(chassis, side, [0, y * dims.track_width / 2, dims.wheel_radius], dims.wheel_radius,
                  dims.wheel_width, mass=0.5)
        add_velocity_motor(model, side, dims.wheel_servo_gain, dims.wheel_torque, max_wheel_speed)
    ir_names, bearings = add_ir_ring(chassis, dims.ir_count, dims.radius + 0.005, dims.ir_height, dims.ir_range)
    camera = add_tracking_camera(chassis, distance=2.0)
    limits = DriveLimits(dims.v_max, dims.omega_max, dims.accel_max, dims.angular_accel_max)
    drive = DifferentialSpec(dims.wheel_radius, dims.track_width, left=("left",), right=("right",))
    return RobotModel(kind="diffdrive", name=name, mjcf=model, root_body="chassis", ir_sensors=ir_names,
                      ir_bearings=bearings, ir=IRModel.for_range(dims.ir_range), drive=drive, limits=limits,
                      footprint_radius=dims.radius, tracking_camera=camera,
                      max_traction=max_traction(2 * dims.wheel_torque / dims.wheel_radius,
                                                dims.mass + dims.battery_mass, TYRE_FRICTION[0]),
                      traversability=dims.traversability)
