"""Following a planned path with the reactive controller (§3.4, §3.6.2): the direction sensor aims N_t nodes ahead
of the path node closest to the robot, so the dynamic window still avoids what the plan did not know about."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PathFollowing:
    # Not given by the thesis (spec §8); chosen.
    lookahead: float = 1.0  # m of path: N_t = lookahead / grid resolution nodes (§3.4)
    search_ahead: int = 4  # the closest node is looked for within this many look-aheads of the previous one
    clearance: float = 0.2  # m added to the footprint radius when inflating obstacles for planning, so that a
    # planned passage leaves room for the dynamic window's safety margin


class PathFollower:
    """Where to aim along ``path`` ((n, 2) world points, one per grid node of ``resolution``); past the end of a
    path that does not reach the goal, at the goal itself (§3.2.2)."""

    def __init__(self, path: np.ndarray, reaches_goal: bool, resolution: float,
                 following: PathFollowing = PathFollowing()):
        self.path = path
        self.reaches_goal = reaches_goal
        self.lookahead_nodes = max(1, round(following.lookahead / resolution))
        self.search_nodes = following.search_ahead * self.lookahead_nodes
        self.node = 0

    def waypoint(self, centre: tuple[float, float], goal: tuple[float, float]) -> tuple[float, float]:
        window = self.path[self.node:self.node + self.search_nodes + 1]
        self.node += int(np.argmin(np.hypot(window[:, 0] - centre[0], window[:, 1] - centre[1])))
        last = len(self.path) - 1
        if self.node == last and not self.reaches_goal:
            return goal
        x, y = self.path[min(self.node + self.lookahead_nodes, last)]
        return float(x), float(y)

    @property
    def at_end(self) -> bool:
        return self.node == len(self.path) - 1
