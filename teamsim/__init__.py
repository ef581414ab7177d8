"""teamsim: MuJoCo simulation of heterogeneous cooperative robot teams.

Importing teamsim selects the offscreen GL backend (``teamsim.gl``) before anything imports mujoco.
"""
from teamsim.gl import choose_backend as _choose_backend

_choose_backend()

__version__ = "0.1.0"
