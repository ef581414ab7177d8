"""Where a bog met by an explorer is taken to lie, so that a wheeled explorer's paths keep out of it (beyond the
thesis; docs/decisions.md, "Bog spots").

The terrain map marks whole local environments boggy (§6.1) and the planner keeps wheeled explorers out of them,
but not out of the one they stand in, which is often the one whose bog just turned them back. A bog is met at its
edge, so it is taken as a disc of ``BOG_REACH`` radius centred ``BOG_REACH`` ahead of where it was met, the way the
robot went (bogs are 3.6-6 m across). The disc never takes in the cells round the robot itself, so it can leave.
"""
from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np

BOG_REACH = 3.0  # m, not given


def keep_out(spots: Iterable[tuple[float, float, float]], position: tuple[float, float], radius: float,
             origin: tuple[float, float], resolution: float, shape: tuple[int, int]) -> np.ndarray:
    """bool (rows, cols): the cells of a grid at ``origin`` and ``resolution`` inside the discs of the bogs met at
    ``spots`` ((x, y, heading) each), short of the robot of ``radius`` at ``position``."""
    x_cells = origin[0] + (np.arange(shape[1]) + 0.5) * resolution
    y_cells = origin[1] + (np.arange(shape[0]) + 0.5) * resolution
    inside = np.zeros(shape, bool)
    for x, y, heading in spots:
        x, y = x + BOG_REACH * math.cos(heading), y + BOG_REACH * math.sin(heading)
        reach = min(BOG_REACH, math.dist((x, y), position) - radius)
        if reach > 0:
            inside |= np.hypot(x_cells[None, :] - x, y_cells[:, None] - y) <= reach
    return inside
