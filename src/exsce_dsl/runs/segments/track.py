"""What the segmentation sources share: the plan, the pose track, the tolerance and start poses.

A path segment is one planned waypoint of a robot's mission, from the robot's previous pose to the
waypoint's pose.  The dispatcher's statuses (`segments`) say which waypoint each action was for;
real stacks do not run the dispatcher, so `goal_segments` matches their navigation goals to the
planned waypoints by pose and `arrival_segments` watches the robot's pose arrive at them.  Both
find, for each planned waypoint, an `WaypointResult` (start, end, status), and `build_segmentation` turns the
outcomes into `RecordedAction`s with the same start-pose rule:

- a segment the robot attempted (one with a start time) starts where it is expected to be: at
  the goal pose of the previous attempted segment if that one SUCCEEDED (SKIPPED and NOT_STARTED
  ones are passed over: the robot went on from the last waypoint it reached), or at its declared
  start pose if it attempted none before;
- but the track has the last word: if it puts the robot farther than the position tolerance from
  that pose when the segment starts (it started elsewhere, or went somewhere off the plan in
  between), the segment starts at the tracked pose, with a warning; and after a segment that did
  not succeed, it starts at the tracked pose (the robot stopped somewhere unplanned), or, without
  a track, at the last SUCCEEDED goal pose, with a warning;
- a segment never attempted (no start) starts at the last SUCCEEDED goal pose, or the declared
  start pose, as the dispatcher's segments do.

A tracked pose is a `Pose` with the id ``<robot>@<t>`` (t in seconds since the epoch, three
decimals), no area, and the track's x, y and yaw.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from exsce_dsl.errors import SegmentError
from exsce_dsl.model import Orientation, Pose, Position, Scenario
from exsce_dsl.model.conventions import Tolerance
from exsce_dsl.runs.segments.dispatcher import planned_goals
from exsce_dsl.runs.segments.recorded import RecordedAction

Floats = npt.NDArray[np.float64]
Flags = npt.NDArray[np.bool_]

SUCCEEDED = "SUCCEEDED"


def near(
    tolerance: Tolerance,
    pose: Pose,
    x: Floats,
    y: Floats,
    yaw: Floats,
    z: Floats | None = None,
    three_d: bool = False,
) -> Flags:
    """Which of the poses (x, y, yaw) are within ``tolerance`` of ``pose``; in 3-D (``z`` too)
    when the track has heights and the pose gives one (not 0) or the robot moves in 3-D."""
    if not tolerance.position > 0 or (tolerance.heading is not None and not tolerance.heading > 0):
        raise SegmentError(
            f"tolerances must be positive, not {tolerance.position} m, {tolerance.heading} rad"
        )
    distance = np.hypot(x - pose.position.x, y - pose.position.y)
    if z is not None and len(z) == len(x) and (three_d or pose.position.z != 0):
        distance = np.hypot(distance, z - pose.position.z)
    close: Flags = distance <= tolerance.position
    if tolerance.heading is not None:
        close &= angle_between(yaw, pose.orientation.yaw) <= tolerance.heading
    return close


def matches(tolerance: Tolerance, pose: Pose, x: float, y: float, yaw: float) -> bool:
    return bool(near(tolerance, pose, np.array([x]), np.array([y]), np.array([yaw]))[0])


DEFAULT_TOLERANCE = Tolerance()
"""See :class:`~exsce_dsl.model.conventions.Tolerance` for why these defaults."""


def angle_between(a: Floats, b: float) -> Floats:
    """The absolute difference of two headings, in [0, π]."""
    difference: Floats = np.abs((a - b + np.pi) % (2 * np.pi) - np.pi)
    return difference


@dataclass(frozen=True, eq=False)
class Track:
    """A robot's pose over time in the map frame: ``times`` (seconds since the epoch, increasing)."""

    times: Floats
    x: Floats
    y: Floats
    yaw: Floats
    z: Floats | None = None
    """Heights, where the pose source has them (arrival compares them: see :func:`near`)."""
    three_d: bool = False
    """Whether the robot moves in 3-D (a drone): arrival then always compares heights."""

    def __post_init__(self) -> None:
        columns = [np.asarray(c, dtype=np.float64) for c in (self.times, self.x, self.y, self.yaw)]
        for name, column in zip(("times", "x", "y", "yaw"), columns, strict=True):
            object.__setattr__(self, name, column)
        if any(c.ndim != 1 or len(c) != len(columns[0]) for c in columns):
            raise SegmentError(
                "a track's times, x, y and yaw must be 1-D and of one length, not of shapes "
                + ", ".join(str(c.shape) for c in columns)
            )
        if np.any(np.diff(columns[0]) < 0):
            raise SegmentError("a track's times must not decrease: sort the samples by time")

    @classmethod
    def empty(cls) -> Track:
        nothing = np.zeros(0)
        return cls(nothing, nothing, nothing, nothing)

    def __len__(self) -> int:
        return len(self.times)

    def index_at(self, t: float) -> int:
        """The last sample at or before ``t`` (the robot's latest known pose), or the first."""
        return max(int(np.searchsorted(self.times, t, side="right")) - 1, 0)

    def xy_yaw_at(self, t: float) -> tuple[float, float, float]:
        i = self.index_at(t)
        return float(self.x[i]), float(self.y[i]), float(self.yaw[i])

    def pose_at(self, robot: str, t: float) -> Pose:
        x, y, yaw = self.xy_yaw_at(t)
        return Pose(f"{robot}@{t:.3f}", Position(x, y), Orientation(yaw=yaw))


@dataclass(frozen=True)
class PlannedWaypoint:
    """One waypoint of a robot's plan, numbered as `RecordedAction` numbers it."""

    allocation: int  # the robot's n-th task, from 1
    task: str
    subtask: int  # from 1
    waypoint: int  # from 1, within the subtask
    pose: Pose

    @property
    def label(self) -> str:
        return f"{self.pose.id} ({self.task} subtask {self.subtask} waypoint {self.waypoint})"


def planned_waypoints(scenario: Scenario, robot: str) -> list[PlannedWaypoint]:
    """The waypoints the mission gives ``robot``, in the order it is to visit them."""
    if scenario.robot(robot) is None:
        raise SegmentError(f"robot '{robot}' is not in scenario '{scenario.id}'")
    return [
        PlannedWaypoint(allocation, task, subtask, w, pose)
        for allocation, task, subtask, poses in planned_goals(scenario, robot)
        for w, pose in enumerate(poses, start=1)
    ]


@dataclass(frozen=True)
class WaypointResult:
    """What a source found for one planned waypoint."""

    start: float | None
    end: float | None
    status: str


@dataclass(frozen=True)
class Segmentation:
    """A robot's path segments from one source, and what the source could not make sense of."""

    segments: tuple[RecordedAction, ...]
    warnings: tuple[str, ...]


def at(x: float, y: float) -> str:
    return f"({x:.2f}, {y:.2f})"


def build_segmentation(
    scenario: Scenario,
    robot: str,
    plan: list[PlannedWaypoint],
    outcomes: list[WaypointResult],
    track: Track,
    tolerance: Tolerance,
    warnings: list[str],
) -> Segmentation:
    """One segment per planned waypoint, with start poses as the module docstring says."""
    declared = scenario.robot(robot)
    assert declared is not None  # planned_waypoints checked it
    reached: Pose | None = None  # the last SUCCEEDED goal pose
    attempted: RecordedAction | None = None  # the last segment with a start time
    untracked = False
    out: list[RecordedAction] = []
    for planned, outcome in zip(plan, outcomes, strict=True):
        home = reached or declared.start_pose
        start_pose: Pose | None = home
        if outcome.start is not None:
            if attempted is None:
                expected, what = declared.start_pose, "its start pose"
            elif attempted.status == SUCCEEDED:
                expected, what = attempted.goal, "the waypoint it last reached"
            else:
                expected, what = None, ""
            if len(track):
                start_pose = _where(robot, planned, expected, what, track, outcome.start, tolerance, warnings)
            elif expected is not None:
                start_pose = expected
            else:
                untracked = True
        if start_pose is None:
            raise SegmentError(f"robot '{robot}' has no start pose and no pose track to take one from")
        segment = RecordedAction(
            robot,
            planned.allocation,
            planned.task,
            planned.subtask,
            planned.waypoint,
            start_pose,
            planned.pose,
            outcome.start,
            outcome.end,
            outcome.status,
        )
        out.append(segment)
        if outcome.start is not None:
            attempted = segment
        if outcome.status == SUCCEEDED:
            reached = planned.pose
    if untracked:
        warnings.append(
            f"robot {robot} has no pose track: segments after a failed one start at the last "
            "waypoint it reached, not where it stopped"
        )
    return Segmentation(tuple(out), tuple(warnings))


def _where(
    robot: str,
    planned: PlannedWaypoint,
    expected: Pose | None,
    what: str,
    track: Track,
    start: float,
    tolerance: Tolerance,
    warnings: list[str],
) -> Pose:
    """The pose the robot set off from: ``expected`` if the track agrees, else the tracked one."""
    tracked = track.pose_at(robot, start)
    if expected is None:
        return tracked
    x, y = tracked.position.x, tracked.position.y
    distance = math.hypot(x - expected.position.x, y - expected.position.y)
    if distance <= tolerance.position:
        return expected
    warnings.append(
        f"robot {robot} was at {at(x, y)} at {start:.3f}, {distance:.2f} m from {what} {expected.id}: "
        f"its segment to {planned.pose.id} starts there"
    )
    return tracked
