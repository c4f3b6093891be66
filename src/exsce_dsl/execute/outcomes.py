"""What a goal's end leads to, and what a run of the mission leaves: one record per goal.

A goal that succeeded lets its lane go on to the next goal.  One that was aborted, rejected or
timed out is handled by a :class:`Policy`; the default, ``SKIP_WAYPOINT``, is what the method's
waypoint dispatcher does: it marks the waypoint ABORTED in its status list and goes on with the
next waypoint of the subtask (DESIGN.md §1; the kinematic executor's ``skip-waypoint`` fault
plays it so).  ``RETRY_ONCE`` sends the goal once more and, if that fails too, skips the waypoint.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from exsce_dsl.model import Pose


class GoalOutcome(enum.Enum):
    SUCCEEDED = "succeeded"
    ABORTED = "aborted"
    REJECTED = "rejected"
    TIMED_OUT = "timed out"
    """No result within the goal's timeout: the dispatcher cancelled it."""
    CANCELLED = "cancelled"
    """The mission was cancelled or stopped while the goal was active."""


FAILED = frozenset({GoalOutcome.ABORTED, GoalOutcome.REJECTED, GoalOutcome.TIMED_OUT})
"""The outcomes that a :class:`Policy` handles (and CANCELLED when another client of the robot's
stack cancelled the goal, not the dispatcher)."""


class Policy(enum.Enum):
    RETRY_ONCE = "retry-once"
    """Send the same goal once more; if it fails again, skip the waypoint."""
    SKIP_WAYPOINT = "skip-waypoint"
    """Go on with the lane's next goal (the method's dispatcher)."""
    SKIP_TASK = "skip-task"
    """Drop the rest of this allocation entry's goals; go on with the lane's next entry."""
    STOP_MISSION = "stop-mission"
    """Cancel every active goal and send no more: the run ends as stopped."""


DEFAULT_POLICY = Policy.SKIP_WAYPOINT


class MissionStatus(enum.Enum):
    COMPLETED = "completed"
    """Every lane was worked through (some goals may have failed and been skipped)."""
    STOPPED = "stopped"
    """A failed goal stopped the mission (``Policy.STOP_MISSION``)."""
    CANCELLED = "cancelled"
    """The caller cancelled the mission."""


@dataclass(frozen=True)
class GoalRecord:
    """One goal as it ran: from its first attempt's start to its last attempt's end."""

    robot: str
    task: str
    task_number: int
    subtask: int
    waypoint: int
    pose: Pose
    start: float
    end: float
    outcome: GoalOutcome
    attempts: int


@dataclass(frozen=True)
class MissionRun:
    """What the dispatcher did: every goal it sent, in the order they ended, and how it ended."""

    status: MissionStatus
    records: tuple[GoalRecord, ...]
    start: float
    end: float
    not_sent: int
    """How many of the schedule's goals were never sent (skipped tasks, a stopped or cancelled run)."""
