"""Path segments from a robot's navigation goals, matched to its planned waypoints by pose.

Real stacks (Nav2, move_base, ...) do not say which planned waypoint a goal was for, so the goal's
target pose says it.  The goals come already read from the bag, as `RecordedGoal`s; the rules:

1. **Legs.**  A goal to one pose is one leg: it starts when the goal became active (``started``,
   else ``accepted``), ends at ``ended`` with the goal's ``status`` (``ACTIVE``: never ended, no
   end).  A follow_waypoints goal (``progress`` given: Nav2's feedback ``current_waypoint``, as
   (index, first time reported) pairs) is one leg per reported index, from that time to the time a
   higher index was reported; the last reported index ends with the goal.  An index left behind
   SUCCEEDED, unless the result lists it in ``missed`` (then ABORTED); the last one has the goal's
   status (ABORTED if missed by a SUCCEEDED goal).  Indices the feedback jumped over are legs of
   no duration at the moment of the jump, with a warning.  Reported indices that do not increase
   are dropped, with a warning.
2. **Targets.**  A leg's target is the goal's ``target`` (``targets[index]`` for a
   follow_waypoints leg) when the bag says it.  Otherwise, for a SUCCEEDED leg only, it is where
   the track puts the robot when it ended: the robot was there when its stack declared success
   (for a follow_waypoints leg, when the feedback moved on to the next index; after a jump, only
   the last index jumped over gets it).  A leg with no target cannot be placed: warning, ignored.
3. **Order.**  Goals are taken in the order they were first seen (``accepted``, else
   ``started``, else ``ended``; a goal with no time at all is ignored with a warning), each
   goal's legs in index order.
4. **Matching.**  Each leg goes to the next planned waypoint, in plan order from the one after
   the last matched, whose pose is within the `Tolerance` of its target.  Planned waypoints
   passed over are SKIPPED (no start, no end), with a warning naming them.  A leg that matches no
   remaining planned waypoint is not a segment: a warning says it is not in the plan (it is never
   attached to the nearest waypoint).
5. **Retries.**  A leg whose target is the last matched waypoint while that waypoint's segment
   did not SUCCEEDED (ABORTED, CANCELED, PREEMPTED, still ACTIVE, ...) is a retry: it replaces
   that segment's end and status, and the segment keeps the first attempt's start, so its
   duration and distance count every attempt at the waypoint (a warning says so).  A goal back to
   a waypoint that already SUCCEEDED is no retry: it is matched forward like any other.
6. **The rest.**  Planned waypoints after the last matched one are NOT_STARTED.  If no leg
   matched at all there are no segments, and a warning says why, so that the caller can fall back
   to another source (arrival at the waypoints).
7. **Start poses** as `segmentation` says: the previous attempted segment's goal if it
   SUCCEEDED and the track has the robot there, else the robot's tracked pose at the segment's
   start.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from exsce_dsl.model import Scenario
from exsce_dsl.model.conventions import Tolerance
from exsce_dsl.runs.segments.track import (
    DEFAULT_TOLERANCE,
    SUCCEEDED,
    PlannedWaypoint,
    Segmentation,
    Track,
    WaypointResult,
    at,
    build_segmentation,
    matches,
    planned_waypoints,
)
from exsce_dsl.runs.signals.navigation_goals import RecordedGoal, XYYaw


@dataclass(frozen=True)
class GoalLeg:
    """One leg of a robot's goals: to one pose, from ``start`` to ``end`` with a final ``status``."""

    label: str
    start: float | None
    end: float | None
    status: str
    target: XYYaw | None


def goal_segments(
    scenario: Scenario,
    robot: str,
    goals: Sequence[RecordedGoal],
    track: Track,
    tolerance: Tolerance = DEFAULT_TOLERANCE,
) -> Segmentation:
    """The path segments of ``robot`` from its navigation ``goals``, by the module's rules."""
    plan = planned_waypoints(scenario, robot)
    warnings: list[str] = []
    if not plan:
        return Segmentation((), (f"robot {robot} has no planned waypoints in scenario {scenario.id}",))
    if not goals:
        return Segmentation((), (f"robot {robot} has no navigation goals: no segments from goals",))
    legs = goal_legs(goals, track, warnings)
    outcomes: list[WaypointResult | None] = [None] * len(plan)
    following, last = 0, -1  # the next planned waypoint to look at; the last one matched
    for leg in legs:
        if leg.target is None:
            warnings.append(f"{leg.label} ({leg.status}) has no target: cannot tell its waypoint; ignored")
            continue
        previous = outcomes[last] if last >= 0 else None
        if previous is not None and previous.status != SUCCEEDED and _matches(plan[last], leg, tolerance):
            start = previous.start if previous.start is not None else leg.start
            outcomes[last] = WaypointResult(start, leg.end, leg.status)
            warnings.append(
                f"{leg.label} retries {plan[last].label} after {previous.status}: "
                "the segment keeps the first attempt's start"
            )
            continue
        match = next((j for j in range(following, len(plan)) if _matches(plan[j], leg, tolerance)), None)
        if match is None:
            x, y, _ = leg.target
            warnings.append(f"{leg.label} to {at(x, y)} is not in the plan of robot {robot}")
            continue
        if match > following:
            warnings.append(
                f"robot {robot} skipped {', '.join(p.label for p in plan[following:match])}: "
                f"{leg.label} went on to {plan[match].label}"
            )
            for j in range(following, match):
                outcomes[j] = WaypointResult(None, None, "SKIPPED")
        outcomes[match] = WaypointResult(leg.start, leg.end, leg.status)
        following, last = match + 1, match
    if last < 0:
        warnings.append(
            f"robot {robot}: none of its {len(goals)} navigation goals reached a planned waypoint "
            "by pose: no segments from goals"
        )
        return Segmentation((), tuple(warnings))
    filled = [o if o is not None else WaypointResult(None, None, "NOT_STARTED") for o in outcomes]
    return build_segmentation(scenario, robot, plan, filled, track, tolerance, warnings)


def _matches(planned: PlannedWaypoint, leg: GoalLeg, tolerance: Tolerance) -> bool:
    assert leg.target is not None
    return matches(tolerance, planned.pose, *leg.target)


def goal_legs(goals: Sequence[RecordedGoal], track: Track, warnings: list[str]) -> list[GoalLeg]:
    """The legs of ``goals`` in the order they were first seen, with their targets (rules 1-3)."""
    timed = []
    for goal in goals:
        if goal.first_seen is None:
            warnings.append(f"goal {goal.key} has no time at all: ignored")
        else:
            timed.append(goal)
    timed.sort(key=lambda g: g.first_seen or 0.0)  # stable: goals seen at once keep their order
    legs: list[GoalLeg] = []
    for goal in timed:
        if goal.follows_waypoints:
            legs.extend(_waypoint_legs(goal, track, warnings))
            continue
        start = goal.started if goal.started is not None else goal.accepted
        end = None if goal.status == "ACTIVE" else goal.ended
        target = goal.target or _reached_at(track, goal.status, end)
        legs.append(GoalLeg(f"goal {goal.key}", start, end, goal.status, target))
    return legs


def _waypoint_legs(goal: RecordedGoal, track: Track, warnings: list[str]) -> list[GoalLeg]:
    """The legs of a follow_waypoints goal: one per waypoint index its feedback reported."""
    progress: list[tuple[int, float]] = []
    for index, t in goal.progress:
        if progress and index <= progress[-1][0]:
            if index < progress[-1][0]:
                warnings.append(
                    f"goal {goal.key} went back from waypoint {progress[-1][0]} to {index}: ignored"
                )
            continue
        progress.append((index, t))
    if not progress:
        warnings.append(f"goal {goal.key} ({goal.status}) never reported a current waypoint: ignored")
        return []
    legs: list[GoalLeg] = []
    for k, (index, t) in enumerate(progress):
        final = k == len(progress) - 1
        if final:
            end = None if goal.status == "ACTIVE" else goal.ended
            reached = [index]
        else:
            end = progress[k + 1][1]
            reached = list(range(index, progress[k + 1][0]))
            if len(reached) > 1:
                warnings.append(
                    f"goal {goal.key}: the feedback jumped from waypoint {index} to {progress[k + 1][0]}; "
                    f"waypoints {', '.join(map(str, reached[1:]))} get segments of no duration"
                )
        for j in reached:
            if goal.missed and j in goal.missed:
                status = "ABORTED"
            elif final and goal.status != SUCCEEDED:
                status = goal.status
            else:
                status = SUCCEEDED
            given = goal.targets[j] if j < len(goal.targets) else None
            # the track knows only where the robot was when the last of these was done
            target = given or (_reached_at(track, status, end) if j == reached[-1] else None)
            legs.append(GoalLeg(f"goal {goal.key}[{j}]", t if j == index else end, end, status, target))
    return legs


def _reached_at(track: Track, status: str, end: float | None) -> XYYaw | None:
    """Where the robot was when its stack declared a goal reached, if it did and the track says."""
    if status != SUCCEEDED or end is None or not len(track):
        return None
    return track.xy_yaw_at(end)
