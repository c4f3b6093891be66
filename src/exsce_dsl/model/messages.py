"""The ROS message types a metric may read, and the fields exsce decodes from their raw bytes.

Field paths are the message definition's (``linear.x``, ``pose.pose.position.x``,
``ranges``); ROS 1 and ROS 2 names of a type are one (``geometry_msgs/Twist`` is
``geometry_msgs/msg/Twist``).  The waypoint dispatcher's feedback and result are
read as windows and successes (``elapsed``, ``succeeded``), not field by field.
"""

from __future__ import annotations

import enum
from typing import Union


class Leaf(enum.Enum):
    NUMBER = "a number"
    ARRAY = "an array of numbers"
    TEXT = "text"


Fields = dict[str, Union[Leaf, "Fields"]]

_VECTOR3: Fields = {"x": Leaf.NUMBER, "y": Leaf.NUMBER, "z": Leaf.NUMBER}
_QUATERNION: Fields = {"x": Leaf.NUMBER, "y": Leaf.NUMBER, "z": Leaf.NUMBER, "w": Leaf.NUMBER}
_HEADER: Fields = {"stamp": {"sec": Leaf.NUMBER, "nanosec": Leaf.NUMBER}, "frame_id": Leaf.TEXT}

TWIST = "geometry_msgs/msg/Twist"
POSE = "geometry_msgs/msg/PoseWithCovarianceStamped"
FLOAT64 = "std_msgs/msg/Float64"
SCAN = "sensor_msgs/msg/LaserScan"
FEEDBACK = "waypoint_dispatcher/msg/FollowWaypointsActionFeedback"
RESULT = "waypoint_dispatcher/msg/FollowWaypointsActionResult"

MESSAGES: dict[str, Fields] = {
    TWIST: {"linear": _VECTOR3, "angular": _VECTOR3},
    POSE: {
        "header": _HEADER,
        "pose": {
            "pose": {"position": _VECTOR3, "orientation": _QUATERNION},
            "covariance": Leaf.ARRAY,
        },
    },
    FLOAT64: {"data": Leaf.NUMBER},
    SCAN: {
        "header": _HEADER,
        "angle_min": Leaf.NUMBER,
        "angle_max": Leaf.NUMBER,
        "angle_increment": Leaf.NUMBER,
        "time_increment": Leaf.NUMBER,
        "scan_time": Leaf.NUMBER,
        "range_min": Leaf.NUMBER,
        "range_max": Leaf.NUMBER,
        "ranges": Leaf.ARRAY,
        "intensities": Leaf.ARRAY,
    },
}
"""Decoded types: each field and what it holds."""

DISPATCHER = (FEEDBACK, RESULT)
"""Read whole by the run's segmentation; a metric uses them through ``elapsed`` and ``succeeded``."""


def canonical_type(name: str) -> str:
    """``pkg/Type`` and ``pkg/msg/Type`` are one type; the ROS 2 spelling is kept."""
    package, _, rest = name.partition("/")
    return name if rest.startswith("msg/") else f"{package}/msg/{rest}"


def field_of(msgtype: str, path: tuple[str, ...]) -> Leaf | Fields | None:
    """What ``path`` names in ``msgtype`` (a leaf, or a sub-message), None if it does not exist."""
    node: Leaf | Fields = MESSAGES[msgtype]
    for part in path:
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


def leaf_paths(msgtype: str) -> dict[str, Leaf]:
    """Every leaf of ``msgtype`` by its dotted path."""
    found: dict[str, Leaf] = {}

    def visit(node: Fields, prefix: str) -> None:
        for name, child in node.items():
            if isinstance(child, dict):
                visit(child, f"{prefix}{name}.")
            else:
                found[f"{prefix}{name}"] = child

    visit(MESSAGES[msgtype], "")
    return found
