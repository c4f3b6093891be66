"""LaserScan ranges, ray-marched on the map's clearance field and against other robots.

Rays advance by the distance to the nearest obstacle (sphere tracing), so a
beam needs a few dozen lookups instead of one per map cell; all beams of all
scans of a robot are marched together as one numpy array.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from exsce_dsl.maps.planning import PlanningGrid
from exsce_dsl.sim.batches import Batch, stamp_columns
from exsce_dsl.sim.executor import Execution
from exsce_dsl.sim.motion import DT
from exsce_dsl.sim.values import header_at

SCAN_EVERY = 5  # samples of the 50 Hz clock: 10 Hz
ROBOT_RADIUS = 0.3  # other robots are discs of this radius


@dataclass(frozen=True)
class Laser:
    beams: int = 720
    angle_min: float = -2.356194490192345  # -135°
    angle_max: float = 2.356194490192345
    range_min: float = 0.05
    range_max: float = 10.0
    noise: float = 0.01

    @property
    def angle_increment(self) -> float:
        return (self.angle_max - self.angle_min) / (self.beams - 1)

    def angles(self) -> np.ndarray:
        return self.angle_min + self.angle_increment * np.arange(self.beams)


def scan_ranges(
    grid: PlanningGrid,
    laser: Laser,
    x: np.ndarray,
    y: np.ndarray,
    yaw: np.ndarray,
    others: list[tuple[np.ndarray, np.ndarray]],
    robot_radius: float,
    rng: np.random.Generator,
) -> np.ndarray:
    """Ranges (scans × beams, float32) for a robot at ``x, y, yaw`` (one row per scan)."""
    theta = yaw[:, None] + laser.angles()[None, :]
    dx, dy = np.cos(theta), np.sin(theta)
    ox, oy = np.broadcast_to(x[:, None], theta.shape), np.broadcast_to(y[:, None], theta.shape)
    # the beams still marching, compacted after each step: each step costs what is left
    beam = np.arange(theta.size)
    bx, by, bdx, bdy = (a.reshape(-1) for a in (ox, oy, dx, dy))
    so_far = np.zeros(theta.size)
    travelled = np.zeros(theta.size)
    hit_eps = grid.map_resolution
    for _ in range(64):
        if beam.size == 0:
            break
        clearance = grid.clearance_of(bx + bdx * so_far, by + bdy * so_far)
        done = clearance < hit_eps
        moved = so_far + np.where(done, 0.0, np.maximum(clearance - hit_eps * 0.5, hit_eps * 0.5))
        going = ~done & (moved < laser.range_max)
        stopped = ~going
        travelled[beam[stopped]] = moved[stopped]
        beam, bx, by, bdx, bdy, so_far = (
            beam[going],
            bx[going],
            by[going],
            bdx[going],
            bdy[going],
            moved[going],
        )
    travelled[beam] = so_far  # beams still marching after the last step
    travelled = travelled.reshape(theta.shape)
    ranges = np.where(travelled < laser.range_max, travelled, np.inf)
    for qx, qy in others:  # other robots are discs
        cx, cy = qx[:, None] - ox, qy[:, None] - oy
        along = cx * dx + cy * dy
        across2 = cx * cx + cy * cy - along * along
        inside = (across2 < robot_radius**2) & (along > 0)
        hit = along - np.sqrt(np.maximum(robot_radius**2 - across2, 0.0))
        ranges = np.where(inside & (hit > 0) & (hit < ranges), hit, ranges)
    noisy = ranges + rng.normal(0.0, laser.noise, ranges.shape)
    noisy = np.where(np.isfinite(ranges), np.maximum(noisy, laser.range_min), np.inf)
    return noisy.astype(np.float32)


def laser_scans(
    store: Any,
    topic: str,
    frame: str,
    robot: str,
    execution: Execution,
    grid: PlanningGrid,
    laser: Laser,
    rng: np.random.Generator,
    stamps: np.ndarray,
) -> Batch:
    """``sensor_msgs/LaserScan`` messages of ``robot`` every SCAN_EVERY samples (stamps: one per
    sample), against the map and the other robots."""
    T = store.types
    tr = execution.trajectories[robot]
    idx = np.arange(0, len(tr), SCAN_EVERY)
    others = [(o.x[idx], o.y[idx]) for r, o in execution.trajectories.items() if r != robot]
    ranges = scan_ranges(grid, laser, tr.x[idx], tr.y[idx], tr.yaw[idx], others, ROBOT_RADIUS, rng)
    empty = np.zeros(0, dtype=np.float32)

    def scan(sec: int, nanosec: int, seq: int, ranges: np.ndarray) -> Any:
        return T["sensor_msgs/msg/LaserScan"](
            header=header_at(store, sec, nanosec, frame, seq),
            angle_min=laser.angle_min,
            angle_max=laser.angle_max,
            angle_increment=laser.angle_increment,
            time_increment=0.0,
            scan_time=SCAN_EVERY * DT,
            range_min=laser.range_min,
            range_max=laser.range_max,
            ranges=ranges,
            intensities=empty,
        )

    seq = np.arange(len(idx)).astype("<u4")
    columns = {**stamp_columns(stamps[idx]), "seq": seq, "ranges": ranges.astype("<f4")}
    return Batch(topic, "sensor_msgs/msg/LaserScan", stamps[idx], scan, columns)
