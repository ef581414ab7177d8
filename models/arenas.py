"""Arenas: the floor, walls, obstacles, lights and the top-down camera that robots are attached into."""
from __future__ import annotations

import math
from dataclasses import dataclass

from dm_control import mjcf

WALL_RGBA = (0.55, 0.5, 0.45, 1)
OBSTACLE_RGBA = (0.45, 0.35, 0.3, 1)


@dataclass(frozen=True)
class Box:
    """An axis-aligned static box obstacle: centre (x, y), half sizes, yaw."""
    x: float
    y: float
    half_x: float
    half_y: float
    half_z: float = 0.25
    yaw: float = 0.0


@dataclass(frozen=True)
class Bog:
    """Boggy ground (Chand ch.6-8): an axis-aligned zone, centre (x, y) and half sizes. It is drawn here and
    resists motion physically in the world (see ``teamsim.world``), in proportion to each robot's
    traversability."""
    x: float
    y: float
    half_x: float
    half_y: float

    def contains(self, x, y):
        return (abs(x - self.x) <= self.half_x) & (abs(y - self.y) <= self.half_y)


def add_bog(arena: mjcf.RootElement, bog: Bog, name: str) -> None:
    """Draw the bog as a thin brown patch that nothing collides with."""
    arena.worldbody.add("geom", name=name, type="box", pos=[bog.x, bog.y, 0.001],
                        size=[bog.half_x, bog.half_y, 0.001], rgba=[0.35, 0.25, 0.12, 0.9],
                        contype=0, conaffinity=0)


def walled_room(size_x: float, size_y: float, *, wall_height: float = 0.5, wall_thickness: float = 0.1,
                obstacles: tuple[Box, ...] = (), physics_dt: float = 0.002, name: str = "arena",
                camera_fovy: float = 45.0, aspect: float = 4 / 3) -> mjcf.RootElement:
    """A rectangular room centred on the origin, with static box obstacles and a top-down camera ``top``."""
    arena = mjcf.RootElement(model=name)
    arena.compiler.angle = "radian"  # every angle teamsim writes (joint ranges, euler) is in radians
    arena.option.timestep = physics_dt
    arena.option.integrator = "implicitfast"
    # Objects at rest (pucks, boxes) sleep until an awake body touches them: robots never sleep (MuJoCo's compiler
    # keeps actuated trees awake), so nothing a robot pushes, grasps or carries is affected. Ten resting pucks made
    # 30 of the cleanup's 48 contacts every step; asleep, the mission runs 1.5x faster (`teamsim bench cleanup`).
    arena.option.flag.sleep = "enable"
    arena.visual.headlight.ambient = [0.35, 0.35, 0.35]  # light the walls' sides, not just their tops
    arena.visual.headlight.diffuse = [0.4, 0.4, 0.4]
    arena.visual.quality.shadowsize = 0  # shadows cost software GL a lot and add little from above
    getattr(arena.visual, "global").offwidth = 1920
    getattr(arena.visual, "global").offheight = 1080
    grid = arena.asset.add("texture", name="grid", type="2d", builtin="checker", width=256, height=256,
                           rgb1=[0.82, 0.82, 0.8], rgb2=[0.74, 0.74, 0.72])
    floor_material = arena.asset.add("material", name="floor", texture=grid, texrepeat=[1, 1],
                                     texuniform=True)
    arena.worldbody.add("light", name="sun", pos=[0, 0, 10], dir=[0, 0, -1], directional=True,
                        diffuse=[0.8, 0.8, 0.8], castshadow=False)
    # Collision with a plane is infinite whatever its size; the size only bounds what is drawn.
    arena.worldbody.add("geom", name="floor", type="plane", size=[size_x, size_y, 0.1], material=floor_material,
                        friction=[1.0, 0.005, 0.0001])
    hx, hy, t, h = size_x / 2, size_y / 2, wall_thickness / 2, wall_height / 2
    for wall, pos, size in (("north", [0, hy + t, h], [hx + 2 * t, t, h]),
                            ("south", [0, -hy - t, h], [hx + 2 * t, t, h]),
                            ("east", [hx + t, 0, h], [t, hy, h]),
                            ("west", [-hx - t, 0, h], [t, hy, h])):
        arena.worldbody.add("geom", name=f"wall_{wall}", type="box", pos=pos, size=size, rgba=WALL_RGBA)
    for k, box in enumerate(obstacles):
        arena.worldbody.add("geom", name=f"obstacle{k}", type="box", pos=[box.x, box.y, box.half_z],
                            size=[box.half_x, box.half_y, box.half_z], euler=[0, 0, box.yaw], rgba=OBSTACLE_RGBA)
    # Height at which the whole room (plus a margin) fits a camera of this field of view and aspect.
    half_view = 1.08 * max(hy + wall_thickness, (hx + wall_thickness) / aspect)
    height = half_view / math.tan(math.radians(camera_fovy) / 2)
    arena.worldbody.add("camera", name="top", pos=[0, 0, height], xyaxes=[1, 0, 0, 0, 1, 0], fovy=camera_fovy)
    return arena
