"""``janitor``: the janitorial-service robot of Parker §6.2, a differential-drive base with two IR rings and tools.

Parker's simulated janitors had a floor vacuum, a garbage dumper and a duster arm extendable to the side, as
switches without mechanics (§2.1), and two rings of proximity sensors at two heights, so that an object that
triggers the lower ring and not the upper one is "dustable" (§6.2.1). Here the base is Chand's differential-drive
robot (:mod:`teamsim.models.diffdrive`), smaller and quicker to turn for a furnished room, and every tool is an
actuated part with a footprint the mission measures (never a switch):

- ``duster``: an arm hinged on the right of the body, folded back along it at 0 and swung out square to the
  right at 1; its tip site ``duster_tip`` must pass by an object's sides for the object to be dusted;
- ``emptier``: a nozzle on a slide at the front, retracted at 0 and reaching ``emptier_reach`` forward at 1;
  a can is emptied while the tip site ``emptier_tip`` is held at it;
- ``cleaner``: a brush deck under the body on a vertical slide, raised at 0 and at the floor at 1; the floor
  under the lowered deck (site ``cleaner``) is cleaned.

The tools do not collide (contype 0): their footprints are measured, and a swinging arm caught on a table leg
would be a mechanism study of its own. They sit between the rings' heights, so no ray of the robot's own rings
meets them. A robot carries the tools of its tasks only (``build(name, tools=...)``, named by task).
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, replace

import numpy as np

from teamsim.models import diffdrive
from teamsim.models.robot import Effector, RobotModel, add_ir_ring

EMPTY, DUST, CLEAN = "empty-garbage", "dust-furniture", "clean-floor"
TOOL_OF_TASK = {EMPTY: "emptier", DUST: "duster", CLEAN: "cleaner"}
TASKS = tuple(TOOL_OF_TASK)
TOOL_RGBA = {"emptier": (0.9, 0.5, 0.1, 1), "duster": (0.95, 0.3, 0.6, 1), "cleaner": (0.2, 0.6, 0.95, 0.9)}


@dataclass(frozen=True)
class JanitorDims:
    # The base (DiffDriveDims fields; not in the thesis: sized for a furnished room).
    radius: float = 0.25
    height: float = 0.45
    mass: float = 8.0
    ir_count: int = 12
    ir_range: float = 1.0
    ir_height: float = 0.35  # the upper ring: above a dustable object's height
    v_max: float = 0.4
    omega_max: float = 1.2
    accel_max: float = 0.5
    angular_accel_max: float = 2.0
    wheel_radius: float = 0.06
    wheel_inset: float = 0.05
    # The lower ring: below a dustable object's height (the mission's ``dust_height``, 0.25 m by default).
    low_ir_height: float = 0.06
    # Tools (assumed).
    duster_length: float = 0.3  # m from the hinge to the tip
    duster_height: float = 0.29  # over the top of a dustable object (below 0.25 m), under the upper ring
    emptier_reach: float = 0.15  # m the nozzle slides out
    emptier_height: float = 0.25
    cleaner_half_width: float = 0.2  # m: the deck cleans a strip 0.4 m wide
    cleaner_half_depth: float = 0.08
    tool_gain: float = 20.0  # position-servo stiffness of every tool

    def base(self) -> dict:
        """The fields the differential-drive base takes."""
        names = {f.name for f in fields(diffdrive.DiffDriveDims)}
        return {k: v for k, v in asdict(self).items() if k in names}


def build(name: str, tools: tuple[str, ...] = TASKS, **overrides) -> RobotModel:
    """The janitor called ``name`` with the tools of ``tools`` (task names, :data:`TASKS`); ``overrides``
    replace JanitorDims fields."""
    unknown = [t for t in tools if t not in TOOL_OF_TASK]
    if unknown:
        raise ValueError(f"tools: unknown task {unknown[0]!r}; allowed: {', '.join(TASKS)}")
    dims = replace(JanitorDims(), **overrides)
    robot = diffdrive.build(name, **dims.base())
    chassis = robot.mjcf.find("body", "chassis")
    low, low_bearings = add_ir_ring(chassis, dims.ir_count, dims.radius + 0.005, dims.low_ir_height, dims.ir_range,
                                    prefix="low")
    effectors = {}
    for task in tools:
        tool = TOOL_OF_TASK[task]
        effectors[tool] = _TOOL_BUILDERS[tool](robot.mjcf, chassis, dims)
    return replace(robot, kind="janitor", ir_sensors=robot.ir_sensors + low,
                   ir_bearings=np.concatenate([robot.ir_bearings, low_bearings]), effectors=effectors)


def _servo(model, joint: str, low: float, high: float, gain: float) -> None:
    model.actuator.add("position", name=joint, joint=joint, kp=gain, ctrlrange=[low, high], ctrllimited=True,
                       forcelimited=True, forcerange=[-5, 5])


def _duster(model, chassis, d: JanitorDims) -> Effector:
    arm = chassis.add("body", name="duster", pos=[0, -d.radius, d.duster_height])
    arm.add("joint", name="duster", type="hinge", axis=[0, 0, 1], range=[0, math.pi / 2], limited=True,
            damping=0.5)
    arm.add("geom", name="duster_arm", type="box", size=[d.duster_length / 2, 0.015, 0.015],
            pos=[-d.duster_length / 2, 0, 0], mass=0.2, contype=0, conaffinity=0, rgba=TOOL_RGBA["duster"])
    arm.add("site", name="duster_tip", pos=[-d.duster_length, 0, 0], size=[0.02], rgba=TOOL_RGBA["duster"])
    _servo(model, "duster", 0.0, math.pi / 2, d.tool_gain)
    return Effector(actuators=("duster",), joint="duster", ctrl_at_0=0.0, ctrl_at_1=math.pi / 2)


def _emptier(model, chassis, d: JanitorDims) -> Effector:
    nozzle = chassis.add("body", name="emptier", pos=[d.radius - 0.1, 0, d.emptier_height])
    nozzle.add("joint", name="emptier", type="slide", axis=[1, 0, 0], range=[0, d.emptier_reach], limited=True,
               damping=5.0)
    nozzle.add("geom", name="emptier_nozzle", type="box", size=[0.06, 0.03, 0.03], pos=[0.04, 0, 0], mass=0.2,
               contype=0, conaffinity=0, rgba=TOOL_RGBA["emptier"])
    nozzle.add("site", name="emptier_tip", pos=[0.1, 0, 0], size=[0.02], rgba=TOOL_RGBA["emptier"])
    _servo(model, "emptier", 0.0, d.emptier_reach, d.tool_gain * 10)
    return Effector(actuators=("emptier",), joint="emptier", ctrl_at_0=0.0, ctrl_at_1=d.emptier_reach)


def _cleaner(model, chassis, d: JanitorDims) -> Effector:
    travel = diffdrive.DiffDriveDims.ground_clearance - 0.01  # the deck drops from under the shell to the floor
    deck = chassis.add("body", name="cleaner", pos=[0, 0, travel + 0.006])
    deck.add("joint", name="cleaner", type="slide", axis=[0, 0, -1], range=[0, travel], limited=True, damping=5.0)
    deck.add("geom", name="cleaner_deck", type="box", size=[d.cleaner_half_depth, d.cleaner_half_width, 0.004],
             mass=0.2, contype=0, conaffinity=0, rgba=TOOL_RGBA["cleaner"])
    deck.add("site", name="cleaner", size=[0.02], rgba=TOOL_RGBA["cleaner"])
    _servo(model, "cleaner", 0.0, travel, d.tool_gain * 10)
    return Effector(actuators=("cleaner",), joint="cleaner", ctrl_at_0=0.0, ctrl_at_1=travel)


_TOOL_BUILDERS = {"duster": _duster, "emptier": _emptier, "cleaner": _cleaner}
