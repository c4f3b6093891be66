"""Paths around occupied cells: shortest paths on the free cells of the map.

The map is coarsened to a planning grid, occupied space is inflated by the
robot's radius (with a soft penalty near walls so paths keep clear of
them), and shortest paths come from scipy's Dijkstra on the 8-connected graph
of free cells: the graph is built once per map, vectorised.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy import ndimage
from scipy.sparse import coo_matrix, csr_matrix
from scipy.sparse.csgraph import dijkstra

from exsce_dsl.errors import ExsceError
from exsce_dsl.errors import PlanningError as PlanningError
from exsce_dsl.lang.occupancy import OccupancyGrid

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
        grey = grid.cells[::-1].astype(np.float64)  # rows from the bottom
        occupancy = grey / 255.0 if grid.negate else (255.0 - grey) / 255.0
        free_full = occupancy < grid.free_thresh
        clearance = ndimage.distance_transform_edt(free_full) * grid.resolution
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

    def clearance_at(self, points: np.ndarray) -> np.ndarray:
        """Metres from each point (n×2) to the nearest non-free cell; 0 outside the map."""
        cols = np.floor((points[:, 0] - self.origin[0]) / self.map_resolution).astype(np.int64)
        rows = np.floor((points[:, 1] - self.origin[1]) / self.map_resolution).astype(np.int64)
        inside = (
            (rows >= 0) & (rows < self.clearance.shape[0]) & (cols >= 0) & (cols < self.clearance.shape[1])
        )
        out = np.zeros(len(points))
        out[inside] = self.clearance[rows[inside], cols[inside]]
        for x, y, radius in self.discs:
            away = np.hypot(points[:, 0] - x, points[:, 1] - y) - radius
            np.minimum(out, np.maximum(away, 0.0), out=out)
        return out

    def plan(self, start: Point, goal: Point, robot_radius: float = 0.3) -> list[Point]:
        """A collision-free polyline from start to goal (both included)."""
        source, target = self._nearest_free(start), self._nearest_free(goal)
        if source is None or target is None:
            bad = start if source is None else goal
            raise PlanningError(f"no free space near ({bad[0]:.2f}, {bad[1]:.2f}) on the map")
        width = self.free.shape[1]
        s, t = source[0] * width + source[1], target[0] * width + target[1]
        dist, pred = dijkstra(self.graph, indices=s, return_predecessors=True, limit=np.inf)
        if not np.isfinite(dist[t]):
            raise PlanningError(
                f"no path from ({start[0]:.2f}, {start[1]:.2f}) to ({goal[0]:.2f}, {goal[1]:.2f})"
            )
        nodes = [t]
        while nodes[-1] != s:
            nodes.append(int(pred[nodes[-1]]))
        cells = [(n // width, n % width) for n in reversed(nodes)]
        path = [start] + [self.centre(c) for c in cells[1:-1]] + [goal]
        return self._shortcut(path, robot_radius)

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


def grid_graph(
    free: np.ndarray, cell: float, penalty: np.ndarray | None = None, node: np.ndarray | None = None
) -> csr_matrix:
    """The 8-connected graph of the ``free`` cells (no corner cutting), each edge weighted by its
    length in metres, times the mean ``penalty`` of its two cells when given.  ``node`` numbers the
    cells (default: row by row, every cell a node)."""
    rows, cols = free.shape
    index = np.arange(rows * cols).reshape(rows, cols) if node is None else node
    sources, targets, weights = [], [], []
    for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
        r0, r1 = max(0, -dr), rows - max(0, dr)
        c0, c1 = max(0, -dc), cols - max(0, dc)
        a = free[r0:r1, c0:c1] & free[r0 + dr : r1 + dr, c0 + dc : c1 + dc]
        if dr and dc:  # no corner cutting: both cells beside the diagonal are free too
            a &= free[r0 + dr : r1 + dr, c0:c1] & free[r0:r1, c0 + dc : c1 + dc]
        step = cell * math.hypot(dr, dc)
        if penalty is None:
            weights.append(np.full(int(a.sum()), step))
        else:
            cost = step * 0.5 * (penalty[r0:r1, c0:c1] + penalty[r0 + dr : r1 + dr, c0 + dc : c1 + dc])
            weights.append(cost[a])
        sources.append(index[r0:r1, c0:c1][a])
        targets.append(index[r0 + dr : r1 + dr, c0 + dc : c1 + dc][a])
    src, dst, w = np.concatenate(sources), np.concatenate(targets), np.concatenate(weights)
    n = int(index.max()) + 1
    graph = coo_matrix(
        (np.concatenate([w, w]), (np.concatenate([src, dst]), np.concatenate([dst, src]))), (n, n)
    )
    return graph.tocsr()
