"""``r2``: IS Robotics' R-2, Parker's puck-gathering, box-pushing robot (Parker §2.2.1, pp.16-19).

Thesis values (§2.2.1, converted from inches): 10 in wide x 12.5 in deep including the gripper x 14 in tall
including the radio/positioning unit; two 3 in drive wheels, differential, up to 18 in/s, two rear casters; a
2-DOF parallel-jaw gripper with 3 in maximum opening, 7 in maximum lift and 2 lb lifting capacity; a cavity
under the gripper that can trap extra pucks; 8 IR proximity sensors at both fingertips and along the sides and
back with an effective range of about 8 to 12 in; piezoelectric bump sensors around the base and inside the
fingers (grip force); shaft encoders on the lift, grip and wheel motors; two break-beams between the fingers,
at the front and rear of the gripper. The mass, the motors and every dimension the thesis does not give are
assumed, and marked so in :class:`R2Dims`, the one place that holds them.

Layout with the default dimensions (x forward, y left, z up; the origin is on the floor under the midpoint of
the drive axle)::

    back bumper | chassis, battery at the back | front bumper | cavity | rear beam | pads        | front beam | tip
    x = -0.164                                   0.045          0.048    0.108       0.114-0.144   0.150        0.154

The gripper rides a carriage on a vertical slide (``lift``) in front of the chassis. The carriage is a top
plate with two fixed side prongs (the jaw frame); the two finger pads slide sideways between the prongs
(``finger_left`` drives, ``finger_right`` follows it through a joint equality, like a rack and pinion), so one
motor closes a jaw that stays centred. The break-beams are mounted on the prongs, one in front of and one
behind the pads, so neither pad ever crosses a beam whatever the opening; a beam reads "broken" only when
something lies across the jaw (the far prong belongs to the beam's own body, which a MuJoCo rangefinder
ignores). The cavity is the open-fronted space between the front bumper and the jaw, under the top plate
and between two side skirts: a puck fits there (below the plate even with the lift down) and is pushed
along by the bumper, as Parker saw R-2s carry extra pucks (an average of 1.6 per transport, §3.8).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from dm_control import mjcf

from teamsim.models.ir import IRModel
from teamsim.models.objects import INCH
from teamsim.models.parts import GRAVITY, add_caster, add_livery, add_velocity_motor, add_wheel
from teamsim.models.robot import DifferentialSpec, DriveLimits, Effector, RobotModel, add_tracking_camera, colour_of

POUND = 0.45359237  # kg
# Sensor names the gripper behaviours look up (teamsim.controllers.skills.gripper).
TIP_IR = ("ir_tip_left", "ir_tip_right")
BEAMS = ("beam_front", "beam_rear")
GRIP_TOUCH = "fingers"


@dataclass(frozen=True)
class R2Dims:
    """Every R-2 dimension and constant, SI units: the thesis' values (§2.2.1) first, then assumed ones."""
    # -- Parker §2.2.1 ------------------------------------------------------------------------------------
    width: float = 10 * INCH
    depth: float = 12.5 * INCH  # including the gripper
    height: float = 14 * INCH  # including the radio/positioning unit
    wheel_radius: float = 1.5 * INCH  # 3 in diameter drive wheels
    v_max: float = 18 * INCH  # m/s
    jaw_opening: float = 3 * INCH  # maximum width between the pads
    lift_travel: float = 7 * INCH  # maximum lift
    payload: float = 2 * POUND  # lifting capacity, kg
    ir_range: float = 0.30  # "effective range about 8 to 12 in" (ch.9: "a 12-inch range"); the upper end
    # -- assumed (not in the thesis) ----------------------------------------------------------------------
    shell_mass: float = 3.88  # kg; with the parts below the whole robot weighs about 5 kg
    omega_max: float = 2.0  # rad/s (a point turn at full wheel speed would be 4.1 rad/s)
    accel_max: float = 0.5  # m/s^2: keeps the robot from pitching onto its gripper when braking with a payload
    angular_accel_max: float = 3.0  # rad/s^2
    traversability: float = 0.1  # Chand's score for small indoor wheeled robots (Table 5.22)
    # N m stall torque per wheel: 31.5 N of push, a little less than the tyres pass to the floor (1.2 x 27 N
    # of wheel load while pushing, measured), so a stalled R-2 does not spin its wheels.
    wheel_torque: float = 0.6
    # N m per rad/s of wheel speed error. Stiff: with 1.0 the wheels overran the chassis by 17 % when braking
    # from full speed (tyre creep under the saturated motor's jerks); with 3.0, 2 %.
    wheel_servo_gain: float = 3.0
    wheel_width: float = 0.01  # MuJoCo touches a cylinder down at both rim edges: wide tyres scrub in turns
    wheel_mass: float = 0.1
    wheel_damping: float = 0.002  # N m s/rad: bearing friction, small beside a 0.6 N m motor
    bumper_thickness: float = 0.003  # the bump ring stands this far proud of the shell
    bumper_height: float = 0.05
    clearance: float = 0.025  # shell floor above the ground
    body_top: float = 0.30  # shell top; the radio/positioning unit rises from here to ``height``
    radio_radius: float = 0.05
    radio_x: float = -0.06
    battery_mass: float = 0.35  # 1400 mAh, 14.4 V NiCd pack (§2.2.1 gives the capacity, not the mass)
    battery_x: float = -0.12
    battery_size: tuple = (0.06, 0.12, 0.04)
    caster_radius: float = 0.0125
    caster_inset: float = 0.03  # caster centres ahead of the back bumper
    caster_y: float = 0.08
    caster_gap: float = 0.002  # as diffdrive's: the drive wheels touch first, the chassis tilts back 0.8 deg
    ir_height: float = 0.10  # side and back sensors
    ir_side_x: tuple = (0.0, -0.12)  # the front and rear sensor on each side
    ir_back_y: float = 0.07  # the two back sensors, either side of the centre line
    livery_radius: float = 0.1
    camera_distance: float = 1.0
    # Gripper (assumed, sized around the 2 in puck of §3.8 and the thesis' opening, lift and payload)
    front_x: float = 0.045  # chassis front face (without bumper), ahead of the axle
    cavity_depth: float = 0.06  # front bumper to rear beam: room for one puck
    cavity_top: float = 0.045  # underside of the gripper's top plate with the lift down: above a puck
    plate_thickness: float = 0.008
    back_plate_height: float = 0.1  # the carriage's plate on the lift slide, above the top plate
    beam_inset: float = 0.006  # beams sit this far outside the pads' front and rear edges
    pad_length: float = 0.03
    pad_thickness: float = 0.008
    pad_bottom: float = 0.005  # pad underside above the floor with the lift down
    prong_thickness: float = 0.006
    prong_clearance: float = 0.004  # between a fully open pad and its prong
    prong_bottom: float = 0.008
    prong_overhang: float = 0.004  # the prongs reach this far past the beams
    beam_height: float = 0.019  # half a puck's height with the lift down
    tip_ir_height: float = 0.029  # fingertip IR, in a puck's upper half with the lift down
    beam_margin: float = 0.005  # beam_length = jaw frame's inner width - this
    carriage_mass: float = 0.25  # top plate 60 %, back plate 20 %, prongs 10 % each
    finger_mass: float = 0.05
    pad_friction: float = 1.0
    pad_torsion: float = 0.01  # m: torsional friction (condim 4) stops a held puck pivoting between the pads
    # Hard pad contacts (the pads take priority, so these apply whatever they touch). MuJoCo's soft friction
    # lets a held puck creep down between the pads at a rate set by the contact's softness, not by the grip
    # force; measured at 2 ms with the arena's pyramidal cone: 2.8 mm/s with default contacts, 0.12 mm/s with
    # solimp 0.99-0.999, 0.011 mm/s with these. The time constant is the stiffest MuJoCo allows at a 2 ms
    # step; critically damped (ratio 1) the pads chattered on a rising puck, the grip force dropping to 2 N
    # for a few steps, so they are overdamped.
    pad_solref: tuple = (0.004, 2.0)
    pad_solimp: tuple = (0.999, 0.9999, 0.001)
    grip_force: float = 30.0  # N, jaw motor force limit: squeezes each pad with 15 N, holds 3x the payload
    grip_gain: float = 5000.0  # N/m: the servo saturates before the pads reach a puck's sides
    grip_damping: float = 300.0  # N s/m: closes the jaw in about half a second
    finger_armature: float = 0.5  # kg: the jaw motor's gearing, reflected to each pad's slide
    # The joint equality that makes the right pad mirror the left: the default soft one let them drift a
    # centimetre apart under the grip force.
    jaw_solref: tuple = (0.004, 1.0)
    jaw_solimp: tuple = (0.95, 0.99, 0.001)
    lift_margin: float = 1.3  # lift force = 1.3 x (payload + carriage) weight: 0.91 kg lifts, 2 kg cannot
    lift_gain: float = 3000.0  # N/m
    lift_damping: float = 60.0  # N s/m

    # -- derived ------------------------------------------------------------------------------------------
    @property
    def tip_x(self) -> float:
        """The jaw's front, so that back bumper to jaw tip is the thesis depth."""
        return self.front_beam_x + self.prong_overhang

    @property
    def back_x(self) -> float:
        return self.tip_x - self.depth

    @property
    def rear_beam_x(self) -> float:
        return self.front_x + self.bumper_thickness + self.cavity_depth

    @property
    def pad_x(self) -> float:
        return self.rear_beam_x + self.beam_inset + self.pad_length / 2

    @property
    def front_beam_x(self) -> float:
        return self.pad_x + self.pad_length / 2 + self.beam_inset

    @property
    def half_jaw(self) -> float:
        return self.jaw_opening / 2

    @property
    def prong_y(self) -> float:
        """Inner face of each jaw-frame prong."""
        return self.half_jaw + self.pad_thickness + self.prong_clearance

    @property
    def beam_length(self) -> float:
        return 2 * self.prong_y - self.beam_margin

    @property
    def track_width(self) -> float:
        return self.width - 2 * (self.bumper_thickness + self.wheel_width)

    @property
    def lift_force(self) -> float:
        return self.lift_margin * (self.payload + self.carriage_mass + 2 * self.finger_mass) * GRAVITY

    @property
    def footprint_radius(self) -> float:
        return math.hypot(self.back_x, self.width / 2)


def build(name: str, **overrides) -> RobotModel:
    """The R-2 called ``name``; ``overrides`` replace R2Dims fields."""
    dims = replace(R2Dims(), **overrides)
    model = mjcf.RootElement(model=name)
    chassis = model.worldbody.add("body", name="chassis")
    _chassis(chassis, dims, colour_of(name))
    max_wheel_speed = 1.5 * dims.v_max / dims.wheel_radius
    for side, y in (("left", 1), ("right", -1)):
        add_wheel(chassis, side, [0, y * dims.track_width / 2, dims.wheel_radius], dims.wheel_radius,
                  dims.wheel_width, mass=dims.wheel_mass, damping=dims.wheel_damping)
        add_velocity_motor(model, side, dims.wheel_servo_gain, dims.wheel_torque, max_wheel_speed)
    ir_names, bearings = _side_and_back_ir(model, chassis, dims)
    carriage = _gripper(model, chassis, dims)
    tip_names, tip_bearings = _fingertip_ir(model, carriage, dims)
    limits = DriveLimits(dims.v_max, dims.omega_max, dims.accel_max, dims.angular_accel_max)
    drive = DifferentialSpec(dims.wheel_radius, dims.track_width, left=("left",), right=("right",))
    effectors = {
        "grip": Effector(actuators=("grip",), joint="finger_left", ctrl_at_0=0.0, ctrl_at_1=dims.half_jaw),
        "lift": Effector(actuators=("lift",), joint="lift", ctrl_at_0=0.0, ctrl_at_1=dims.lift_travel),
    }
    touch = {f"bump_{side}": (f"bumper_{side}",) for side in ("front", "left", "right", "back")}
    touch[GRIP_TOUCH] = ("pad_left", "pad_right")
    return RobotModel(kind="r2", name=name, mjcf=model, root_body="chassis", ir_sensors=tip_names + ir_names,
                      ir_bearings=np.concatenate([tip_bearings, bearings]), ir=IRModel.for_range(dims.ir_range),
                      drive=drive, limits=limits, footprint_radius=dims.footprint_radius,
                      tracking_camera=add_tracking_camera(chassis, distance=dims.camera_distance),
                      max_traction=2 * dims.wheel_torque / dims.wheel_radius, traversability=dims.traversability,
                      effectors=effectors, touch=touch, beams=_beams(model, carriage, dims),
                      beam_length=dims.beam_length)


def _box(body, name, x, y, z, **kwargs):
    """A box geom spanning the intervals x, y and z (each a (low, high) pair) in the body frame."""
    lo, hi = np.array([x[0], y[0], z[0]]), np.array([x[1], y[1], z[1]])
    return body.add("geom", name=name, type="box", pos=(lo + hi) / 2, size=(hi - lo) / 2, **kwargs)


def _chassis(chassis, d: R2Dims, rgba) -> None:
    t, hw = d.bumper_thickness, d.width / 2
    _box(chassis, "shell", (d.back_x + t, d.front_x), (-hw + t, hw - t), (d.clearance, d.body_top),
         mass=d.shell_mass, rgba=[0.3, 0.3, 0.33, 1])
    chassis.add("geom", name="radio", type="cylinder", size=[d.radio_radius, (d.height - d.body_top) / 2],
                pos=[d.radio_x, 0, (d.height + d.body_top) / 2], mass=0.0, rgba=[0.85, 0.85, 0.85, 1])
    add_livery(chassis, rgba, d.body_top, d.livery_radius, centre_x=(d.back_x + d.front_x) / 2)
    length, width, height = d.battery_size
    _box(chassis, "battery", (d.battery_x - length / 2, d.battery_x + length / 2), (-width / 2, width / 2),
         (d.clearance, d.clearance + height), mass=d.battery_mass, contype=0, conaffinity=0, group=3)
    # The bump ring, low on the base; each side is a touch sensor. The front one is the cavity's back wall.
    ring_top = d.clearance + d.bumper_height
    grey = [0.15, 0.15, 0.15, 1]
    for side, x, y in (("front", (d.front_x, d.front_x + t), (-hw + t, hw - t)),
                       ("back", (d.back_x, d.back_x + t), (-hw + t, hw - t)),
                       ("left", (d.back_x + t, d.front_x), (hw - t, hw)),
                       ("right", (d.back_x + t, d.front_x), (-hw, -hw + t))):
        _box(chassis, f"bumper_{side}", x, y, (d.clearance, ring_top), mass=0.0, rgba=grey)
    # The cavity's side skirts continue the jaw frame's prongs back to the bumper, clear of the rear beam.
    for side, s in (("left", 1), ("right", -1)):
        y = sorted((s * d.prong_y, s * (d.prong_y + d.prong_thickness)))
        _box(chassis, f"skirt_{side}", (d.front_x, d.rear_beam_x - d.prong_overhang), y,
             (d.prong_bottom, d.cavity_top), mass=0.0, rgba=grey)
    for side, y in (("left", d.caster_y), ("right", -d.caster_y)):
        add_caster(chassis, side, d.back_x + d.caster_inset, d.caster_radius, d.caster_gap, y=y)


def _gripper(model, chassis, d: R2Dims):
    """The lift carriage with its jaw frame, and the two pads; returns the carriage body."""
    carriage = chassis.add("body", name="carriage")
    carriage.add("joint", name="lift", type="slide", axis=[0, 0, 1], range=[0, d.lift_travel], limited=True,
                 damping=d.lift_damping)
    model.actuator.add("position", name="lift", joint="lift", kp=d.lift_gain, forcelimited=True,
                       forcerange=[-d.lift_force, d.lift_force], ctrlrange=[0, d.lift_travel])
    metal = [0.7, 0.7, 0.72, 1]
    back = d.front_x + d.bumper_thickness
    outer = d.prong_y + d.prong_thickness
    plate = (d.cavity_top, d.cavity_top + d.plate_thickness)
    _box(carriage, "top_plate", (back, d.tip_x), (-outer, outer), plate, mass=d.carriage_mass * 0.6, rgba=metal)
    _box(carriage, "back_plate", (back, back + d.plate_thickness), (-outer, outer),
         (plate[1], plate[1] + d.back_plate_height), mass=d.carriage_mass * 0.2, rgba=metal)
    for side, s in (("left", 1), ("right", -1)):
        _box(carriage, f"prong_{side}", (d.rear_beam_x - d.prong_overhang, d.tip_x),
             sorted((s * d.prong_y, s * outer)), (d.prong_bottom, d.cavity_top), mass=d.carriage_mass * 0.1,
             rgba=metal)
    fingers = []
    for side, s in (("left", 1), ("right", -1)):
        finger = carriage.add("body", name=f"finger_{side}", pos=[d.pad_x, 0, 0])
        # Joint coordinate = the pad's inner face's distance from the jaw's centre line.
        finger.add("joint", name=f"finger_{side}", type="slide", axis=[0, s, 0], range=[0, d.half_jaw],
                   limited=True, damping=d.grip_damping / 2, armature=d.finger_armature)
        _box(finger, f"pad_{side}", (-d.pad_length / 2, d.pad_length / 2), sorted((0, s * d.pad_thickness)),
             (d.pad_bottom, d.cavity_top), mass=d.finger_mass, condim=4, priority=1,
             friction=[d.pad_friction, d.pad_torsion, 0.0001], solref=list(d.pad_solref),
             solimp=list(d.pad_solimp), rgba=[0.2, 0.2, 0.2, 1])
        fingers.append(finger)
    model.contact.add("exclude", body1=fingers[0], body2=fingers[1])
    model.equality.add("joint", name="jaw", joint1="finger_right", joint2="finger_left", polycoef=[0, 1, 0, 0, 0],
                       solref=list(d.jaw_solref), solimp=list(d.jaw_solimp))
    model.actuator.add("position", name="grip", joint="finger_left", kp=d.grip_gain, forcelimited=True,
                       forcerange=[-d.grip_force, d.grip_force], ctrlrange=[0, d.half_jaw])
    return carriage


def _fingertip_ir(model, carriage, d: R2Dims):
    """IR at the jaw's tips, toed in so their rays cross at maximum range: a puck ahead and to the left is
    seen by the left tip first (bearings are negative on the left tip: it looks slightly right)."""
    y = d.prong_y + d.prong_thickness / 2
    bearings = []
    for name, s in zip(TIP_IR, (1, -1)):
        bearing = -s * math.atan2(y, d.ir_range)
        site = carriage.add("site", name=name, pos=[d.tip_x, s * y, d.tip_ir_height],
                            zaxis=[math.cos(bearing), math.sin(bearing), 0], size=[0.005], group=3,
                            rgba=[1, 0.3, 0.3, 0.6])
        model.sensor.add("rangefinder", name=name, site=site, cutoff=d.ir_range)
        bearings.append(bearing)
    return TIP_IR, np.asarray(bearings)


def _side_and_back_ir(model, chassis, d: R2Dims):
    hw, (front, rear) = d.width / 2, d.ir_side_x
    layout = (("ir_left_front", front, hw, math.pi / 2), ("ir_left_rear", rear, hw, math.pi / 2),
              ("ir_right_front", front, -hw, -math.pi / 2), ("ir_right_rear", rear, -hw, -math.pi / 2),
              ("ir_back_left", d.back_x, d.ir_back_y, math.pi), ("ir_back_right", d.back_x, -d.ir_back_y, math.pi))
    for name, x, y, bearing in layout:
        site = chassis.add("site", name=name, pos=[x, y, d.ir_height], size=[0.005], group=3,
                           zaxis=[math.cos(bearing), math.sin(bearing), 0], rgba=[1, 0.3, 0.3, 0.6])
        model.sensor.add("rangefinder", name=name, site=site, cutoff=d.ir_range)
    return tuple(n for n, *_ in layout), np.array([b for *_, b in layout])


def _beams(model, carriage, d: R2Dims) -> tuple[str, ...]:
    """Break-beams from the left prong across the jaw (front, then rear)."""
    for name, x in zip(BEAMS, (d.front_beam_x, d.rear_beam_x)):
        site = carriage.add("site", name=name, pos=[x, d.prong_y, d.beam_height], zaxis=[0, -1, 0],
                            size=[0.003], group=3, rgba=[1, 0, 0, 0.6])
        model.sensor.add("rangefinder", name=name, site=site)
    return BEAMS
