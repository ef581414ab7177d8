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
from dataclasses import dataclass, field, replace

import mujoco
import numpy as np

from teamsim.config import ConfigError, TrialConfig
from teamsim.controllers.base import Command, Observation
from teamsim.controllers.skills.locomotion import make_locomotion
from teamsim.faults import Fault, Health, apply_fault, role_refusal
from teamsim.models import ROBOT_BUILDERS, build_robot
from teamsim.models.robot import RobotModel
from teamsim.network import Delivery, Network, NetworkConfig
from teamsim.positioning import PositioningService, wrap_angle
from teamsim.radio import RadioBus
from teamsim.rng import RandomStreams

_SENSOR_STAGE = int(mujoco.mjtDisableBit.mjDSBL_SENSOR)
# Warnings that mean the physics can no longer be trusted (MuJoCo resets the state on a bad qacc).
UNSTABLE_WARNINGS = tuple(int(w) for w in (
    mujoco.mjtWarning.mjWARN_INERTIA, mujoco.mjtWarning.mjWARN_CONTACTFULL, mujoco.mjtWarning.mjWARN_CNSTRFULL,
    mujoco.mjtWarning.mjWARN_BADQPOS, mujoco.mjtWarning.mjWARN_BADQVEL, mujoco.mjtWarning.mjWARN_BADQACC))
PARKING_X = 1000.0  # m; dormant robots wait here, far outside every arena, until an add-robot fault
EFFECTOR_STILL = 1e-3  # encoder change per control tick (of a [0, 1] range) below which an effector motor is idle


class PhysicsUnstable(RuntimeError):
    """The simulation produced NaN/Inf or MuJoCo raised a warning that invalidates the state."""


@dataclass
class Robot:
    """One robot in the world: its model, controller, health and bookkeeping."""
    model: RobotModel
    controller: object
    drive: object  # the locomotion controller (teamsim.controllers.skills.locomotion)
    ir_rng: np.random.Generator
    dormant: bool
    spawn: tuple[float, float, float]
    health: Health = field(default_factory=Health)
    behaviour: str = "idle"
    parker_energy: float = 0.0  # Parker's count (ch.5): 1 unit per second while any motor is in use
    effector_positions: dict = field(default_factory=dict)  # encoder readings at the last tick
    odometry_at: tuple | None = None  # (time, pose) at the last tick, whence the odometry's displacement
    behaviour_time: dict = field(default_factory=dict)
    # model indices, filled by World
    qpos_adr: int = 0
    qvel_adr: int = 0
    ir_adr: np.ndarray = None
    actuators: np.ndarray = None
    motor_dofs: np.ndarray = None
    geoms: np.ndarray = None
    beam_adr: np.ndarray = None
    effectors: dict = field(default_factory=dict)  # name -> (actuator ids, joint qpos address)
    _blind: tuple | None = field(default=None, repr=False)  # (health.ir_blind, its mask over the IR sensors)

    @property
    def name(self) -> str:
        return self.model.name

    @property
    def active(self) -> bool:
        return self.health.alive and not self.dormant

    def ir_blind_mask(self) -> np.ndarray:
        prefixes = self.health.ir_blind
        if self._blind is None or self._blind[0] != prefixes:  # read every tick, changed only by a fault
            mask = np.array([any(name.startswith(p) for p in prefixes) for name in self.model.ir_sensors], bool)
            self._blind = (prefixes, mask)
        return self._blind[1]


def bog_drag(robot: RobotModel) -> float:
    """Viscous drag coefficient (N s/m) of a bog on ``robot``, chosen so that at full effort its locomotion
    holds a speed of ``traversability x v_max`` there. Chand (Table 5.22) scores traversability in [0, 1] with
    tracked robots at 1.0 (they cross bogs at full speed) and wheeled ones at 0.1-0.3; the thesis gives no
    physical model, so this one makes a robot's top speed in a bog proportional to its traversability."""
    return robot.max_traction / (max(robot.traversability, 1e-3) * robot.limits.v_max)


def yaw_of(quat: np.ndarray) -> float:
    w, x, y, z = quat
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def _radio_event(now: float, message) -> dict:
    """The event a sent radio message or network packet is logged as; a packet's payload (a map array) is not."""
    if isinstance(message, Delivery):
        return {"t": round(now, 6), "event": "net", "robot": message.sender, "to": message.to,
                "kind": message.kind, "bytes": message.size}
    return {"t": round(now, 6), "event": "radio", "robot": message.sender, "payload": message.payload}


def _state_the_arena_extent(arena) -> None:
    """Write the arena's own extent and centre into its ``<statistic>``, before robots are attached.

    MuJoCo derives them from every body, so robots parked at ``PARKING_X`` would stretch the extent (box
    pushing: 2018 m against 12 m), and with it a renderer's near clip plane (``vis.map.znear`` x extent): the
    camera would see nothing. The mass and inertia statistics, which scale the solver, are left to the compiler."""
    try:
        stat = mujoco.MjModel.from_xml_string(arena.to_xml_string(), arena.get_assets()).stat
    except ValueError as exc:
        raise ConfigError(f"the arena does not compile: {' '.join(str(exc).split())}") from None
    arena.statistic.extent = float(stat.extent)
    arena.statistic.center = [float(c) for c in stat.center]


class World:
    def __init__(self, config: TrialConfig, mission, events=None):
        self.config = config
        self.mission = mission
        self.streams = RandomStreams(config.seed)
        self.record = events or (lambda event: None)
        self.record_trace = lambda robot, time, trace: None  # gets each Command.trace (the runner records them)
        timing = config.timing
        self.physics_dt = timing.physics_dt
        self.steps_per_tick = max(1, round(timing.control_dt / timing.physics_dt))
        self.control_dt = self.steps_per_tick * self.physics_dt
        self.steps_per_energy = max(1, round(timing.energy_dt / timing.physics_dt))

        newcomers = [(f.robot, f.options["kind"]) for f in config.faults if f.kind == "add-robot"]
        if config.scenario is not None:  # a described world (teamsim.scenario)
            scene = mission.scene(config.scenario, newcomers, timing.physics_dt)
        else:
            scene = mission.build(config.params, self.streams.get("mission", "layout"), newcomers, timing.physics_dt)
        if any(slot.dormant for slot in scene.robots):
            _state_the_arena_extent(scene.arena)
        self.robots: dict[str, Robot] = {}
        for slot in scene.robots:
            if slot.name in self.robots:
                raise ConfigError(f"--fault add-robot:{slot.name}: robot {slot.name!r} is already in the team")
            if slot.kind not in ROBOT_BUILDERS:
                raise ConfigError(f"robot {slot.name!r}: kind {slot.kind!r} is not available; "
                                  f"available: {', '.join(ROBOT_BUILDERS)}")
            try:
                model = build_robot(slot.kind, slot.name, **slot.options)
            except ValueError as exc:
                raise ConfigError(str(exc)) from None
            frame = scene.arena.attach(model.mjcf)
            frame.add("freejoint")
            x, y = (PARKING_X + 3.0 * len(self.robots), 0.0) if slot.dormant else (slot.x, slot.y)
            frame.pos = [x, y, 0.002]
            frame.euler = [0, 0, slot.yaw]
            self.robots[slot.name] = Robot(
                model=model,
                controller=mission.controller(model, scene, self.streams.get("robot", slot.name, "brain")),
                drive=make_locomotion(model.drive, model.limits, self.control_dt),
                ir_rng=self.streams.get("robot", slot.name, "ir"), dormant=slot.dormant,
                spawn=(slot.x, slot.y, slot.yaw))
        self.scene = scene
        self.bogs = list(scene.bogs)
        faults = list(scene.faults) + list(config.faults)  # the scenario's own, then the user's
        self.check_faults(faults)
        self.schedule = faults
        self._user_faults = len(scene.faults)  # schedule[_user_faults:] are config.faults
        self.struck: list[tuple[str, float] | None] = [None] * len(faults)  # (robot, when) each fault struck
        self._pending = sorted(range(len(faults)), key=lambda k: faults[k].time)  # indices into schedule
        self._waiting: set[int] = set()  # role faults due whose role was vacant (their wait is logged once)
        self.xml = scene.arena.to_xml_string()
        try:
            self.model = mujoco.MjModel.from_xml_string(self.xml, scene.arena.get_assets())
        except ValueError as exc:  # e.g. robot options whose parts do not fit together
            raise ConfigError(f"the scene does not compile: {' '.join(str(exc).split())}") from None
        self.data = mujoco.MjData(self.model)
        self.model.opt.disableflags |= _SENSOR_STAGE
        self._index_model()
        radio_rngs = {n: self.streams.get("robot", n, "radio") for n in self.robots}
        self.radio = (Network(scene.network_config or NetworkConfig(), scene.network, radio_rngs)
                      if scene.network is not None
                      else RadioBus(config.radio, radio_rngs))
        self.positioning = PositioningService(config.positioning,
                                              {n: self.streams.get("robot", n, "positioning") for n in self.robots})
        for robot in self.robots.values():
            self.radio.set_enabled(robot.name, robot.active)
        self.step = 0
        self._restarts = 0
        self._sense = getattr(mission, "sense", None)  # a mission's own sensors: sense(world, robot) -> dict
        mujoco.mj_forward(self.model, self.data)

    # -- set-up ---------------------------------------------------------------------------------------------
    def check_faults(self, faults: list[Fault]) -> None:
        """Reject faults naming unknown robots or roles, or parts their robots lack, before anything runs. A role
        may fall to any robot of the team, so a fault by role must suit every one of them."""
        joins = {f.robot: f.time for f in faults if f.kind == "add-robot"}
        roles = getattr(self.mission, "fault_roles", {})
        for fault in faults:
            spec = f"--fault {fault.kind}:{fault.robot}@{fault.time:g}"
            if fault.kind == "add-robot":
                continue  # checked as the team is built
            if fault.role is not None:
                if fault.role not in roles:
                    raise ConfigError(f"{spec}: {role_refusal(self.mission.name, fault.role, roles)}")
                for robot in self.robots.values():
                    if not robot.dormant:
                        self._check_parts(fault, robot, f"{spec} (the role may fall to {robot.name})")
                continue
            if fault.robot in joins and fault.time < joins[fault.robot]:
                raise ConfigError(f"{spec}: {fault.robot} joins at {joins[fault.robot]:g} s (add-robot); its faults "
                                  f"must come at or after that")
            robot = self.robots.get(fault.robot)
            if robot is None:
                raise ConfigError(f"{spec}: no robot {fault.robot!r}; team: {', '.join(self.robots)}")
            self._check_parts(fault, robot, spec)

    @staticmethod
    def _check_parts(fault: Fault, robot: Robot, spec: str) -> None:
        """The parts a fault's options name (a motor, IR sensors, the gripper) exist on ``robot``."""
        if fault.kind == "break-motor" and fault.options.get("motor") not in (None, *robot.model.motors):
            raise ConfigError(f"{spec}: motor must be one of {', '.join(robot.model.motors)}")
        if fault.kind == "break-gripper" and not robot.model.effectors:
            raise ConfigError(f"{spec}: a {robot.model.kind} robot has no gripper")
        for prefix in fault.options.get("sensors", "").split("+") if fault.kind == "blind-ir" else ():
            if not any(name.startswith(prefix) for name in robot.model.ir_sensors):
                raise ConfigError(f"{spec}: sensors: no IR sensor of {robot.name} starts with {prefix!r}; "
                                  f"its sensors: {', '.join(robot.model.ir_sensors)}")

    def _index_model(self) -> None:
        m = self.model

        def ids(kind, names, prefix):
            return np.array([mujoco.mj_name2id(m, kind, f"{prefix}/{n}") for n in names], dtype=int)

        owner_of_actuator = np.full(m.nu, -1)
        self._geom_owner = np.full(m.ngeom, -1)
        self._touch_of_geom = np.full(m.ngeom, -1)  # geom -> index into self._touch_names
        self._touch_names: list[tuple[int, str]] = []  # (robot index, touch sensor name)
        for k, robot in enumerate(self.robots.values()):
            name, spec = robot.name, robot.model
            root = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"{name}/")
            joint = m.body_jntadr[root]
            robot.qpos_adr, robot.qvel_adr = int(m.jnt_qposadr[joint]), int(m.jnt_dofadr[joint])
            robot.ir_adr = m.sensor_adr[ids(mujoco.mjtObj.mjOBJ_SENSOR, spec.ir_sensors, name)]
            robot.beam_adr = m.sensor_adr[ids(mujoco.mjtObj.mjOBJ_SENSOR, spec.beams, name)]
            robot.actuators = ids(mujoco.mjtObj.mjOBJ_ACTUATOR, spec.motors, name)
            robot.motor_dofs = m.jnt_dofadr[m.actuator_trnid[robot.actuators, 0]]
            for effector_name, effector in spec.effectors.items():
                joint_id = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"{name}/{effector.joint}")
                robot.effectors[effector_name] = (ids(mujoco.mjtObj.mjOBJ_ACTUATOR, effector.actuators, name),
                                                  int(m.jnt_qposadr[joint_id]))
            owner_of_actuator[[a for a in range(m.nu) if m.actuator(a).name.startswith(f"{name}/")]] = k
            bodies = [b for b in range(m.nbody) if m.body(b).name.startswith(f"{name}/")]
            robot.geoms = np.flatnonzero(np.isin(m.geom_bodyid, bodies))
            self._geom_owner[robot.geoms] = k
            for touch_name, geom_names in spec.touch.items():
                self._touch_of_geom[ids(mujoco.mjtObj.mjOBJ_GEOM, geom_names, name)] = len(self._touch_names)
                self._touch_names.append((k, touch_name))
        self._all_actuators = np.flatnonzero(owner_of_actuator >= 0)
        self._actuator_owner = owner_of_actuator[self._all_actuators]
        self._continuous = [r for r in self.robots.values() if r.drive.continuous]
        self._is_floor = m.geom_type == mujoco.mjtGeom.mjGEOM_PLANE
        self._touching_s = np.zeros(len(self.robots))
        self._names = list(self.robots)
        self._index_of = {name: k for k, name in enumerate(self._names)}
        self._root_dofs = np.array([r.qvel_adr for r in self.robots.values()])
        self._actuator_energy_j = np.zeros(len(self._all_actuators))
        self._root_qpos = np.array([r.qpos_adr for r in self.robots.values()])
        self._bog_drag = np.array([bog_drag(r.model) for r in self.robots.values()])
        # Turning in a bog drags the footprint's rim: rotational damping = drag x (radius^2 / 2).
        self._yaw_arm2 = np.array([r.model.footprint_radius ** 2 / 2 for r in self.robots.values()])
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
        for robot, observation in self.observe():
            self.act(robot, observation, robot.controller(observation))

    def observe(self):
        """Apply due faults and sample every sensor, then yield ``(robot, Observation)`` for each live robot, in
        team order. Lazily: :meth:`tick` acts on each robot before the next one's observation is built."""
        self.check_stable()
        now = self.time
        waiting = []
        while self._pending and self.schedule[self._pending[0]].time <= now + 1e-9:
            k = self._pending.pop(0)
            if not self._strike(k, now):
                waiting.append(k)
        self._pending[:0] = waiting  # (due already, so still first in time order)
        m, d = self.model, self.data
        mujoco.mj_kinematics(m, d)
        m.opt.disableflags &= ~_SENSOR_STAGE
        mujoco.mj_sensorPos(m, d)
        m.opt.disableflags |= _SENSOR_STAGE
        live = [r for r in self.robots.values() if r.active]
        poses = {r.name: self.pose(r) for r in live}
        self.positioning.update(now, poses, {r.name: self.speed(r) for r in live})
        for message in self.radio.update(now, poses):
            self.record(_radio_event(now, message))
        for k in self._robots_touching():
            self._touching_s[k] += self.control_dt
        touch = self._touch_forces()
        for robot, (raw, ranges) in zip(live, self._read_ir(live)):
            yield robot, self._observation(robot, now, raw, ranges, touch[self._index_of[robot.name]])

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
            blind = np.concatenate([robots[k].ir_blind_mask() for k in members])
            raw = np.where(blind, 0.0, ir.read(distance, noise))
            ranges = ir.to_range(raw)
            bounds = np.cumsum([0] + [len(robots[k].ir_adr) for k in members])
            for k, lo, hi in zip(members, bounds[:-1], bounds[1:]):
                readings[k] = (raw[lo:hi], ranges[lo:hi])
        return readings

    def _observation(self, robot: Robot, now: float, ir_raw: np.ndarray, ir_range: np.ndarray,
                     touch: dict) -> Observation:
        d, spec = self.data, robot.model
        beams = d.sensordata[robot.beam_adr]
        return Observation(
            time=now, robot=robot.name, ir_raw=ir_raw, ir_range=ir_range,
            ir_bearings=spec.ir_bearings, pose=self.positioning.fix(robot.name),
            inbox=tuple(self.radio.take_inbox(robot.name)),
            robots_present=self.radio.robots_present(robot.name, now),
            motor_speeds=d.qvel[robot.motor_dofs], velocity=self.read_odometry(robot, now), touch=touch,
            break_beams=(beams >= 0) & (beams < spec.beam_length),
            inclination=self.inclination(robot) if spec.inclinometer else None,
            effectors={name: self._effector_position(robot, name) for name in robot.effectors},
            drive_effort=self._drive_effort(robot),
            signals=self._sense(self, robot.name) if self._sense is not None else {})

    def act(self, robot: Robot, observation: Observation, command: Command) -> None:
        """Carry out ``command``, the answer to ``observation``: record its behaviour, queue its broadcast, set the
        locomotion and effector set-points."""
        now = observation.time
        if not (math.isfinite(command.v) and math.isfinite(command.omega)):
            raise ValueError(f"controller of {robot.name} returned a non-finite command {command}")
        if command.trace is not None:
            self.record_trace(robot.name, now, command.trace)
        if command.behaviour != robot.behaviour:
            self.record({"t": round(now, 6), "event": "behaviour", "robot": robot.name,
                         "from": robot.behaviour, "to": command.behaviour})
            robot.behaviour = command.behaviour
        robot.behaviour_time[robot.behaviour] = robot.behaviour_time.get(robot.behaviour, 0.0) + self.control_dt
        if command.broadcast is not None:
            self.radio.set_outbox(robot.name, command.broadcast)
        effectors_moved = any(abs(observation.effectors[n] - robot.effector_positions.get(n, observation.effectors[n]))
                              > EFFECTOR_STILL for n in observation.effectors)
        robot.effector_positions = observation.effectors
        if command.v or command.omega or effectors_moved:
            robot.parker_energy += self.control_dt
        factor = robot.health.speed_factor
        if hasattr(robot.drive, "feedback"):
            robot.drive.feedback(self.yaw_rate(robot))
        robot.drive.command(command.v * factor, command.omega * factor)
        self.data.ctrl[robot.actuators] = robot.drive.targets(now)
        for name, setpoint in command.extras.items():
            self._set_effector(robot, name, setpoint)

    def _set_effector(self, robot: Robot, name: str, setpoint: float) -> None:
        if name not in robot.effectors:
            raise ValueError(f"{robot.name} ({robot.model.kind}) has no effector {name!r}; "
                             f"it has: {', '.join(robot.effectors) or 'none'}")
        effector = robot.model.effectors[name]
        setpoint = min(max(float(setpoint), 0.0), 1.0)
        span = effector.ctrl_at_1 - effector.ctrl_at_0
        self.data.ctrl[robot.effectors[name][0]] = effector.ctrl_at_0 + setpoint * span

    def _drive_effort(self, robot: Robot) -> float:
        """Mean |force| / force limit of the locomotion motors: the PWM effort a motor driver would show."""
        limit = self.model.actuator_forcerange[robot.actuators, 1]
        force = np.abs(self.data.actuator_force[robot.actuators])
        return float(np.mean(np.where(limit > 0, force / np.where(limit > 0, limit, 1.0), 0.0)))

    def _effector_position(self, robot: Robot, name: str) -> float:
        """The effector's encoder reading, on the same [0, 1] scale as its command."""
        effector = robot.model.effectors[name]
        q = self.data.qpos[robot.effectors[name][1]]
        return float((q - effector.ctrl_at_0) / (effector.ctrl_at_1 - effector.ctrl_at_0))

    def read_odometry(self, robot: Robot, now: float) -> tuple[float, float]:
        """What the chassis's odometry reads at a control tick: (forward speed, m/s; turn rate, rad/s) over the
        period since the last tick, from the displacement, as encoder counts over a period give it (a sampled
        instantaneous velocity would carry the chassis's contact chatter). A blocked robot reads about zero
        whatever its wheels are asked to do."""
        pose = self.pose(robot)
        last, robot.odometry_at = robot.odometry_at, (now, pose)
        if last is None or now <= last[0]:
            return 0.0, 0.0
        dt = now - last[0]
        dx, dy = pose[:2] - last[1][:2]
        turn = wrap_angle(pose[2] - last[1][2])
        middle = last[1][2] + turn / 2
        return float((dx * math.cos(middle) + dy * math.sin(middle)) / dt), float(turn / dt)

    def yaw_rate(self, robot: Robot) -> float:
        """What a gyro on the chassis reads about its vertical axis, rad/s (free-joint angular velocity is in
        the body frame)."""
        return float(self.data.qvel[robot.qvel_adr + 5])

    def inclination(self, robot: Robot) -> tuple[float, float]:
        """(roll, pitch) of the robot's body, rad: what an inclinometer on its chassis reads."""
        w, x, y, z = self.data.qpos[robot.qpos_adr + 3:robot.qpos_adr + 7]
        roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
        pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
        return roll, pitch

    def _touch_forces(self) -> list[dict]:
        """Per robot, each touch sensor's summed normal force from contacts with anything but itself, N."""
        readings = [{name: 0.0 for name in r.model.touch} for r in self.robots.values()]
        d = self.data
        if not self._touch_names or d.ncon == 0:
            return readings
        pairs = d.contact.geom[: d.ncon]
        sensors = self._touch_of_geom[pairs]
        owners = self._geom_owner[pairs]
        candidates = np.flatnonzero((sensors >= 0).any(axis=1) & (owners[:, 0] != owners[:, 1]))
        wrench = np.zeros(6)
        for i in candidates:
            mujoco.mj_contactForce(self.model, d, int(i), wrench)
            for sensor in sensors[i]:
                if sensor >= 0:
                    robot_index, name = self._touch_names[sensor]
                    readings[robot_index][name] += abs(wrench[0])
        return readings

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

    def _strike(self, k: int, now: float) -> bool:
        """Apply fault ``k`` of the schedule, which is due; False if it names a role that nobody holds now (it
        waits for a holder: docs/decisions.md, "Faults by run-time role")."""
        fault, by_role = self.schedule[k], None
        if fault.role is not None:
            target = self.mission.role_holder(self, fault.role)
            if target is not None and target not in self.robots:
                raise ValueError(f"{self.mission.name}.role_holder({fault.role!r}) gave {target!r}, not a robot")
            if target is None or not self.robots[target].active:  # a role held by the dead is vacant
                if k not in self._waiting:
                    self._waiting.add(k)
                    self.record({"t": round(now, 6), "event": "fault-waiting", **fault.describe(),
                                 "reason": f"no robot holds the role {fault.role!r}: the fault waits for one"})
                return False
            by_role, fault = fault.robot, replace(fault, robot=target)
        self._apply(fault, now, by_role)
        self.struck[k] = (fault.robot, round(now, 6))
        return True

    def fault_report(self) -> list[dict]:
        """The user's faults (``config.faults``) as scheduled; a fault by role also says whom it struck and when
        (``hit``, ``hit_at``; None while its role stayed vacant)."""
        report = []
        for fault, struck in zip(self.schedule[self._user_faults:], self.struck[self._user_faults:]):
            described = fault.describe()
            if fault.role is not None:
                described["hit"], described["hit_at"] = struck if struck is not None else (None, None)
            report.append(described)
        return report

    def _apply(self, fault: Fault, now: float, by_role: str | None = None) -> None:
        robot = self.robots[fault.robot]
        if fault.kind == "add-robot":
            self._place(robot)
        elif fault.kind == "revive":
            apply_fault(fault, robot.health, robot.model.motors)
            self._revive(robot)
        else:
            apply_fault(fault, robot.health, robot.model.motors)
            if fault.kind == "break-motor":
                motor = fault.options.get("motor") or robot.model.motors[0]
                self._unpower(robot.actuators[robot.model.motors.index(motor)])
            if fault.kind == "break-gripper":
                for actuators, _ in robot.effectors.values():
                    self._unpower(*actuators)
            if not robot.health.alive:
                robot.drive.stop()
                self.data.ctrl[robot.actuators] = robot.drive.targets(now)
            if fault.kind == "remove":
                self._move(robot, (PARKING_X + 3.0 * self._index_of[robot.name], 0.0, 0.0))
        self.radio.set_enabled(robot.name, robot.health.radio_on and not robot.dormant)
        self.record({"t": round(now, 6), "event": "fault", **fault.describe(),
                     **({"target": by_role} if by_role is not None else {})})

    def _unpower(self, *actuators: int) -> None:
        """A broken motor goes limp: its actuator no longer produces force."""
        for actuator in actuators:
            self.model.actuator_gainprm[actuator, :] = 0
            self.model.actuator_biasprm[actuator, :] = 0

    def _place(self, robot: Robot) -> None:
        """Bring a dormant robot into the arena (the add-robot fault): where the mission's ``entry_pose(world,
        name)`` says, with a controller made for that place, or else at its reserved spawn pose."""
        where = getattr(self.mission, "entry_pose", None)
        if where is not None:
            self._move(robot, where(self, robot.name))
            self._restart_controller(robot)
        else:
            self._move(robot, robot.spawn)
        robot.dormant = False

    def _revive(self, robot: Robot) -> None:
        """Switch a robot on again (the revive fault) with a fresh controller, as after a power cycle; a removed
        robot is first put back where the mission's ``entry_pose`` says (its start pose when it has none)."""
        if robot.health.removed:
            where = getattr(self.mission, "entry_pose", None)
            self._move(robot, where(self, robot.name) if where else robot.spawn)
            robot.health.removed = False
        self._restart_controller(robot)

    def _restart_controller(self, robot: Robot) -> None:
        """A fresh controller, as after a power cycle; its radio forgets what it was about to say."""
        self._restarts += 1
        self.radio.set_outbox(robot.name, {})
        stream = self.streams.get("robot", robot.name, "brain", "restart", str(self._restarts))
        robot.controller = self.mission.controller(robot.model, self.scene, stream)
        robot.drive = make_locomotion(robot.model.drive, robot.model.limits, self.control_dt)

    def _move(self, robot: Robot, pose: tuple[float, float, float]) -> None:
        """Set a robot down at (x, y, yaw), at rest."""
        x, y, yaw = pose
        q = self.data.qpos
        q[robot.qpos_adr:robot.qpos_adr + 7] = [x, y, 0.002, math.cos(yaw / 2), 0, 0, math.sin(yaw / 2)]
        self.data.qvel[robot.qvel_adr:robot.qvel_adr + 6] = 0
        robot.odometry_at = None
        mujoco.mj_forward(self.model, self.data)

    # -- physics --------------------------------------------------------------------------------------------
    def advance(self, steps: int) -> None:
        """Step physics ``steps`` times, in chunks of ``energy_dt`` so actuator power is sampled."""
        m, d = self.model, self.data
        end = self.step + steps
        while self.step < end:
            chunk = min(self.steps_per_energy - self.step % self.steps_per_energy, end - self.step)
            for robot in self._continuous:  # gaits: set-points move within the control period
                if robot.active:
                    d.ctrl[robot.actuators] = robot.drive.targets(self.time)
            if self.bogs:
                self._apply_bog_drag()
            mujoco.mj_step(m, d, nstep=chunk)
            self.step += chunk
            self._sample_power(chunk * self.physics_dt)

    def _apply_bog_drag(self) -> None:
        """Viscous drag on the horizontal motion of robots inside a bog, as damping on their free joint.

        MuJoCo integrates joint damping implicitly, so even the stiff drag of a bog on a poorly
        traversable robot stays stable at the physics timestep. Membership is re-checked every
        ``energy_dt``."""
        x, y = self.data.qpos[self._root_qpos], self.data.qpos[self._root_qpos + 1]
        inside = np.zeros(len(x), bool)
        for bog in self.bogs:
            inside |= bog.contains(x, y)
        drag = np.where(inside, self._bog_drag, 0.0)
        for axis in (0, 1):
            self.model.dof_damping[self._root_dofs + axis] = drag
        self.model.dof_damping[self._root_dofs + 5] = drag * self._yaw_arm2

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
