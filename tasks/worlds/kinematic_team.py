"""A team without physics: the explore mission's kinematic backend, as Chand's own MATLAB simulations ran (§8.2).

Each robot is a ``KinematicBody`` in the world's boxes (ideal IR ranges to the boxes, walls and the other robots'
enclosing circles; exact positioning fixes every tick), its controller the same as in physics, its messages on
the same ``teamsim.network``. A motion that would touch a box,
a wall or another robot is refused and the robot halted, as a bumper stops it. Terrain (docs/decisions.md,
"Exploration"): in a bog a robot moves at its traversability times the commanded speed, the physics bog's top
speed; the drive effort a controller reads is the share of the motors' force the motion needs, as measured on the
physics robots: ``FIRM_EFFORT`` per unit of speed on firm ground, ``BOG_EFFORT`` / traversability in a bog.
Faults: kill and remove (the robot stops and falls silent), radio-off, break-motor (it cannot move), slow.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from numba import njit

from teamsim.config import ConfigError
from teamsim.controllers.base import Observation
from teamsim.faults import Fault
from teamsim.network import Network
from teamsim.positioning import PoseFix
from teamsim.tasks.worlds.navigation import KinematicBody, NavWorld

# The drive effort model, from the physics robots (decisions.md, "Exploration"): on firm ground about 0.05 of full
# effort at top speed; in a bog 0.3 at a tracked robot's top speed, the wheeled robots' motors saturating.
FIRM_EFFORT = 0.05  # effort per unit of speed / v_max on firm ground
BOG_EFFORT = 0.3  # effort per unit of speed / (traversability x v_max) in a bog
KINEMATIC_FAULTS = ("kill", "remove", "radio-off", "break-motor", "slow")
REACH_MARGIN = 1e-3  # m beyond the IR's reach within which another robot's circle is still ray-cast


@dataclass
class Member:
    body: KinematicBody
    controller: Callable[[Observation], object]
    traversability: float
    alive: bool = True
    speed_factor: float = 1.0
    effort: float = 0.0
    behaviour: str = "idle"
    travelled: float = 0.0
    touches: int = 0
    trail: list = field(default_factory=list)  # (time, x, y)


class KinematicTeam:
    def __init__(self, world: NavWorld, bogs, members: dict[str, Member], network: Network,
                 faults: list[Fault] = (), control_dt: float = 0.1):
        self.world = world
        self.bogs = list(bogs)
        self.members = members
        self.network = network
        self.control_dt = control_dt
        for fault in faults:
            if fault.kind not in KINEMATIC_FAULTS:
                raise ConfigError(f"--fault {fault.kind}: the kinematic backend has {', '.join(KINEMATIC_FAULTS)}")
            if fault.robot not in members:
                raise ConfigError(f"--fault {fault.kind}:{fault.robot}: no robot {fault.robot!r} in the team; "
                                  f"allowed: {', '.join(members)}")
        self.faults = sorted(faults, key=lambda f: f.time)
        self.time = 0.0
        self.events: list[dict] = []

    def in_bog(self, x: float, y: float) -> bool:
        return any(abs(x - b.x) <= b.half_x and abs(y - b.y) <= b.half_y for b in self.bogs)

    def tick(self) -> None:
        """Faults due, the network, then every live robot senses, decides and moves."""
        now = self.time
        while self.faults and self.faults[0].time <= now + 1e-9:
            self._apply(self.faults.pop(0))
        live = {name: m for name, m in self.members.items() if m.alive}
        self.network.update(now, {name: np.array([m.body.x, m.body.y]) for name, m in live.items()})
        for name, member in live.items():
            self._control(name, member, now)
        self.time = round(now + self.control_dt, 9)

    def _control(self, name: str, member: Member, now: float) -> None:
        body = member.body
        ranges = self._ranges(name, body)
        observation = Observation(time=now, robot=name, ir_raw=ranges, ir_range=ranges, ir_bearings=body.bearings,
                                  pose=PoseFix(body.x, body.y, body.heading, now),
                                  inbox=tuple(self.network.take_inbox(name)),
                                  robots_present=self.network.robots_present(name, now), velocity=body.velocity,
                                  drive_effort=member.effort)
        command = member.controller(observation)
        self.network.set_outbox(name, command.broadcast)
        if command.behaviour != member.behaviour:
            self.events.append({"t": round(now, 6), "event": "behaviour", "robot": name,
                                "from": member.behaviour, "to": command.behaviour})
            member.behaviour = command.behaviour
        bogged = self.in_bog(*body.centre(body.x, body.y, body.heading))
        terrain = member.traversability if bogged else 1.0
        x, y, heading, velocity = body.motion(command, terrain * member.speed_factor)
        v_max = body.robot.limits.v_max
        share = abs(body.slew.v) / v_max
        member.effort = min(1.0, BOG_EFFORT * share / max(member.traversability, 1e-3) if bogged
                            else FIRM_EFFORT * share)
        if body.gap(self.world, x, y, heading) < 0 or self._bumps(name, body, x, y, heading):
            member.touches += 1
            body.halt()
            return
        member.travelled += body.move(x, y, heading, velocity)
        member.trail.append((now, body.x, body.y))

    def _ranges(self, name: str, body: KinematicBody) -> np.ndarray:
        """IR ranges to the boxes and walls, and to the other live robots' enclosing circles."""
        origins, directions = body.rays()
        ranges = body.ranges(self.world)
        cx, cy = body.centre(body.x, body.y, body.heading)
        # A circle farther than any ray reaches cannot be seen; the margin covers circle_ranges' rounding
        reach = body.robot.ir_range + float(body.sensor_radius.max()) + REACH_MARGIN
        centres, radii = [], []
        for other, member in self.members.items():
            if other == name or not member.alive:
                continue
            them = member.body
            centre = them.centre(them.x, them.y, them.heading)
            if math.dist(centre, (cx, cy)) - them.robot.radius <= reach:
                centres.append(centre)
                radii.append(them.robot.radius)
        if not centres:
            return ranges
        return np.minimum(ranges, circle_ranges(origins, directions, np.array(centres), np.array(radii),
                                                body.robot.ir_range))

    def _bumps(self, name: str, body: KinematicBody, x: float, y: float, heading: float) -> bool:
        """The move would bring its enclosing circle closer into another live robot's."""
        if (x, y, heading) == (body.x, body.y, body.heading):
            return False  # standing still brings it closer to none
        after = body.centre(x, y, heading)
        before = body.centre(body.x, body.y, body.heading)
        for other, member in self.members.items():
            if other == name or not member.alive:
                continue
            them = member.body.centre(member.body.x, member.body.y, member.body.heading)
            reach = body.robot.radius + member.body.robot.radius
            if math.dist(after, them) < reach and math.dist(after, them) < math.dist(before, them):
                return True
        return False

    def _apply(self, fault: Fault) -> None:
        member = self.members[fault.robot]
        if fault.kind in ("kill", "remove"):
            member.alive = False
            self.network.set_enabled(fault.robot, False)
        elif fault.kind == "radio-off":
            self.network.set_enabled(fault.robot, False)
        elif fault.kind == "break-motor":
            member.speed_factor = 0.0
        elif fault.kind == "slow":
            member.speed_factor = float(fault.options.get("factor", 0.5))
        self.events.append({"t": round(self.time, 6), "event": "fault", **fault.describe()})


@njit("f8[::1](f8[:, ::1], f8[:, ::1], f8[:, ::1], f8[::1], f8)", cache=True)
def circle_ranges(origins: np.ndarray, directions: np.ndarray, centres: np.ndarray, radii: np.ndarray,
                  max_range: float) -> np.ndarray:
    """Distance along each ray (origin (n, 2), unit direction (n, 2)) to the nearest circle it enters ahead,
    ``inf`` where none lies within ``max_range``; a ray starting inside a circle does not see it."""
    out = np.full(origins.shape[0], np.inf)
    for r in range(origins.shape[0]):
        for c in range(centres.shape[0]):
            ox, oy = centres[c, 0] - origins[r, 0], centres[c, 1] - origins[r, 1]
            along = ox * directions[r, 0] + oy * directions[r, 1]
            miss = (ox * ox + oy * oy) - along * along  # squared distance of the centre off the ray
            depth = radii[c] * radii[c] - miss
            entry = along - math.sqrt(max(depth, 0.0))
            if depth >= 0 and 0 < entry <= max_range:
                out[r] = min(out[r], entry)
    return out
