"""Gripper behaviours of the R-2 (Parker §2.2.1; the puck handling of the hazardous-waste cleanup, §3.8).

Each behaviour is a small state machine: call it with an :class:`Observation`, get a :class:`Command` whose
``behaviour`` is the behaviour's name, and read its ``status`` ("running", "succeeded" or "failed"). Success
and failure are judged only from the robot's own sensors, as on the real R-2: the two break-beams between the
fingers, the grip force from the pads' contacts, the lift and grip motors' encoders (``Observation.effectors``,
0 = closed / down, 1 = open / up) and the fingertip IR. Objects are held by contact friction alone.

- :class:`Approach`: drive at an object the fingertip IR sees, steering to balance the two toed-in tips, then
  creep until both beams are broken (the object is centred between the pads).
- :class:`Grasp`: close the jaw; succeeded when it stops on something (grip force, jaw still apart, a beam
  broken), failed when it closes on nothing.
- :class:`Lift`: raise the lift; failed if it stalls (too heavy: the lift motor's force limit is sized to the
  thesis' 2 lb capacity) or the object is lost.
- :class:`Carry`: drive a route while holding; failed if the object is lost.
- :class:`Lower`, :class:`Release`: set it down, open and back off until the beams are clear.
- :class:`Sequence` runs behaviours one after the other and stops at the first failure.

Thresholds and speeds are in :class:`GripperParams`; Parker gives none of them, so every one is assumed.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from teamsim.controllers.base import Command, Observation
from teamsim.models.r2 import BEAMS, GRIP_TOUCH, TIP_IR
from teamsim.models.robot import RobotModel

RUNNING, SUCCEEDED, FAILED = "running", "succeeded", "failed"
OPEN, CLOSED, UP, DOWN = 1.0, 0.0, 1.0, 0.0


@dataclass(frozen=True)
class GripperParams:
    """Assumed (Parker §2.2.1 gives the gripper's size and capacity, not how R-2's behaviours used it)."""
    approach_speed: float = 0.06  # m/s towards an object the fingertips see
    creep_speed: float = 0.02  # m/s once a beam is broken: 2 mm a tick, inside the 9 mm where both are broken
    steer_gain: float = 8.0  # rad/s per m of difference between the two fingertip ranges
    turn_rate: float = 0.3  # rad/s towards the side whose fingertip alone sees the object
    blind_time: float = 4.0  # s to keep driving straight after the fingertips lose a close object
    approach_timeout: float = 30.0  # s
    held_force: float = 5.0  # N of grip force (both pads) that means something is held
    closed_empty: float = 0.1  # grip encoder below this: the jaw has closed on nothing
    settled: float = 0.002  # encoder change per tick below which a motor has stopped
    grasp_timeout: float = 3.0  # s
    lift_done: float = 0.9  # lift encoder: up
    lower_done: float = 0.05  # lift encoder: down
    open_done: float = 0.95  # grip encoder: open
    stall_time: float = 1.0  # s without stall_progress of lift travel: the lift has stalled
    stall_progress: float = 0.02
    lower_timeout: float = 6.0  # s
    back_off_speed: float = 0.05  # m/s while backing away from a released object
    release_timeout: float = 6.0  # s
    # s a hold must stay gone before a raised object counts as lost: the pad force reading dips for single ticks
    # as the pads settle on a swinging puck (measured 30 -> 2 N for one tick mid-turn, the puck still held)
    lost_time: float = 0.25


@dataclass(frozen=True)
class GripperSensors:
    """Where the gripper's sensors sit in an Observation."""
    tip_left: int  # index of the left fingertip IR in ir_range
    tip_right: int
    front_beam: int  # index in break_beams
    rear_beam: int
    grip_touch: str = GRIP_TOUCH

    @classmethod
    def of(cls, robot: RobotModel) -> "GripperSensors":
        left, right = (robot.ir_sensors.index(name) for name in TIP_IR)
        front, rear = (robot.beams.index(name) for name in BEAMS)
        return cls(left, right, front, rear)

    def beams(self, obs: Observation) -> tuple[bool, bool]:
        """(front, rear) beam broken."""
        return bool(obs.break_beams[self.front_beam]), bool(obs.break_beams[self.rear_beam])

    def holding(self, obs: Observation, params: GripperParams) -> bool:
        """Something lies across the jaw and the pads squeeze it. One beam is enough: both are broken only
        while an object is within a few millimetres of the pads' centre, and a held puck may settle a little
        off it as the jaw closes."""
        return any(self.beams(obs)) and obs.touch.get(self.grip_touch, 0.0) >= params.held_force


class Behaviour:
    """One gripper behaviour: ``status`` moves from running to succeeded or failed, then stays there."""
    name = "behaviour"
    grip = OPEN  # set-points this behaviour holds the effectors at
    lift = DOWN

    def __init__(self, sensors: GripperSensors, params: GripperParams = GripperParams()):
        self.sensors = sensors
        self.params = params
        self.status = RUNNING
        self.started: float | None = None
        self.reason = ""  # why it failed
        self.unheld_since: float | None = None

    def __call__(self, obs: Observation) -> Command:
        if self.started is None:
            self.started = obs.time
        if self.status != RUNNING:
            return self.command()
        return self.step(obs, obs.time - self.started)

    def step(self, obs: Observation, elapsed: float) -> Command:
        raise NotImplementedError

    def command(self, v: float = 0.0, omega: float = 0.0) -> Command:
        return Command(v=v, omega=omega, behaviour=self.name, extras={"grip": self.grip, "lift": self.lift})

    def lost(self, obs: Observation) -> bool:
        """The held object has been gone for ``lost_time`` (see :class:`GripperParams`)."""
        if self.sensors.holding(obs, self.params):
            self.unheld_since = None
            return False
        if self.unheld_since is None:
            self.unheld_since = obs.time
        return obs.time - self.unheld_since >= self.params.lost_time

    def succeed(self) -> Command:
        self.status = SUCCEEDED
        return self.command()

    def fail(self, reason: str) -> Command:
        self.status, self.reason = FAILED, reason
        return self.command()


class Approach(Behaviour):
    """Jaw open and down; drive at what the fingertip IR sees until both beams are broken.

    It waits for the jaw to be open and down (encoders) before it moves. The tips' rays cross at their
    maximum range, so nearer than that an object to the left is seen by the left tip first (and nearer).
    Close in, the object passes between the rays and no tip sees it: the robot keeps straight for
    ``blind_time``. Then the beams take over: the front one alone means "not in yet", the rear one alone
    "too far in"."""
    name = "approach"

    def __init__(self, sensors: GripperSensors, params: GripperParams = GripperParams()):
        super().__init__(sensors, params)
        self.last_seen: float | None = None

    def step(self, obs: Observation, elapsed: float) -> Command:
        p = self.params
        front, rear = self.sensors.beams(obs)
        if front and rear:
            return self.succeed()
        if elapsed > p.approach_timeout:
            return self.fail("timed out")
        if obs.effectors["grip"] < p.open_done or obs.effectors["lift"] > p.lower_done:
            return self.command()  # wait for the jaw to open and come down
        if front or rear:
            return self.command(p.creep_speed if front else -p.creep_speed)
        left, right = obs.ir_range[self.sensors.tip_left], obs.ir_range[self.sensors.tip_right]
        if np.isfinite(left) or np.isfinite(right):
            self.last_seen = obs.time
            if np.isfinite(left) and np.isfinite(right):
                omega = p.steer_gain * (right - left)
            else:
                omega = p.turn_rate if np.isfinite(left) else -p.turn_rate
            return self.command(p.approach_speed, float(np.clip(omega, -p.turn_rate, p.turn_rate)))
        if self.last_seen is not None and obs.time - self.last_seen <= p.blind_time:
            return self.command(p.approach_speed)
        return self.fail("nothing ahead" if self.last_seen is None else "lost it")


class Grasp(Behaviour):
    """Close the jaw, standing still, and judge by the encoder and the grip force once it has stopped."""
    name = "grasp"
    grip = CLOSED

    def __init__(self, sensors: GripperSensors, params: GripperParams = GripperParams()):
        super().__init__(sensors, params)
        self.previous: float | None = None

    def step(self, obs: Observation, elapsed: float) -> Command:
        p = self.params
        position = obs.effectors["grip"]
        moving = self.previous is None or abs(position - self.previous) > p.settled
        self.previous = position
        if position <= p.closed_empty:
            return self.fail("closed on nothing")
        if not moving and self.sensors.holding(obs, p):
            return self.succeed()
        if elapsed > p.grasp_timeout:
            return self.fail("no grip")
        return self.command()


class Lift(Behaviour):
    """Raise the held object; fail if the lift stalls below the top or the object slips out."""
    name = "lift"
    grip, lift = CLOSED, UP

    def __init__(self, sensors: GripperSensors, params: GripperParams = GripperParams()):
        super().__init__(sensors, params)
        self.mark: tuple[float, float] | None = None  # (time, encoder) when the lift last made progress

    def step(self, obs: Observation, elapsed: float) -> Command:
        p = self.params
        position = obs.effectors["lift"]
        if self.lost(obs):
            return self.fail("lost it")
        if position >= p.lift_done:
            return self.succeed()
        if self.mark is None or position - self.mark[1] >= p.stall_progress:
            self.mark = (obs.time, position)
        elif obs.time - self.mark[0] > p.stall_time:
            return self.fail("too heavy")
        return self.command()


class Carry(Behaviour):
    """Hold the object up and drive ``route``: a function of the observation giving (v, omega), or None when
    the destination is reached."""
    name = "carry"
    grip, lift = CLOSED, UP

    def __init__(self, sensors: GripperSensors, route, params: GripperParams = GripperParams()):
        super().__init__(sensors, params)
        self.route = route

    def step(self, obs: Observation, elapsed: float) -> Command:
        if self.lost(obs):
            return self.fail("lost it")
        drive = self.route(obs)
        if drive is None:
            return self.succeed()
        return self.command(*drive)


class Lower(Behaviour):
    """Put the held object down, still gripping it."""
    name = "lower"
    grip = CLOSED

    def step(self, obs: Observation, elapsed: float) -> Command:
        if obs.effectors["lift"] <= self.params.lower_done:
            return self.succeed()
        if elapsed > self.params.lower_timeout:
            return self.fail("lift stuck")
        return self.command()


class Release(Behaviour):
    """Open the jaw, then back away until neither beam is broken."""
    name = "release"

    def step(self, obs: Observation, elapsed: float) -> Command:
        p = self.params
        if elapsed > p.release_timeout:
            return self.fail("still in the jaw")
        if obs.effectors["grip"] < p.open_done:
            return self.command()
        if any(self.sensors.beams(obs)):
            return self.command(-p.back_off_speed)
        return self.succeed()


class TimedRoute:
    """A route of timed legs ``(v, omega, seconds)``, for :class:`Carry`: dead reckoning, no positioning."""

    def __init__(self, legs):
        self.legs = list(legs)
        self.ends = np.cumsum([seconds for *_, seconds in self.legs])
        self.start: float | None = None

    def __call__(self, obs: Observation):
        if self.start is None:
            self.start = obs.time
        k = int(np.searchsorted(self.ends, obs.time - self.start, side="right"))
        return None if k >= len(self.legs) else self.legs[k][:2]


class Sequence:
    """Behaviours one after another; fails with the first that fails. When done (or failed) it stands still
    with the effectors where the last behaviour left them."""

    def __init__(self, behaviours):
        self.behaviours = list(behaviours)
        self.index = 0

    @property
    def current(self) -> Behaviour:
        return self.behaviours[min(self.index, len(self.behaviours) - 1)]

    @property
    def status(self) -> str:
        if any(b.status == FAILED for b in self.behaviours):
            return FAILED
        return SUCCEEDED if self.index >= len(self.behaviours) else RUNNING

    def __call__(self, obs: Observation) -> Command:
        command = self.current(obs)
        while self.index < len(self.behaviours) and self.current.status == SUCCEEDED:
            self.index += 1
            if self.index < len(self.behaviours):
                command = self.current(obs)
        return command
