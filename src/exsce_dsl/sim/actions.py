"""What the executor did, as the dispatcher and its ground truth record it: goals, their
statuses and the path segments driven."""

from __future__ import annotations

from dataclasses import dataclass

from exsce_dsl.model import Pose
from exsce_dsl.model.goals import GoalStatus


@dataclass(frozen=True)
class SimulatedAction:
    """One waypoint goal: the ground truth of a path segment."""

    robot: str
    task_number: int  # per robot, from 1 (the method's task_NN)
    task: str
    subtask_number: int
    waypoint_number: int
    start_pose: Pose
    goal: Pose
    start: float  # seconds from the run's start
    end: float
    status: GoalStatus
    path_length: float
    path: tuple[tuple[float, float], ...] = ()
    """The planned path, from where the robot was at ``start`` to the goal (a skipped waypoint's
    too: it is planned, then not driven)."""
    outcome: str | None = None
    """Why an ABORTED goal ended, when the simulator says: ``collided``, ``no progress``,
    ``timed out``."""


@dataclass(frozen=True)
class GoalEvent:
    """A dispatcher transition: the whole status list of one goal (subtask) at time ``t``."""

    t: float
    robot: str
    goal_key: str
    waypoint_ids: tuple[str, ...]
    statuses: tuple[GoalStatus, ...]
    final: bool  # the goal is over: a result is published too
