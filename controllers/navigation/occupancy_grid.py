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

A reading's evidence (its summed log-odds over the window of cells it reaches, ``OccupancyGrid.evidence``) does not
depend on the grid's probabilities, so one computation serves every grid of the same frame (``apply``): an explorer
maps the same reading into its navigator's grid and its outgoing map. The evidence is a compiled loop (numba), beam
by beam and cell by cell, that repeats the numpy form's arithmetic operation for operation (the numpy form is the
test oracle, ``tests/controllers/navigation/test_occupancy_grid.py``): each cell's log-odds are summed in beam
order as ``np.sum(axis=0)`` sums them, and by numpy's pairwise order in the one case where numpy uses it (a window
of a single cell). ``math.log``, ``exp``, ``cos``, ``sin``, ``tan`` and ``hypot`` compiled are the C library's, as
numpy's float64 ufuncs are on x86-64 without AVX-512 (with it numpy has its own log, exp, sin and cos, and the
last bit may differ).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit


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


@dataclass(frozen=True)
class Evidence:
    """One IR reading's evidence over the window of grid cells it can reach (``OccupancyGrid.evidence``)."""
    rows: slice  # the window's rows of the grid
    cols: slice  # and its columns
    log_odds: np.ndarray  # (rows, cols): per cell, the sum over beams of logit(q) (6.3)-(6.5), then the footprint's
    frame: tuple  # the ``OccupancyGrid.frame`` it was computed for: it applies to any grid of that frame
    pose: tuple[float, float, float]  # the robot pose (x, y, heading) of the reading
    time: float | None = None  # when the reading was taken, if the caller records it (HRDU does)


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


def _floats(values) -> np.ndarray:
    return np.ascontiguousarray(values, dtype=float).reshape(-1)


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

    @property
    def frame(self) -> tuple:
        """What evidence depends on besides the reading: origin, resolution, shape and mapping parameters."""
        return self.origin, self.resolution, self.shape, self.params

    def update(self, pose: tuple[float, float, float], ranges: np.ndarray, bearings: np.ndarray, *,
               sensor_radius: float | np.ndarray, centre_offset: float = 0.0,
               footprint_radius: float = 0.0) -> Evidence:
        """Integrate one IR reading taken at robot ``pose`` (x, y, heading): ``apply(evidence(...))``; returns the
        evidence applied."""
        evidence = self.evidence(pose, ranges, bearings, sensor_radius=sensor_radius, centre_offset=centre_offset,
                                 footprint_radius=footprint_radius)
        self.apply(evidence)
        return evidence

    def evidence(self, pose: tuple[float, float, float], ranges: np.ndarray, bearings: np.ndarray, *,
                 sensor_radius: float | np.ndarray, centre_offset: float = 0.0,
                 footprint_radius: float = 0.0) -> Evidence:
        """The evidence (6.3)-(6.4) of one IR reading taken at robot ``pose`` (x, y, heading), as summed log-odds
        over the window of cells it can reach; the grid is not changed.

        The sensors sit ``sensor_radius`` (one for all, or one per sensor) from the robot's physical centre,
        which is ``centre_offset`` ahead of the pose's reference point, each looking out along its body-frame
        ``bearing``; ``ranges`` are measured from the sensor, ``inf`` where the beam saw nothing. Cells within
        ``footprint_radius`` of the centre are free (the robot is standing on them)."""
        p = self.params
        x, y, heading = (float(v) for v in pose)
        ranges, bearings, radius = _floats(ranges), _floats(bearings), _floats(sensor_radius)
        if radius.size != 1 and radius.size != ranges.size:
            raise ValueError("one sensor radius for all sensors, or one per sensor")
        row0, col0, log_odds = _reading_log_odds(
            x, y, heading, ranges, bearings, radius, float(centre_offset), float(footprint_radius), *self.origin,
            self.resolution, *self.shape, float(p.beam_angle), p.range_min, p.range_max, p.p_free_near,
            p.p_free_far, p.noise_min, p.noise_max, p.hit_cell == "beyond")
        return Evidence(slice(row0, row0 + log_odds.shape[0]), slice(col0, col0 + log_odds.shape[1]), log_odds,
                        self.frame, (x, y, heading))

    def apply(self, evidence: Evidence) -> None:
        """(6.5) for every beam at once: add the evidence's log-odds to the window's cells, then clamp. The evidence
        may come from another grid of the same ``frame``."""
        if evidence.frame != self.frame:
            raise ValueError("evidence computed for a grid of another origin, resolution, shape or parameters")
        _apply_log_odds(self.probabilities, evidence.rows.start, evidence.cols.start, evidence.log_odds,
                        self.params.p_min, self.params.p_max)

    def window(self, x: float, y: float, reach: float) -> tuple[np.ndarray, np.ndarray]:
        """Row and column indices of the grid cells within ``reach`` (a square) of (x, y)."""
        row_lo, col_lo = self.world_to_cell(x - reach, y - reach)
        row_hi, col_hi = self.world_to_cell(x + reach, y + reach)
        rows = np.arange(max(int(row_lo), 0), min(int(row_hi), self.shape[0] - 1) + 1)
        cols = np.arange(max(int(col_lo), 0), min(int(col_hi), self.shape[1] - 1) + 1)
        return rows, cols


@njit("i8(f8, f8, f8)", cache=True)
def _cell_index(coordinate, origin, resolution):
    """``world_to_cell`` along one axis."""
    return int(math.floor((coordinate - origin) / resolution))


@njit("f8(f8)", cache=True)
def _logit(p):
    return math.log(p / (1.0 - p))


@njit("f8(f8, f8, f8, f8, f8)", cache=True)
def _linear_in_range(distance, range_min, range_max, at_min, at_max):
    """The linear models of ``sensor_noise`` and ``p_free_given_free`` (6.4), operation for operation."""
    fraction = (distance - range_min) / (range_max - range_min)
    return at_min + (at_max - at_min) * min(max(fraction, 0.0), 1.0)


@njit("b1(f8, f8, f8, f8, f8)", cache=True)
def _in_cone(along, across, tan_half, resolution, range_max):
    """Whether a cell ``along`` the beam and ``across`` it lies in the cone, never narrower than one cell so that a
    beam marks every cell its centre line crosses."""
    half_width = max(along * tan_half, resolution / 2)
    return along > 0 and across <= half_width and along <= range_max


@njit("UniTuple(b1, 2)(f8, f8, f8, b1, b1)", cache=True)
def _marks(along, measured, resolution, hit, beyond):
    """Whether a cell of the cone ``along`` the beam is evidence of free space, and of an obstacle, by
    ``MappingParams.hit_cell``."""
    if beyond:  # the first cell whose centre lies past the surface; those short of it free
        return along < measured, hit and along >= measured and along < measured + resolution
    # the cell whose centre lies within half a cell of the surface (§6.2.2's "cell at the hit")
    return along < measured - resolution / 2, hit and abs(along - measured) <= resolution / 2


@njit("f8(f8[:])", cache=True)
def _numpy_sum(values):
    """``np.add.reduce`` of ``values`` when numpy runs them as its inner loop, by its pairwise summation
    (``pairwise_sum``): in order below 8 terms, eight interleaved partial sums up to 128, halves of a multiple of 8
    terms above."""
    n = values.shape[0]
    if n > 128:
        half = n // 2
        half -= half % 8
        return _numpy_sum(values[:half]) + _numpy_sum(values[half:])
    total = 0.0
    k = 0
    if n >= 8:
        partial = values[:8].copy()
        for k in range(8, n - n % 8, 8):
            for j in range(8):
                partial[j] += values[k + j]
        k = n - n % 8
        total = ((partial[0] + partial[1]) + (partial[2] + partial[3])) + ((partial[4] + partial[5])
                                                                           + (partial[6] + partial[7]))
    for j in range(k, n):
        total += values[j]
    return total


@njit("Tuple((i8, i8, f8[:, ::1]))(f8, f8, f8, f8[::1], f8[::1], f8[::1], f8, f8, f8, f8, f8, i8, i8, f8, f8, f8, "
      "f8, f8, f8, f8, b1)", cache=True)
def _reading_log_odds(x, y, heading, ranges, bearings, sensor_radius, centre_offset,  # noqa: PLR0913
                      footprint_radius, origin_x, origin_y, resolution, n_rows, n_cols, beam_angle, range_min,
                      range_max, p_free_near, p_free_far, noise_min, noise_max, beyond):
    """(row0, col0, log-odds) of one reading's window, as ``OccupancyGrid.evidence`` describes it: per beam its
    cone's free evidence (6.4) and its hit's occupied evidence (6.3), as logit(q) where informative (6.5), summed
    over the beams in their order as ``np.sum(axis=0)`` sums them (numpy's pairwise order for a single cell);
    then the footprint's free evidence."""
    cx, cy = x + centre_offset * math.cos(heading), y + centre_offset * math.sin(heading)
    reach = sensor_radius.max() + range_max + resolution
    row0 = max(_cell_index(cy - reach, origin_y, resolution), 0)
    col0 = max(_cell_index(cx - reach, origin_x, resolution), 0)
    rows = min(_cell_index(cy + reach, origin_y, resolution), n_rows - 1) + 1 - row0
    cols = min(_cell_index(cx + reach, origin_x, resolution), n_cols - 1) + 1 - col0
    if rows <= 0 or cols <= 0:
        return row0, col0, np.zeros((0, 0))
    wx = origin_x + (np.arange(col0, col0 + cols) + 0.5) * resolution  # cell centres, as ``cell_to_world``
    wy = origin_y + (np.arange(row0, row0 + rows) + 0.5) * resolution
    single = rows * cols == 1  # one cell: every beam's terms kept, for numpy's pairwise order
    free = np.zeros((ranges.shape[0] if single else 1, rows, cols))
    occupied = np.zeros_like(free)
    tan_half = math.tan(beam_angle / 2)
    area = resolution * resolution
    for b in range(ranges.shape[0]):
        k = b if single else 0
        direction = heading + bearings[b]
        ux, uy = math.cos(direction), math.sin(direction)
        radius = sensor_radius[0] if sensor_radius.shape[0] == 1 else sensor_radius[b]
        sx, sy = cx + radius * ux, cy + radius * uy
        hit = math.isfinite(ranges[b]) and ranges[b] < range_max
        measured = ranges[b] if hit else range_max
        noise = _linear_in_range(measured, range_min, range_max, noise_min, noise_max)
        q_occupied = area / (area + 2.0 * noise * (resolution + resolution))  # (6.3)
        for i in range(rows):
            dy = wy[i] - sy
            for j in range(cols):
                dx = wx[j] - sx
                along = dx * ux + dy * uy
                if not _in_cone(along, abs(dx * uy - dy * ux), tan_half, resolution, range_max):
                    continue
                is_free, is_occupied = _marks(along, measured, resolution, hit, beyond)
                # (6.5)'s cases: evidence counts only when it is informative (q_free < 0.5, q_occupied > 0.5).
                if is_free:
                    q_free = _linear_in_range(along, range_min, range_max, p_free_near, p_free_far)  # (6.4)
                    if q_free < 0.5:
                        free[k, i, j] += _logit(q_free)
                if is_occupied and q_occupied > 0.5:
                    occupied[k, i, j] += _logit(q_occupied)
    if single:
        log_odds = np.full((1, 1), _numpy_sum(free[:, 0, 0]) + _numpy_sum(occupied[:, 0, 0]))
    else:
        log_odds = free[0] + occupied[0]
    if footprint_radius > 0:
        for i in range(rows):
            for j in range(cols):
                if math.hypot(wx[j] - cx, wy[i] - cy) <= footprint_radius:
                    log_odds[i, j] += _logit(p_free_near)
    return row0, col0, log_odds


@njit("void(f8[:, :], i8, i8, f8[:, ::1], f8, f8)", cache=True)
def _apply_log_odds(probabilities, row0, col0, log_odds, p_min, p_max):
    """(6.5) in log-odds over the window at (row0, col0): p = 1 / (1 + exp(-(logit(p) + evidence))), clamped."""
    for i in range(log_odds.shape[0]):
        for j in range(log_odds.shape[1]):
            prior = probabilities[row0 + i, col0 + j]
            posterior = 1.0 / (1.0 + math.exp(-(_logit(prior) + log_odds[i, j])))
            probabilities[row0 + i, col0 + j] = min(max(posterior, p_min), p_max)
