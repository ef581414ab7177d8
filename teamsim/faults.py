"""Faults as scenario data: what goes wrong, to which robot, and when (DESIGN.md, "Faults").

CLI form: ``KIND:ROBOT@SECONDS[,key=value...]``, e.g. ``kill:red@60``, ``blind-ir:green@30``,
``radio-off:blue@0``, ``slow:red@10,factor=0.5``, ``blind-ir:green@0,sensors=ir_left+ir_right``,
``break-motor:red@5,motor=left``, ``add-robot:purple@20,kind=diffdrive``, ``remove:red@60`` (taken out of the
arena, as Parker seized an R-2, §6.1.2), ``revive:red@120`` (switched on again with a fresh controller; a removed
robot is put back where the mission says, else at its start). The world applies each fault at its time and
records an event; a fault changes a robot's :class:`Health`, which the world consults when sensing and actuating
(and the world moves a removed or revived robot and gives a revived one a fresh controller).

A fault may strike a *role* instead of a named robot: ``@ROLE`` in place of ROBOT (``kill:@leader@300``,
``kill:@leader:A@300``). Which robot holds a role is known only while the mission runs (bounding overwatch elects
its leaders, Parker §6.3), so the world asks the mission (``role_holder(world, role)``) when the fault is due, and
a role nobody holds then keeps the fault waiting until somebody does (docs/decisions.md, "Faults by run-time
role"). The ``@`` keeps a role apart from a robot name, which may not contain it.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

from teamsim.config import ConfigError

# kind -> {option: (parser, default, meaning)}
FAULT_OPTIONS: dict[str, dict[str, tuple]] = {
    "kill": {},
    "blind-ir": {"sensors": (str, None, "IR sensor names or name prefixes joined by '+' (default: every sensor)")},
    "radio-off": {},
    "radio-on": {},
    "break-motor": {"motor": (str, None, "locomotion motor name (default: the first)")},
    "slow": {"factor": (float, 0.5, "speed multiplier in (0, 1]")},
    "break-gripper": {},
    "add-robot": {"kind": (str, "diffdrive", "robot kind of the newcomer")},
    "remove": {},
    "revive": {},
}
FAULT_KINDS = tuple(FAULT_OPTIONS)
_SPEC = re.compile(r"^(?P<kind>[a-z-]+):(?P<robot>[A-Za-z0-9_-]+|@[A-Za-z0-9_-]+(:[A-Za-z0-9_-]+)?)@(?P<time>[^,]+)"
                   r"(?P<rest>(,[^,=]+=[^,]*)*)$")
SPEC_FORM = "KIND:ROBOT@SECONDS[,key=value...]"
ROLE_MARK = "@"  # a target that starts with it is a role (``@leader``), resolved when the fault is due
# A role's holder is a robot that is running: a role cannot bring a robot in or switch one on again.
NOT_BY_ROLE = ("add-robot", "revive")


@dataclass(frozen=True)
class Fault:
    kind: str
    robot: str
    time: float
    options: dict = field(default_factory=dict)

    @property
    def role(self) -> str | None:
        """The role this fault strikes (``leader`` for ``@leader``), or None when it names a robot."""
        return self.robot[len(ROLE_MARK):] if self.robot.startswith(ROLE_MARK) else None

    def describe(self) -> dict:
        described = {"kind": self.kind, "robot": self.robot, "time": self.time}
        return {**described, "options": dict(self.options)} if self.options else described


@dataclass
class Health:
    """What faults have done to one robot so far."""
    alive: bool = True
    ir_blind: tuple = ()  # name prefixes of the blinded IR sensors ("" blinds them all)
    radio_on: bool = True
    radio_cut: bool = False  # a radio-off fault: the radio stays off through a power cycle (revive)
    gripper_broken: bool = False
    speed_factor: float = 1.0
    broken_motors: set = field(default_factory=set)
    removed: bool = False  # taken out of the arena (parked outside it) until revived


def parse_fault(spec: str) -> Fault:
    """Parse one ``--fault`` spec; raise ConfigError with a one-line reason."""
    match = _SPEC.match(spec.strip())
    if not match:
        raise ConfigError(f"--fault {spec!r}: expected {SPEC_FORM} (ROBOT: a robot's name, or @ROLE), e.g. "
                          "kill:red@60")
    kind = match["kind"]
    if kind not in FAULT_OPTIONS:
        raise ConfigError(f"--fault {spec!r}: unknown kind {kind!r}; allowed: {', '.join(FAULT_KINDS)}")
    if match["robot"].startswith(ROLE_MARK) and kind in NOT_BY_ROLE:
        allowed = ", ".join(k for k in FAULT_KINDS if k not in NOT_BY_ROLE)
        raise ConfigError(f"--fault {spec!r}: {kind} needs a robot's name, not a role; kinds a role "
                          f"({match['robot']}) may take: {allowed}")
    try:
        time = float(match["time"])
    except ValueError:
        raise ConfigError(f"--fault {spec!r}: time {match['time']!r} is not a number of seconds") from None
    if not math.isfinite(time) or time < 0:
        raise ConfigError(f"--fault {spec!r}: time must be a finite number of seconds >= 0")
    allowed = FAULT_OPTIONS[kind]
    options = {key: default for key, (_, default, _) in allowed.items() if default is not None}
    for pair in filter(None, match["rest"].split(",")):
        key, _, text = pair.partition("=")
        if key not in allowed:
            names = ", ".join(allowed) or "none"
            raise ConfigError(f"--fault {spec!r}: unknown option {key!r} for {kind}; allowed: {names}")
        try:
            options[key] = allowed[key][0](text)
        except ValueError:
            raise ConfigError(f"--fault {spec!r}: {key}={text!r} is not a valid {allowed[key][0].__name__}") from None
    if kind == "slow" and not 0.0 < options["factor"] <= 1.0:
        raise ConfigError(f"--fault {spec!r}: factor must be in (0, 1]")
    return Fault(kind, match["robot"], time, options)


def apply_fault(fault: Fault, health: Health, motor_names: tuple[str, ...]) -> None:
    """Change ``health`` as ``fault`` says (add-robot is the world's job: it has no health to change; so is
    moving a removed or revived robot)."""
    kind = fault.kind
    if kind in ("kill", "remove"):
        health.alive = False
        health.radio_on = False
        health.removed = health.removed or kind == "remove"
    elif kind == "revive":
        health.alive = True
        health.radio_on = not health.radio_cut
    elif kind == "blind-ir":
        health.ir_blind += tuple(fault.options.get("sensors", "").split("+"))
    elif kind == "radio-off":
        health.radio_on, health.radio_cut = False, True
    elif kind == "radio-on":
        health.radio_on, health.radio_cut = health.alive, False
    elif kind == "break-motor":
        health.broken_motors.add(fault.options.get("motor") or motor_names[0])
    elif kind == "slow":
        health.speed_factor *= fault.options["factor"]
    elif kind == "break-gripper":
        health.gripper_broken = True


def role_refusal(mission: str, role: str, roles: dict) -> str:
    """Why a fault may not name ``@role`` in ``mission`` (whose ``fault_roles`` are ``roles``), with what may be
    named instead: one line."""
    if not roles:
        return f"{mission} has no roles a fault may name (@ROLE is for missions that elect them); name a robot"
    return f"{mission} has no role {role!r}; allowed roles: {', '.join(ROLE_MARK + r for r in roles)}"
