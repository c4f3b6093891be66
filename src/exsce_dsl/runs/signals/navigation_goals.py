"""A robot's navigation goals as its stack recorded them: Nav2's actions and ROS 1 move_base's.

Few messages (a status array a second and at each change), so they are read as
message objects (:data:`~exsce_dsl.runs.bags.reading.OBJECTS`, each distinct one once)
and walked here into :class:`RecordedGoal`\\ s, in receive
time.  (A global plan is long, but rosbags deserializes its poses faster than the
vectorised decoder walks them one element index at a time, for a plan a chunk.)

- **Nav2** (``navigate_to_pose``, ``navigate_through_poses``, ``follow_waypoints``):
  ``ACTION/_action/status`` (action_msgs/GoalStatusArray: each goal's UUID and status)
  says when each goal was accepted, executed and ended; ``follow_waypoints``'
  feedback ``current_waypoint`` says which of its poses the robot was going to.  No
  action topic carries the goal's target: it is taken from the global plan the
  planner published while the goal executed (``/{ns}/plan``, nav_msgs/Path: its
  last pose), else left to the segmentation (where the robot was when it succeeded).
- **move_base** (actionlib): ``move_base/goal`` carries each goal's id and target
  pose, ``move_base/status`` (actionlib_msgs/GoalStatusArray) its statuses.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from exsce_dsl.model.conventions import Navigation, Signals
from exsce_dsl.model.goals import ACTION_FINAL, ACTIONLIB_FINAL, action_names, actionlib_names
from exsce_dsl.model.metrics import expand_topic
from exsce_dsl.runs.bags.data import OBJECTS, BagData, Wanted
from exsce_dsl.runs.signals.dispatcher_statuses import dispatcher_wanted
from exsce_dsl.runs.signals.tf_poses import yaw_from_quaternion

XYYaw = tuple[float, float, float]


@dataclass(frozen=True)
class RecordedGoal:
    """One navigation goal of a robot, as read from its bag (times in seconds since the epoch)."""

    key: str  # the goal's id (a Nav2 UUID as hex, a move_base goal id string)
    accepted: float | None  # first seen (accepted / pending)
    started: float | None  # became active / executing
    ended: float | None  # reached a final status
    status: str  # final: SUCCEEDED, ABORTED, CANCELED, PREEMPTED, REJECTED, ... or ACTIVE (never ended)
    target: XYYaw | None = None  # x, y, yaw of a one-pose goal, when the bag says it
    progress: tuple[tuple[int, float], ...] = ()
    """follow_waypoints: each ``current_waypoint`` the feedback reported and when it first did."""
    targets: tuple[XYYaw | None, ...] = ()
    """follow_waypoints: the goal's poses by index, where the bag says them."""
    missed: tuple[int, ...] = ()
    """follow_waypoints: the result's missed waypoint indices."""

    @property
    def first_seen(self) -> float | None:
        return next((t for t in (self.accepted, self.started, self.ended) if t is not None), None)

    @property
    def follows_waypoints(self) -> bool:
        return bool(self.progress or self.targets)


NAV2_STATUS = action_names()
NAV2_FINAL: set[int] = {int(s) for s in ACTION_FINAL}
MOVE_BASE_STATUS = actionlib_names()
MOVE_BASE_FINAL: set[int] = {int(s) for s in ACTIONLIB_FINAL}
PLAN = "/{ns}/plan"

Messages = Sequence[tuple[float, Any]]


def goal_wanted(signals: Signals, namespace: str) -> dict[str, Wanted]:
    """What the robot's navigation goals are read from, all as message objects (few: a status
    array a second and at each change, a plan per goal or replanning); the method's dispatcher's
    are its feedback and result (:mod:`~exsce_dsl.runs.signals.dispatcher_statuses`)."""
    if signals.navigation is Navigation.DISPATCHER:
        return dispatcher_wanted(namespace)
    actions = [expand_topic(a, namespace) for a in signals.actions]
    if signals.navigation is Navigation.NAV2:
        found = [f"{a}/_action/status" for a in actions]
        found += [f"{a}/_action/feedback" for a in actions if _follows_waypoints(a)]
        return {t: Wanted(OBJECTS) for t in [*found, expand_topic(PLAN, namespace)]}
    if signals.navigation is Navigation.MOVE_BASE:
        return {f"{a}/{part}": Wanted(OBJECTS) for a in actions for part in ("goal", "status", "result")}
    return {}


def read_goals(signals: Signals, namespace: str, data: BagData) -> tuple[list[RecordedGoal], list[str]]:
    """The robot's goals from the bag's messages, and the topics they came from."""
    messages = data.messages
    actions = [expand_topic(a, namespace) for a in signals.actions]
    goals: list[RecordedGoal] = []
    used: list[str] = []
    for action in actions:
        if signals.navigation is Navigation.NAV2:
            status = messages.get(f"{action}/_action/status")
            if not status:
                continue
            feedback = messages.get(f"{action}/_action/feedback", []) if _follows_waypoints(action) else []
            plans = messages.get(expand_topic(PLAN, namespace), [])
            goals += _nav2_goals(status, feedback, plans)
            used += [f"{action}/_action/status"] + (
                [expand_topic(PLAN, namespace)] if plans is not None else []
            )
        elif signals.navigation is Navigation.MOVE_BASE:
            status = messages.get(f"{action}/status")
            if not status:
                continue
            targets = {
                _move_base_key(m.goal_id): _xy_yaw(m.goal.target_pose.pose)
                for _, m in messages.get(f"{action}/goal", [])
            }
            goals += _statuses(
                status,
                lambda entry: _move_base_key(entry.goal_id),
                MOVE_BASE_STATUS,
                MOVE_BASE_FINAL,
                started_at={1},
                targets=targets,
            )
            used += [f"{action}/status"] + ([f"{action}/goal"] if targets else [])
    return sorted(goals, key=lambda g: (g.first_seen or 0.0, g.key)), used


def _follows_waypoints(action: str) -> bool:
    """Whether the action's feedback says which pose it goes to (only follow_waypoints' does:
    the others' feedback, five times a second, is not read)."""
    return action.rsplit("/", 1)[-1] == "follow_waypoints"


def _move_base_key(goal_id: Any) -> str:
    return str(goal_id.id)


def _nav2_goals(status: Messages, feedback: Messages, plans: Messages) -> list[RecordedGoal]:
    progress: dict[str, list[tuple[int, float]]] = {}
    for t, message in feedback:
        current = getattr(message.feedback, "current_waypoint", None)
        if current is None:
            continue
        steps = progress.setdefault(_uuid(message.goal_id), [])
        if not steps or steps[-1][0] != int(current):
            steps.append((int(current), t))
    goals = _statuses(
        status,
        lambda entry: _uuid(entry.goal_info.goal_id),
        NAV2_STATUS,
        NAV2_FINAL,
        started_at={2},
        targets={},
    )
    found = []
    for goal in goals:
        reported = tuple(progress.get(goal.key, ()))
        target = None if reported else _plan_target(plans, goal)
        found.append(
            RecordedGoal(goal.key, goal.accepted, goal.started, goal.ended, goal.status, target, reported)
        )
    return found


def _statuses(
    status: Messages,
    key_of: Any,
    names: Mapping[int, str],
    final: set[int],
    started_at: set[int],
    targets: Mapping[str, tuple[float, float, float]],
) -> list[RecordedGoal]:
    """Goals from status arrays: when each was first seen, became active and reached a final status."""
    seen: dict[str, dict[str, Any]] = {}
    for t, message in status:
        for entry in message.status_list:
            key = key_of(entry)
            goal = seen.setdefault(key, {"accepted": t, "started": None, "ended": None, "status": "ACTIVE"})
            code = int(entry.status)
            if code in started_at and goal["started"] is None:
                goal["started"] = t
            if code in final and goal["ended"] is None:
                goal["ended"], goal["status"] = t, names.get(code, str(code))
    return [
        RecordedGoal(key, g["accepted"], g["started"], g["ended"], g["status"], targets.get(key))
        for key, g in seen.items()
    ]


def _plan_target(plans: Messages, goal: RecordedGoal) -> tuple[float, float, float] | None:
    """The last pose of the first global plan published while the goal was under way."""
    begin = goal.accepted if goal.accepted is not None else goal.started
    if begin is None:
        return None
    end = goal.ended if goal.ended is not None else float("inf")
    for t, plan in plans:
        if begin <= t <= end and len(plan.poses):
            return _xy_yaw(plan.poses[-1].pose)
    return None


def _uuid(goal_id: Any) -> str:
    return bytes(np.asarray(goal_id.uuid, dtype=np.uint8)).hex()


def _xy_yaw(pose: Any) -> tuple[float, float, float]:
    q = pose.orientation
    yaw = float(yaw_from_quaternion(np.array([[q.x, q.y, q.z, q.w]]))[0])
    return float(pose.position.x), float(pose.position.y), yaw
