"""Shortest paths on a grid of free cells: the 8-connected graph of the cells (built once per map,
vectorised) and scipy's Dijkstra on it.

The planner (:mod:`exsce_dsl.maps.planning`) weights the graph's edges by a penalty near walls;
the estimates' path lengths (:mod:`exsce_dsl.derive.grid_lengths`) use plain lengths and keep the
shortest-path trees of the sources they ask about again and again.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.sparse import coo_matrix, csr_matrix
from scipy.sparse.csgraph import dijkstra


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


def shortest_path_tree(graph: csr_matrix, source: int) -> np.ndarray:
    """Each node's predecessor on its shortest path from ``source`` (negative: the source itself,
    or a node no path reaches)."""
    _, predecessors = dijkstra(graph, indices=source, return_predecessors=True)
    tree: np.ndarray = np.asarray(predecessors, dtype=np.int32)
    return tree


def path_in_tree(tree: np.ndarray, source: int, target: int) -> list[int] | None:
    """The nodes of the shortest path from ``source`` to ``target`` (both included) in ``tree``
    (:func:`shortest_path_tree` of ``source``); None when no path reaches ``target``."""
    if target != source and tree[target] < 0:
        return None
    nodes = [target]
    while nodes[-1] != source:
        nodes.append(int(tree[nodes[-1]]))
    return nodes[::-1]


def shortest_path(graph: csr_matrix, source: int, target: int) -> list[int] | None:
    """The nodes of the shortest path from ``source`` to ``target`` on ``graph`` (both included);
    None when there is none."""
    return path_in_tree(shortest_path_tree(graph, source), source, target)
