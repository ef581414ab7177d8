"""A built world: the arena's MJCF and the team to place in it, as a mission builds it (``teamsim.tasks.base``) and
the world loads it (``teamsim.world``)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from dm_control import mjcf


@dataclass(frozen=True)
class RobotSlot:
    """One robot of the team: who, what kind, where it starts, and whether it waits for an add-robot fault."""
    name: str
    kind: str
    x: float
    y: float
    yaw: float
    dormant: bool = False
    options: dict = field(default_factory=dict)  # builder overrides of the kind's dimensions, e.g. radius=0.40


@dataclass
class Scene:
    arena: mjcf.RootElement
    robots: list[RobotSlot]
    bogs: list = field(default_factory=list)  # teamsim.models.arenas.Bog zones, already drawn in the arena
    params: Any = None  # the mission parameters it was built from
    info: dict = field(default_factory=dict)  # whatever else the mission needs later (goal, known map, ...)
    faults: list = field(default_factory=list)  # teamsim.faults.Fault the scenario starts with (a dead sensor, ...)
    scenario: Any = None  # the teamsim.scenario.Scenario it was built from, if the mission describes worlds so
    # Robot -> (bandwidth bit/s, range m): the team talks over teamsim.network (Chand's 802.11) instead of the radio,
    # with the latency and loss of ``network_config`` (a teamsim.network.NetworkConfig; None: its defaults)
    network: dict | None = None
    network_config: Any = None
