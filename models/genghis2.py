"""``genghis2``: IS Robotics' Genghis-II six-legged walker (Parker §2.2.2, pp.19-20; Fig. 2-4).

Thesis values: six legs with two degrees of freedom each (swing and lift, so twelve motors); standing about
16 in long x 11 in wide x 9 in high including the radio positioning unit (0.41 x 0.28 x 0.23 m); legs about
6 in (0.15 m); two front whiskers, four near-IR sensors on the shoulders, an inclinometer, three tactile
sensors on the belly. Parker gives no speed, mass, gait or motor data; she says only that it "cannot push the
box as quickly as an R-2, due to less powerful effectors" (§6.1.1). DESIGN.md assumes 1.5 kg and a tripod
gait. Everything else below (servo torques and gains, gait frequency and stride, speed limits, sensor
placement, IR range, traversability) is assumed, and every value lives in :class:`Genghis2Dims`.

Each leg is a hip *swing* hinge about the vertical (foot fore and aft) carrying a *lift* hinge about the
body's long axis (foot up and down) and a straight leg ending in a spherical foot. Joint axes are mirrored
between the sides, so on every leg a positive swing angle moves the foot forward and a positive lift angle
raises it. At zero angles every foot touches the floor and the robot stands at its nominal height.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from dm_control import mjcf

from teamsim.models.ir import IRModel
from teamsim.models.robot import DriveLimits, RobotModel, add_tracking_camera, colour_of

# Legs in the usual hexapod numbering 1..6, counter-clockwise seen from above starting at the left front, so
# legs 1, 3, 5 (left front, left rear, right middle) form one tripod and 2, 4, 6 the other.
LEGS = ("lf", "lm", "lr", "rr", "rm", "rf")
TRIPOD_PHASE = (0.0, 0.5, 0.0, 0.5, 0.0, 0.5)  # gait phase offset of each leg, in cycles


@dataclass(frozen=True)
class GaitSpec:
    """What the tripod gait (``teamsim.controllers.skills.gait.TripodGait``) needs to know about the legs.

    Per-leg tuples follow :data:`LEGS`. ``foot_y`` is each foot's lateral position in the body frame (m,
    left positive), which sets how much a leg's stride changes with the turn rate."""
    legs: tuple[str, ...]
    phase_offset: tuple[float, ...]
    foot_y: tuple[float, ...]
    reach: float  # m, horizontal distance from a swing axis to its foot: a swing of a rad moves the foot reach*sin(a)
    swing_max: float  # rad, largest swing angle either side of the leg's neutral
    lift_stance: float  # rad, lift set-point of a foot on the ground
    lift_swing: float  # rad, lift set-point at the top of a step
    frequency: float  # Hz, step cycles per second (one stance and one swing per leg)
    turn_gain: float  # stride per unit of turn rate, relative to the no-slip ideal (front and rear feet slip)

    @property
    def actuators(self) -> tuple[str, ...]:
        return tuple(f"{joint}_{leg}" for leg in self.legs for joint in ("swing", "lift"))

    @property
    def stride_max(self) -> float:
        """Longest foot travel during one stance, m."""
        return 2 * self.reach * math.sin(self.swing_max)

    @property
    def foot_speed_max(self) -> float:
        """Fastest a stance foot can move back relative to the body, m/s: a stride every half cycle."""
        return 2 * self.frequency * self.stride_max


@dataclass(frozen=True)
class Genghis2Dims:
    # Parker §2.2.2 (standing size, including the radio positioning unit; leg length).
    length: float = 0.41
    width: float = 0.28
    height: float = 0.23
    leg_length: float = 0.15  # hip axis to foot centre
    # DESIGN.md: mass assumed 1.5 kg in total (split below).
    mass: float = 1.5
    # Assumed body layout. The whiskers stick out whisker_reach ahead of the chassis nose, so chassis length =
    # length - whisker_reach; the feet are at +-width/2, so the hips sit width/2 - reach off the centre line.
    whisker_reach: float = 0.04
    whisker_spread: float = 0.045  # m each whisker tip reaches sideways beyond its root
    whisker_radius: float = 0.003
    whisker_root_y: float = 0.02  # m off the centre line, on the nose
    whisker_height: float = 0.11  # m above the floor: above a stepping foot, below a box or wall top
    hip_height: float = 0.12  # m above the floor when standing; the chassis is centred on it
    chassis_thickness: float = 0.05
    leg_spacing: float = 0.13  # m between neighbouring hips along the body
    foot_radius: float = 0.012
    shank_radius: float = 0.006
    swing_stop: float = 0.45  # rad either side of neutral: the swing joint's mechanical range
    lift_stops: tuple[float, float] = (-0.3, 0.45)  # rad, the lift joint's range: limp legs stop the belly 3 cm up
    foot_friction: float = 1.2
    radio_radius: float = 0.03  # the radio positioning unit on top: a cylinder up to the standing height
    belly_pad: tuple[float, float, float] = (0.04, 0.025, 0.003)  # half sizes of each belly tactile pad
    belly_pad_inset: float = 0.01  # m from the chassis ends to the front and back pads
    # Each leg: a hip bracket (servo horn), the shank and the foot.
    leg_masses: tuple[float, float, float] = (0.01, 0.03, 0.01)
    radio_mass: float = 0.12
    whisker_mass: float = 0.005
    # Assumed servos: high-torque hobby position servos, 1.5 N m (about 15 kg cm) on both joints. The swing
    # torque is what lets Genghis-II push the long box at all (Parker §6.1.1: it pushes, more weakly and slowly
    # than an R-2): at 0.3 N m its stance tripod stalled at 5.4 N and an end of the box never moved; at 1.5 N m
    # its feet slip first (friction 1.2 x 14.7 N of weight) and an end creeps (about 0.1 degree/s of box turn).
    # Lift 1.5 N m, since one leg of a tripod carries half the weight (7.4 N at the 0.104 m reach is 0.77 N m)
    # and must also lift it.
    swing_torque: float = 1.5
    lift_torque: float = 1.5
    swing_gain: float = 10.0  # N m/rad
    lift_gain: float = 30.0  # N m/rad
    joint_damping: float = 0.05  # N m s/rad
    joint_armature: float = 0.002  # kg m^2, the servo's reflected rotor inertia
    # Mean horizontal push over a step cycle relative to the stance tripod's stall force (3 x swing_torque /
    # reach = 43 N): the feet slip before the servos stall. Calibrated so that it walks a bog at traversability x
    # v_max (10.4 N while walking); standing against the long heavy box it pushes 13.8 N steady (measured).
    # This sets max_traction, which calibrates bog drag.
    push_efficiency: float = 0.24
    # Assumed gait (Parker gives none): tripod at 0.8 Hz, swing up to 0.3 rad, foot raised by 0.3 rad of lift.
    frequency: float = 0.8
    swing_max: float = 0.3
    lift_swing: float = 0.3
    # Turning, a two-DOF leg moves its foot only fore and aft, so the front and rear feet slip sideways and a
    # tripod stepping the ideal differential stride turns at only about 75 % of the rate (measured here on the
    # 1.0-1.2 friction floor; 60 % with 0.3 N m swing servos). The gait steps 1/0.75 times harder to turn at the
    # commanded rate.
    turn_gain: float = 1.0 / 0.75
    # Assumed command limits, well below the R-2's 0.457 m/s (§2.2.1): Genghis-II is the slower robot (§6.1.1).
    v_max: float = 0.08
    omega_max: float = 0.4  # rad/s; turning on the spot at this rate uses nearly the whole stride
    accel_max: float = 0.2
    angular_accel_max: float = 1.0
    # Assumed sensors: four 0.3 m near-IR rangers at the shoulder corners, the front pair looking 30 degrees
    # either side of ahead and the rear pair 30 degrees either side of behind.
    ir_range: float = 0.3
    ir_bearings: tuple[float, ...] = (math.radians(30), math.radians(-30), math.radians(150), math.radians(-150))
    # Assumed: a light walker with small feet steps over and out of soft ground that bogs wheels down (Chand's
    # Table 5.22 scores wheeled robots 0.1-0.3 and tracked 1.0); we put it between the two.
    traversability: float = 0.7

    @property
    def chassis_length(self) -> float:
        return self.length - self.whisker_reach

    @property
    def foot_drop(self) -> float:
        """Height of a hip axis above its foot centre when standing."""
        return self.hip_height - self.foot_radius

    @property
    def reach(self) -> float:
        """Horizontal distance from a hip to its foot centre when standing."""
        return math.sqrt(self.leg_length ** 2 - self.foot_drop ** 2)

    @property
    def hip_y(self) -> float:
        return self.width / 2 - self.reach

    @property
    def chassis_mass(self) -> float:
        return self.mass - 6 * sum(self.leg_masses) - self.radio_mass - 2 * self.whisker_mass


def _leg_layout(dims: Genghis2Dims) -> dict[str, tuple[float, int]]:
    """Leg name -> (hip x, side: +1 left, -1 right)."""
    x = {"f": dims.leg_spacing, "m": 0.0, "r": -dims.leg_spacing}
    return {leg: (x[leg[1]], 1 if leg[0] == "l" else -1) for leg in LEGS}


def gait_spec(dims: Genghis2Dims = Genghis2Dims()) -> GaitSpec:
    """The gait's view of the legs; refuses a speed limit the gait cannot step."""
    layout = _leg_layout(dims)
    gait = GaitSpec(legs=LEGS, phase_offset=TRIPOD_PHASE, foot_y=tuple(layout[leg][1] * dims.width / 2 for leg in LEGS),
                    reach=dims.reach, swing_max=dims.swing_max, lift_stance=0.0, lift_swing=dims.lift_swing,
                    frequency=dims.frequency, turn_gain=dims.turn_gain)
    if dims.v_max > gait.foot_speed_max:
        raise ValueError(f"v_max {dims.v_max} m/s exceeds what the gait can step ({gait.foot_speed_max:.3f} m/s)")
    return gait


def build(name: str, **overrides) -> RobotModel:
    """The robot called ``name``; ``overrides`` replace Genghis2Dims fields."""
    dims = replace(Genghis2Dims(), **overrides)
    model = mjcf.RootElement(model=name)
    rgba = colour_of(name)
    half_length, half_width = dims.chassis_length / 2, dims.hip_y
    chassis = model.worldbody.add("body", name="chassis")
    chassis.add("geom", name="shell", type="box", pos=[0, 0, dims.hip_height],
                size=[half_length, half_width, dims.chassis_thickness / 2], mass=dims.chassis_mass,
                rgba=[0.3, 0.3, 0.32, 1])
    top = dims.hip_height + dims.chassis_thickness / 2
    radio_half = (dims.height - top) / 2
    chassis.add("geom", name="radio", type="cylinder", size=[dims.radio_radius, radio_half],
                pos=[0, 0, top + radio_half], mass=dims.radio_mass, rgba=rgba)
    # A white mark on the front of the deck shows the heading in videos (visual only).
    chassis.add("geom", name="nose", type="box", size=[0.02, half_width * 0.6, 0.004],
                pos=[half_length - 0.03, 0, top + 0.004], rgba=[1, 1, 1, 1], contype=0, conaffinity=0, mass=0)

    # Belly tactile pads under the chassis: contact-force sensors (touch entries of the same names).
    bottom = dims.hip_height - dims.chassis_thickness / 2
    pad = dims.belly_pad
    belly = {}
    pad_x = half_length - pad[0] - dims.belly_pad_inset
    for part, x in (("front", pad_x), ("middle", 0.0), ("back", -pad_x)):
        chassis.add("geom", name=f"belly_{part}", type="box", size=list(pad), pos=[x, 0, bottom - pad[2]],
                    mass=0, rgba=[0.9, 0.6, 0.1, 1])
        belly[f"belly_{part}"] = (f"belly_{part}",)

    # Front whiskers: thin stiff rods from the nose, angled outward; their contact force is the reading.
    whiskers = {}
    for side, s in (("left", 1), ("right", -1)):
        root = [half_length, s * dims.whisker_root_y, dims.whisker_height]
        tip = [half_length + dims.whisker_reach - dims.whisker_radius, s * (dims.whisker_root_y + dims.whisker_spread),
               dims.whisker_height]
        chassis.add("geom", name=f"whisker_{side}", type="capsule", fromto=root + tip, size=[dims.whisker_radius],
                    mass=dims.whisker_mass, rgba=[0.9, 0.9, 0.9, 1])
        whiskers[f"whisker_{side}"] = (f"whisker_{side}",)

    # Legs: swing hinge (vertical axis) -> lift hinge (long axis) -> straight leg and spherical foot.
    bracket_mass, shank_mass, foot_mass = dims.leg_masses
    for leg, (x, s) in _leg_layout(dims).items():
        hip = chassis.add("body", name=f"hip_{leg}", pos=[x, s * dims.hip_y, dims.hip_height])
        hip.add("joint", name=f"swing_{leg}", type="hinge", axis=[0, 0, -s], damping=dims.joint_damping,
                armature=dims.joint_armature, range=[-dims.swing_stop, dims.swing_stop])
        hip.add("geom", name=f"bracket_{leg}", type="sphere", size=[dims.shank_radius * 2.5], mass=bracket_mass,
                contype=0, conaffinity=0, rgba=[0.2, 0.2, 0.2, 1])
        thigh = hip.add("body", name=f"leg_{leg}")
        thigh.add("joint", name=f"lift_{leg}", type="hinge", axis=[s, 0, 0], damping=dims.joint_damping,
                  armature=dims.joint_armature, range=list(dims.lift_stops))
        foot = [0, s * dims.reach, -dims.foot_drop]
        thigh.add("geom", name=f"shank_{leg}", type="capsule", fromto=[0, 0, 0] + foot, size=[dims.shank_radius],
                  mass=shank_mass, rgba=[0.25, 0.25, 0.25, 1])
        thigh.add("geom", name=f"foot_{leg}", type="sphere", pos=foot, size=[dims.foot_radius],
                  mass=foot_mass, friction=[dims.foot_friction, 0.01, 0.001], rgba=[0.1, 0.1, 0.1, 1])
        # A leg's root sits inside the chassis edge: the two never collide (a leg's hinge is their only link).
        model.contact.add("exclude", body1=chassis, body2=thigh)
        for joint, gain, torque, low, high in (
                ("swing", dims.swing_gain, dims.swing_torque, -dims.swing_max, dims.swing_max),
                ("lift", dims.lift_gain, dims.lift_torque, 0.0, dims.lift_swing)):
            model.actuator.add("position", name=f"{joint}_{leg}", joint=f"{joint}_{leg}", kp=gain,
                               forcerange=[-torque, torque], forcelimited=True, ctrlrange=[low, high],
                               ctrllimited=True)

    # Four near-IR rangers at the shoulder corners (rangefinders look along their site's +Z).
    ir_names = []
    for k, bearing in enumerate(dims.ir_bearings):
        c, s = math.cos(bearing), math.sin(bearing)
        site = chassis.add("site", name=f"ir{k}", pos=[math.copysign(half_length, c), math.copysign(half_width, s),
                                                        dims.hip_height], size=[0.008], zaxis=[c, s, 0],
                           rgba=[1, 0.3, 0.3, 0.6], group=3)
        model.sensor.add("rangefinder", name=f"ir{k}", site=site, cutoff=dims.ir_range)
        ir_names.append(f"ir{k}")

    camera = add_tracking_camera(chassis, distance=0.9)
    gait = gait_spec(dims)
    limits = DriveLimits(dims.v_max, dims.omega_max, dims.accel_max, dims.angular_accel_max)
    # Horizontal push at full effort: the three stance legs' swing servos through the foot lever, over a step.
    traction = dims.push_efficiency * 3 * dims.swing_torque / dims.reach
    return RobotModel(kind="genghis2", name=name, mjcf=model, root_body="chassis", ir_sensors=tuple(ir_names),
                      ir_bearings=np.asarray(dims.ir_bearings), ir=IRModel.for_range(dims.ir_range), drive=gait,
                      # The circle around the standing 0.41 x 0.28 m outline encloses every part.
                      limits=limits, footprint_radius=math.hypot(dims.length / 2, dims.width / 2),
                      tracking_camera=camera, max_traction=traction, traversability=dims.traversability,
                      touch={**whiskers, **belly}, inclinometer=True)
