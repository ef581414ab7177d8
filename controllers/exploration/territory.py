"""The territorial division every role knows before it starts (Chand §6.1, Fig 6.1): a square global area at a
map resolution, split into square local environments, each the size of one local map (§4.2's partition).

Environments are numbered from 0, row-major from the area's lower-left corner (the two-tiered A*'s 1-based local
maps less one); a map cell is (row, col) with the row along world y, as in ``OccupancyGrid``.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from teamsim.controllers.navigation.occupancy_grid import MappingParams, OccupancyGrid
from teamsim.controllers.navigation.two_tier_astar import Partition, partition_global_map


SMALL_MESSAGE = 64  # bytes on the link of a request, report or notice: a few doubles and a header


@dataclass(frozen=True)
class Territory:
    size: float  # m, side of the square global area
    resolution: float  # m per map cell
    divisions: int  # local environments per side

    @property
    def origin(self) -> tuple[float, float]:
        return (-self.size / 2, -self.size / 2)

    @property
    def cells(self) -> int:
        """Map cells per side of the global area."""
        return round(self.size / self.resolution)

    @property
    def environment_cells(self) -> int:
        return self.cells // self.divisions

    @property
    def environments(self) -> int:
        return self.divisions ** 2

    @functools.cached_property
    def partition(self) -> Partition:
        return partition_global_map(self.cells, self.cells, self.environment_cells ** 2)

    def neighbours(self, environment: int) -> tuple[int, ...]:
        return tuple(k - 1 for k in self.partition.neighbours[environment + 1])

    @functools.cached_property
    def neighbour_lists(self) -> tuple[tuple[int, ...], ...]:
        return tuple(self.neighbours(e) for e in range(self.environments))

    def slices(self, environment: int) -> tuple[slice, slice]:
        """The environment's rows and columns of the global map."""
        return self.partition.slices(environment + 1)

    def bounds(self, environment: int) -> tuple[tuple[float, float], tuple[float, float]]:
        """Lower-left and upper-right corners, m."""
        rows, cols = self.slices(environment)
        x0, y0 = self.origin
        return ((x0 + cols.start * self.resolution, y0 + rows.start * self.resolution),
                (x0 + cols.stop * self.resolution, y0 + rows.stop * self.resolution))

    def centre(self, environment: int) -> tuple[float, float]:
        (x_lo, y_lo), (x_hi, y_hi) = self.bounds(environment)
        return ((x_lo + x_hi) / 2, (y_lo + y_hi) / 2)

    @functools.cached_property
    def centres(self) -> tuple[tuple[float, float], ...]:
        return tuple(self.centre(e) for e in range(self.environments))

    def overlapping(self, lo: tuple[float, float], hi: tuple[float, float]) -> frozenset[int]:
        """The environments the rectangle from corner ``lo`` to corner ``hi`` (m) shares some area with; an
        environment it only touches along an edge or at a corner is not among them."""
        return frozenset(e for e in range(self.environments) if _share_area(self.bounds(e), (lo, hi)))

    def environment_of(self, x: float, y: float) -> int:
        """The environment holding (x, y); a point outside the area counts as in the nearest cell inside it."""
        row, col = self.cell_of(x, y)
        return self.partition.index_of(row, col) - 1

    def cell_of(self, x: float, y: float) -> tuple[int, int]:
        """The map cell holding (x, y), clamped to the area."""
        x0, y0 = self.origin
        last = self.cells - 1
        return (min(max(int((y - y0) // self.resolution), 0), last),
                min(max(int((x - x0) // self.resolution), 0), last))

    def unexplored_map(self, params: MappingParams = MappingParams()) -> OccupancyGrid:
        return OccupancyGrid.unexplored(self.origin, self.resolution, (self.cells, self.cells), params)

    def local_map_bytes(self, bytes_per_node: int = 8) -> int:
        """One local map's size on the link (§8.2: 32 x 32 doubles, 8 KB)."""
        return self.environment_cells ** 2 * bytes_per_node

    def environment_grid(self) -> np.ndarray:
        """(cells, cells) int: each map cell's environment."""
        index = np.arange(self.cells) // self.environment_cells
        return index[:, None] * self.divisions + index[None, :]


def _share_area(a: tuple[tuple[float, float], tuple[float, float]],
                b: tuple[tuple[float, float], tuple[float, float]]) -> bool:
    """Whether two axis-aligned rectangles, each (lower-left, upper-right), overlap with some area."""
    (a_lo, a_hi), (b_lo, b_hi) = a, b
    return all(a_lo[k] < b_hi[k] and b_lo[k] < a_hi[k] for k in (0, 1))
