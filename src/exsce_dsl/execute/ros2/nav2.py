"""The goals the ROS 2 adapter sends to Nav2, as plain data built from the core's schedule.

Per robot, two of Nav2's actions (``nav2_msgs/action``), named by the robot's convention
(:data:`exsce_dsl.model.conventions.NAV2`: ``/{ns}/navigate_to_pose`` and
``/{ns}/follow_waypoints``, or the names its robot type writes after ``navigation nav2 on``):

- ``NavigateToPose``, one goal per waypoint: what the live navigator sends, so that the core's
  per-goal timeouts and policies apply to each waypoint;
- ``FollowWaypoints``, one goal per subtask holding its waypoints in order: built here with the
  mapping of its result onto the core's outcomes (:func:`waypoint_outcomes`), for a stack that
  is driven by subtasks; the live navigator does not send it.

A goal's pose is a ``geometry_msgs/PoseStamped`` in the ``map`` frame, its orientation the
quaternion of the waypoint's roll, pitch and yaw; the stamp is set when the goal is sent.

Outcomes: an action goal ends with an ``action_msgs/msg/GoalStatus`` code (:func:`goal_outcome`):
SUCCEEDED (4) is :attr:`GoalOutcome.SUCCEEDED`, ABORTED (6) :attr:`GoalOutcome.ABORTED`, CANCELED (5)
:attr:`GoalOutcome.CANCELLED` (cancelled by someone else than the dispatcher, whose own cancels are
not reported), UNKNOWN (0: the server no longer knows the goal) :attr:`GoalOutcome.ABORTED`; a goal
the server did not accept is :attr:`GoalOutcome.REJECTED`.  ACCEPTED, EXECUTING and CANCELING are not
ends.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from exsce_dsl.errors import ExsceError
from exsce_dsl.execute.mission import Goal, Schedule
from exsce_dsl.execute.outcomes import GoalOutcome
from exsce_dsl.model import Pose, Scenario
from exsce_dsl.model.conventions import NAV2, Navigation
from exsce_dsl.model.geometry import quaternion
from exsce_dsl.model.metrics import expand_topic
from exsce_dsl.model.robots import Robot

NAVIGATE_TO_POSE = "nav2_msgs/action/NavigateToPose"
FOLLOW_WAYPOINTS = "nav2_msgs/action/FollowWaypoints"
MAP_FRAME = "map"
"""The frame of every goal's pose: Nav2's ``global_frame`` default, the frame of the spec's poses."""

# action_msgs/msg/GoalStatus
STATUS_UNKNOWN = 0
STATUS_ACCEPTED = 1
STATUS_EXECUTING = 2
STATUS_CANCELING = 3
STATUS_SUCCEEDED = 4
STATUS_CANCELED = 5
STATUS_ABORTED = 6

_ENDS = {
    STATUS_SUCCEEDED: GoalOutcome.SUCCEEDED,
    STATUS_ABORTED: GoalOutcome.ABORTED,
    STATUS_CANCELED: GoalOutcome.CANCELLED,
    STATUS_UNKNOWN: GoalOutcome.ABORTED,
}
_UNDERWAY = {STATUS_ACCEPTED, STATUS_EXECUTING, STATUS_CANCELING}


@dataclass(frozen=True)
class Nav2Actions:
    """A robot's Nav2 action names, resolved in its namespace."""

    navigate_to_pose: str
    follow_waypoints: str


@dataclass(frozen=True)
class StampedPose:
    """A ``geometry_msgs/msg/PoseStamped`` but its stamp (set when the goal is sent)."""

    frame_id: str
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]
    """The quaternion x, y, z, w."""


@dataclass(frozen=True)
class NavigateToPoseGoal:
    """A ``NavigateToPose`` goal: one waypoint of the schedule."""

    action: str
    pose: StampedPose
    goal: Goal


@dataclass(frozen=True)
class FollowWaypointsGoal:
    """A ``FollowWaypoints`` goal: the waypoints of one subtask of an allocation entry, in order."""

    action: str
    poses: tuple[StampedPose, ...]
    goals: tuple[Goal, ...]


def nav2_actions(robot: Robot) -> Nav2Actions:
    """``robot``'s Nav2 actions: those its convention names (``navigation nav2 on ...``), else
    Nav2's defaults.  An action named neither ``follow_waypoints`` nor ``navigate_through_poses``
    is taken for ``NavigateToPose``.  A robot whose author names the move_base convention or the
    method's dispatcher (as its convention or its navigation) is refused: its stack takes other
    goals than Nav2's.  One that names none (its convention detected from each bag) gets Nav2's."""
    signals = robot.signals
    said = robot.declares_signals and (signals.named or "navigation" in signals.said)
    if said and signals.navigation in {Navigation.MOVE_BASE, Navigation.DISPATCHER}:
        raise ExsceError(
            f"robot '{robot.id}' takes its goals through {signals.navigation.value}: the ROS 2 adapter "
            "sends Nav2 goals (write 'convention nav2' or 'navigation nav2' in its robot type)"
        )
    named = signals.actions if signals.navigation is Navigation.NAV2 else ()
    to_pose = [a for a in named if _leaf(a) not in {"follow_waypoints", "navigate_through_poses"}]
    waypoints = [a for a in named if _leaf(a) == "follow_waypoints"]
    defaults = {_leaf(a): a for a in NAV2.actions}
    return Nav2Actions(
        expand_topic((to_pose or [defaults["navigate_to_pose"]])[0], robot.namespace),
        expand_topic((waypoints or [defaults["follow_waypoints"]])[0], robot.namespace),
    )


def stamped_pose(pose: Pose, frame: str = MAP_FRAME) -> StampedPose:
    """``pose`` as a goal's ``PoseStamped`` in ``frame``."""
    p, o = pose.position, pose.orientation
    return StampedPose(frame, (p.x, p.y, p.z), quaternion(o.roll, o.pitch, o.yaw))


def navigate_to_pose_goals(scenario: Scenario, schedule: Schedule) -> tuple[NavigateToPoseGoal, ...]:
    """One ``NavigateToPose`` goal per goal of ``schedule``, lane after lane."""
    actions = _actions(scenario, schedule.goals)
    return tuple(
        NavigateToPoseGoal(actions[g.robot].navigate_to_pose, stamped_pose(g.pose), g) for g in schedule.goals
    )


def follow_waypoints_goals(scenario: Scenario, schedule: Schedule) -> tuple[FollowWaypointsGoal, ...]:
    """One ``FollowWaypoints`` goal per subtask of each allocation entry, lane after lane."""
    actions = _actions(scenario, schedule.goals)
    batches: list[list[Goal]] = []
    for lane in schedule.lanes:
        for goal in lane:
            last = batches[-1][-1] if batches else None
            same = last is not None and (last.task_key, last.subtask) == (goal.task_key, goal.subtask)
            if same:
                batches[-1].append(goal)
            else:
                batches.append([goal])
    return tuple(
        FollowWaypointsGoal(
            actions[batch[0].robot].follow_waypoints,
            tuple(stamped_pose(g.pose) for g in batch),
            tuple(batch),
        )
        for batch in batches
    )


def goal_outcome(status: int, accepted: bool = True) -> GoalOutcome | None:
    """The outcome of a goal whose result came with ``status`` (a GoalStatus code); None while it
    is underway.  A goal the server did not accept is REJECTED, whatever the status."""
    if not accepted:
        return GoalOutcome.REJECTED
    if status in _UNDERWAY:
        return None
    if status not in _ENDS:
        raise ExsceError(f"{status} is no action_msgs/msg/GoalStatus code (0 to 6)")
    return _ENDS[status]


def waypoint_outcomes(
    status: int, count: int, missed: Iterable[int], current: int
) -> tuple[GoalOutcome | None, ...]:
    """Each waypoint's outcome of a ``FollowWaypoints`` goal of ``count`` waypoints that ended with
    ``status``, whose result listed the ``missed`` waypoints (indices from 0; Humble's
    ``int32[] missed_waypoints``, or the ``index`` of Jazzy's ``MissedWaypoint``) and whose last
    feedback's ``current_waypoint`` was ``current``.  A missed waypoint was ABORTED; one before
    ``current`` was reached (SUCCEEDED); when the goal succeeded every other one was reached;
    when it was aborted, the current one (if not missed) was ABORTED and those after it never
    sent (None); when it was cancelled, the current one was CANCELLED and those after it None."""
    outcome = goal_outcome(status)
    if outcome is None:
        raise ExsceError(f"a FollowWaypoints goal with status {status} has not ended")
    missing = set(missed)
    if any(not 0 <= i < count for i in missing):
        raise ExsceError(f"missed waypoints {sorted(missing)} outside the goal's {count} waypoints")
    ends: list[GoalOutcome | None] = []
    for index in range(count):
        if index in missing:
            ends.append(GoalOutcome.ABORTED)
        elif outcome is GoalOutcome.SUCCEEDED or index < current:
            ends.append(GoalOutcome.SUCCEEDED)
        elif index == current:
            ends.append(outcome)
        else:
            ends.append(None)
    return tuple(ends)


def _actions(scenario: Scenario, goals: tuple[Goal, ...]) -> dict[str, Nav2Actions]:
    robots = {r.id: r for r in scenario.robots}
    unknown = sorted({g.robot for g in goals} - robots.keys())
    if unknown:
        raise ExsceError(
            f"the schedule has goals for robots scenario '{scenario.id}' does not have: {unknown}"
        )
    return {robot: nav2_actions(robots[robot]) for robot in sorted({g.robot for g in goals})}


def _leaf(name: str) -> str:
    return name.rstrip("/").rsplit("/", 1)[-1]
