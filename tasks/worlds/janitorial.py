"""The janitorial room's ground truth (Parker §6.2): the cans' sound, and what the tools have done.

- **Sound** (:func:`detector_levels`). Every can still holding garbage emits at its frequency. A detector at
  distance d from a can, its axis at angle a to the direction of the can, hears ``power / (1 + (d / d0)^2) x
  (1 + cos a) / 2``: an inverse-square falloff without the singularity at the can, and a cardioid detector, so two
  detectors angled left and right tell the side (and front from back) of the source. Each reading is multiplied by
  ``1 + noise x N(0, 1)`` (Parker's simulator used about 20 % on sensors, §2.1), and sound passes through
  obstacles. These are choices: the thesis says only that each robot has two detectors per frequency.
- **Cans** (:class:`Cans`): a can is emptied once an emptier, extended, has had its tip within ``reach`` of the
  can's side for ``empty_time`` s in all; then it is silent.
- **Dust** (:class:`Furniture`): points every ``spacing`` m round each object's edge, those with room for a robot
  beside them being its accessible sides. A point is dusted when the swung-out duster arm passes within ``reach``
  of it; an object is dusted when ``share`` of its accessible points are.
- **Floor** (:class:`Floor`): a raster of the floor. Reachable cells are those the cleaner deck covers from some
  place a robot's body fits, connected to the robots' start: free of every obstacle by the robot's radius and a
  margin, flood-filled, then grown by the deck's half depth (what it covers whichever way the robot faces). A cell
  is cleaned when the lowered deck's rectangle covers its centre.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage


def detector_levels(ears: np.ndarray, axes: np.ndarray, sources: np.ndarray, power: float, d0: float,
                    noise: float, rng: np.random.Generator) -> np.ndarray:
    """Levels at detectors at ``ears`` (n, 2) facing unit ``axes`` (n, 2) from the ``sources`` (m, 2)."""
    draws = rng.standard_normal(len(ears))  # drawn whether or not anything sounds: the stream never shifts
    if len(sources) == 0:
        return np.zeros(len(ears))
    offsets = sources[None, :, :] - ears[:, None, :]
    distance = np.hypot(offsets[..., 0], offsets[..., 1])
    facing = np.einsum("nmk,nk->nm", offsets, axes) / np.maximum(distance, 1e-9)
    level = (power / (1.0 + (distance / d0) ** 2) * 0.5 * (1.0 + facing)).sum(axis=1)
    return np.maximum(level * (1.0 + noise * draws), 0.0)


@dataclass
class Can:
    x: float
    y: float
    radius: float
    frequency: str
    appears: float = 0.0  # s: a can added mid-mission is out of the room until then
    held: float = 0.0  # s an emptier has been held at it
    emptied_at: float | None = None
    emptied_by: str | None = None

    def sounding(self, time: float) -> bool:
        return self.emptied_at is None and time >= self.appears


class Cans:
    def __init__(self, cans: list[Can], empty_time: float, reach: float):
        self.cans, self.empty_time, self.reach = cans, empty_time, reach

    def sources(self, frequency: str, time: float) -> np.ndarray:
        return np.array([(c.x, c.y) for c in self.cans if c.frequency == frequency and c.sounding(time)]
                        ).reshape(-1, 2)

    def hold(self, robot: str, tip: np.ndarray, dt: float, time: float) -> None:
        """An extended emptier whose tip is at ``tip``: the can it is held at fills its clock."""
        for can in self.cans:
            if can.sounding(time) and math.hypot(tip[0] - can.x, tip[1] - can.y) <= can.radius + self.reach:
                can.held += dt
                if can.held >= self.empty_time:
                    can.emptied_at, can.emptied_by = time, robot

    def all_emptied(self) -> bool:
        return all(c.emptied_at is not None for c in self.cans)


class Furniture:
    """Dustable objects as boxes (x, y, half_x, half_y, yaw)."""

    def __init__(self, boxes: list[tuple[float, float, float, float, float]], free: "Floor", spacing: float,
                 reach: float, share: float, clearance: float):
        self.boxes, self.reach, self.share = boxes, reach, share
        self.points, self.accessible, self.dusted, self.done_at = [], [], [], []
        for x, y, hx, hy, yaw in boxes:
            points, normals = _edge_points(x, y, hx, hy, yaw, spacing)
            self.points.append(points)
            self.accessible.append(free.fits(points + normals * clearance))
            self.dusted.append(np.zeros(len(points), bool))
            self.done_at.append(None)

    def sweep(self, hinge: np.ndarray, tip: np.ndarray, time: float) -> None:
        """The duster arm, swung out, lies from ``hinge`` to ``tip``."""
        for k, points in enumerate(self.points):
            self.dusted[k] |= _segment_distance(points, hinge, tip) <= self.reach
            if self.done_at[k] is None and self.fraction(k) >= self.share:
                self.done_at[k] = time

    def fraction(self, k: int) -> float:
        accessible = self.accessible[k]
        return float((self.dusted[k] & accessible).sum() / max(accessible.sum(), 1))

    def all_dusted(self) -> bool:
        return all(t is not None for t in self.done_at)


class Floor:
    """The floor raster: ``occupied`` cells from the static obstacles, then reachable and cleaned cells."""

    def __init__(self, size: tuple[float, float], cell: float, occupied: np.ndarray):
        self.size, self.cell, self.occupied = size, cell, occupied
        self.shape = occupied.shape
        self.cleaned = np.zeros(self.shape, bool)
        self.reachable = np.zeros(self.shape, bool)
        walled = np.pad(occupied, 1, constant_values=True)  # the walls stand just outside the floor
        self._clearance = ndimage.distance_transform_edt(~walled)[1:-1, 1:-1] * cell - cell / 2

    def index(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ij = np.floor((np.asarray(points) + np.array(self.size) / 2) / self.cell).astype(int)
        return np.clip(ij[..., 0], 0, self.shape[0] - 1), np.clip(ij[..., 1], 0, self.shape[1] - 1)

    def centres(self) -> tuple[np.ndarray, np.ndarray]:
        xs = (np.arange(self.shape[0]) + 0.5) * self.cell - self.size[0] / 2
        ys = (np.arange(self.shape[1]) + 0.5) * self.cell - self.size[1] / 2
        return np.meshgrid(xs, ys, indexing="ij")

    def fits(self, points: np.ndarray, radius: float = 0.0) -> np.ndarray:
        """Whether a disc of ``radius`` at each point is on free floor inside the room."""
        points = np.asarray(points)
        inside = (np.abs(points[:, 0]) < self.size[0] / 2 - radius) & (np.abs(points[:, 1]) < self.size[1] / 2 - radius)
        i, j = self.index(points)
        return inside & (self._clearance[i, j] > radius)

    def settle_reachable(self, robot_radius: float, starts: np.ndarray, deck_reach: float) -> None:
        free = self._clearance > robot_radius
        labels, _ = ndimage.label(free)
        i, j = self.index(starts)
        start_labels = {int(v) for v in labels[i, j] if v}
        centres = np.isin(labels, list(start_labels))
        grow = int(math.ceil(deck_reach / self.cell))
        reach = ndimage.binary_dilation(centres, iterations=grow) if grow else centres
        self.reachable = reach & ~self.occupied

    def clean(self, centre: np.ndarray, yaw: float, half_depth: float, half_width: float) -> None:
        """Mark the cells whose centres the deck's rectangle covers."""
        reach = math.hypot(half_depth, half_width)
        lo_i, lo_j = self.index(centre - reach)
        hi_i, hi_j = self.index(centre + reach)
        xs, ys = self.centres_window(lo_i, hi_i, lo_j, hi_j)
        dx, dy = xs - centre[0], ys - centre[1]
        c, s = math.cos(yaw), math.sin(yaw)
        inside = (np.abs(dx * c + dy * s) <= half_depth) & (np.abs(-dx * s + dy * c) <= half_width)
        self.cleaned[lo_i:hi_i + 1, lo_j:hi_j + 1] |= inside

    def centres_window(self, lo_i: int, hi_i: int, lo_j: int, hi_j: int) -> tuple[np.ndarray, np.ndarray]:
        xs = (np.arange(lo_i, hi_i + 1) + 0.5) * self.cell - self.size[0] / 2
        ys = (np.arange(lo_j, hi_j + 1) + 0.5) * self.cell - self.size[1] / 2
        return np.meshgrid(xs, ys, indexing="ij")

    def share_cleaned(self) -> float:
        return float((self.cleaned & self.reachable).sum() / max(self.reachable.sum(), 1))


def rasterise(size: tuple[float, float], cell: float, boxes, discs) -> np.ndarray:
    """Occupied cells of the floor: ``boxes`` (x, y, half_x, half_y, yaw) and ``discs`` (x, y, radius)."""
    shape = (int(round(size[0] / cell)), int(round(size[1] / cell)))
    xs = (np.arange(shape[0]) + 0.5) * cell - size[0] / 2
    ys = (np.arange(shape[1]) + 0.5) * cell - size[1] / 2
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    occupied = np.zeros(shape, bool)
    for x, y, hx, hy, yaw in boxes:
        c, s = math.cos(yaw), math.sin(yaw)
        dx, dy = gx - x, gy - y
        occupied |= (np.abs(dx * c + dy * s) <= hx) & (np.abs(-dx * s + dy * c) <= hy)
    for x, y, r in discs:
        occupied |= np.hypot(gx - x, gy - y) <= r
    return occupied


def _edge_points(x, y, hx, hy, yaw, spacing) -> tuple[np.ndarray, np.ndarray]:
    """Points every ``spacing`` along a box's sides, and their outward normals, in the world frame."""
    points, normals = [], []
    for nx, ny in ((1, 0), (0, 1), (-1, 0), (0, -1)):
        half_along = hy if nx else hx
        count = max(2, int(round(2 * half_along / spacing)))
        for t in ((np.arange(count) + 0.5) / count * 2 - 1) * half_along:
            points.append((nx * hx - ny * t, ny * hy + nx * t))
            normals.append((nx, ny))
    c, s = math.cos(yaw), math.sin(yaw)
    rot = np.array([[c, -s], [s, c]])
    return np.array(points) @ rot.T + np.array([x, y]), np.array(normals, float) @ rot.T


def _segment_distance(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ab = b - a
    t = np.clip(((points - a) @ ab) / max(float(ab @ ab), 1e-12), 0.0, 1.0)
    closest = a + t[:, None] * ab
    return np.hypot(*(points - closest).T)
