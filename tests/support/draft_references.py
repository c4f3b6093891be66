"""What a bag says of one robot, read with rosbags alone: the references that a specification
drafted from the bag (``exscec init --from-bag``) and the run ingested under it must meet.

- ``targets``: the robot's navigation goals' targets in recorded order: a move_base goal's
  target pose; for Nav2, the last pose of the first plan published while the goal was under way;
  for the method's dispatcher (whose messages carry no poses), where ``robot_pose`` had the robot
  when each waypoint first SUCCEEDED;
- ``duration`` and ``distance``: from the first goal that went active to the last goal's first
  SUCCEEDED (log times), the odometry's path length in that window (the method: the change of
  ``distance_travelled``, interpolated at the window's ends); without goals, the span and path length of the robot's whole recording.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.highlevel import AnyReader

NAV2_EXECUTING, NAV2_SUCCEEDED = 2, 4  # action_msgs/msg/GoalStatus
ACTIONLIB_ACTIVE, ACTIONLIB_SUCCEEDED = 1, 3  # actionlib_msgs/msg/GoalStatus


@dataclass(frozen=True)
class Reference:
    targets: list[tuple[float, float]]
    duration: float
    distance: float


def read(bag: Path) -> dict[str, list[tuple[float, Any]]]:
    """Every topic's messages (log time in seconds, message), deserialised by rosbags."""
    found: dict[str, list[tuple[float, Any]]] = {}
    with AnyReader([bag]) as reader:
        for connection, t, raw in reader.messages():
            found.setdefault(connection.topic, []).append(
                (t * 1e-9, reader.deserialize(raw, connection.msgtype))
            )
    return found


def _name(ns: str, topic: str) -> str:
    return f"/{ns}/{topic}" if ns else f"/{topic}"


def _xy(pose: Any) -> tuple[float, float]:
    return float(pose.position.x), float(pose.position.y)


def path_length(points: list[tuple[float, float]]) -> float:
    xy = np.array(points)
    return float(np.sum(np.hypot(*np.diff(xy, axis=0).T))) if len(xy) > 1 else 0.0


def _window(pairs: list[tuple[float, Any]], start: float, end: float) -> list[Any]:
    return [m for t, m in pairs if start <= t <= end]


def reference(bag: Path, ns: str, convention: str) -> Reference:
    """The robot of namespace ``ns`` (``""``: the root) in a bag of ``convention``."""
    topics = read(bag)
    if convention == "method":
        return _method(topics, ns)
    if convention == "nav2":
        status = topics[_name(ns, "navigate_to_pose/_action/status")]
        key, active, done = (lambda s: bytes(s.goal_info.goal_id.uuid)), NAV2_EXECUTING, NAV2_SUCCEEDED
    else:
        status = topics[_name(ns, "move_base/status")]
        key, active, done = (lambda s: s.goal_id.id), ACTIONLIB_ACTIVE, ACTIONLIB_SUCCEEDED
    first: dict[Any, float] = {}
    succeeded: dict[Any, float] = {}
    for t, message in status:
        for s in message.status_list:
            first.setdefault(key(s), t)
            if s.status == done:
                succeeded.setdefault(key(s), t)
    start = min(t for t, m in status if any(s.status == active for s in m.status_list))
    end = max(succeeded.values())
    if convention == "nav2":
        plans = topics[_name(ns, "plan")]
        targets = []
        for goal, seen in sorted(first.items(), key=lambda kv: kv[1]):
            plan = next(m for t, m in plans if seen <= t <= succeeded[goal] and len(m.poses))
            targets.append(_xy(plan.poses[-1].pose))
    else:
        targets = [_xy(m.goal.target_pose.pose) for _, m in topics[_name(ns, "move_base/goal")]]
    odom = [_xy(m.pose.pose) for m in _window(topics[_name(ns, "odom")], start, end)]
    return Reference(targets, end - start, path_length(odom))


def _method(topics: dict[str, list[tuple[float, Any]]], ns: str) -> Reference:
    feedback = topics[_name(ns, "waypoint_dispatcher/feedback")]
    poses = topics[_name(ns, "robot_pose")]
    succeeded: dict[str, float] = {}
    for t, message in feedback:
        for s in message.feedback.goal_status.status_list:
            if s.status == ACTIONLIB_SUCCEEDED:
                succeeded.setdefault(s.goal_id.id, t)
    start = min(
        t
        for t, m in feedback
        if any(s.status == ACTIONLIB_ACTIVE for s in m.feedback.goal_status.status_list)
    )
    end = max(succeeded.values())
    targets = []
    for t in sorted(succeeded.values()):
        latest = [m for u, m in poses if u <= t][-1]
        targets.append(_xy(latest.pose.pose))
    travelled = topics[_name(ns, "distance_travelled")]  # the change: its values at the ends, interpolated
    ends = np.interp([start, end], [t for t, _ in travelled], [m.data for _, m in travelled])
    return Reference(targets, end - start, float(ends[1] - ends[0]))


def whole_path(bag: Path, pose_topic: str, signal_topics: list[str]) -> Reference:
    """A robot without goals: its path along ``pose_topic`` (an Odometry or PoseStamped), over the
    whole recording of its ``signal_topics`` (pose, velocity...); its start, farthest point and end
    as targets."""
    topics = read(bag)
    pose_of = lambda m: m.pose.pose if hasattr(m.pose, "pose") else m.pose  # noqa: E731
    points = [_xy(pose_of(m)) for _, m in topics[pose_topic]]
    xy = np.array(points)
    far = int(np.argmax(np.hypot(*(xy - xy[0]).T)))
    times = [t for name in signal_topics for t, _ in topics[name]]
    return Reference([points[0], points[far], points[-1]], max(times) - min(times), path_length(points))
