"""Mission objects: Parker's pucks and the long heavy box, as free bodies to attach into an arena.

Static walls and obstacles are part of the arena (``teamsim.models.arenas``).
"""
from __future__ import annotations

from dataclasses import dataclass

from dm_control import mjcf

INCH = 0.0254


@dataclass(frozen=True)
class PuckDims:
    """Parker §3.8: the spill is cylinders 2 in in diameter and 1.5 in high. Mass and friction are assumed
    (a solid plastic cylinder of that size is about 0.08 kg)."""
    radius: float = 1.0 * INCH
    height: float = 1.5 * INCH
    mass: float = 0.08
    friction: float = 0.8
    # N m s per rad/s (and N s per m/s) on the puck's free joint: rolling resistance. MuJoCo's contacts as used
    # here have none, and a puck knocked onto its side rolled on at about 3 mm/s for the rest of the mission
    # (measured: five pucks from the goal to the far wall, kill-red seed 5). With this a puck rolling at 0.1 m/s
    # stops within 6 cm, and a sliding or carried puck is unaffected (the force is 1e-4 of its friction). Rolling
    # friction (condim 6) does the same but adds 4 constraint rows per puck contact, half as many again in all.
    roll_damping: float = 1.5e-4


@dataclass(frozen=True)
class BoxDims:
    """Parker §6.1: a long, heavy box that one robot pushing at its middle cannot move. The thesis gives no
    size or mass; these are assumed so that one R-2 (31.5 N of traction) cannot slide it (friction
    0.5 x 7.5 kg x 9.81 = 36.8 N) but can turn it by pushing one end. Its contact takes priority over the
    floor's (so its own friction applies) and is hard: with default soft contact a push below the friction
    limit made the box creep about 3 mm/s."""
    length: float = 1.5
    depth: float = 0.3
    height: float = 0.3
    mass: float = 7.5
    friction: float = 0.5


def puck(name: str, dims: PuckDims = PuckDims(), rgba=(0.95, 0.75, 0.1, 1)) -> mjcf.RootElement:
    model = mjcf.RootElement(model=name)
    body = model.worldbody.add("body", name="puck")
    body.add("geom", name="shell", type="cylinder", size=[dims.radius, dims.height / 2],
             pos=[0, 0, dims.height / 2], mass=dims.mass, rgba=rgba, friction=[dims.friction, 0.005, 0.0001],
             condim=4)  # (against the floor, MuJoCo takes the larger friction: the floor's 1.0)
    return model


def box(name: str, dims: BoxDims = BoxDims(), rgba=(0.6, 0.45, 0.3, 1)) -> mjcf.RootElement:
    model = mjcf.RootElement(model=name)
    body = model.worldbody.add("body", name="box")
    body.add("geom", name="shell", type="box", size=[dims.depth / 2, dims.length / 2, dims.height / 2],
             pos=[0, 0, dims.height / 2], mass=dims.mass, rgba=rgba, friction=[dims.friction, 0.005, 0.0001],
             priority=1, solref=[0.004, 1], solimp=[0.999, 0.9999, 0.001])
    return model


def place_puck(arena: mjcf.RootElement, name: str, dims: PuckDims, x: float, y: float) -> mjcf.Element:
    """A puck standing at (x, y), with its rolling resistance (``dims.roll_damping`` on the free joint): every
    world places its pucks through here. (Placed without it, the cleanup's pucks knocked onto their side rolled on
    at 0.6 mm/s for the rest of the mission, out of the goal zone and against the walls.)"""
    return place(arena, puck(name, dims), x, y, damping=dims.roll_damping)


def place(arena: mjcf.RootElement, thing: mjcf.RootElement, x: float, y: float, yaw: float = 0.0,
          z: float = 0.0, damping: float = 0.0) -> mjcf.Element:
    """Attach a free object into the arena at (x, y, z) with heading ``yaw`` (and ``damping`` on its motion)."""
    frame = arena.attach(thing)
    frame.add("joint", type="free", damping=damping)
    frame.pos = [x, y, z]
    frame.euler = [0, 0, yaw]
    return frame
