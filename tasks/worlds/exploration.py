"""Worlds of Chand's exploration experiments (§6.1, §8.2): 38.4 m x 38.4 m at 0.3 m resolution, divided into 16
square local environments (4 x 4, each 9.6 m and 32 x 32 cells, one local map), randomly and evenly spread
obstacles at 5, 10 or 15 % density, and in half the worlds about 5 % boggy terrain.

Obstacles come from the navigation worlds' generator (``navigation.random_world``: jittered boxes 1 m to 2 m
across, ``min_gap`` apart, a passage for Robot C's disc) at this size and resolution. Choices where the thesis is
silent (docs/decisions.md, "Exploration worlds"):
  - the team gathers at a base in the top-left corner (the navigation generator's start), ``base_radius`` from
    both walls, and no obstacle comes within ``base_radius`` of it (4 m: the formation of six robots of up to
    0.67 m radius reaches 3.3 m from the base, so the outermost robots keep about a robot's radius to the
    nearest box; at most a quarter of the world's side, which keeps the two corners' zones apart). The
    generator keeps the opposite corner (its goal) as clear, and keeps a layout only if Robot C's disc can get
    from the base to that corner, so the team is never walled into its corner;
  - bog patches are axis-aligned rectangles with sides on the raster's cell edges (so a bog's area, its raster
    and the environments it marks agree exactly), each side drawn from ``bog_side_range``: 3.6 m to 6 m, so that
    5 % is three or four patches marking about 6 of the 16 environments boggy (measured; 2.4 m to 4.8 m makes six
    patches and marks half of them, leaving robots that cannot cross bogs little of the world), and a robot
    fits wholly inside one. Each lies inside the world, wholly outside the base's clear zone, with free ground
    for the largest robot at its centre (a bog is somewhere a robot can drive into; its edges may run under
    boxes). Patches are added until the raster's boggy fraction is as close to ``bog_share`` as one more patch
    could bring it;
  - a local environment must be at least 2 x the largest robot's diameter + the IR range across (4.18 m): room
    for a robot's body at either side and a sensed strip between, so that a boustrophedon sweep of it is not
    one pass along its middle;
  - local environments are the exploration controllers' (``ExploreWorld.territory``, a ``Territory``): numbered
    0 to 15, row-major from the lowest-y row (the raster's row 0);
  - density is at most 15 %, the thesis's densest: the generator keeps a layout only if Robot C's disc has a
    passage from the base to the far corner, and at 0.3 m cells denser layouts leave it none.
``thesis_world`` draws the ten worlds of each density and terrain from their own seeded streams.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from teamsim.config import ConfigError
from teamsim.controllers.exploration.territory import Territory
from teamsim.models.arenas import Bog
from teamsim.rng import RandomStreams
from teamsim.scenario import Obstacle
from teamsim.tasks.worlds.navigation import NavWorld, NavWorldParams, cell_centres, clearance, random_world

THESIS_DENSITIES = (0.05, 0.10, 0.15)  # §8.2
THESIS_WORLDS = 10  # worlds per density and terrain (§8.2)
THESIS_BOG_SHARE = 0.05  # "about 5 % boggy terrain" (§8.2)
MAX_DENSITY = 0.15  # the densest world with a passage for Robot C at 0.3 m cells (see above)
THESIS_SEED = 8  # the root of the thesis worlds' streams: chapter 8
START_GAP = 0.5  # m between neighbouring robots' circles at the base: room to turn away without touching


@dataclass(frozen=True)
class ExploreWorldParams:
    size: float = 38.4  # m, side of the square world (§8.2)
    resolution: float = 0.3  # m, map cell (§8.2)
    divisions: int = 4  # local environments per side: 4 x 4 = 16 (§6.1, §8.2)
    density: float = 0.05  # obstacle fraction of the raster: 0.05, 0.10 or 0.15 in §8.2, at most MAX_DENSITY
    bog_share: float = 0.0  # boggy fraction of the raster: 0.05 in the boggy worlds (§8.2)
    bog_side_range: tuple[float, float] = (3.6, 6.0)  # m, each side of a bog patch (see above)
    bog_attempts: int = 1000  # patches drawn before giving up
    base_radius: float = 4.0  # m, the base's clear zone, and its distance from both walls (see above)
    robot_radius: float = 0.67  # m, the largest robot's (Robot C, Table 3.1; Robots 4 and 8 are 0.6 m)
    ir_range: float = 1.5  # m, every robot's IR range (§6.2.2)
    half_size_range: tuple[float, float] = NavWorldParams.half_size_range  # m, obstacle half-sides, as navigation
    min_gap: float = NavWorldParams.min_gap  # m, between boxes that do not overlap, and to a wall, as navigation

    @property
    def cells(self) -> int:
        """Cells along a side of the world."""
        return round(self.size / self.resolution)

    @property
    def environment_side(self) -> float:
        return self.size / self.divisions

    @property
    def least_environment_side(self) -> float:
        """2 x the largest robot's diameter + the IR range (see above)."""
        return 4 * self.robot_radius + self.ir_range

    def nav_params(self) -> NavWorldParams:
        """The navigation generator's parameters: the base is its start, the opposite corner its goal."""
        return NavWorldParams(size=self.size, resolution=self.resolution, half_size_range=self.half_size_range,
                              min_gap=self.min_gap, corner_margin=self.base_radius, clear_radius=self.base_radius,
                              passage_radius=self.robot_radius)

    def check(self) -> None:
        """Raise ConfigError, naming the field and what is allowed, for a world that cannot be built."""
        if not self.size > 0:
            raise ConfigError(f"explore: size={self.size:g} m: allowed: a positive length")
        if not self.resolution > 0:
            raise ConfigError(f"explore: resolution={self.resolution:g} m: allowed: a positive length")
        if self.divisions < 1:
            raise ConfigError(f"explore: divisions={self.divisions}: allowed: 1 or more local environments a side")
        if self.environment_side < self.least_environment_side:
            raise ConfigError(f"explore: size {self.size:g} m is too small for divisions {self.divisions}: each "
                              f"local environment would be {self.environment_side:g} m, at least "
                              f"{self.least_environment_side:g} m is needed")
        self._check_cells()
        self._check_shares()
        low, high = self.bog_side_range
        if not self.resolution <= low <= high <= self.environment_side:
            raise ConfigError(f"explore: bog_side_range=({low:g}, {high:g}) m: allowed: resolution <= low <= high "
                              f"<= a local environment's side ({self.environment_side:g} m)")
        if not self.robot_radius <= self.base_radius <= self.size / 4:
            raise ConfigError(f"explore: base_radius={self.base_radius:g} m: allowed: from robot_radius "
                              f"({self.robot_radius:g} m) to a quarter of size ({self.size / 4:g} m)")

    def _check_shares(self) -> None:
        """Obstacle density up to ``MAX_DENSITY`` (see above), boggy share up to 0.3."""
        if not 0 <= self.density <= MAX_DENSITY:
            raise ConfigError(f"explore: density={self.density:g}: allowed: 0 to {MAX_DENSITY:g} (denser layouts "
                              f"at 0.3 m cells leave Robot C no passage)")
        if not 0 <= self.bog_share <= 0.3:
            raise ConfigError(f"explore: bog_share={self.bog_share:g}: allowed: 0 to 0.3")

    def _check_cells(self) -> None:
        """The raster must split into whole local maps of at least 2 x 2 cells."""
        if not math.isclose(self.size / self.resolution, self.cells, abs_tol=1e-6):
            raise ConfigError(f"explore: resolution={self.resolution:g} m: allowed: a length that divides size "
                              f"({self.size:g} m) into whole cells")
        if self.cells % self.divisions:
            raise ConfigError(f"explore: divisions={self.divisions}: allowed: a divisor of the {self.cells} cells "
                              f"a side, so that every local map has the same whole number of cells")
        if self.cells // self.divisions < 2:
            raise ConfigError(f"explore: resolution={self.resolution:g} m leaves {self.cells // self.divisions} "
                              f"cell a local map side; allowed: at least 2")


@dataclass(frozen=True)
class ExploreWorld:
    nav: NavWorld  # boxes, the true occupancy raster, origin, resolution, size; start = base, goal = far corner
    bogs: tuple[Bog, ...]
    territory: Territory  # the local environments, 0-based (see above)
    base: tuple[float, float]  # where the team gathers
    base_radius: float  # m, the base's clear zone

    def in_bog(self, x: float, y: float) -> bool:
        return any(bool(bog.contains(x, y)) for bog in self.bogs)

    def bog_raster(self) -> np.ndarray:
        """bool, the occupancy's shape: the cells whose centre lies in a bog."""
        centres = cell_centres(self.nav.size, self.nav.resolution)
        raster = np.zeros(self.nav.occupancy.shape, bool)
        for bog in self.bogs:
            raster |= bog_cells(bog, centres)
        return raster

    def boggy_environments(self) -> frozenset[int]:
        """The local environments any part of which is under a bog: the manager's terrain map marks them whole
        (§6.1)."""
        return frozenset().union(*(self.territory.overlapping(*_corners(bog)) for bog in self.bogs))

    def start_poses(self, radii: Sequence[float]) -> list[tuple[float, float, float]]:
        """(x, y, heading) for robots of the given radii, in order: on a square lattice around the base, a robot's
        diameter and ``START_GAP`` apart, the nearest slots first (ahead before abreast before behind), all facing
        the world's centre. ConfigError if the outermost would leave the clear zone."""
        pitch = 2 * max(radii, default=0.0) + START_GAP
        heading = self.nav.start[2]
        poses = []
        for (ahead, left), radius in zip(_formation(len(radii)), radii):
            if pitch * math.hypot(ahead, left) + radius > self.base_radius:
                raise ConfigError(f"explore: {len(radii)} robots of up to {max(radii):g} m radius do not fit the "
                                  f"base's clear zone; allowed: a larger base_radius than {self.base_radius:g} m")
            x = self.base[0] + pitch * (ahead * math.cos(heading) - left * math.sin(heading))
            y = self.base[1] + pitch * (ahead * math.sin(heading) + left * math.cos(heading))
            poses.append((x, y, heading))
        return poses


def bog_cells(bog: Bog, centres: np.ndarray) -> np.ndarray:
    """(rows, cols) bool: the cells whose centre lies in the bog."""
    return bog.contains(centres[None, :], centres[:, None])


def _corners(bog: Bog) -> tuple[tuple[float, float], tuple[float, float]]:
    """The bog's lower-left and upper-right corners."""
    return (bog.x - bog.half_x, bog.y - bog.half_y), (bog.x + bog.half_x, bog.y + bog.half_y)


def _formation(count: int) -> list[tuple[int, int]]:
    """The ``count`` lattice slots (ahead, left) nearest the origin; ties go to the slot further ahead, then to
    the right."""
    reach = math.isqrt(count) + 1
    slots = [(i, j) for i in range(-reach, reach + 1) for j in range(-reach, reach + 1)]
    return sorted(slots, key=lambda s: (s[0] ** 2 + s[1] ** 2, -s[0], s[1]))[:count]


def explore_world(params: ExploreWorldParams, rng: np.random.Generator) -> ExploreWorld:
    """An exploration world, reproducible from ``rng``: obstacles first, then bogs from the same stream."""
    params.check()
    nav = random_world(params.density, rng, params.nav_params())
    base = nav.start[:2]
    territory = Territory(params.size, params.resolution, params.divisions)
    return ExploreWorld(nav, _bogs(params, nav, base, rng), territory, base, params.base_radius)


def _bogs(params: ExploreWorldParams, nav: NavWorld, base: tuple[float, float],
          rng: np.random.Generator) -> tuple[Bog, ...]:
    """Patches added until the boggy fraction of the raster is as close to ``bog_share`` as one more could bring
    it (the rule the obstacles follow)."""
    centres = cell_centres(params.size, params.resolution)
    boggy = np.zeros(nav.occupancy.shape, bool)
    target = params.bog_share * boggy.size
    bogs: list[Bog] = []
    for _ in range(params.bog_attempts):
        bog = _patch(params, rng)
        if not _fits(bog, nav, base, params):
            continue
        covered = bog_cells(bog, centres)
        added = np.count_nonzero(covered & ~boggy)
        if added == 0:
            continue
        present = np.count_nonzero(boggy)
        if abs(present + added - target) >= abs(present - target):
            return tuple(bogs)
        boggy |= covered
        bogs.append(bog)
    raise ConfigError(f"explore: bog_share={params.bog_share:g}: could not reach {params.bog_share:.0%} boggy "
                      f"ground in {params.bog_attempts} patches; allowed: a smaller bog_share")


def _patch(params: ExploreWorldParams, rng: np.random.Generator) -> Bog:
    """A patch with its sides on cell edges, wholly inside the world."""
    low, high = (round(side / params.resolution) for side in params.bog_side_range)
    width, height = rng.integers(low, high, size=2, endpoint=True)
    col = rng.integers(0, params.cells - width, endpoint=True)
    row = rng.integers(0, params.cells - height, endpoint=True)
    half = params.size / 2
    return Bog(float(-half + (col + width / 2) * params.resolution),
               float(-half + (row + height / 2) * params.resolution),
               float(width * params.resolution / 2), float(height * params.resolution / 2))


def _fits(bog: Bog, nav: NavWorld, base: tuple[float, float], params: ExploreWorldParams) -> bool:
    """Wholly outside the base's clear zone, with room for the largest robot at its centre."""
    footprint = Obstacle("box", bog.x, bog.y, bog.half_x, bog.half_y)
    return (footprint.distance(*base) >= params.base_radius
            and clearance(nav, bog.x, bog.y) >= params.robot_radius)


def thesis_world(density: float, boggy: bool, index: int) -> ExploreWorld:
    """World ``index`` (0 to 9) of the given density (5, 10 or 15 %) and terrain, as §8.2 uses ten of each: drawn
    from its own stream, so that each is the same whatever else is drawn."""
    if not any(math.isclose(density, d) for d in THESIS_DENSITIES):
        raise ConfigError(f"explore: density={density:g}: the thesis's worlds have 0.05, 0.1 or 0.15")
    if not 0 <= index < THESIS_WORLDS:
        raise ConfigError(f"explore: index={index}: allowed: 0 to {THESIS_WORLDS - 1}")
    params = ExploreWorldParams(density=density, bog_share=THESIS_BOG_SHARE if boggy else 0.0)
    rng = RandomStreams(THESIS_SEED).get("explore-world", f"{density:g}", "boggy" if boggy else "plain", str(index))
    return explore_world(params, rng)
