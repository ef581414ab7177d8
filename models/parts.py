"""Small MJCF builders shared by the wheeled robots: wheels, velocity-servo motors, ball casters."""
from __future__ import annotations

from dm_control import mjcf

TYRE_FRICTION = (1.2, 0.01, 0.001)
TYRE_RGBA = (0.1, 0.1, 0.1, 1)


def add_wheel(parent: mjcf.Element, name: str, pos, radius: float, width: float, mass: float,
              damping: float = 0.05, friction: tuple = TYRE_FRICTION) -> mjcf.Element:
    """A cylinder wheel on a hinge about the parent's y axis; the hinge joint is called ``name``.
    Positive rotation rolls the parent forward (+x)."""
    wheel = parent.add("body", name=f"{name}_wheel", pos=list(pos))
    joint = wheel.add("joint", name=name, type="hinge", axis=[0, 1, 0], damping=damping)
    wheel.add("geom", name=f"{name}_tyre", type="cylinder", size=[radius, width / 2], zaxis=[0, 1, 0],
              mass=mass, friction=list(friction), rgba=list(TYRE_RGBA))
    return joint


def add_velocity_motor(model: mjcf.RootElement, joint: str, gain: float, torque: float, max_speed: float) -> str:
    """A velocity servo on ``joint`` (actuator of the same name): torque = gain x speed error, within +-torque."""
    model.actuator.add("velocity", name=joint, joint=joint, kv=gain, forcerange=[-torque, torque],
                       forcelimited=True, ctrlrange=[-max_speed, max_speed], ctrllimited=True)
    return joint


def add_caster(parent: mjcf.Element, name: str, x: float, radius: float, gap: float, y: float = 0.0) -> None:
    """A frictionless ball caster (condim 1: normal load only). A caster with lateral friction stops a
    differential robot turning (maxspahn/gym_envs_urdf#140). It rides ``gap`` above the floor so the drive
    wheels carry the load: rigid supports share weight arbitrarily, and lightly loaded wheels slip."""
    # Priority 1: MuJoCo gives a contact the larger condim of two equal-priority geoms, so against the floor's
    # condim 3 the caster would drag with the floor's friction (measured 19 N on an R-2).
    parent.add("geom", name=f"caster_{name}", type="sphere", size=[radius], pos=[x, y, radius + gap], condim=1,
               priority=1, mass=0.1, rgba=[0.2, 0.2, 0.2, 1])


def add_livery(body: mjcf.Element, rgba, top: float, radius: float, centre_x: float = 0.0) -> None:
    """A disc in the robot's team colour on its top and a white nose pointing forward, so videos show who is
    who and where each robot faces. Visual only (no collision, negligible mass)."""
    body.add("geom", name="lid", type="cylinder", size=[radius, 0.005], pos=[centre_x, 0, top + 0.005],
             rgba=list(rgba), contype=0, conaffinity=0, mass=0.01)
    body.add("geom", name="nose", type="box", size=[radius * 0.25, 0.04, 0.006],
             pos=[centre_x + radius * 0.75, 0, top + 0.012], rgba=[1, 1, 1, 1], contype=0, conaffinity=0, mass=0.01)


GRAVITY = 9.81


def max_traction(motor_force: float, driven_load_kg: float, friction: float) -> float:
    """The horizontal force (N) a robot can push with at full effort: its motors' force at the ground,
    unless the driven wheels slip first (friction x weight they carry)."""
    return min(motor_force, friction * driven_load_kg * GRAVITY)
