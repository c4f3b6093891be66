"""A scenario as an IR-SIM world: the real building of scenario_c (its map's origin is far from
0, 0) in IR-SIM has the map's cells where the map has them, and a pose of the specification is
the same point in IR-SIM.  The map is read here with plain numpy from its PGM file, as map_server
reads it; IR-SIM's grid is read from IR-SIM's own world."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from exsce_dsl.lang import load_spec
from exsce_dsl.maps.planning import planning_grid
from exsce_dsl.model import Scenario
from exsce_dsl.sim.irsim_play import irsim_module
from exsce_dsl.sim.irsim_world import BODIES, world_file

from tests.support.paths import EXAMPLES

SPEC = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"
MAP = EXAMPLES / "brsu_building_c" / "maps" / "brsu_building_c_with_doorways.yaml"


def _pgm(path: Path) -> np.ndarray:
    data = path.read_bytes()
    fields = data.split(maxsplit=4)  # P5, width, height, maxval, pixels
    width, height = int(fields[1]), int(fields[2])
    return np.frombuffer(fields[4], dtype=np.uint8)[: width * height].reshape(height, width)


def _blocked_from_the_bottom() -> tuple[np.ndarray, float, tuple[float, float]]:
    """Cells that are not free space by map_server's reading (rows from the bottom)."""
    meta = yaml.safe_load(MAP.read_text())
    grey = _pgm(MAP.parent / meta["image"]).astype(np.float64)
    occupancy = (255.0 - grey) / 255.0
    return (occupancy >= meta["free_thresh"])[::-1], float(meta["resolution"]), tuple(meta["origin"][:2])


@pytest.fixture(scope="module")
def scenario() -> Scenario:
    return load_spec(SPEC).scenarios[0]


@pytest.fixture(scope="module")
def env(scenario: Scenario, tmp_path_factory: pytest.TempPathFactory) -> Any:
    folder = tmp_path_factory.mktemp("world")
    speeds = {r.id: 0.5 for r in scenario.robots}
    world = world_file(scenario, planning_grid(scenario), folder, "dash", speeds, None)
    made = irsim_module().make(str(world), display=False, headless=True, log_level="CRITICAL")
    yield made
    made.end(0)


def test_irsim_has_the_maps_walls_where_the_map_has_them(env: Any) -> None:
    blocked, resolution, (ox, oy) = _blocked_from_the_bottom()
    world = env._world
    assert world.offset == [pytest.approx(ox), pytest.approx(oy)]
    assert float(world.reso[0, 0]) == pytest.approx(resolution)
    assert float(world.reso[1, 0]) == pytest.approx(resolution)
    walls = np.asarray(world.grid_map) > 50  # IR-SIM's grid: [x index, y index from the bottom]
    assert walls.shape == (blocked.shape[1], blocked.shape[0])
    free = ~blocked
    # a wall cell beside free space (the only ones IR-SIM is given) is a wall in IR-SIM
    padded = np.pad(free, 1)
    beside_free = np.zeros_like(free)
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            beside_free |= padded[1 + dr : 1 + dr + free.shape[0], 1 + dc : 1 + dc + free.shape[1]]
    border = blocked & beside_free
    assert border.sum() > 10_000  # the building's walls, not a handful of cells
    assert np.array_equal(walls.T[border], np.ones(int(border.sum()), dtype=bool))
    # and no free cell is a wall
    assert not walls.T[free].any()


def test_a_robot_stands_on_its_start_pose_and_collides_on_a_wall(env: Any, scenario: Scenario) -> None:
    robots = {obj.name: obj for obj in env.robot_list}
    for robot in scenario.robots:
        pose = robot.start_pose
        assert pose is not None
        state = robots[robot.id].state[:, 0]
        assert state[:3] == pytest.approx([pose.position.x, pose.position.y, pose.orientation.yaw])
        assert robots[robot.id].radius == pytest.approx(BODIES["pmb2"].radius)
    env.step()
    assert not any(obj.collision_flag for obj in env.robot_list)
    # a wall next to tiago1's start pose, found on the map by the test: the robot put there collides
    blocked, resolution, (ox, oy) = _blocked_from_the_bottom()
    start = scenario.robots[0].start_pose
    assert start is not None
    col = int((start.position.x - ox) / resolution)
    row = int((start.position.y - oy) / resolution)
    rows, cols = np.nonzero(blocked[row - 60 : row + 60, col - 60 : col + 60])
    nearest = int(np.argmin((rows - 60) ** 2 + (cols - 60) ** 2))
    wall_x = ox + (col - 60 + cols[nearest] + 0.5) * resolution
    wall_y = oy + (row - 60 + rows[nearest] + 0.5) * resolution
    tiago1 = robots[scenario.robots[0].id]
    tiago1.set_state([wall_x, wall_y, 0.0])
    env.step()
    assert tiago1.collision_flag
