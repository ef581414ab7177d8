"""teamsim as a multi-agent learning environment (issue 30): any mission or scenario file as a PettingZoo
``ParallelEnv``, and a one-robot mission as a Gymnasium ``Env``. Needs ``pip install 'teamsim[rl]'``.

One agent per robot (or per robot named in ``agents``; the others keep their mission controllers). A step is one
control period (``timing.control_dt``, 0.1 s): each agent's action is carried out, physics runs to the next tick,
and each agent observes what its controller would: the same readings with the same noise
(``teamsim.controllers.base.Observation``), flattened into a vector whose layout ``observation_names(agent)``
gives. Actions are (v, omega), plus a set-point in [0, 1] per effector (an R-2's ``grip`` and ``lift``).

Reward and termination are the mission's own (docs/env.md): the team shares ``progress(world)``'s increase each
step, where a mission defines progress (navigate: the share of the start-goal distance covered; hazardous-waste:
pucks delivered out of the target; box-pushing: the box's advance out of the set distance); otherwise the only
reward is 1 when the mission ends completed. Episodes terminate when ``mission.done`` says so and are truncated at
the mission's duration. A robot killed by a fault terminates alone. Faults of the scenario and of ``faults`` fire.
"""
from __future__ import annotations

import functools

import mujoco
import numpy as np

try:
    import gymnasium
    from gymnasium import spaces
    from pettingzoo import ParallelEnv
except ImportError as exc:  # pragma: no cover - exercised only without the extra
    raise ImportError("teamsim.env needs the rl extra: pip install 'teamsim[rl]'") from exc

from teamsim.config import ConfigError
from teamsim.controllers.base import Command, Observation
from teamsim.runner import mission_of, trial_config
from teamsim.scenario import resolve
from teamsim.tasks import MISSIONS
from teamsim.world import World


def _observation_layout(robot) -> list[tuple[str, int]]:
    """(name, length) of each part of a robot's observation vector."""
    model = robot.model
    return [("ir_range", len(model.ir_sensors)), ("pose", 4), ("velocity", 2), ("motor_speeds", len(model.motors)),
            ("effectors", len(model.effectors)), ("touch", len(model.touch)), ("break_beams", len(model.beams))]


def flatten(observation: Observation, robot) -> np.ndarray:
    """A robot's Observation as its vector: IR ranges (beyond range: the sensor's maximum), the latest positioning
    fix (has fix, x, y, heading), odometry (v, omega), locomotion encoders, effector encoders, touch forces and
    break beams, in ``_observation_layout``'s order."""
    fix = observation.pose
    pose = (1.0, fix.x, fix.y, fix.heading) if fix is not None else (0.0, 0.0, 0.0, 0.0)
    parts = [np.minimum(observation.ir_range, robot.model.ir.max_range), pose, observation.velocity or (0.0, 0.0),
             observation.motor_speeds, [observation.effectors[n] for n in robot.model.effectors],
             [observation.touch.get(n, 0.0) for n in robot.model.touch], observation.break_beams]
    return np.concatenate([np.asarray(p, np.float64).ravel() for p in parts]).astype(np.float32)


def _agent_drives(agent: str):
    """What stands in an agent's robot for its controller: the agent's actions drive it, nothing may ask it."""
    def refuse(observation: Observation) -> Command:
        raise RuntimeError(f"{agent} is driven by its agent's actions (teamsim.env), not by a controller")
    return refuse


def _observation_bounds(robot) -> tuple[np.ndarray, np.ndarray]:
    """Lows and highs of a robot's observation vector, part by part (unbounded where the physics does not bound
    a reading)."""
    bounds = {"ir_range": (0.0, robot.model.ir.max_range), "touch": (0.0, np.inf), "break_beams": (0.0, 1.0)}
    low, high = [], []
    for part, size in _observation_layout(robot):
        lo, hi = bounds.get(part, (-np.inf, np.inf))
        if part == "pose":
            lo, hi = [0.0, -np.inf, -np.inf, -np.pi], [1.0, np.inf, np.inf, np.pi]
        low.append(np.broadcast_to(lo, size))
        high.append(np.broadcast_to(hi, size))
    return np.concatenate(low).astype(np.float32), np.concatenate(high).astype(np.float32)


class TeamEnv(ParallelEnv):
    """A teamsim mission as a PettingZoo ``ParallelEnv``; arguments as ``teamsim run``'s (``settings`` are ``--set``
    strings, ``faults`` ``--fault`` specs). ``seed`` seeds the first reset; later resets without a seed draw their
    trial seeds from it, as PettingZoo expects."""

    metadata = {"name": "teamsim_v0", "render_modes": []}

    def __init__(self, mission: str, *, scenario=None, settings=(), faults=(), seed: int | None = None,
                 duration: float | None = None, agents: list[str] | None = None):
        if mission not in MISSIONS:
            raise ValueError(f"mission: unknown mission {mission!r}; known: {', '.join(MISSIONS)}")
        self._arguments = dict(scenario=scenario, settings=tuple(settings), faults=tuple(faults), duration=duration)
        self._seeds = np.random.default_rng(seed)
        self.mission = mission_of(mission)
        self.render_mode = None
        try:
            self._build(seed or 0)
        except ConfigError as exc:
            raise ValueError(str(exc)) from None
        team = [name for name, robot in self.world.robots.items() if not robot.dormant]
        unknown = [a for a in agents or () if a not in team]
        if unknown:
            raise ValueError(f"agents: no robot {unknown[0]!r} in the team; robots: {', '.join(team)}")
        self.possible_agents = list(agents or team)
        self.agents: list[str] = []

    # -- spaces ------------------------------------------------------------------------------------------------
    @functools.lru_cache(maxsize=None)
    def observation_space(self, agent: str) -> spaces.Box:
        low, high = _observation_bounds(self.world.robots[agent])
        return spaces.Box(low, high, dtype=np.float32)

    @functools.lru_cache(maxsize=None)
    def action_space(self, agent: str) -> spaces.Box:
        model = self.world.robots[agent].model
        effectors = len(model.effectors)
        low = np.array([-model.limits.v_max, -model.limits.omega_max] + [0.0] * effectors, np.float32)
        high = np.array([model.limits.v_max, model.limits.omega_max] + [1.0] * effectors, np.float32)
        return spaces.Box(low, high, dtype=np.float32)

    def observation_names(self, agent: str) -> list[str]:
        """What each entry of ``agent``'s observation vector is."""
        robot = self.world.robots[agent]
        names = {"ir_range": list(robot.model.ir_sensors), "pose": ["has_fix", "x", "y", "heading"],
                 "velocity": ["v", "omega"], "motor_speeds": list(robot.model.motors),
                 "effectors": list(robot.model.effectors), "touch": list(robot.model.touch),
                 "break_beams": list(robot.model.beams)}
        return [f"{part}/{name}" for part, _ in _observation_layout(robot) for name in names[part]]

    # -- the episode -------------------------------------------------------------------------------------------
    def reset(self, seed: int | None = None, options: dict | None = None):
        if seed is not None:  # reseeded: this trial's seed, and the stream later resets draw theirs from
            self._seeds = np.random.default_rng(seed)
        self._build(seed if seed is not None else int(self._seeds.integers(2**31)))
        self.agents = list(self.possible_agents)
        for agent in self.agents:
            self.world.robots[agent].controller = _agent_drives(agent)
        self._progress = self._measure_progress()
        observations = self._observe()
        return ({a: observations[a] for a in self.agents},
                {a: {"time": self.world.time, "seed": self.world.config.seed} for a in self.agents})

    def step(self, actions: dict):
        world = self.world
        for name, (robot, observation) in self._pending.items():
            world.act(robot, observation, self._command(name, actions.get(name)))
        world.advance(min(world.steps_per_tick, self._end_step - world.step))
        world.check_stable()
        done = self.mission.done(world)
        truncated = not done and world.step >= self._end_step
        observations = self._observe()
        progress = self._measure_progress()
        reward, self._progress = progress - self._progress, progress
        info = {"time": world.time}
        if done or truncated:
            completed, metrics = self.mission.outcome(world)
            info.update(completed=completed, metrics=metrics)
            if not hasattr(self.mission, "progress"):
                reward += float(completed)
        live = set(observations)
        agents, self.agents = self.agents, [a for a in self.agents if a in live and not (done or truncated)]
        return ({a: observations.get(a, np.zeros(self.observation_space(a).shape, np.float32)) for a in agents},
                {a: float(reward) for a in agents},
                {a: done or a not in live for a in agents},
                {a: truncated and a in live for a in agents},
                {a: dict(info) for a in agents})

    def state(self) -> np.ndarray:
        """MuJoCo's integration state (qpos, qvel, act, ...): the whole world, bit for bit."""
        spec = mujoco.mjtState.mjSTATE_INTEGRATION
        state = np.empty(mujoco.mj_stateSize(self.world.model, spec))
        mujoco.mj_getState(self.world.model, self.world.data, state, spec)
        return state

    def close(self) -> None:
        self.agents = []

    # -- for a controller of teamsim's own, driven through the interface ----------------------------------------
    def last_observation(self, agent: str) -> Observation:
        """The Observation ``agent``'s vector was made from (a teamsim controller's input)."""
        return self._pending[agent][1]

    def mission_controller(self, agent: str):
        """A fresh instance of the controller the mission gives ``agent`` (to drive it through ``step``)."""
        robot = self.world.robots[agent]
        return self.mission.controller(robot.model, self.world.scene,
                                       self.world.streams.get("robot", agent, "brain"))

    def command_of(self, agent: str, command: Command) -> np.ndarray:
        """A teamsim Command as ``agent``'s action vector, in float64: carried out exactly as the command would be
        (a float32 action rounds v and omega, and the physics then differs in the last bits)."""
        robot = self.world.robots[agent]
        extras = [command.extras.get(n, robot.effector_positions.get(n, 0.0)) for n in robot.model.effectors]
        space = self.action_space(agent)
        return np.clip(np.array([command.v, command.omega, *extras]), space.low, space.high)

    # -- inside -------------------------------------------------------------------------------------------------
    def _build(self, seed: int) -> None:
        config = trial_config(self.mission.name, seed=seed, **self._arguments)
        config = resolve(config, self.mission)
        if getattr(self.mission, "without_physics", None) and self.mission.without_physics(config):
            raise ConfigError("backend: the environment needs the physics backend")
        self.world = World(config, self.mission)
        self._end_step = round((config.duration or self.mission.default_duration) / self.world.physics_dt)
        self._pending: dict = {}

    def _observe(self) -> dict[str, np.ndarray]:
        """Sense at the current tick: the agents' observations, kept until their actions come; robots that are not
        agents are answered by their own controllers at once, as in ``World.tick``."""
        self._pending = {}
        observations = {}
        for robot, observation in self.world.observe():
            if robot.name in self.agents:
                self._pending[robot.name] = (robot, observation)
                observations[robot.name] = flatten(observation, robot)
            else:
                self.world.act(robot, observation, robot.controller(observation))
        return observations

    def _command(self, agent: str, action) -> Command:
        model = self.world.robots[agent].model
        if action is None:  # no action for a live agent: it stands still
            return Command(behaviour="agent")
        action = np.asarray(action, np.float64).ravel()
        space = self.action_space(agent)
        if action.shape != space.shape or not np.isfinite(action).all():
            raise ValueError(f"actions[{agent!r}]: expected {space.shape[0]} finite numbers (v, omega"
                             f"{''.join(', ' + n for n in model.effectors)}); got {action.tolist()}")
        action = np.clip(action, space.low, space.high)
        return Command(v=float(action[0]), omega=float(action[1]), behaviour="agent",
                       extras={n: float(x) for n, x in zip(model.effectors, action[2:])})

    def _measure_progress(self) -> float:
        measure = getattr(self.mission, "progress", None)
        return float(measure(self.world)) if measure is not None else 0.0


class SingleRobotEnv(gymnasium.Env):
    """A mission with one robot (``navigate``, or any scenario with one agent) as a Gymnasium ``Env``; arguments as
    :class:`TeamEnv`'s."""

    metadata = {"render_modes": []}

    def __init__(self, mission: str, **arguments):
        self.team = TeamEnv(mission, **arguments)
        if len(self.team.possible_agents) != 1:
            raise ValueError(f"mission: {mission} has {len(self.team.possible_agents)} robots "
                             f"({', '.join(self.team.possible_agents)}); a Gymnasium Env drives one (use TeamEnv)")
        self.agent = self.team.possible_agents[0]
        self.observation_space = self.team.observation_space(self.agent)
        self.action_space = self.team.action_space(self.agent)
        self.render_mode = None

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        observations, infos = self.team.reset(seed=seed, options=options)
        return observations[self.agent], infos[self.agent]

    def step(self, action):
        observations, rewards, terminated, truncated, infos = self.team.step({self.agent: action})
        a = self.agent
        return observations[a], rewards[a], terminated[a], truncated[a], infos[a]


def parallel_env(mission: str, **arguments) -> TeamEnv:
    """PettingZoo's constructor convention."""
    return TeamEnv(mission, **arguments)


