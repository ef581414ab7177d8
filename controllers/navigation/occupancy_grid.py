"""Rectangular occupancy grid with Bayes updates from IR readings (Chand §3.2.1 and §6.2.2, eq. 6.3-6.5).

Each cell holds the probability that it is occupied. Unexplored cells hold 0.5, and every probability is kept in
[0.05, 0.95] so that Bayes' rule keeps working (§3.2.1). An IR beam is a narrow cone (the Sharp GP2Y0A02YK's is
about 5 degrees, §6.2.2): the cells it crosses short of the reading are evidence of free space, the cells at the
reading are evidence of an obstacle, and the cells under the robot are free.

Frames: ``origin`` is the world position of the grid's lower-left corner; a cell is (row, col) with the row along
world y and the column along world x, so ``probabilities[row, col]``.

Update, per cell and beam (§6.2.2):
  (6.3) P(occ_s|occ)   = X_res Y_res / (X_res Y_res + 2 NS_sen (X_res + Y_res)), NS_sen the sensor noise at the
        reading's range; the thesis takes noise as linear in range between NS_min and NS_max (§6.2.1, eq. 6.2).
  (6.4) P(uocc_s|uocc) = 0.2 + (0.5 - 0.2)(SR - SR_min)/(SR_max - SR_min), SR the cell's distance along the beam.
  (6.5) P_u = P_i q / (P_i q + (1 - P_i)(1 - q)) with q = P(occ_s|occ) if it exceeds 0.5 (occupied evidence), or
        q = P(uocc_s|uocc) if it is below 0.5 (free evidence); otherwise P_u = P_i.
(6.5) multiplies a cell's odds by q/(1-q); all the beams of one reading are applied together by adding their
log-odds, which is (6.5) applied once per beam, and the result is then clamped.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class MappingParams:
    p_min: float = 0.05  # §3.2.1: lower clamp, "free"
    p_max: float = 0.95  # §3.2.1: upper clamp, "occupied"
    p_unexplored: float = 0.5  # §6.2.2: initial value of every cell
    p_free_near: float = 0.2  # (6.4): P(uocc_s|uocc) at the minimum sensing range (thesis: "arbitrarily selected")
    p_free_far: float = 0.5  # (6.4): P(uocc_s|uocc) at the maximum sensing range (no information)
    beam_angle: float = np.radians(5.0)  # §6.2.2: full cone angle of the Sharp GP2Y0A02YK
    # Not given by the thesis (§8 of the spec); chosen:
    range_min: float = 0.0  # SR_min, m: the IR model here reads from 0 m
    range_max: float = 1.5  # SR_max, m: the IR range of every Chand robot (Table 3.1)
    # With 0.1 m cells these give P(occ_s|occ) from 0.83 near to 0.56 at full range, so every hit counts.
    noise_min: float = 0.005  # NS_min, m, sensor noise at SR_min
    noise_max: float = 0.02  # NS_max, m, sensor noise at SR_max
    # Which cell a hit marks occupied: "around" the surface (within half a cell of it, as §6.2.2 reads; a cell
    # whose centre lies just short of a box's face is marked too), or the first cell "beyond" it, whose centre
    # lies inside the obstacle: a cell is then occupied when its centre is, as the worlds' density rasters count
    # (docs/decisions.md, "Exploration": the explorers map at 0.3 m, where the difference is a row of cells
    # along every face and wall).
    hit_cell: str = "around"


def sensor_noise(distance: np.ndarray, params: MappingParams) -> np.ndarray:
    """NS_sen at a range: linear from NS_min at SR_min to NS_max at SR_max (§6.2.1, the inverse of eq. 6.2)."""
    fraction = (np.asarray(distance, float) - params.range_min) / (params.range_max - params.range_min)
    return params.noise_min + (params.noise_max - params.noise_min) * np.clip(fraction, 0.0, 1.0)


def p_occupied_given_occupied(noise: np.ndarray, x_res: float, y_res: float) -> np.ndarray:
    """(6.3): the area of one cell over that area enlarged by the sensor noise on every side."""
    area = x_res * y_res
    return area / (area + 2.0 * np.asarray(noise, float) * (x_res + y_res))


def p_free_given_free(distance: np.ndarray, params: MappingParams) -> np.ndarray:
    """(6.4): 0.2 at SR_min rising linearly to 0.5 at SR_max, so near cells saturate to free faster."""
    fraction = (np.asarray(distance, float) - params.range_min) / (params.range_max - params.range_min)
    return params.p_free_near + (params.p_free_far - params.p_free_near) * np.clip(fraction, 0.0, 1.0)


def bayes_update(prior: np.ndarray, q: np.ndarray) -> np.ndarray:
    """(6.5) for one piece of evidence q (either P(occ_s|occ) > 0.5 or P(uocc_s|uocc) < 0.5); q = 0.5 keeps the
    prior, as the "otherwise" case does."""
    prior, q = np.asarray(prior, float), np.asarray(q, float)
    return prior * q / (prior * q + (1.0 - prior) * (1.0 - q))


def _logit(p: np.ndarray) -> np.ndarray:
    return np.log(p / (1.0 - p))


class OccupancyGrid:
    """Occupancy probabilities over a rectangle of square cells ``resolution`` metres wide."""

    def __init__(self, origin: tuple[float, float], resolution: float, probabilities: np.ndarray,
                 params: MappingParams = MappingParams()):
        self.origin = (float(origin[0]), float(origin[1]))
        self.resolution = float(resolution)
        self.params = params
        self.probabilities = np.clip(np.asarray(probabilities, float), params.p_min, params.p_max)

    @classmethod
    def unexplored(cls, origin: tuple[float, float], resolution: float, shape: tuple[int, int],
                   params: MappingParams = MappingParams()) -> "OccupancyGrid":
        return cls(origin, resolution, np.full(shape, params.p_unexplored), params)

    @classmethod
    def known(cls, origin: tuple[float, float], resolution: float, occupied: np.ndarray,
              params: MappingParams = MappingParams()) -> "OccupancyGrid":
        """A fully known map: occupied cells at the upper clamp, the rest at the lower."""
        return cls(origin, resolution, np.where(np.asarray(occupied, bool), params.p_max, params.p_min), params)

    @property
    def shape(self) -> tuple[int, int]:
        return self.probabilities.shape

    def world_to_cell(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """(row, col) of the cells containing world points (they may lie outside the grid; see ``contains``)."""
        col = np.floor((np.asarray(x, float) - self.origin[0]) / self.resolution).astype(int)
        row = np.floor((np.asarray(y, float) - self.origin[1]) / self.resolution).astype(int)
        return row, col

    def cell_to_world(self, row, col) -> tuple[np.ndarray, np.ndarray]:
        """World (x, y) of cell centres."""
        x = self.origin[0] + (np.asarray(col, float) + 0.5) * self.resolution
        y = self.origin[1] + (np.asarray(row, float) + 0.5) * self.resolution
        return x, y

    def contains(self, row, col) -> np.ndarray:
        row, col = np.asarray(row), np.asarray(col)
        return (row >= 0) & (row < self.shape[0]) & (col >= 0) & (col < self.shape[1])

    def update(self, pose: tuple[float, float, float], ranges: np.ndarray, bearings: np.ndarray, *,
               sensor_radius: float | np.ndarray, centre_offset: float = 0.0,
               footprint_radius: float = 0.0) -> None:
        """Integrate one IR reading taken at robot ``pose`` (x, y, heading).

        The sensors sit ``sensor_radius`` (one for all, or one per sensor) from the robot's physical centre,
        which is ``centre_offset`` ahead of the pose's reference point, each looking out along its body-frame
        ``bearing``; ``ranges`` are measured from the sensor, ``inf`` where the beam saw nothing. Cells within
        ``footprint_radius`` of the centre are free (the robot is standing on them)."""
        p = self.params
        x, y, heading = (float(v) for v in pose)
        ranges = np.asarray(ranges, float)
        bearings = np.asarray(bearings, float)
        cx, cy = x + centre_offset * np.cos(heading), y + centre_offset * np.sin(heading)
        directions = heading + bearings
        ux, uy = np.cos(directions), np.sin(directions)
        sx, sy = cx + sensor_radius * ux, cy + sensor_radius * uy
        reach = float(np.max(sensor_radius)) + p.range_max + self.resolution
        rows, cols = self.window(cx, cy, reach)
        if rows.size == 0 or cols.size == 0:
            return
        wx, wy = self.cell_to_world(rows[:, None], cols[None, :])  # (R, C) cell centres
        # Per beam and cell: distance along the beam and off its centre line, (beams, R, C).
        dx, dy = wx[None] - sx[:, None, None], wy[None] - sy[:, None, None]
        along = dx * ux[:, None, None] + dy * uy[:, None, None]
        across = np.abs(dx * uy[:, None, None] - dy * ux[:, None, None])
        # The cone, never narrower than one cell, so that a beam marks every cell its centre line crosses.
        half_width = np.maximum(along * np.tan(p.beam_angle / 2), self.resolution / 2)
        in_beam = (along > 0) & (across <= half_width) & (along <= p.range_max)
        hit = np.isfinite(ranges) & (ranges < p.range_max)
        measured = np.where(hit, ranges, p.range_max)[:, None, None]
        if p.hit_cell == "beyond":  # the first cell whose centre lies past the surface; those short of it free
            free = in_beam & (along < measured)
            occupied = in_beam & hit[:, None, None] & (along >= measured) & (along < measured + self.resolution)
        else:  # the cell whose centre lies within half a cell of the surface (§6.2.2's "cell at the hit")
            free = in_beam & (along < measured - self.resolution / 2)
            occupied = in_beam & hit[:, None, None] & (np.abs(along - measured) <= self.resolution / 2)
        q_free = p_free_given_free(along, p)
        q_occ = p_occupied_given_occupied(sensor_noise(measured, p), self.resolution, self.resolution)
        # (6.5)'s cases: evidence counts only when it is informative (q_occ > 0.5, q_free < 0.5).
        evidence = (np.where(free & (q_free < 0.5), _logit(q_free), 0.0).sum(axis=0)
                    + np.where(occupied & (q_occ > 0.5), _logit(q_occ), 0.0).sum(axis=0))
        if footprint_radius > 0:
            under_robot = np.hypot(wx - cx, wy - cy) <= footprint_radius
            evidence += np.where(under_robot, _logit(np.asarray(p.p_free_near)), 0.0)
        block = np.ix_(rows, cols)
        posterior = 1.0 / (1.0 + np.exp(-(_logit(self.probabilities[block]) + evidence)))
        self.probabilities[block] = np.clip(posterior, p.p_min, p.p_max)

    def window(self, x: float, y: float, reach: float) -> tuple[np.ndarray, np.ndarray]:
        """Row and column indices of the grid cells within ``reach`` (a square) of (x, y)."""
        row_lo, col_lo = self.world_to_cell(x - reach, y - reach)
        row_hi, col_hi = self.world_to_cell(x + reach, y + reach)
        rows = np.arange(max(int(row_lo), 0), min(int(row_hi), self.shape[0] - 1) + 1)
        cols = np.arange(max(int(col_lo), 0), min(int(col_hi), self.shape[1] - 1) + 1)
        return rows, cols
