"""How far a robot drives between two points: the length of the shortest path on the environment's
occupancy grid, round walls and through doorways, not the straight line across them.

The grid is the executor's (``exsce_dsl.maps.planning.planning_grid``: the map_server map the
environment declares, coarsened to the planner's 10 cm cells, occupied space inflated by the robot's
radius).  A path is the shortest one on its free cells, 8-connected (a diagonal step costs √2 cells,
and never cuts a corner), by :mod:`exsce_dsl.maps.paths` on a graph built once per map.  Then
it is pulled tight: from each corner, the farthest later corner that a straight line of free cells
reaches comes next, so a path across an open room is its straight line, not a staircase of 45° and
90° steps (8-connected lengths alone are up to 8 % too long, depending on the direction); and each
remaining corner slides along its legs from the centre of its cell to where the path touches the
margin round the obstacle, on the map's own (finer) cells.  Round a wall's end, the length is then
within a few centimetres of the one worked out by hand (tests/derive/test_grid_estimates.py).

One :class:`GridLengths` per map and process (:func:`grid_lengths`); it keeps the lengths it has
measured and the shortest-path trees of the last sources, since an estimate asks for the same few
poses again and again.  On scenario_c's building: 1.5 s to load the map and build the graph, then
about 25 ms per new pair of points.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from pathlib import Path

import numpy as np
from scipy import ndimage

from exsce_dsl.maps.paths import grid_graph, path_in_tree, shortest_path_tree
from exsce_dsl.maps.planning import PlanningGrid, planning_grid
from exsce_dsl.model import Scenario

Point = tuple[float, float]

SNAP = 0.5
"""Metres a point may lie from the nearest free cell (a pose by a wall, inside the robot's radius
of it): the executor's planner starts from free cells as far away (5 of its cells)."""

TREES = 32
"""Shortest-path trees kept per map (about 1 MB each on scenario_c's building)."""

REFINE = 8
"""Bisection steps that slide a path's corner along one of its legs (to 1/256 of the leg)."""

SWEEPS = 3
"""Times at most every corner of a path slides along both its legs."""

SETTLED = 0.001
"""Metres below which corners that moved in a sweep count as settled."""

MAPS = 4
"""Maps kept per process."""

BLOCK = 64
"""Corners whose visibility is checked together when a path is pulled tight."""


class GridLengths:
    """Shortest-path lengths on one planning grid; see the module's description."""

    def __init__(self, grid: PlanningGrid) -> None:
        free: np.ndarray = grid.free
        self.grid = grid
        self.origin = grid.origin
        self.resolution = grid.resolution
        self.free = free
        self._node = np.full(free.shape, -1, dtype=np.int64)
        self._node[free] = np.arange(int(free.sum()))
        self._cells = np.argwhere(free)  # node → (row, col)
        self._graph = grid_graph(free, grid.resolution, node=self._node)  # the planner's, no wall penalty
        distance, nearest = ndimage.distance_transform_edt(~free, return_indices=True)
        self._snap_distance: np.ndarray = distance * grid.resolution
        self._nearest: np.ndarray = nearest  # (2, rows, cols): the nearest free cell of every cell
        self._trees: OrderedDict[int, np.ndarray] = OrderedDict()
        self._lengths: dict[tuple[Point, Point], float | None] = {}

    def length(self, a: Point, b: Point) -> float | None:
        """Metres of the shortest path from ``a`` to ``b`` on free space; None when either point is
        off the map or farther than :data:`SNAP` from free space, or no path joins them."""
        key = (a, b) if a <= b else (b, a)
        if key not in self._lengths:
            self._lengths[key] = self._measure(*key)
        return self._lengths[key]

    def path(self, a: Point, b: Point) -> list[Point] | None:
        """The pulled-tight path from ``a`` to ``b`` (both included), or None as for :meth:`length`."""
        source, target = self._snap(a), self._snap(b)
        if source is None or target is None:
            return None
        nodes = path_in_tree(self._tree(source), source, target)
        if nodes is None:
            return None
        rows, cols = self._cells[nodes].T
        centres = np.column_stack(
            [self.origin[0] + (cols + 0.5) * self.resolution, self.origin[1] + (rows + 0.5) * self.resolution]
        )
        corners = np.vstack([np.asarray([a]), centres, np.asarray([b])])
        return [(float(x), float(y)) for x, y in self._round_corners(self._pull_tight(corners))]

    def _measure(self, a: Point, b: Point) -> float | None:
        if a == b:
            return 0.0
        path = self.path(a, b)
        if path is None:
            return None
        return math.fsum(math.dist(p, q) for p, q in zip(path, path[1:], strict=False))

    def _snap(self, p: Point) -> int | None:
        """The node of the free cell nearest ``p``, if within :data:`SNAP`."""
        row = math.floor((p[1] - self.origin[1]) / self.resolution)
        col = math.floor((p[0] - self.origin[0]) / self.resolution)
        if not (0 <= row < self.free.shape[0] and 0 <= col < self.free.shape[1]):
            return None
        if self._snap_distance[row, col] > SNAP:
            return None
        return int(self._node[self._nearest[0, row, col], self._nearest[1, row, col]])

    def _tree(self, source: int) -> np.ndarray:
        """Predecessors on the shortest paths from ``source`` (negative: unreachable)."""
        if source in self._trees:
            self._trees.move_to_end(source)
            return self._trees[source]
        tree = shortest_path_tree(self._graph, source)
        self._trees[source] = tree
        if len(self._trees) > TREES:
            self._trees.popitem(last=False)
        return tree

    def _pull_tight(self, corners: np.ndarray) -> np.ndarray:
        """Drop the corners a straight line of free cells can skip: from each corner, the farthest
        later one it sees comes next (looked for from the end, a block of corners at a time)."""
        kept, i, last = [0], 0, len(corners) - 1
        while i < last:
            following = i + 1  # the end points may stand in the inflated margin by a wall: no line
            for stop in range(last + 1, i + 1, -BLOCK):
                first = max(i + 1, stop - BLOCK)
                seen = np.flatnonzero(self._visible(corners[i], corners[first:stop]))
                if len(seen):
                    following = first + int(seen[-1])
                    break
            i = following
            kept.append(i)
        pulled: np.ndarray = corners[kept]
        return pulled

    def _round_corners(self, corners: np.ndarray) -> np.ndarray:
        """Slide each inner corner, from the centre of its planning cell, along its legs towards
        its neighbours, as far as the other leg keeps the robot's radius from occupied space on the
        map's own cells (bisection; a slide along a leg never lengthens the path): corners end
        where the path touches the obstacles' margin, not up to a cell beyond it."""
        out = corners.copy()
        for _ in range(SWEEPS):  # a corner moved lets its neighbours move a little farther
            before = out.copy()
            for k in range(1, len(out) - 1):
                for towards, other in ((k + 1, k - 1), (k - 1, k + 1)):
                    corner, step = out[k], out[towards] - out[k]
                    low, high = 0.0, 1.0
                    for _ in range(REFINE):
                        middle = (low + high) / 2
                        if self._clear(out[other], corner + middle * step):
                            low = middle
                        else:
                            high = middle
                    out[k] = corner + low * step
            if np.abs(out - before).max() < SETTLED:
                break
        return out

    def _clear(self, a: np.ndarray, b: np.ndarray) -> bool:
        """Whether the straight line from ``a`` to ``b`` keeps the robot's radius from occupied space,
        sampled every half map cell (as the executor's planner checks its shortcuts)."""
        steps = max(2, math.ceil(float(np.hypot(*(b - a))) / (self.grid.map_resolution / 2)) + 1)
        points = np.linspace(a, b, steps)
        return bool(np.all(self.grid.clearance_at(points) > self.grid.robot_radius))

    def _visible(self, start: np.ndarray, ends: np.ndarray) -> np.ndarray:
        """Whether each straight line from ``start`` to one of ``ends`` crosses free cells only,
        sampled a cell apart (occupied space is inflated by the robot's radius on both sides, so
        no obstacle is thinner than several cells)."""
        longest = float(np.max(np.hypot(*(ends - start).T)))
        steps = max(2, math.ceil(longest / self.resolution) + 1)
        t = np.linspace(0.0, 1.0, steps)
        points = start + (ends - start)[:, None, :] * t[None, :, None]  # (ends, steps, 2)
        cols = np.floor((points[..., 0] - self.origin[0]) / self.resolution).astype(np.int64)
        rows = np.floor((points[..., 1] - self.origin[1]) / self.resolution).astype(np.int64)
        inside = (rows >= 0) & (rows < self.free.shape[0]) & (cols >= 0) & (cols < self.free.shape[1])
        ok = np.zeros(points.shape[:2], dtype=bool)
        ok[inside] = self.free[rows[inside], cols[inside]]
        seen: np.ndarray = np.asarray(ok.all(axis=1), dtype=bool)
        return seen


_LOADED: OrderedDict[str, GridLengths] = OrderedDict()


def grid_lengths(scenario: Scenario) -> GridLengths | None:
    """The path lengths on the occupancy grid of the scenario's environment, loaded once per map
    and process; None when the environment declares no map file.  Raises :class:`ExsceError` when
    it declares one that cannot be used (unreadable, not a map, a rotated origin); such a map is
    tried again on the next call (it may have been fixed)."""
    declared = scenario.environment.map
    if declared is None or declared.file is None:
        return None
    key = str(Path(declared.file).resolve())
    if key not in _LOADED:
        _LOADED[key] = GridLengths(planning_grid(scenario))
        if len(_LOADED) > MAPS:
            _LOADED.popitem(last=False)
    _LOADED.move_to_end(key)
    return _LOADED[key]
