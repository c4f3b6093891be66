"""Message values built in a rosbags typestore: stamps, headers, poses and transforms.

The same calls build ROS 1 and ROS 2 values: only a ROS 1 ``std_msgs/Header`` has a ``seq``.
Poses are planar (a heading, no roll or pitch), as the executor drives them.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from exsce_dsl.sim.motion import DT


def sample_stamps(start_ns: int, samples: int, dt: float = DT) -> np.ndarray:
    """The stamp (ns) of each sample of the executor's clock (``dt`` seconds apart)."""
    stamps: np.ndarray = start_ns + (np.arange(samples) * dt * 1e9).astype(np.int64)
    return stamps


def samples_per(period: float, dt: float) -> int:
    """How many samples ``dt`` apart make a topic's ``period`` (at least one: a topic is never
    published faster than the run is sampled)."""
    return max(1, int(round(period / dt)))


def ros_time(store: Any, ns: int) -> Any:
    return store.types["builtin_interfaces/msg/Time"](sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def duration(store: Any, seconds: float) -> Any:
    ns = max(int(round(seconds * 1e9)), 0)
    return store.types["builtin_interfaces/msg/Duration"](sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def header(store: Any, ns: int, frame: str, seq: int = 0) -> Any:
    return header_at(store, ns // 1_000_000_000, ns % 1_000_000_000, frame, seq)


def header_at(store: Any, sec: int, nanosec: int, frame: str, seq: int = 0) -> Any:
    """A header stamped ``sec`` s + ``nanosec`` ns (the ``seq`` only where the header has one)."""
    kind = store.types["std_msgs/msg/Header"]
    stamp = store.types["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec)
    if "seq" in kind.__dataclass_fields__:
        return kind(seq=seq, stamp=stamp, frame_id=frame)
    return kind(stamp=stamp, frame_id=frame)


def planar_rotation(store: Any, qz: float, qw: float) -> Any:
    """The quaternion of a heading, given as its ``z`` and ``w`` (see :func:`heading_columns`)."""
    return store.types["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=qz, w=qw)


def heading_columns(yaw: np.ndarray) -> dict[str, np.ndarray]:
    """``qz`` and ``qw`` of each heading, by ``math`` as :func:`quaternion` computes them (numpy's
    sine may differ in the last bit)."""
    return {
        "qz": np.array([math.sin(a / 2) for a in yaw.tolist()], dtype="<f8"),
        "qw": np.array([math.cos(a / 2) for a in yaw.tolist()], dtype="<f8"),
    }


def quaternion(store: Any, yaw: float) -> Any:
    return planar_rotation(store, math.sin(yaw / 2), math.cos(yaw / 2))


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
    rotation = quaternion(store, float(yaw))
    sec, nanosec = ns // 1_000_000_000, ns % 1_000_000_000
    return transform_at(store, sec, nanosec, parent, child, float(x), float(y), rotation, float(z), seq)


def transform_at(
    store: Any,
    sec: int,
    nanosec: int,
    parent: str,
    child: str,
    x: float,
    y: float,
    rotation: Any,
    z: float = 0.0,
    seq: int = 0,
) -> Any:
    """:func:`transform` stamped ``sec`` s + ``nanosec`` ns, its rotation given as a quaternion."""
    T = store.types
    return T["geometry_msgs/msg/TransformStamped"](
        header=header_at(store, sec, nanosec, parent, seq),
        child_frame_id=child,
        transform=T["geometry_msgs/msg/Transform"](translation=vector(store, x, y, z), rotation=rotation),
    )
