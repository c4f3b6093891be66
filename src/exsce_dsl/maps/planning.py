"""Paths around occupied cells: shortest paths on the free cells of the map.

The map is coarsened to a planning grid, occupied space is inflated by the
robot's radius (with a soft penalty near walls so paths keep clear of
them), and shortest paths come from :mod:`exsce_dsl.maps.paths` (scipy's
Dijkstra on the 8-connected graph of free cells, built once per map).
:func:`planning_grid` is a scenario's grid: its map's, read once per process,
or open floor round its poses when it declares no map file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import cached_property, lru_cache
from pathlib import Path

import numpy as np
from scipy import ndimage
from scipy.sparse import csr_matrix

from exsce_dsl.errors import ExsceError, PlanningError
from exsce_dsl.maps.grid import OccupancyGrid, load_occupancy_grid
from exsce_dsl.maps.paths import grid_graph, shortest_path
from exsce_dsl.model import Scenario

Point = tuple[float, float]


@dataclass(frozen=True)
class PlanningGrid:
    """Free space of a map at planning resolution, with clearance to walls."""

    free: np.ndarray  # bool (rows from the bottom, cols)
    clearance: np.ndarray  # metres to the nearest occupied or unknown cell, full map resolution
    origin: tuple[float, float]
    resolution: float  # planning cell size
    map_resolution: float
    graph: csr_matrix
    coarse: np.ndarray  # clearance per planning cell
    robot_radius: float = 0.3
    discs: tuple[tuple[float, float, float], ...] = ()
    """Round obstacles over the map (x, y, radius): robots standing still."""

    @classmethod
    def from_map(cls, grid: OccupancyGrid, robot_radius: float = 0.3, cell: float = 0.1) -> PlanningGrid:
        if grid.origin[2]:
            raise ExsceError("maps with a rotated origin are not supported by the executor")
        free_full = grid.free_cells()[::-1]  # rows from the bottom
        # outside the map is no free space either (clearance_of finds 0 there): a free cell's
        # clearance is also bounded by its distance to the map's edge, so that a laser beam
        # marched on it stops at the edge instead of stepping past it
        bordered = np.pad(free_full, 1, constant_values=False)
        clearance = ndimage.distance_transform_edt(bordered)[1:-1, 1:-1] * grid.resolution
        factor = max(1, round(cell / grid.resolution))
        rows, cols = (s // factor for s in free_full.shape)
        coarse = (
            clearance[: rows * factor, : cols * factor].reshape(rows, factor, cols, factor).min(axis=(1, 3))
        )
        free = coarse > robot_radius
        graph = _grid_graph(free, coarse, factor * grid.resolution, robot_radius)
        return cls(
            free,
            clearance,
            grid.origin[:2],
            factor * grid.resolution,
            grid.resolution,
            graph,
            coarse,
            robot_radius,
        )

    def with_discs(self, discs: tuple[tuple[float, float, float], ...]) -> PlanningGrid:
        """The grid with round obstacles added (robots parked where a path would cross them)."""
        if not discs:
            return self
        rows, cols = self.free.shape
        ys = self.origin[1] + (np.arange(rows) + 0.5) * self.resolution
        xs = self.origin[0] + (np.arange(cols) + 0.5) * self.resolution
        coarse = self.coarse.copy()
        for x, y, radius in discs:
            away = np.hypot(xs[None, :] - x, ys[:, None] - y) - radius
            np.minimum(coarse, np.maximum(away, 0.0), out=coarse)
        free = coarse > self.robot_radius
        graph = _grid_graph(free, coarse, self.resolution, self.robot_radius)
        return replace(self, free=free, graph=graph, coarse=coarse, discs=self.discs + discs)

    def cell_of(self, p: Point) -> tuple[int, int]:
        return (
            int((p[1] - self.origin[1]) // self.resolution),
            int((p[0] - self.origin[0]) // self.resolution),
        )

    def centre(self, rc: tuple[int, int]) -> Point:
        return (
            self.origin[0] + (rc[1] + 0.5) * self.resolution,
            self.origin[1] + (rc[0] + 0.5) * self.resolution,
        )

    @cached_property
    def _bordered_clearance(self) -> np.ndarray:
        """:attr:`clearance` with a border of zeros: where every point outside the map is looked up."""
        return np.pad(self.clearance, 1)

    def clearance_at(self, points: np.ndarray) -> np.ndarray:
        """Metres from each point (n×2) to the nearest non-free cell; 0 outside the map."""
        return self.clearance_of(points[:, 0], points[:, 1])

    def clearance_of(self, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
        """:meth:`clearance_at` of the points ``(xs[i], ys[i])``."""
        height, width = self.clearance.shape
        cols = np.clip(np.floor((xs - self.origin[0]) / self.map_resolution), -1, width).astype(np.int64)
        rows = np.clip(np.floor((ys - self.origin[1]) / self.map_resolution), -1, height).astype(np.int64)
        out: np.ndarray = self._bordered_clearance.take((rows + 1) * (width + 2) + (cols + 1))
        for x, y, radius in self.discs:
            away = np.hypot(xs - x, ys - y) - radius
            np.minimum(out, np.maximum(away, 0.0), out=out)
        return out

    def plan(self, start: Point, goal: Point, robot_radius: float = 0.3) -> list[Point]:
        """A collision-free polyline from start to goal (both included)."""
        return self._shortcut(self.cell_path(start, goal), robot_radius)

    def cell_path(self, start: Point, goal: Point) -> list[Point]:
        """The planned path from start to goal (both included) through the centres of its cells,
        before corners are cut: it keeps to the middle of doorways and corridors."""
        source, target = self._nearest_free(start), self._nearest_free(goal)
        if source is None or target is None:
            bad = start if source is None else goal
            raise PlanningError(f"no free space near ({bad[0]:.2f}, {bad[1]:.2f}) on the map")
        width = self.free.shape[1]
        s, t = source[0] * width + source[1], target[0] * width + target[1]
        nodes = shortest_path(self.graph, s, t)
        if nodes is None:
            raise PlanningError(
                f"no path from ({start[0]:.2f}, {start[1]:.2f}) to ({goal[0]:.2f}, {goal[1]:.2f})"
            )
        cells = [(n // width, n % width) for n in nodes]
        return [start] + [self.centre(c) for c in cells[1:-1]] + [goal]

    def _nearest_free(self, p: Point) -> tuple[int, int] | None:
        r, c = self.cell_of(p)
        for radius in range(0, 6):
            window = [
                (r + dr, c + dc)
                for dr in range(-radius, radius + 1)
                for dc in range(-radius, radius + 1)
                if max(abs(dr), abs(dc)) == radius
            ]
            for rr, cc in sorted(window, key=lambda rc: (rc[0] - r) ** 2 + (rc[1] - c) ** 2):
                if 0 <= rr < self.free.shape[0] and 0 <= cc < self.free.shape[1] and self.free[rr, cc]:
                    return rr, cc
        return None

    def in_sight(self, a: Point, b: Point) -> bool:
        """A robot drives from ``a`` to ``b`` in a straight line without touching the map's walls."""
        return self._visible(a, b, self.robot_radius)

    def _visible(self, a: Point, b: Point, robot_radius: float) -> bool:
        n = max(2, int(math.dist(a, b) / (self.map_resolution / 2)) + 1)
        pts = np.linspace(a, b, n)
        return bool(np.all(self.clearance_at(pts) > robot_radius))

    def _shortcut(self, path: list[Point], robot_radius: float) -> list[Point]:
        """Drop corners that a straight line can skip (line of sight on the clearance map)."""
        out = [path[0]]
        i = 0
        while i < len(path) - 1:
            j = len(path) - 1
            while j > i + 1 and not self._visible(path[i], path[j], robot_radius):
                j -= 1
            out.append(path[j])
            i = j
        return out


def _grid_graph(free: np.ndarray, clearance: np.ndarray, cell: float, robot_radius: float) -> csr_matrix:
    # cells near walls cost more, so paths keep some clearance (as a costmap would)
    penalty = 1.0 + 2.0 * np.clip(1.0 - (clearance - robot_radius) / 0.5, 0.0, 1.0)
    return grid_graph(free, cell, penalty)


def planning_grid(scenario: Scenario) -> PlanningGrid:
    """The grid robots of ``scenario`` plan on: its environment's map file (read once per process
    and file), else open floor round its poses."""
    env = scenario.environment
    if env.map is not None and env.map.file is not None:
        return _grid_from_file(env.map.file)
    return _open_space(scenario)


@lru_cache(maxsize=4)
def _grid_from_file(path: str) -> PlanningGrid:
    return PlanningGrid.from_map(load_occupancy_grid(Path(path)))


def _open_space(scenario: Scenario) -> PlanningGrid:
    """No map given: an empty grid around every pose of the scenario, 10 m of margin."""
    poses = [p for p in scenario.environment.poses()] + [w for t in scenario.tasks for w in t.waypoints()]
    xs = [p.position.x for p in poses]
    ys = [p.position.y for p in poses]
    resolution = 0.05
    x0, y0 = min(xs) - 10.0, min(ys) - 10.0
    width = int((max(xs) + 10.0 - x0) / resolution) + 1
    height = int((max(ys) + 10.0 - y0) / resolution) + 1
    cells = np.full((height, width), 254, dtype=np.uint8)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = 0  # a wall round the edge, for the laser
    return PlanningGrid.from_map(OccupancyGrid(cells, resolution, (x0, y0, 0.0), 0.65, 0.196, False))
