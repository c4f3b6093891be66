"""A navigator for tests: robots drive the occupancy grid's shortest paths on a simulated clock.

Each goal is planned from where its robot stands to the goal's position (the kinematic
executor's planner, :mod:`exsce_dsl.maps.planning`) and driven at the robot's constant speed
limit; it succeeds when the robot arrives.  Tests can make chosen goals fail, named by robot and
pose id: one in ``aborts`` is aborted ``ABORT_AFTER`` seconds after it was sent, as many times as
given; one in ``rejects`` is rejected at once; one in ``silent`` is accepted and never answered
(in all three the robot does not move).  Cancelling a goal leaves its robot where it was on the
path at that time.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from exsce_dsl.errors import ExsceError
from exsce_dsl.execute.mission import DEFAULT_SPEED
from exsce_dsl.execute.navigator import Finished, SimulatedClock
from exsce_dsl.execute.outcomes import GoalOutcome
from exsce_dsl.maps.planning import PlanningGrid, Point
from exsce_dsl.model import Pose, Scenario

ABORT_AFTER = 2.0
"""Seconds after which a goal the test wants aborted is aborted."""

GoalName = tuple[str, str]
"""A goal as tests name it: (robot, pose id)."""


@dataclass(frozen=True)
class _Drive:
    robot: str
    name: GoalName
    path: tuple[Point, ...]
    start: float
    end: float | None
    """None: never answered."""
    outcome: GoalOutcome

    def position(self, t: float) -> Point:
        """Where the robot is at ``t`` on this drive (at the start if it does not move)."""
        if self.outcome is not GoalOutcome.SUCCEEDED or self.end is None or self.end <= self.start:
            return self.path[0] if self.outcome is not GoalOutcome.SUCCEEDED else self.path[-1]
        along = min(1.0, max(0.0, (t - self.start) / (self.end - self.start))) * _length(self.path)
        for a, b in zip(self.path, self.path[1:], strict=False):
            step = math.dist(a, b)
            if along <= step and step > 0:
                f = along / step
                return a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])
            along -= step
        return self.path[-1]


class KinematicNavigator:
    """Robots that drive goals on ``grid`` at ``speeds[robot]`` (else ``DEFAULT_SPEED``) m/s."""

    def __init__(
        self,
        scenario: Scenario,
        grid: PlanningGrid,
        clock: SimulatedClock,
        speeds: Mapping[str, float] | None = None,
        aborts: Mapping[GoalName, int] | None = None,
        silent: Iterable[GoalName] = (),
        rejects: Iterable[GoalName] = (),
    ) -> None:
        self.grid, self.clock = grid, clock
        self.speeds = dict(speeds or {})
        self.aborts = dict(aborts or {})
        self.silent = set(silent)
        self.rejects = set(rejects)
        self.where: dict[str, Point] = {
            r.id: (r.start_pose.position.x, r.start_pose.position.y)
            for r in scenario.robots
            if r.start_pose is not None
        }
        self.active: dict[int, _Drive] = {}
        self.sent: list[tuple[int, str, Pose, float]] = []
        """Every goal received: its number, robot, pose and when it was sent."""

    def send(self, goal: int, robot: str, pose: Pose) -> None:
        if robot not in self.where:
            raise ExsceError(f"robot '{robot}' has no start pose: the kinematic navigator cannot place it")
        if any(d.robot == robot for d in self.active.values()):
            raise ExsceError(f"robot '{robot}' got goal {goal} while it still had one")
        now = self.clock.now()
        self.sent.append((goal, robot, pose, now))
        name, here = (robot, pose.id), self.where[robot]
        if name in self.silent:
            self.active[goal] = _Drive(robot, name, (here,), now, None, GoalOutcome.ABORTED)
        elif name in self.rejects:
            self.active[goal] = _Drive(robot, name, (here,), now, now, GoalOutcome.REJECTED)
        elif self.aborts.get(name, 0) > 0:
            self.aborts[name] -= 1
            self.active[goal] = _Drive(robot, name, (here,), now, now + ABORT_AFTER, GoalOutcome.ABORTED)
        else:
            path = tuple(self.grid.plan(here, (pose.position.x, pose.position.y)))
            speed = self.speeds.get(robot, DEFAULT_SPEED)
            self.active[goal] = _Drive(robot, name, path, now, now + _length(path) / speed, GoalOutcome.SUCCEEDED)

    def cancel(self, goal: int) -> None:
        drive = self.active.pop(goal, None)
        if drive is not None:
            self.where[drive.robot] = drive.position(self.clock.now())

    def next_finished(self, deadline: float) -> Finished | None:
        ends = [(d.end, n) for n, d in self.active.items() if d.end is not None and d.end <= deadline]
        if not ends:
            if math.isinf(deadline):
                raise ExsceError("waiting for ever: no goal will end and no deadline was given")
            self.clock.advance_to(deadline)
            return None
        end, number = min(ends)
        drive = self.active.pop(number)
        self.clock.advance_to(end)
        self.where[drive.robot] = drive.position(end)
        return Finished(number, drive.outcome, end)


def _length(path: tuple[Point, ...]) -> float:
    return sum(math.dist(a, b) for a, b in zip(path, path[1:], strict=False))
