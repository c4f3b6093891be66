"""The executor's laser scans against geometry worked out by hand: a wall across a 10 m floor,
another robot in the way, a robot inside a wall; and a run's scans marched in several batches
(more beams than :data:`MARCHED_AT_ONCE`) give each scan's ranges as that scan alone gives them."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pytest

from exsce_dsl.maps.grid import load_occupancy_grid
from exsce_dsl.maps.planning import PlanningGrid
from exsce_dsl.sim.laser import Laser
from exsce_dsl.sim.scan import MARCHED_AT_ONCE, scan_ranges

from tests.support.map_files import write_map

EXACT = Laser(noise=0.0)
WALL_X = 7.5
"""The wall's face: cells 150-159 of 5 cm are occupied, the whole height of the map."""


@pytest.fixture(scope="module")
def grid(tmp_path_factory: pytest.TempPathFactory) -> PlanningGrid:
    folder = tmp_path_factory.mktemp("scan_map")
    write_map(folder, size=200, occupied=(150, 0, 160, 200))
    return PlanningGrid.from_map(load_occupancy_grid(folder / "map.yaml"))


def _ranges(
    grid: PlanningGrid, x: float, y: float, yaw: float, others: Sequence[tuple[np.ndarray, np.ndarray]] = ()
) -> np.ndarray:
    found = scan_ranges(
        grid,
        EXACT,
        np.array([x]),
        np.array([y]),
        np.array([yaw]),
        list(others),
        0.3,
        np.random.default_rng(0),
    )
    return found[0]


def _beam(angle: float) -> int:
    return int(round((angle - EXACT.angle_min) / EXACT.angle_increment))


def test_a_beam_straight_at_the_wall_stops_at_its_face(grid: PlanningGrid) -> None:
    ranges = _ranges(grid, 2.5, 5.0, 0.0)
    ahead = ranges[_beam(0.0)]
    # a beam stops in the cell where it meets the wall: within one cell of its face
    assert ahead == pytest.approx(WALL_X - 2.5, abs=grid.map_resolution)
    slanted = ranges[_beam(math.pi / 6)]  # 30° to the left: 5 m / cos 30°
    assert slanted == pytest.approx((WALL_X - 2.5) / math.cos(math.pi / 6), abs=2 * grid.map_resolution)


def test_another_robot_in_the_way_is_a_disc_of_its_radius(grid: PlanningGrid) -> None:
    other = (np.array([4.5]), np.array([5.0]))  # 2 m ahead
    ahead = _ranges(grid, 2.5, 5.0, 0.0, [other])[_beam(0.0)]
    assert ahead == pytest.approx(2.0 - 0.3, abs=1e-3)  # the beam nearest 0° is 0.19° off it


def test_a_robot_inside_the_wall_sees_every_beam_at_range_min(grid: PlanningGrid) -> None:
    ranges = _ranges(grid, 7.75, 5.0, 0.0)
    assert np.all(ranges == np.float32(EXACT.range_min))


def test_scans_marched_in_batches_are_each_scan_alone(grid: PlanningGrid) -> None:
    count = MARCHED_AT_ONCE // EXACT.beams + 20  # beams of the last scans go in a second batch
    rng = np.random.default_rng(7)
    x, y, yaw = (
        rng.uniform(0.5, 7.0, count),
        rng.uniform(0.5, 9.5, count),
        rng.uniform(-math.pi, math.pi, count),
    )
    together = scan_ranges(grid, EXACT, x, y, yaw, [], 0.3, np.random.default_rng(0))
    assert together.shape == (count, EXACT.beams) and count * EXACT.beams > MARCHED_AT_ONCE
    for i in (0, count // 2, count - 1):
        assert np.array_equal(together[i], _ranges(grid, x[i], y[i], yaw[i]))
    assert np.isfinite(together).mean() > 0.5  # most beams meet the wall or the map's edge


def test_a_beam_that_leaves_the_map_stops_at_its_edge(grid: PlanningGrid) -> None:
    """Outside the map is nothing free: a beam stops where it leaves (5 m below the robot here),
    not where a step from inside happened to land (it stepped 5 m past the edge)."""
    down = _ranges(grid, 2.5, 5.0, 0.0)[_beam(-math.pi / 2)]
    assert down == pytest.approx(5.0, abs=grid.map_resolution)
