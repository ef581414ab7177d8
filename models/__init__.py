"""Robot models, arenas and objects: what things *are* (bodies, sensors, actuators, dimensions).

This package imports nothing else of teamsim's.
"""
from __future__ import annotations

import importlib

from teamsim.models.robot import RobotModel

# Every robot kind teamsim knows by name, and the module whose ``build(name)`` makes it.
ROBOT_KINDS = ("r2", "genghis2", "tricycle", "diffdrive", "tracked", "janitor")
_MODULES = {kind: f"teamsim.models.{kind}" for kind in ROBOT_KINDS}


# A robot module that fails to import fails everything that imports the models, its tests included (issue 28).
ROBOT_BUILDERS = {kind: importlib.import_module(module).build for kind, module in _MODULES.items()}


def build_robot(kind: str, name: str, **options) -> RobotModel:
    """Robot ``name`` of ``kind``; ``options`` override fields of the kind's dimensions (e.g. radius=0.40)."""
    if kind not in ROBOT_BUILDERS:
        raise ValueError(f"robot kind {kind!r} is not available; available: {', '.join(ROBOT_BUILDERS)}")
    try:
        return ROBOT_BUILDERS[kind](name, **options)
    except TypeError as exc:
        raise ValueError(f"robot {name!r} ({kind}): {exc}") from None
