"""Robot models, arenas and objects: what things *are* (bodies, sensors, actuators, dimensions).

This package imports nothing else of teamsim's.
"""
from __future__ import annotations

from collections.abc import Callable

from teamsim.models import diffdrive
from teamsim.models.robot import RobotModel

# Every robot kind teamsim knows by name. Builders exist for those in ROBOT_BUILDERS; the others are
# reserved names for the kinds still to come (r2 and genghis2 from Parker, tricycle and tracked from Chand).
ROBOT_KINDS = ("r2", "genghis2", "tricycle", "diffdrive", "tracked")
ROBOT_BUILDERS: dict[str, Callable[[str], RobotModel]] = {
    "diffdrive": diffdrive.build,
}


def build_robot(kind: str, name: str) -> RobotModel:
    if kind not in ROBOT_BUILDERS:
        built = ", ".join(ROBOT_BUILDERS)
        raise ValueError(f"robot kind {kind!r} is not available; available: {built}")
    return ROBOT_BUILDERS[kind](name)
