"""The world: a composed MuJoCo scene, its clock, and the per-tick data flow of DESIGN.md.

Each control tick (``control_dt``, 100 ms by default)::

    faults due now are applied
    sensors are sampled (IR through the IR model, encoders), positioning and radio are updated
    each live robot's controller turns its Observation into a Command
    locomotion turns (v, omega) into wheel set-points
    physics steps (at ``physics_dt``) until the next tick, sampling actuator power on the way

Sensors are sampled only at ticks: MuJoCo's sensor stage is disabled while stepping and run on demand, since a
rangefinder casts against every geom and per-step sensing dominated the cost of large teams.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np

from teamsim.config import ConfigError, TrialConfig
from teamsim.controllers.base import Command, Observation
from teamsim.controllers.locomotion import DifferentialDrive
from teamsim.faults import Fault, Health, apply_fault
from teamsim.models import ROBOT_BUILDERS, build_robot
from teamsim.models.robot import RobotModel
from teamsim.positioning import PositioningService
from teamsim.radio import RadioBus
from teamsim.rng import RandomStreams

_SENSOR_STAGE = int(mujoco.mjtDisableBit.mjDSBL_SENSOR)
# Warnings that mean the physics can no longer be trusted (MuJoCo resets the state on a bad qacc).
UNSTABLE_WARNINGS = tuple(int(w) for w in (
    mujoco.mjtWarning.mjWARN_INERTIA, mujoco.mjtWarning.mjWARN_CONTACTFULL, mujoco.mjtWarning.mjWARN_CNSTRFULL,
    mujoco.mjtWarning.mjWARN_BADQPOS, mujoco.mjtWarning.mjWARN_BADQVEL, mujoco.mjtWarning.mjWARN_BADQACC))
PARKING_X = 1000.0  # m; dormant robots wait here, far outside every arena, until an add-robot fault


class PhysicsUnstable(RuntimeError):
    """The simulation produced NaN/Inf or MuJoCo raised a warning that invalidates the state."""


@dataclass
class Robot:
    """One robot in the world: its model, controller, health and bookkeeping."""
    model: RobotModel
    controller: object
    drive: DifferentialDrive
    ir_rng: np.random.Generator
    dormant: bool
    spawn: tuple[float, float, float]
    health: Health = field(default_factory=Health)
    behaviour: str = "idle"
    parker_energy: float = 0.0  # Parker's count: 1 unit per second while any motor is commanded
    behaviour_time: dict = field(default_factory=dict)
    # model indices, filled by World
    qpos_adr: int = 0
    qvel_adr: int = 0
    ir_adr: np.ndarray = None
    actuators: np.ndarray = None
    wheel_dofs: np.ndarray = None
    geoms: np.ndarray = None

    @property
    def name(self) -> str:
        return self.model.name

    @property
    def active(self) -> bool:
        return self.health.alive and not self.dormant


def yaw_of(quat: np.ndarray) -> float:
    w, x, y, z = quat
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


class World:
    def __init__(self, config: TrialConfig, mission, events=None):
        self.config = config
        self.mission = mission
        self.streams = RandomStreams(config.seed)
        self.record = events or (lambda event: None)
        timing = config.timing
        self.physics_dt = timing.physics_dt
        self.steps_per_tick = max(1, round(timing.control_dt / timing.physics_dt))
        self.control_dt = self.steps_per_tick * self.physics_dt
        self.steps_per_energy = max(1, round(timing.energy_dt / timing.physics_dt))

        newcomers = [(f.robot, f.options["kind"]) for f in config.faults if f.kind == "add-robot"]
        scene = mission.build(config.params, self.streams.get("mission", "layout"), newcomers, timing.physics_dt)
        self.robots: dict[str, Robot] = {}
        for slot in scene.robots:
            if slot.name in self.robots:
                raise ConfigError(f"--fault add-robot:{slot.name}: robot {slot.name!r} is already in the team")
            if slot.kind not in ROBOT_BUILDERS:
                raise ConfigError(f"robot {slot.name!r}: kind {slot.kind!r} is not available; "
                                  f"available: {', '.join(ROBOT_BUILDERS)}")
            model = build_robot(slot.kind, slot.name)
            frame = scene.arena.attach(model.mjcf)
            frame.add("freejoint")
            x, y = (PARKING_X + 3.0 * len(self.robots), 0.0) if slot.dormant else (slot.x, slot.y)
            frame.pos = [x, y, 0.002]
            frame.euler = [0, 0, slot.yaw]
            self.robots[slot.name] = Robot(
                model=model,
                controller=mission.controller(model, config.params, self.streams.get("robot", slot.name, "brain")),
                drive=DifferentialDrive(model.wheel_radius, model.track_width, model.limits, self.control_dt),
                ir_rng=self.streams.get("robot", slot.name, "ir"), dormant=slot.dormant,
                spawn=(slot.x, slot.y, slot.yaw))
        self.check_faults(config.faults)
        self.faults = sorted(config.faults, key=lambda f: f.time)
        self.xml = scene.arena.to_xml_string()
        self.model = mujoco.MjModel.from_xml_string(self.xml, scene.arena.get_assets())
        self.data = mujoco.MjData(self.model)
        self.model.opt.disableflags |= _SENSOR_STAGE
        self._index_model()
        self.radio = RadioBus(config.radio, {n: self.streams.get("robot", n, "radio") for n in self.robots})
        self.positioning = PositioningService(config.positioning,
                                              {n: self.streams.get("robot", n, "positioning") for n in self.robots})
        for robot in self.robots.values():
            self.radio.set_enabled(robot.name, robot.active)
        self.step = 0
        mujoco.mj_forward(self.model, self.data)

    # -- set-up ---------------------------------------------------------------------------------------------
    def check_faults(self, faults: list[Fault]) -> None:
        """Reject faults naming unknown robots or parts they lack, before anything runs."""
        for fault in faults:
            robot = self.robots.get(fault.robot)
            spec = f"--fault {fault.kind}:{fault.robot}@{fault.time:g}"
            if fault.kind == "add-robot":
                continue  # checked as the team is built
            if robot is None:
                raise ConfigError(f"{spec}: no robot {fault.robot!r}; team: {', '.join(self.robots)}")
            if fault.kind == "break-motor" and fault.options.get("motor") not in (None, *robot.model.motors):
                raise ConfigError(f"{spec}: motor must be one of {', '.join(robot.model.motors)}")
            if fault.kind == "break-gripper":
                raise ConfigError(f"{spec}: a {robot.model.kind} robot has no gripper")

    def _index_model(self) -> None:
        m = self.model
        robot_of_actuator = []
        for k, robot in enumerate(self.robots.values()):
            name = robot.name
            root = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"{name}/")
            joint = m.body_jntadr[root]
            robot.qpos_adr, robot.qvel_adr = int(m.jnt_qposadr[joint]), int(m.jnt_dofadr[joint])
            robot.ir_adr = np.array([m.sensor_adr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SENSOR, f"{name}/{s}")]
                                     for s in robot.model.ir_sensors])
            robot.actuators = np.array([mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, f"{name}/{a}")
                                        for a in robot.model.motors])
            robot.wheel_dofs = m.jnt_dofadr[m.actuator_trnid[robot.actuators, 0]]
            bodies = [b for b in range(m.nbody) if m.body(b).name.startswith(f"{name}/")]
            robot.geoms = np.flatnonzero(np.isin(m.geom_bodyid, bodies))
            robot_of_actuator += [k] * len(robot.actuators)
        self._actuator_owner = np.array(robot_of_actuator, dtype=int)
        self._all_actuators = np.concatenate([r.actuators for r in self.robots.values()])
        self._geom_owner = np.full(m.ngeom, -1)
        for k, robot in enumerate(self.robots.values()):
            self._geom_owner[robot.geoms] = k
        self._is_floor = m.geom_type == mujoco.mjtGeom.mjGEOM_PLANE
        self._touching_s = np.zeros(len(self.robots))
        self._names = list(self.robots)
        self._root_dofs = np.array([r.qvel_adr for r in self.robots.values()])
        self._actuator_energy_j = np.zeros(len(self._all_actuators))
        self.odometry_m = np.zeros(len(self.robots))

    # -- state ----------------------------------------------------------------------------------------------
    @property
    def time(self) -> float:
        return self.step * self.physics_dt

    def pose(self, robot: Robot) -> np.ndarray:
        q = self.data.qpos[robot.qpos_adr:robot.qpos_adr + 7]
        return np.array([q[0], q[1], yaw_of(q[3:7])])

    def speed(self, robot: Robot) -> float:
        v = self.data.qvel[robot.qvel_adr:robot.qvel_adr + 2]
        return float(math.hypot(v[0], v[1]))

    def odometry(self) -> dict[str, float]:
        """Distance each robot has travelled (from its true speed), m."""
        return {name: round(float(self.odometry_m[k]), 6) for k, (name, r) in enumerate(self.robots.items())
                if not r.dormant}

    def contact_fraction(self) -> dict[str, float]:
        """Share of the trial each robot spent touching walls, obstacles or other robots."""
        return {name: round(float(self._touching_s[k]) / max(self.time, 1e-9), 6)
                for k, name in enumerate(self.robots)}

    # -- the control tick -----------------------------------------------------------------------------------
    def tick(self) -> None:
        """Apply due faults, sense, decide and set actuators, at the current time."""
        self.check_stable()
        now = self.time
        while self.faults and self.faults[0].time <= now + 1e-9:
            self._apply(self.faults.pop(0), now)
        m, d = self.model, self.data
        mujoco.mj_kinematics(m, d)
        m.opt.disableflags &= ~_SENSOR_STAGE
        mujoco.mj_sensorPos(m, d)
        m.opt.disableflags |= _SENSOR_STAGE
        live = [r for r in self.robots.values() if r.active]
        poses = {r.name: self.pose(r) for r in live}
        self.positioning.update(now, poses, {r.name: self.speed(r) for r in live})
        for message in self.radio.update(now, poses):
            self.record({"t": round(now, 6), "event": "radio", "robot": message.sender, "payload": message.payload})
        for k in self._robots_touching():
            self._touching_s[k] += self.control_dt
        for robot, (raw, ranges) in zip(live, self._read_ir(live)):
            self._control(robot, now, raw, ranges)

    def _read_ir(self, robots: list[Robot]) -> list[tuple[np.ndarray, np.ndarray]]:
        """(raw, range) IR readings per robot, one vectorised IR-model call per sensor model."""
        readings: list = [None] * len(robots)
        groups: dict = {}
        for k, robot in enumerate(robots):
            groups.setdefault(robot.model.ir, []).append(k)
        for ir, members in groups.items():
            distance = self.data.sensordata[np.concatenate([robots[k].ir_adr for k in members])]
            # Each robot draws from its own stream, blind or not, so one robot's faults never shift another's.
            noise = np.concatenate([robots[k].ir_rng.standard_normal(len(robots[k].ir_adr)) for k in members])
            blind = np.concatenate([np.full(len(robots[k].ir_adr), robots[k].health.ir_blind) for k in members])
            raw = np.where(blind, 0.0, ir.read(distance, noise))
            ranges = ir.to_range(raw)
            bounds = np.cumsum([0] + [len(robots[k].ir_adr) for k in members])
            for k, lo, hi in zip(members, bounds[:-1], bounds[1:]):
                readings[k] = (raw[lo:hi], ranges[lo:hi])
        return readings

    def _control(self, robot: Robot, now: float, ir_raw: np.ndarray, ir_range: np.ndarray) -> None:
        d = self.data
        observation = Observation(
            time=now, robot=robot.name, ir_raw=ir_raw, ir_range=ir_range,
            ir_bearings=robot.model.ir_bearings, pose=self.positioning.fix(robot.name),
            inbox=tuple(self.radio.take_inbox(robot.name)),
            robots_present=self.radio.robots_present(robot.name, now),
            wheel_speeds=d.qvel[robot.wheel_dofs])
        command: Command = robot.controller(observation)
        if command.behaviour != robot.behaviour:
            self.record({"t": round(now, 6), "event": "behaviour", "robot": robot.name,
                         "from": robot.behaviour, "to": command.behaviour})
            robot.behaviour = command.behaviour
        robot.behaviour_time[robot.behaviour] = robot.behaviour_time.get(robot.behaviour, 0.0) + self.control_dt
        if command.broadcast is not None:
            self.radio.set_outbox(robot.name, command.broadcast)
        if command.v or command.omega:
            robot.parker_energy += self.control_dt
        d.ctrl[robot.actuators] = robot.drive.wheel_speeds(command.v, command.omega) * robot.health.speed_factor

    def _robots_touching(self) -> np.ndarray:
        """Indices of robots in contact with anything but the floor (walls, obstacles, other robots)."""
        d = self.data
        if d.ncon == 0:
            return np.zeros(0, dtype=int)
        pairs = d.contact.geom[: d.ncon]
        owners = self._geom_owner[pairs]
        relevant = (owners[:, 0] != owners[:, 1]) & ~self._is_floor[pairs].any(axis=1)
        hit = owners[relevant].ravel()
        return np.unique(hit[hit >= 0])

    def _apply(self, fault: Fault, now: float) -> None:
        robot = self.robots[fault.robot]
        if fault.kind == "add-robot":
            self._place(robot)
        else:
            apply_fault(fault, robot.health, robot.model.motors)
            if fault.kind == "break-motor":
                self._unpower(robot, fault.options.get("motor") or robot.model.motors[0])
            if not robot.health.alive:
                self.data.ctrl[robot.actuators] = robot.drive.stop()
        self.radio.set_enabled(robot.name, robot.health.radio_on and not robot.dormant)
        self.record({"t": round(now, 6), "event": "fault", **fault.describe()})

    def _unpower(self, robot: Robot, motor: str) -> None:
        """A broken motor freewheels: its actuator no longer produces force."""
        actuator = robot.actuators[robot.model.motors.index(motor)]
        self.model.actuator_gainprm[actuator, :] = 0
        self.model.actuator_biasprm[actuator, :] = 0

    def _place(self, robot: Robot) -> None:
        """Bring a dormant robot into the arena at its reserved spawn pose (the add-robot fault)."""
        x, y, yaw = robot.spawn
        q = self.data.qpos
        q[robot.qpos_adr:robot.qpos_adr + 7] = [x, y, 0.002, math.cos(yaw / 2), 0, 0, math.sin(yaw / 2)]
        self.data.qvel[robot.qvel_adr:robot.qvel_adr + 6] = 0
        robot.dormant = False
        mujoco.mj_forward(self.model, self.data)

    # -- physics --------------------------------------------------------------------------------------------
    def advance(self, steps: int) -> None:
        """Step physics ``steps`` times, in chunks of ``energy_dt`` so actuator power is sampled."""
        m, d = self.model, self.data
        end = self.step + steps
        while self.step < end:
            chunk = min(self.steps_per_energy - self.step % self.steps_per_energy, end - self.step)
            mujoco.mj_step(m, d, nstep=chunk)
            self.step += chunk
            self._sample_power(chunk * self.physics_dt)

    def _sample_power(self, dt: float) -> None:
        """Integrate |force x velocity| of every actuator, and odometry, over the last ``dt`` seconds."""
        d, ids = self.data, self._all_actuators
        self._actuator_energy_j += np.abs(d.actuator_force[ids] * d.actuator_velocity[ids]) * dt
        # Parked (dormant) robots stand still, so they add nothing here.
        self.odometry_m += np.hypot(d.qvel[self._root_dofs], d.qvel[self._root_dofs + 1]) * dt

    @property
    def energy_j(self) -> np.ndarray:
        """Mechanical energy each robot's actuators have delivered, J (integral of |force x velocity|)."""
        return np.bincount(self._actuator_owner, self._actuator_energy_j, minlength=len(self.robots))

    def check_stable(self) -> None:
        """Raise PhysicsUnstable on NaN/Inf state or a warning that invalidates the physics."""
        d = self.data
        raised = d.warning.number[list(UNSTABLE_WARNINGS)]
        if raised.any():
            name = mujoco.mjtWarning(UNSTABLE_WARNINGS[int(np.argmax(raised > 0))]).name
            raise PhysicsUnstable(f"MuJoCo warning {name} at t={self.time:.3f} s")
        if not (np.isfinite(d.qpos).all() and np.isfinite(d.qvel).all()):
            raise PhysicsUnstable(f"non-finite state at t={self.time:.3f} s")

    def robot_summary(self) -> dict:
        return {name: {"kind": r.model.kind, "alive": r.health.alive, "joined": not r.dormant,
                       "energy_j": round(float(self.energy_j[k]), 6), "parker_energy_units": round(r.parker_energy, 6),
                       "task_time_s": {k: round(v, 6) for k, v in sorted(r.behaviour_time.items())}}
                for k, (name, r) in enumerate(self.robots.items())}
