"""Navigation goal statuses, as the two action interfaces of ROS number them: defined once here.

ROS 1's actionlib (``actionlib_msgs/GoalStatus``: the method's waypoint dispatcher and move_base)
and ROS 2's actions (``action_msgs/GoalStatus``: Nav2) number their statuses differently.  The
monitors' runtime (``monitor_kit/monitor_runtime.py``) keeps its own copy of actionlib's: it is
copied into generated ROS nodes and imports nothing of exsce.
"""

from __future__ import annotations

import enum


class GoalStatus(enum.IntEnum):
    """``actionlib_msgs/GoalStatus`` (ROS 1)."""

    PENDING = 0
    ACTIVE = 1
    PREEMPTED = 2
    SUCCEEDED = 3
    ABORTED = 4
    REJECTED = 5
    PREEMPTING = 6
    RECALLING = 7
    RECALLED = 8
    LOST = 9


ACTIONLIB_FINAL = frozenset(
    {
        GoalStatus.PREEMPTED,
        GoalStatus.SUCCEEDED,
        GoalStatus.ABORTED,
        GoalStatus.REJECTED,
        GoalStatus.RECALLED,
        GoalStatus.LOST,
    }
)
"""The actionlib statuses a goal ends in."""


class ActionGoalStatus(enum.IntEnum):
    """``action_msgs/GoalStatus`` (ROS 2)."""

    UNKNOWN = 0
    ACCEPTED = 1
    EXECUTING = 2
    CANCELING = 3
    SUCCEEDED = 4
    CANCELED = 5
    ABORTED = 6


ACTION_FINAL = frozenset({ActionGoalStatus.SUCCEEDED, ActionGoalStatus.CANCELED, ActionGoalStatus.ABORTED})
"""The ROS 2 action statuses a goal ends in."""


def actionlib_names() -> dict[int, str]:
    """actionlib's status codes → their names (``3`` → ``SUCCEEDED``)."""
    return {s.value: s.name for s in GoalStatus}


def action_names() -> dict[int, str]:
    """ROS 2 action status codes → their names (``4`` → ``SUCCEEDED``)."""
    return {s.value: s.name for s in ActionGoalStatus}
