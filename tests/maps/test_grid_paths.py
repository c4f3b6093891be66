"""The shared grid graph and shortest paths (exsce_dsl.maps), on grids small enough to check by hand."""

from __future__ import annotations

import numpy as np

from exsce_dsl.maps.grid import OccupancyGrid
from exsce_dsl.maps.paths import grid_graph, path_in_tree, shortest_path, shortest_path_tree


def test_a_wall_is_walked_round_and_no_corner_is_cut() -> None:
    free = np.array(
        [
            [True, True, True],
            [False, False, True],
            [True, True, True],
        ]
    )
    graph = grid_graph(free, 1.0)
    nodes = shortest_path(graph, 0, 6)  # (0, 0) to (2, 0), cells numbered row by row
    # no diagonal step past the wall's end: (0, 1)-(1, 2) and (1, 2)-(2, 1) would cut (1, 1)
    assert nodes == [0, 1, 2, 5, 8, 7, 6]
    assert sum(graph[a, b] for a, b in zip(nodes, nodes[1:], strict=False)) == 6.0
    penalised = grid_graph(free, 1.0, penalty=np.full(free.shape, 2.0))
    assert penalised[0, 1] == 2.0 and penalised[5, 7] == 0.0  # a step of 1 m at twice the cost; no edge


def test_an_unreachable_cell_has_no_path() -> None:
    free = np.array([[True, False, True]])
    tree = shortest_path_tree(grid_graph(free, 0.5), 0)
    assert path_in_tree(tree, 0, 2) is None
    assert path_in_tree(tree, 0, 0) == [0]


def test_free_cells_follow_map_servers_thresholds() -> None:
    cells = np.array([[254, 205, 0]], dtype=np.uint8)
    grid = OccupancyGrid(cells, 0.05, (0.0, 0.0, 0.0), 0.65, 0.196, False)
    assert grid.free_cells().tolist() == [[True, False, False]]
    assert [grid.state_at(x, 0.01) for x in (0.01, 0.06, 0.11)] == ["free", "unknown", "occupied"]
