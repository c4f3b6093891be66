"""A path segment: one planned waypoint of a robot's mission, as a run executed it.

Every source of segments (the method's dispatcher, a navigation stack's goals, arrival at the
planned waypoints: :data:`~exsce_dsl.runs.segments.sources.SEGMENT_SOURCES`) gives this one type;
the metrics cut their windows from it, and the run's PROV records it as an action.
"""

from __future__ import annotations

from dataclasses import dataclass

from exsce_dsl.model import Pose


@dataclass(frozen=True)
class Segment:
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
