"""Where robots still meet after giving way, and which leg to plan again so they do not.

Giving way (:mod:`exsce_dsl.sim.give_way`) only changes when robots drive, never where: two
robots whose paths cross where neither can wait, or one that stands on the other's path, still
meet.  A fleet manager repairs such a plan: the robot that drives into the other is sent round the
place where the other was.  :func:`conflict_repairs` finds the first moment two robots are
closer than the clearance and proposes the legs to plan again, best first, then those of the
next time, for when the first cannot be repaired.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from exsce_dsl.maps.planning import Point
from exsce_dsl.sim.motion import DT, SampledMotion

CLEARANCE = 0.7
"""Metres between two robots' centres below which they touch (two 0.3 m robots, 0.1 m apart)."""
MAX_REPAIRS = 12
"""Legs planned again per run at most: the run is played once more for each."""
MOVING = 0.05
"""Metres a robot moves in the second round a moment for it to count as driving then."""

STOOD = 3.0
"""Seconds before the moment robots meet within which a robot that stood is sent round where
it stood (when both were waiting for each other, the one that then moved on is met a little
further on, where nobody can go round it)."""

LegId = tuple[str, int]
"""A robot's drive to one waypoint: the robot and the leg's number (from 1, over the run)."""


class Timed(Protocol):
    """What a repair needs of an executor's action: whose leg it is and when it was driven."""

    @property
    def robot(self) -> str: ...

    @property
    def start(self) -> float: ...

    @property
    def end(self) -> float: ...


@dataclass(frozen=True)
class Repair:
    """Plan ``leg`` again round ``place``."""

    leg: LegId
    place: Point


def conflict_repairs(
    trajectories: Mapping[str, SampledMotion],
    actions: Sequence[Timed],
    order: Sequence[str],
    clearance: float = CLEARANCE,
) -> list[Repair]:
    """The repairs of each time two robots come closer than ``clearance``, earliest first: for
    each, the leg of a robot driving then, round the other robot's place, a robot driving into
    one that stands first, then the robot with less right of way (later in ``order``).  Empty
    when robots keep clear all the run."""
    robots = [r for r in order if r in trajectories]
    if len(robots) < 2:
        return []
    xs, ys = _positions(trajectories, robots)
    index = {r: i for i, r in enumerate(robots)}
    repairs = []
    for k, a, b in meetings(trajectories, order, clearance):
        repairs += _repairs_of(xs, ys, k, index[a], index[b], robots, actions)
    return repairs


def meetings(
    trajectories: Mapping[str, SampledMotion], order: Sequence[str], clearance: float = CLEARANCE
) -> list[tuple[int, str, str]]:
    """Each time two robots come closer than ``clearance``: its first sample and the two robots
    (in ``order``), earliest first."""
    robots = [r for r in order if r in trajectories]
    if len(robots) < 2:
        return []
    xs, ys = _positions(trajectories, robots)
    found: list[tuple[int, int, int]] = []
    for i in range(len(robots)):
        for j in range(i + 1, len(robots)):
            close = np.hypot(xs[j] - xs[i], ys[j] - ys[i]) < clearance
            starts = np.flatnonzero(close & ~np.concatenate(([False], close[:-1])))
            found += [(int(k), i, j) for k in starts]
    return [(k, robots[i], robots[j]) for k, i, j in sorted(found)]


def _positions(
    trajectories: Mapping[str, SampledMotion], robots: Sequence[str]
) -> tuple[np.ndarray, np.ndarray]:
    """The robots' x and y, one row each, over the samples they all have."""
    n = min(len(trajectories[r]) for r in robots)
    xs = np.stack([trajectories[r].x[:n] for r in robots])
    return xs, np.stack([trajectories[r].y[:n] for r in robots])


def _repairs_of(
    xs: np.ndarray, ys: np.ndarray, k: int, i: int, j: int, robots: Sequence[str], actions: Sequence[Timed]
) -> list[Repair]:
    """The repairs of robots ``i`` and ``j`` meeting at sample ``k``, best first."""
    n = xs.shape[1]
    window = slice(max(0, k - int(0.5 / DT)), min(n, k + int(0.5 / DT) + 1))

    def driving(a: int) -> bool:
        x, y = xs[a, window], ys[a, window]
        return bool(np.hypot(x - x[0], y - y[0]).max() > MOVING)

    def place(a: int) -> Point:
        """Where robot ``a`` stood last, a few seconds before the moment at most (the place the
        other would have had to go round), else where it was then."""
        since = max(0, k - int(STOOD / DT))
        step = np.hypot(np.diff(xs[a, since : k + 1]), np.diff(ys[a, since : k + 1]))
        stood = np.flatnonzero(step < 1e-9)
        at = since + int(stood[-1]) if len(stood) else k
        return float(xs[a, at]), float(ys[a, at])

    repairs = []
    for mover, other in sorted(((j, i), (i, j)), key=lambda pair: (not driving(pair[0]), pair[0] < pair[1])):
        leg = leg_at(actions, robots[mover], k * DT)
        if leg is not None:
            repairs.append(Repair(leg, place(other)))
    return repairs


def leg_at(actions: Sequence[Timed], robot: str, t: float) -> LegId | None:
    """The leg ``robot`` drives at ``t`` (or last drove, when it waits between legs)."""
    number, found = 0, None
    for action in actions:
        if action.robot != robot:
            continue
        number += 1
        if action.start <= t:
            found = (robot, number)
    return found
