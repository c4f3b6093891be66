"""A recorded action: one planned waypoint of a robot's mission (the path segment that ends at
it), as a run's bag shows it executed.

Every source of segments (the method's dispatcher, a navigation stack's goals, arrival at the
planned waypoints: :data:`~exsce_dsl.runs.segments.sources.SEGMENT_SOURCES`) gives this one type;
the metrics cut their windows from it, and the run's PROV records it as an action.
"""

from __future__ import annotations

from dataclasses import dataclass

from exsce_dsl.model import Pose


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
