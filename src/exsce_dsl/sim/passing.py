"""Head-on meetings: the robot with less right of way waits beside the other's path.

Giving way (:mod:`exsce_dsl.sim.give_way`) only changes when robots drive, never where.  Two
robots that meet head-on where their paths are one (a doorway, a corridor both drive along)
stop facing each other, each waiting for the other, until one gives up and they drive through
each other.  Sending one of them round the other (:mod:`exsce_dsl.sim.conflicts`) then often
means round the building, through another door: not what a fleet manager does for a robot that
is about to move on.  It sends the robot with less right of way to a place beside the other's
path, near where it stopped, to wait there until the other has gone by, as people step aside
in a corridor: :func:`head_on_wait` finds that place and how long to wait, and the executor
plays the leg again through it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from exsce_dsl.maps.planning import PlanningGrid, Point
from exsce_dsl.sim.conflicts import CLEARANCE, STOOD, LegId, Timed, leg_at
from exsce_dsl.sim.motion import DT, SampledMotion

ASIDE = CLEARANCE + 0.3
"""Metres between a waiting robot's centre and the other's path: room to pass at clearance."""
REACH = 3.0
"""Metres from where a robot stopped within which it looks for a place to wait."""
GONE_BY = 1.5
"""Metres past the waiting robot the other has to be before it drives on."""
MARGIN = 1.0
"""Seconds added to the time the other is expected to have gone by (speeds vary)."""
LONGEST = 15.0
"""Seconds a robot waits beside the path at most: longer, the other is not just going by."""
ENDS = 1.0
"""Metres from a leg's start or goal within which a standing robot is at a waypoint, not on its way."""
STILL = 1e-9
"""Metres a robot moves in a sample at most to count as standing."""


class Driven(Timed, Protocol):
    """What a wait needs of an executor's action: whose leg it is, when, and its planned path."""

    @property
    def path(self) -> tuple[Point, ...]: ...


@dataclass(frozen=True)
class Wait:
    """Drive ``leg`` by way of ``place`` and wait there until ``until`` (seconds on the run's
    clock; None: do not wait) before driving on to its goal."""

    leg: LegId
    place: Point
    until: float | None


def head_on_wait(
    trajectories: dict[str, SampledMotion],
    actions: Sequence[Driven],
    order: Sequence[str],
    grid: PlanningGrid,
    meeting: tuple[int, str, str],
) -> Wait | None:
    """The wait that keeps the robots of ``meeting`` (the first sample they are closer than the
    clearance, and the two robots) apart, when both had stopped facing each other just before:
    the robot later in ``order`` waits beside the other's path.  None when they had not both
    stopped on their way (one waiting at a waypoint is not a head-on meeting), when no place
    near enough is free, in sight and clear of the other's path, or when the other would not
    have gone by within LONGEST seconds."""
    k, a, b = meeting
    mover, other = sorted((a, b), key=order.index, reverse=True)
    tm, to = trajectories[mover], trajectories[other]
    mover_stop, other_stop = _stood_since(tm, k), _stood_since(to, k)
    leg, passing = leg_at(actions, mover, k * DT), leg_at(actions, other, k * DT)
    if mover_stop is None or other_stop is None or leg is None or passing is None:
        return None
    stood: Point = (float(tm.x[k - 1]), float(tm.y[k - 1]))
    at: Point = (float(to.x[k - 1]), float(to.y[k - 1]))
    if not (_mid_leg(actions, leg, stood) and _mid_leg(actions, passing, at)):
        return None  # one waits at a waypoint: not two robots nose to nose on their way
    ahead = _path_ahead(actions, passing, at)
    place = _place_aside(grid, stood, ahead)
    if place is None:
        return None
    speed = float(np.max(np.abs(to.v))) or 0.5
    until = other_stop * DT + (_along(ahead, place) + GONE_BY) / speed + MARGIN
    return Wait(leg, place, until) if until - mover_stop * DT <= LONGEST else None


def _mid_leg(actions: Sequence[Driven], leg: LegId, point: Point) -> bool:
    """``point`` is on the way: farther than ENDS from both ends of the leg's path."""
    robot, number = leg
    path = [x for x in actions if x.robot == robot][number - 1].path
    return bool(path) and all(math.dist(point, end) > ENDS for end in (path[0], path[-1]))


def _stood_since(trajectory: SampledMotion, k: int) -> int | None:
    """The first sample of the stop the robot was in just before sample ``k`` (within STOOD
    seconds of it), or None when it did not stand then."""
    since = max(0, k - int(STOOD / DT))
    step = np.hypot(np.diff(trajectory.x[since:k]), np.diff(trajectory.y[since:k]))
    standing = step < STILL
    if not standing.any():
        return None
    last = since + int(np.flatnonzero(standing)[-1])
    moves = np.flatnonzero(
        np.hypot(np.diff(trajectory.x[: last + 1]), np.diff(trajectory.y[: last + 1])) >= STILL
    )
    return int(moves[-1]) + 1 if len(moves) else 0


def _path_ahead(actions: Sequence[Driven], leg: LegId, at: Point) -> np.ndarray:
    """The other robot's path from ``at`` to the end of its leg, and its next leg's."""
    robot, number = leg
    own = [x for x in actions if x.robot == robot]
    points = list(own[number - 1].path) + (list(own[number].path) if number < len(own) else [])
    path = np.asarray(points if points else [at], dtype=float)
    if len(path) < 2:
        return np.asarray([at], dtype=float)
    segments = [_distance_to_path(np.asarray([at]), path[i : i + 2])[0] for i in range(len(path) - 1)]
    on = int(np.argmin(segments))  # the segment the robot stands on: on from its end
    return np.vstack([np.asarray([at]), path[on + 1 :]])


def _place_aside(grid: PlanningGrid, stood: Point, ahead: np.ndarray) -> Point | None:
    """The free place nearest ``stood`` (within REACH, in straight sight of it) at ASIDE from the
    path ``ahead`` at least."""
    step = grid.resolution
    offsets = np.arange(-REACH, REACH + step / 2, step)
    xs, ys = np.meshgrid(stood[0] + offsets, stood[1] + offsets)
    candidates = np.column_stack([xs.ravel(), ys.ravel()])
    near = np.hypot(candidates[:, 0] - stood[0], candidates[:, 1] - stood[1])
    keep = (near <= REACH) & (grid.clearance_at(candidates) > grid.robot_radius + 0.1)
    candidates, near = candidates[keep], near[keep]
    keep = _distance_to_path(candidates, ahead) >= ASIDE
    candidates, near = candidates[keep], near[keep]
    for i in np.argsort(near, kind="stable"):
        place = (float(candidates[i, 0]), float(candidates[i, 1]))
        if grid.in_sight(stood, place):
            return place
    return None


def _distance_to_path(points: np.ndarray, path: np.ndarray) -> np.ndarray:
    """Each point's distance to the polyline ``path`` (one point: to that point)."""
    if len(path) == 1:
        single: np.ndarray = np.hypot(points[:, 0] - path[0, 0], points[:, 1] - path[0, 1])
        return single
    a, b = path[:-1], path[1:]
    ab = b - a
    length2 = np.maximum((ab**2).sum(axis=1), 1e-12)
    rel = points[:, None, :] - a[None, :, :]
    t = np.clip((rel * ab[None]).sum(axis=2) / length2[None], 0.0, 1.0)
    closest = a[None] + t[..., None] * ab[None]
    offset = points[:, None, :] - closest
    distances: np.ndarray = np.hypot(offset[..., 0], offset[..., 1]).min(axis=1)
    return distances


def _along(path: np.ndarray, place: Point) -> float:
    """Metres along ``path`` from its start to its point nearest ``place``."""
    if len(path) == 1:
        return 0.0
    a, b = path[:-1], path[1:]
    ab = b - a
    lengths = np.hypot(ab[:, 0], ab[:, 1])
    t = np.clip(((np.asarray(place) - a) * ab).sum(axis=1) / np.maximum(lengths**2, 1e-12), 0.0, 1.0)
    closest = a + t[:, None] * ab
    i = int(np.argmin(np.hypot(closest[:, 0] - place[0], closest[:, 1] - place[1])))
    return float(lengths[:i].sum() + t[i] * lengths[i])


__all__ = ["Wait", "head_on_wait"]
