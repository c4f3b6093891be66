"""A recorded action: one planned waypoint of a robot's mission (the path segment that ends at
it), as a run's bag shows it executed.

Every source of segments (the method's dispatcher, a navigation stack's goals, arrival at the
planned waypoints: :data:`~exsce_dsl.runs.segments.sources.SEGMENT_SOURCES`) gives this one type;
the metrics cut their windows from it, and the run's PROV records it as an action: the run keeps
a robot's recorded actions grouped per task, on the recorder's wall clock
(:func:`task_executions`).
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from exsce_dsl.model import Pose
from exsce_dsl.model.runs import Action, ActionId, ActionStatus, TaskExecution


@dataclass(frozen=True)
class RecordedAction:
    """One waypoint goal as ingest finds it in a bag (times in seconds since the epoch, the status
    as text); analysis makes one that started and ended the run's
    :class:`~exsce_dsl.model.runs.Action`."""

    robot: str
    allocation: int  # the robot's n-th task, from 1
    task: str
    subtask: int
    waypoint: int
    start_pose: Pose
    goal: Pose
    start: float | None  # became ACTIVE (seconds since the epoch); None if never
    end: float | None  # reached a final status
    status: str  # SUCCEEDED, ABORTED, ... or NOT_STARTED


def task_executions(
    actions: list[RecordedAction], segmented_by: dict[str, str], wall: Callable[[np.ndarray], np.ndarray]
) -> tuple[TaskExecution, ...]:
    """The robots' tasks as executed, with their actions' times as the wall clock had them.  A
    segment that started and ended is an action (its metric values need one): ABORTED when its
    goal ended other than SUCCEEDED (aborted, or cancelled: PREEMPTED, CANCELED, as the
    dispatcher cancels a goal that timed out); ``segmented_by``: robot → the segment source that
    found its segments, where that is not the method's dispatcher."""

    def on_wall(t: float) -> dt.datetime:
        return dt.datetime.fromtimestamp(float(wall(np.array([t]))[0]), tz=dt.timezone.utc)

    started = [a for a in actions if a.start is not None and a.end is not None]
    started.sort(key=lambda a: (a.start or 0.0, a.robot))
    grouped: dict[tuple[str, int], list[Action]] = {}
    for a in started:
        assert a.start is not None and a.end is not None
        status = ActionStatus.SUCCEEDED if a.status == "SUCCEEDED" else ActionStatus.ABORTED
        grouped.setdefault((a.robot, a.allocation), []).append(
            Action(
                ActionId(a.robot, a.allocation, a.subtask, a.waypoint),
                a.start_pose,
                a.goal,
                status,
                on_wall(a.start),
                on_wall(a.end),
            )
        )
    return tuple(
        TaskExecution(robot, n, tuple(acts), segmented_by.get(robot)) for (robot, n), acts in grouped.items()
    )
