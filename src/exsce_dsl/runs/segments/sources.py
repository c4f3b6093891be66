"""Where a robot's path segments come from: a registry of sources, tried in order.

:data:`SEGMENT_SOURCES` lists them, each knowing what it needs and how it finds segments: the
method's waypoint dispatcher (its goal statuses), the navigation stack's goals (Nav2's actions,
move_base's) matched to the planned waypoints by pose, and arrival of the robot's pose at the
planned waypoints.  The first that gives a segment the robot started wins; when none does, the
robot's metrics are of its whole run only, and a problem says why.  Only recorded goals may
window the whole run (their span); arrivals cut segments, and the run stays its recording.
Adding a source is one entry here (and its module beside this one).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

from exsce_dsl.model import Scenario
from exsce_dsl.model.conventions import Navigation
from exsce_dsl.model.robots import Robot
from exsce_dsl.runs.bags.data import BagData
from exsce_dsl.runs.segments.arrival import arrival_segments
from exsce_dsl.runs.segments.dispatcher import segments as dispatcher_segments
from exsce_dsl.runs.segments.dispatcher import succeeded_waypoints
from exsce_dsl.runs.segments.goals import goal_segments
from exsce_dsl.runs.segments.recorded import RecordedAction
from exsce_dsl.runs.segments.track import SUCCEEDED, Track
from exsce_dsl.runs.signals.dispatcher_statuses import dispatcher_statuses
from exsce_dsl.runs.signals.navigation_goals import read_goals

DISPATCHER_SOURCE = "the waypoint dispatcher"


@dataclass(frozen=True)
class RobotSegments:
    """One robot's segments, what segmented them, and what it could not make sense of."""

    segments: list[RecordedAction]
    source: str
    succeeded: int | None
    topics: tuple[str, ...] = ()
    """The bag's topics the segments came from."""
    problems: tuple[str, ...] = ()
    goals: bool = True
    """Whether the segments are recorded goals, whose span may stand for the robot's whole run;
    arrival's are not: an arrival cuts segments, never the run (the run is then its recording)."""
    outcomes: tuple[str, ...] = ()
    """The bag's topics ``succeeded`` came from, where not ``topics`` (the dispatcher's result)."""


@dataclass
class SegmentInput:
    """What a source may look at: the plan, the robot, its bag's data and pose track; where to
    say problems, and what a source could tell without segments (``unsegmented``: the dispatcher's
    successes, when it recorded goals none of which started)."""

    scenario: Scenario
    robot: Robot
    data: BagData
    track: Track
    problems: list[str] = field(default_factory=list)
    unsegmented: RobotSegments | None = None


@dataclass(frozen=True)
class SegmentSource:
    """One source of segments: its name and how it finds them (None: it gives none here)."""

    name: str
    find: Callable[[SegmentInput], RobotSegments | None]


def _dispatcher(given: SegmentInput) -> RobotSegments | None:
    """The method's waypoint dispatcher's goals, matched in order to the robot's subtasks; the
    waypoints its results say SUCCEEDED (None: the bag has no result topic)."""
    statuses = dispatcher_statuses(given.robot.namespace, given.data)
    if statuses.feedback is None:
        return None
    found = dispatcher_segments(given.scenario, given.robot.id, statuses.feedback)
    feedback, result = statuses.topics
    succeeded = succeeded_waypoints(statuses.result)
    given.unsegmented = RobotSegments([], DISPATCHER_SOURCE, succeeded, (feedback,), outcomes=(result,))
    return replace(given.unsegmented, segments=found) if _started(found) else None


def _goals(given: SegmentInput) -> RobotSegments | None:
    robot, signals = given.robot, given.robot.signals
    if signals.navigation not in (Navigation.NAV2, Navigation.MOVE_BASE):
        return None
    goals, used = read_goals(signals, robot.namespace, given.data)
    if not goals:
        given.problems.append(f"robot '{robot.id}': no {signals.navigation.value} goals in this bag")
        return None
    found = goal_segments(given.scenario, robot.id, goals, given.track, signals.tolerance)
    given.problems.extend(f"robot '{robot.id}': {w}" for w in found.warnings)
    if not _started(found.segments):
        return None
    name = f"{signals.navigation.value} goals"
    return RobotSegments(list(found.segments), name, _succeeded(found.segments), tuple(used))


def _arrival(given: SegmentInput) -> RobotSegments | None:
    if not len(given.track):
        return None
    robot = given.robot
    found = arrival_segments(given.scenario, robot.id, given.track, robot.signals.tolerance)
    given.problems.extend(f"robot '{robot.id}': {w}" for w in found.warnings)
    if not _started(found.segments):
        return None
    name = "arrival at the planned waypoints"
    return RobotSegments(list(found.segments), name, _succeeded(found.segments), goals=False)


SEGMENT_SOURCES: tuple[SegmentSource, ...] = (
    SegmentSource(DISPATCHER_SOURCE, _dispatcher),
    SegmentSource("navigation goals", _goals),
    SegmentSource("arrival at the planned waypoints", _arrival),
)
"""The sources of a robot's segments, in the order they are tried."""


def segment_robot(scenario: Scenario, robot: Robot, data: BagData, track: Track) -> RobotSegments:
    """The robot's segments from the first of :data:`SEGMENT_SOURCES` that gives any."""
    given = SegmentInput(scenario, robot, data, track)
    for source in SEGMENT_SOURCES:
        found = source.find(given)
        if found is not None:
            problems = tuple(given.problems)
            return replace(found, problems=problems)
    given.problems.append(
        f"robot '{robot.id}': no path segments (no navigation goals, and no pose that reaches its planned "
        "waypoints): its metrics are of the whole run only"
    )
    if given.unsegmented is not None:
        return replace(given.unsegmented, problems=tuple(given.problems))
    return RobotSegments([], "", None, (), tuple(given.problems))


def _started(segments: list[RecordedAction] | tuple[RecordedAction, ...]) -> bool:
    return any(s.start is not None for s in segments)


def _succeeded(segments: tuple[RecordedAction, ...]) -> int:
    return sum(s.status == SUCCEEDED for s in segments)
