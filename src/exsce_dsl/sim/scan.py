"""LaserScan ranges, ray-marched on the map's clearance field and against other robots.

Rays advance by the distance to the nearest obstacle (sphere tracing), so a
beam needs a few dozen lookups instead of one per map cell; all beams of all
scans of a robot are marched together as one numpy array.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np

from exsce_dsl.maps.planning import PlanningGrid
from exsce_dsl.sim.batches import Batch, stamp_columns
from exsce_dsl.sim.executor import SimulatedExecution
from exsce_dsl.sim.laser import SCAN_PERIOD, Laser, RecordedScans
from exsce_dsl.sim.values import header_at, samples_per

ROBOT_RADIUS = 0.3  # other robots are discs of this radius


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
    travelled = _marched(grid, laser, x, y, dx, dy).reshape(theta.shape)
    ranges = np.where(travelled < laser.range_max, travelled, np.inf)
    for qx, qy in others:  # other robots are discs
        cx, cy = qx[:, None] - x[:, None], qy[:, None] - y[:, None]
        along = cx * dx + cy * dy
        across2 = cx * cx + cy * cy - along * along
        inside = (across2 < robot_radius**2) & (along > 0)
        hit = along - np.sqrt(np.maximum(robot_radius**2 - across2, 0.0))
        ranges = np.where(inside & (hit > 0) & (hit < ranges), hit, ranges)
    noisy = ranges + rng.normal(0.0, laser.noise, ranges.shape)
    noisy = np.where(np.isfinite(ranges), np.maximum(noisy, laser.range_min), np.inf)
    return noisy.astype(np.float32)


MARCHED_AT_ONCE = 65536
"""Beams marched together: their arrays stay in the processor's cache (all of a run's beams at
once, near a million, marched a third slower)."""


def _marched(
    grid: PlanningGrid, laser: Laser, x: np.ndarray, y: np.ndarray, dx: np.ndarray, dy: np.ndarray
) -> np.ndarray:
    """How far each beam (scan-major, flat) goes until it hits (range_max or more: nothing hit)."""
    beams = dx.shape[1]
    hit_eps, least = grid.map_resolution, grid.map_resolution * 0.5
    # a scan's beams all start where the robot stands: their first step is the scan's own
    start = grid.clearance_of(x, y)
    first = np.repeat(np.maximum(start - least, least), beams)
    inside = np.repeat(start < hit_eps, beams)  # in a wall: every beam hits at once
    travelled = np.where(inside, 0.0, first)
    marching = np.flatnonzero(~inside & (first < laser.range_max))
    ox, oy, ux, uy = np.repeat(x, beams), np.repeat(y, beams), dx.reshape(-1), dy.reshape(-1)
    for chunk in np.array_split(marching, max(1, -(-marching.size // MARCHED_AT_ONCE))):
        _march(grid, laser.range_max, chunk, ox[chunk], oy[chunk], ux[chunk], uy[chunk], travelled)
    return travelled


def _march(
    grid: PlanningGrid,
    range_max: float,
    beam: np.ndarray,
    bx: np.ndarray,
    by: np.ndarray,
    bdx: np.ndarray,
    bdy: np.ndarray,
    travelled: np.ndarray,
) -> None:
    """March the beams ``beam`` from ``travelled[beam]`` on (sphere tracing), each step as far as
    the clearance where it stands, and write where each stops into ``travelled``; the beams still
    marching are compacted after each step, so that each step costs what is left."""
    hit_eps, least = grid.map_resolution, grid.map_resolution * 0.5
    so_far = travelled[beam]
    for _ in range(63):  # the first step was the scan's
        if beam.size == 0:
            break
        clearance = grid.clearance_of(bx + bdx * so_far, by + bdy * so_far)
        hit = clearance < hit_eps
        moved = so_far + np.maximum(clearance - least, least)
        going = ~hit & (moved < range_max)
        if going.all():
            so_far = moved
            continue
        stopped = ~going
        travelled[beam[stopped]] = np.where(hit[stopped], so_far[stopped], moved[stopped])
        beam, bx, by, bdx, bdy, so_far = (
            beam[going],
            bx[going],
            by[going],
            bdx[going],
            bdy[going],
            moved[going],
        )
    travelled[beam] = so_far  # beams still marching after the last step


def laser_scans(
    store: Any,
    topic: str,
    frame: str,
    robot: str,
    execution: SimulatedExecution,
    grid: PlanningGrid,
    laser: Laser,
    rng: np.random.Generator,
    stamps: np.ndarray,
) -> Iterator[Batch]:
    """``sensor_msgs/LaserScan`` messages of ``robot`` (stamps: one per sample): those the
    executor's own sensor recorded, else ray-marched every SCAN_EVERY samples against the map and
    the other robots; none when the executor recorded scans but not this robot's (no sensor)."""
    if execution.scans is not None:
        recorded = execution.scans.get(robot)
        if recorded is not None:
            yield _scan_batch(store, topic, frame, recorded, stamps, execution.dt)
        return
    tr = execution.trajectories[robot]
    idx = np.arange(0, len(tr), samples_per(SCAN_PERIOD, execution.dt))
    others = [(o.x[idx], o.y[idx]) for r, o in execution.trajectories.items() if r != robot]
    ranges = scan_ranges(grid, laser, tr.x[idx], tr.y[idx], tr.yaw[idx], others, ROBOT_RADIUS, rng)
    yield _scan_batch(store, topic, frame, RecordedScans(laser, idx, ranges), stamps, execution.dt)


def _scan_batch(
    store: Any, topic: str, frame: str, scans: RecordedScans, stamps: np.ndarray, dt: float
) -> Batch:
    T = store.types
    laser = scans.laser
    empty = np.zeros(0, dtype=np.float32)
    apart = scans.samples[1] - scans.samples[0] if len(scans.samples) > 1 else samples_per(SCAN_PERIOD, dt)

    def scan(sec: int, nanosec: int, seq: int, ranges: np.ndarray) -> Any:
        return T["sensor_msgs/msg/LaserScan"](
            header=header_at(store, sec, nanosec, frame, seq),
            angle_min=laser.angle_min,
            angle_max=laser.angle_max,
            angle_increment=laser.angle_increment,
            time_increment=0.0,
            scan_time=int(apart) * dt,
            range_min=laser.range_min,
            range_max=laser.range_max,
            ranges=ranges,
            intensities=empty,
        )

    at = stamps[scans.samples]
    seq = np.arange(len(at)).astype("<u4")
    columns = {**stamp_columns(at), "seq": seq, "ranges": scans.ranges.astype("<f4")}
    return Batch(topic, "sensor_msgs/msg/LaserScan", at, scan, columns)
