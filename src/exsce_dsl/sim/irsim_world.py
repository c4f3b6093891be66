"""A scenario as an IR-SIM world: its map, its robots and their sensors, written as the YAML
world file (and the map image) that ``irsim.make`` reads.

The map is the scenario's occupancy grid at its own resolution and origin: IR-SIM's world has the
grid's width and height and is offset by the grid's origin, so a pose of the specification is the
same point in IR-SIM (``tests/sim/test_irsim_world.py`` places a robot on one).  Every cell that
is not free space (occupied or unknown, as the planner reads the map) borders the free space it
faces: only those border cells are written as obstacles, because a robot or a beam meets the
border of a wall before its inside, and IR-SIM turns every obstacle cell into geometry.

A robot type's base gives IR-SIM's kinematics and footprint (:data:`BODIES`); its speed and
acceleration limits are those the kinematic executor drives with.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from scipy import ndimage

from exsce_dsl.errors import ExsceError
from exsce_dsl.maps.planning import PlanningGrid
from exsce_dsl.model import Robot, Scenario
from exsce_dsl.sim.laser import Laser
from exsce_dsl.sim.motion import Limits
from exsce_dsl.suggest import did_you_mean

BEHAVIOURS = ("dash", "rvo", "orca", "sfm")
"""IR-SIM's behaviours exsce offers: ``dash`` drives straight at the next goal; ``rvo``
(reciprocal velocity obstacles) and ``sfm`` (social forces) avoid the other robots; ``orca`` is
the group behaviour of pyrvo's ORCA (``pip install pyrvo``)."""

STEP = 0.1
"""Seconds of IR-SIM's step (its ``step_time``; 0.1 s is IR-SIM's default): the run's sample
period, so odometry, TF and poses are at 10 Hz."""
GOAL_TOLERANCE = 0.2
"""Metres from a goal at which IR-SIM counts it reached (Nav2's default is 0.25)."""


@dataclass(frozen=True)
class Body:
    """What IR-SIM is told of a mobile base: its kinematics and a round footprint."""

    kinematics: str
    radius: float


BODIES: dict[str, Body] = {
    "pmb2": Body("diff", 0.275),  # PAL's PMB2 (TIAGo's base): differential drive, 0.275 m radius
}
"""Only differential drives: the run's samples are (x, y, heading, speed, turn rate), and an omni
base's IR-SIM velocity is (vx, vy); such a base is played as a differential drive for now."""
DEFAULT_BODY = Body("diff", 0.3)
"""A base exsce knows nothing of: a differential drive as big as the planner assumes."""


SCAN_SOURCES = ("exsce", "irsim", "none")
"""Who measures the scans: ``exsce``'s laser model, ray-marched on the same grid against the
robots where IR-SIM put them (fast); IR-SIM's own ``lidar2d`` (exact on IR-SIM's geometry, but
each scan casts every beam against every segment of the map, about 0.1 s a scan on scenario_c's
building); or nobody (no scan topics)."""


def check_settings(behaviour: str, scans: str) -> None:
    """An :class:`ExsceError` unless ``behaviour`` is one of :data:`BEHAVIOURS` and ``scans`` one
    of :data:`SCAN_SOURCES`."""
    if behaviour not in BEHAVIOURS:
        hint = did_you_mean(behaviour, list(BEHAVIOURS))
        raise ExsceError(f"IR-SIM has no behaviour '{behaviour}'{hint}; use one of {', '.join(BEHAVIOURS)}")
    if scans not in SCAN_SOURCES:
        raise ExsceError(f"unknown scan source '{scans}'; use one of {', '.join(SCAN_SOURCES)}")


def body_of(robot: Robot) -> Body:
    return BODIES.get(robot.type.base or "", DEFAULT_BODY)


def world_file(
    scenario: Scenario,
    grid: PlanningGrid,
    folder: Path,
    behaviour: str,
    speeds: dict[str, float],
    laser: Laser | None,
    limits: Limits | None = None,
    step: float = STEP,
) -> Path:
    """Write ``scenario`` as an IR-SIM world into ``folder`` (the world file and its map image)
    and return the world file's path.  ``speeds``: each robot's top speed; ``laser``: each robot's
    ``lidar2d`` (None: no sensor); ``step``: IR-SIM's step, in seconds."""
    limits = limits or Limits()
    flying = [r.id for r in scenario.robots if r.type.motion != "planar"]
    if flying:
        raise ExsceError(
            f"IR-SIM plays ground robots on a plane; the robots {', '.join(flying)} of scenario "
            f"'{scenario.id}' fly (motion 3d)"
        )
    image = folder / "map.png"
    height, width = _write_map_image(grid, image)
    world = {
        "world": {
            "width": width * grid.map_resolution,
            "height": height * grid.map_resolution,
            "offset": [float(grid.origin[0]), float(grid.origin[1])],
            "step_time": step,
            "obstacle_map": str(image),
            "collision_mode": "stop",
        },
        "robot": [
            _robot(robot, behaviour, speeds[robot.id], laser, limits)
            for robot in scenario.robots
            if robot.start_pose is not None
        ],
    }
    path = folder / "world.yaml"
    path.write_text(yaml.safe_dump(world, sort_keys=False), encoding="utf-8")
    return path


def _robot(robot: Robot, behaviour: str, speed: float, laser: Laser | None, limits: Limits) -> dict[str, Any]:
    assert robot.start_pose is not None
    body = body_of(robot)
    pose = robot.start_pose
    spec: dict[str, Any] = {
        "name": robot.id,
        "kinematics": {"name": body.kinematics},
        "shape": {"name": "circle", "radius": body.radius},
        "state": [pose.position.x, pose.position.y, pose.orientation.yaw],
        "vel_min": [0.0, -limits.max_turn_rate] if body.kinematics == "diff" else [-speed, -speed],
        "vel_max": [speed, limits.max_turn_rate] if body.kinematics == "diff" else [speed, speed],
        "acce": [limits.max_accel, 2.0 * limits.max_turn_rate],
        "goal_threshold": GOAL_TOLERANCE,
        "arrive_mode": "position",
    }
    if behaviour == "orca":
        spec["group_behavior"] = {"name": "orca"}
    else:
        spec["behavior"] = {"name": behaviour, "vxmax": speed, "vymax": speed}
    if laser is not None:
        spec["sensors"] = [
            {
                "name": "lidar2d",
                "range_min": laser.range_min,
                "range_max": laser.range_max,
                "angle_range": laser.angle_max - laser.angle_min,
                "number": laser.beams,
                "noise": False,
            }
        ]
    return spec


def _write_map_image(grid: PlanningGrid, path: Path) -> tuple[int, int]:
    """The map as IR-SIM reads an image (black: obstacle; the top row is the far side of the
    map), only the cells that border free space black; its height and width in cells."""
    import matplotlib.image as mpimg  # IR-SIM's own dependency, with it in the irsim extra

    blocked = grid.clearance <= 0.0  # rows from the bottom, as the planner keeps them
    border = blocked & ndimage.binary_dilation(~blocked, structure=np.ones((3, 3), dtype=bool))
    mpimg.imsave(path, np.where(border[::-1], 0.0, 1.0), cmap="gray", vmin=0.0, vmax=1.0)
    return int(blocked.shape[0]), int(blocked.shape[1])
