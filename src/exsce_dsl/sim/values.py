"""Message values built in a rosbags typestore: stamps, headers, poses and transforms.

The same calls build ROS 1 and ROS 2 values: only a ROS 1 ``std_msgs/Header`` has a ``seq``.
Poses are planar (a heading, no roll or pitch), as the executor drives them.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from exsce_dsl.sim.motion import DT


def sample_stamps(start_ns: int, samples: int) -> np.ndarray:
    """The stamp (ns) of each sample of the executor's clock."""
    stamps: np.ndarray = start_ns + (np.arange(samples) * DT * 1e9).astype(np.int64)
    return stamps


def ros_time(store: Any, ns: int) -> Any:
    return store.types["builtin_interfaces/msg/Time"](sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def duration(store: Any, seconds: float) -> Any:
    ns = max(int(round(seconds * 1e9)), 0)
    return store.types["builtin_interfaces/msg/Duration"](sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def header(store: Any, ns: int, frame: str, seq: int = 0) -> Any:
    kind = store.types["std_msgs/msg/Header"]
    if "seq" in kind.__dataclass_fields__:
        return kind(seq=seq, stamp=ros_time(store, ns), frame_id=frame)
    return kind(stamp=ros_time(store, ns), frame_id=frame)


def quaternion(store: Any, yaw: float) -> Any:
    return store.types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))


def pose(store: Any, x: float, y: float, yaw: float, z: float = 0.0) -> Any:
    return store.types["geometry_msgs/msg/Pose"](
        position=store.types["geometry_msgs/msg/Point"](x=float(x), y=float(y), z=float(z)),
        orientation=quaternion(store, float(yaw)),
    )


def pose_stamped(store: Any, ns: int, frame: str, x: float, y: float, yaw: float, z: float = 0.0) -> Any:
    return store.types["geometry_msgs/msg/PoseStamped"](
        header=header(store, ns, frame), pose=pose(store, x, y, yaw, z)
    )


def vector(store: Any, x: float = 0.0, y: float = 0.0, z: float = 0.0) -> Any:
    return store.types["geometry_msgs/msg/Vector3"](x=float(x), y=float(y), z=float(z))


def twist(store: Any, v: float, w: float) -> Any:
    """A planar body twist: ``v`` forward (m/s), ``w`` about z (rad/s)."""
    return store.types["geometry_msgs/msg/Twist"](linear=vector(store, x=v), angular=vector(store, z=w))


def transform(
    store: Any, ns: int, parent: str, child: str, x: float, y: float, yaw: float, z: float = 0.0, seq: int = 0
) -> Any:
    """``geometry_msgs/TransformStamped``: the pose of ``child`` in ``parent``."""
    return store.types["geometry_msgs/msg/TransformStamped"](
        header=header(store, ns, parent, seq),
        child_frame_id=child,
        transform=store.types["geometry_msgs/msg/Transform"](
            translation=vector(store, x, y, z), rotation=quaternion(store, float(yaw))
        ),
    )
