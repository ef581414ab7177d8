"""Explorer coverage waypoints for one local environment (Chand §6.2, Fig 6.4, eq. 6.1-6.2).

The explorer sweeps its local environment along evenly spaced parallel lines (boustrophedon coverage, after
trapezoidal decomposition). The line spacing comes from the range SR_t at which an IR reading is still good enough
to push an unexplored cell to the expected occupancy-probability threshold P_s:
  (6.1) NS_t = 0.5 X_res Y_res (1 - P_s) / (2 P_s (X_res + Y_res))     threshold sensor noise
  (6.2) SR_t = SR_min + (SR_max - SR_min)(NS_t - NS_min)/(NS_max - NS_min)   noise taken as linear in range
(6.1) is meant as (6.3) solved for the noise, but the exact inverse of (6.3) has no 0.5 factor; the printed form is
the one implemented, so SR_t is shorter (and the lines closer) than the exact inverse would give.
Fig 6.4: the minimum number of parallel lines that cover the environment when each line senses SR_t to either side,
  n = ceil(width / (2 SR_t)), evenly spaced at width / n,
with the end points of each line ordered into a lawn-mower waypoint list from the corner nearest the explorer.
[RECON] Lines run along x; each end point is inset half a spacing from the environment's edge (so the sensed band
reaches the edge there too); ties between equally near corners go to the first of (lo, lo), (hi, lo), (lo, hi),
(hi, hi) in (x, y). SR_t is clipped to [SR_min, SR_max]: the sensor reads no further.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from teamsim.controllers.navigation.occupancy_grid import MappingParams


def threshold_noise(p_s: float, x_res: float, y_res: float) -> float:
    """(6.1) NS_t exactly as printed, 0.5 factor included (it is not the exact inverse of (6.3))."""
    return 0.5 * x_res * y_res * (1.0 - p_s) / (2.0 * p_s * (x_res + y_res))


def threshold_range(noise: float, params: MappingParams) -> float:
    """(6.2) SR_t: the range whose sensor noise is ``noise``, clipped to the sensor's [SR_min, SR_max]."""
    fraction = (noise - params.noise_min) / (params.noise_max - params.noise_min)
    sensing_range = params.range_min + (params.range_max - params.range_min) * fraction
    return float(np.clip(sensing_range, params.range_min, params.range_max))


@dataclass(frozen=True)
class WaypointParams:
    # P_s is not given by the thesis (spec §8); chosen so that Fig 6.5's 8 waypoints come out of the ch.8 setup
    # (9.6 m local environments of 0.3 m cells) with MappingParams() defaults. 4 lines across 9.6 m need
    # SR_t >= 9.6 / (2 * 4) = 1.2 m, i.e. NS_t >= 0.005 + 0.015 * 1.2 / 1.5 = 0.017 m, i.e. by (6.1)
    # 0.0375 (1 - P_s) / P_s >= 0.017, P_s <= 0.688. 0.68 is the largest two-decimal value: NS_t = 0.01765 m,
    # SR_t = 1.265 m, n = ceil(9.6 / 2.529) = 4. (Any P_s <= 0.688 gives 4 lines, since SR_max = 1.5 m caps SR_t.)
    p_s: float = 0.68

    def sensing_range(self, resolution: float, mapping: MappingParams = MappingParams()) -> float:
        """SR_t for square cells ``resolution`` metres wide; computed once per P_s, as §6.2 does."""
        return threshold_range(threshold_noise(self.p_s, resolution, resolution), mapping)


def line_count(width: float, sensing_range: float) -> int:
    """Minimum number of parallel lines covering ``width`` when each senses ``sensing_range`` to either side."""
    # The tolerance keeps an exact fit (9.6 m at SR_t = 1.2 m) from gaining a line to rounding.
    return max(1, math.ceil(width / (2.0 * sensing_range) - 1e-9))


def coverage_waypoints(lo, hi, sensing_range: float, start) -> np.ndarray:
    """Boustrophedon waypoints (K, 2) in world (x, y) covering the rectangle ``lo``..``hi`` (Fig 6.4).

    Lines run along x at y = lo_y + (k + 0.5) spacing, spacing = width / n; each line's end points are inset
    spacing / 2 from the rectangle's x edges. The list starts at the corner nearest ``start``."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    if sensing_range <= 0 or np.any(hi <= lo):
        raise ValueError("need a positive sensing range and hi > lo")
    width = hi[1] - lo[1]
    count = line_count(width, sensing_range)
    spacing = width / count
    inset = min(spacing / 2.0, (hi[0] - lo[0]) / 2.0)  # a rectangle narrower than one spacing: meet in the middle
    line_y = lo[1] + (np.arange(count) + 0.5) * spacing
    ends_x = np.array([lo[0] + inset, hi[0] - inset])
    corner_x, corner_y = _nearest_corner(lo, hi, np.asarray(start, float))
    if corner_y:  # start from the top line
        line_y = line_y[::-1]
    if corner_x:  # start from the right-hand end
        ends_x = ends_x[::-1]
    points = []
    for k, y in enumerate(line_y):
        xs = ends_x if k % 2 == 0 else ends_x[::-1]  # lawn-mower: every other line is run backwards
        points.extend((x, y) for x in xs)
    return np.array(points)


def _nearest_corner(lo: np.ndarray, hi: np.ndarray, start: np.ndarray) -> tuple[int, int]:
    """(x, y) flags of the corner nearest ``start``: 0 for the lo side, 1 for the hi side."""
    flags = [(0, 0), (1, 0), (0, 1), (1, 1)]
    corners = np.array([[(lo, hi)[fx][0], (lo, hi)[fy][1]] for fx, fy in flags])
    return flags[int(np.argmin(np.hypot(*(corners - start).T)))]
